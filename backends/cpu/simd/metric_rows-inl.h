// The paper metric (shaders/pyr_metric.h), over the quant words and, for the fused front end, over QuantRows.
// Included by cpu_simd.cpp inside each target's namespace, once per target (foreach_target.h): no include guard.
// NOLINTBEGIN(llvm-header-guard)

// Per pixel the scalar code sums qn . qn_j over the valid 8-neighbours j and takes the smallest and largest |z - z_j|.
// The sum is computed as qn . (sum of the valid neighbours' qn): the same integer, as integer arithmetic is exact
// and no partial sum overflows (|sum of qn_j| <= 8 * 2^13, so each product is below 2^29 and their sum below 2^31).
// The neighbours' sums come from column sums (three rows) of qn masked by validity: the 3 x 3 box less the pixel.
// A row is handled in chunks: its three quant rows are unpacked, per pixel, into column sums, the middle row's qn,
// and each row's depth and validity.

// Pixels per chunk (with one more on either side).
constexpr std::size_t kMetricChunk = 128;
constexpr std::size_t kMetricSpan = kMetricChunk + 2;

// The n quantized pixels whose words start at `words` (store_quant): qn (0 where not valid), validity (-1 where
// valid, else 0) and depth.
HWY_INLINE void load_quant(const std::uint32_t* words, VI& qx, VI& qy, VI& qz, VI& valid, VF& z) {
    const DF df;
    const DI di;
    const DU du;
    VU w0, w1, w2;  // NOLINT(readability-isolate-declaration)
    hn::LoadInterleaved3(du, words, w0, w1, w2);
    const VI i0 = hn::BitCast(di, w0);
    const VI i1 = hn::BitCast(di, w1);
    const MI is_valid = hn::RebindMask(di, hn::Ne(hn::ShiftRight<16>(w1), hn::Zero(du)));
    qx = hn::IfThenElseZero(is_valid, hn::ShiftRight<16>(hn::ShiftLeft<16>(i0)));  // sign-extended halves
    qy = hn::IfThenElseZero(is_valid, hn::ShiftRight<16>(i0));
    qz = hn::IfThenElseZero(is_valid, hn::ShiftRight<16>(hn::ShiftLeft<16>(i1)));
    valid = hn::VecFromMask(di, is_valid);
    z = hn::BitCast(df, w2);
}

// One chunk of a row, unpacked. Index i is the pixel begin - 1 + i.
struct MetricChunk {
    HWY_ALIGN std::int32_t column[4][kMetricSpan];  // column sums of qx, qy, qz (masked) and of validity (-count)
    HWY_ALIGN std::int32_t middle[4][kMetricSpan];  // the middle row's qx, qy, qz (masked) and validity
    HWY_ALIGN std::int32_t valid[3][kMetricSpan];   // each row's validity, -1 or 0
    HWY_ALIGN float z[3][kMetricSpan];              // each row's depth
};

// pyr_metric_fillable for the pixels begin + i .. begin + i + n - 1, which have both horizontal neighbours.
HWY_INLINE void metric_vector(const MetricChunk& m, const bool has_row[3], std::size_t i, std::int32_t tc, float dt,
                              std::uint8_t* out) {
    const DF df;
    const DI di;
    const hn::Rebind<std::uint8_t, DI> d8;
    const std::size_t c = i + 1;  // the pixel itself
    // The 3 x 3 box of field f less the pixel itself.
    const auto neighbours = [&](int f) {
        const VI box = hn::Add(hn::Add(hn::LoadU(di, m.column[f] + c - 1), hn::LoadU(di, m.column[f] + c)),
                               hn::LoadU(di, m.column[f] + c + 1));
        return hn::Sub(box, hn::LoadU(di, m.middle[f] + c));
    };
    const VI qx = hn::LoadU(di, m.middle[0] + c);
    const VI qy = hn::LoadU(di, m.middle[1] + c);
    const VI qz = hn::LoadU(di, m.middle[2] + c);
    const VI s = hn::Add(hn::Add(hn::Mul(qx, neighbours(0)), hn::Mul(qy, neighbours(1))), hn::Mul(qz, neighbours(2)));
    const VI k = hn::Neg(neighbours(3));  // 0..8
    // Both depths are finite where both pixels are valid: |dz| is then finite and >= 0, and Min / Max are the scalar
    // code's comparisons. Invalid neighbours leave dmin and dmax as they are.
    const VF z = hn::LoadU(df, m.z[1] + c);
    VF dmin = hn::Set(df, hwy::HighestValue<float>());
    VF dmax = hn::Zero(df);
    for (int row = 0; row < 3; ++row) {
        if (!has_row[row]) continue;
        for (std::size_t j = c - 1; j <= c + 1; ++j) {
            if (row == 1 && j == c) continue;
            const auto use = hn::MaskFromVec(hn::BitCast(df, hn::LoadU(di, m.valid[row] + j)));
            const VF dd = hn::Abs(hn::Sub(z, hn::LoadU(df, m.z[row] + j)));
            dmin = hn::IfThenElse(use, hn::Min(dmin, dd), dmin);
            dmax = hn::IfThenElse(use, hn::Max(dmax, dd), dmax);
        }
    }
    // k * tc fits int32: k <= 8, tc in [-2^28, 2^26].
    const MI curvature_ok = hn::Not(hn::Lt(s, hn::Mul(k, hn::Set(di, tc))));
    const MI depth_ok = hn::RebindMask(di, hn::Le(hn::Sub(dmax, dmin), hn::Set(df, dt)));
    const MI center_valid = hn::Ne(hn::LoadU(di, m.middle[3] + c), hn::Zero(di));
    const MI fillable = hn::And(hn::And(center_valid, hn::Gt(k, hn::Zero(di))), hn::And(curvature_ok, depth_ok));
    hn::StoreU(hn::DemoteTo(d8, hn::IfThenElseZero(fillable, hn::Set(di, 1))), d8, out);
}

void metric_row(const PassContext& c, std::uint32_t w, std::uint32_t h, std::uint32_t y, std::int32_t tc, float dt,
                std::uint8_t* out) {
    const DF df;
    const DI di;
    const std::size_t n = hn::Lanes(df);
    const auto scalar = [&](std::uint32_t x) {
        out[x] = std::uint8_t(pixel::pyr_metric_fillable(c, w, h, x, y, tc, dt));
    };
    if (std::size_t(w) < n + 2 || n > kMetricChunk) {
        for (std::uint32_t x = 0; x < w; ++x) scalar(x);
        return;
    }
    scalar(0);
    scalar(w - 1);
    const bool has_row[3] = {y > 0, true, std::size_t(y) + 1 < h};
    const std::uint32_t* source[3];
    for (int k = 0; k < 3; ++k) {
        source[k] = c.quant + kQuantWords * std::size_t(has_row[k] ? y - 1 + std::uint32_t(k) : y) * w;
    }
    // Scratch: each chunk writes every element it reads first (zeroing it would cost a pass over 10 KiB a row).
    MetricChunk m;  // NOLINT(cppcoreguidelines-pro-type-member-init)
    // Pixels 1 .. w - 2 in chunks; a chunk narrower than a vector starts earlier (recomputing some pixels).
    for (std::size_t x0 = 1; x0 < std::size_t(w) - 1; x0 += kMetricChunk) {
        const std::size_t x1 = std::min(x0 + kMetricChunk, std::size_t(w) - 1);
        const std::size_t begin = std::min(x0, x1 - n);
        const std::size_t span = x1 - begin + 2;  // pixels begin - 1 .. x1
        // Every store below is a function of the words at i only: the last, overlapping vector rewrites the same.
        for (std::size_t i = 0;; i += n) {
            i = std::min(i, span - n);
            VI cx, cy, cz, cv, qx, qy, qz, valid;  // NOLINT(readability-isolate-declaration)
            VF z;
            load_quant(source[1] + kQuantWords * (begin - 1 + i), cx, cy, cz, cv, z);
            hn::StoreU(cx, di, m.middle[0] + i);
            hn::StoreU(cy, di, m.middle[1] + i);
            hn::StoreU(cz, di, m.middle[2] + i);
            hn::StoreU(cv, di, m.middle[3] + i);
            hn::StoreU(cv, di, m.valid[1] + i);
            hn::StoreU(z, df, m.z[1] + i);
            for (int k = 0; k < 3; k += 2) {
                if (!has_row[k]) continue;
                load_quant(source[k] + kQuantWords * (begin - 1 + i), qx, qy, qz, valid, z);
                cx = hn::Add(cx, qx);
                cy = hn::Add(cy, qy);
                cz = hn::Add(cz, qz);
                cv = hn::Add(cv, valid);
                hn::StoreU(valid, di, m.valid[k] + i);
                hn::StoreU(z, df, m.z[k] + i);
            }
            hn::StoreU(cx, di, m.column[0] + i);
            hn::StoreU(cy, di, m.column[1] + i);
            hn::StoreU(cz, di, m.column[2] + i);
            hn::StoreU(cv, di, m.column[3] + i);
            if (i + n >= span) break;
        }
        for (std::size_t x = begin;; x += n) {
            x = std::min(x, x1 - n);
            metric_vector(m, has_row, x - begin, tc, dt, out + x);
            if (x + n >= x1) break;
        }
    }
}

// pyr_metric_fillable of pixel x from unpacked rows (rows[1] its own, rows[0] / rows[2] above / below or null): the
// shared function on the image's part of the pixel's 3 x 3 box, packed into store_quant's words as an image of its
// own, whose borders are the image's wherever the box meets them (so every neighbour test is the same).
std::uint8_t metric_pixel(const QuantRow* const rows[3], std::uint32_t w, std::uint32_t x, std::int32_t tc, float dt) {
    std::uint32_t words[9 * kQuantWords];
    const std::uint32_t x0 = x > 0 ? x - 1 : 0;
    const std::uint32_t x1 = std::min(w, x + 2);
    const std::uint32_t box_w = x1 - x0;
    std::uint32_t box_h = 0;
    std::uint32_t box_y = 0;
    for (int k = 0; k < 3; ++k) {
        const QuantRow* row = rows[k];
        if (row == nullptr) continue;
        if (k == 1) box_y = box_h;
        for (std::uint32_t i = x0; i < x1; ++i) {
            store_quant(words + kQuantWords * (std::size_t(box_h) * box_w + (i - x0)), row->q[0][i], row->q[1][i],
                        row->q[2][i], std::uint32_t(row->valid[i]), row->z[i]);
        }
        ++box_h;
    }
    PassContext c;
    c.quant = words;
    return std::uint8_t(pixel::pyr_metric_fillable(c, box_w, box_h, x - x0, box_y, tc, dt));
}

// pyr_metric_fillable for the pixels x .. x + n - 1 of a row, which have both horizontal neighbours, from the
// unpacked rows (metric_vector's arithmetic): qn . (the 3 x 3 box of sums less the pixel's own qn), k from the
// validity sums; each neighbour's |z - z_j| once. A neighbour that is not valid has z_j = +infinity: |z - z_j| is
// +infinity where the pixel is valid (z finite), which leaves dmin as it is (Min with +infinity is exact on every
// target, like Min of finite values), and dmax takes only the valid ones. In lanes whose pixel is not valid
// (z = +infinity) the depths may be NaN; the result there is 0 whatever they are.
template <bool kAbove, bool kBelow>
HWY_INLINE void metric_quant_vector(const QuantRow& above, const QuantRow& row, const QuantRow& below, std::size_t x,
                                    VI tc, VF dt, std::uint8_t* out) {
    const DF df;
    const DI di;
    const hn::Rebind<std::uint8_t, DI> d8;
    const auto box = [&](int f) {
        VI s = hn::LoadU(di, row.sum[f] + x);
        if constexpr (kAbove) s = hn::Add(s, hn::LoadU(di, above.sum[f] + x));
        if constexpr (kBelow) s = hn::Add(s, hn::LoadU(di, below.sum[f] + x));
        return s;
    };
    const VI qx = hn::LoadU(di, row.q[0] + x);
    const VI qy = hn::LoadU(di, row.q[1] + x);
    const VI qz = hn::LoadU(di, row.q[2] + x);
    const VI s = hn::Add(hn::Add(hn::Mul(qx, hn::Sub(box(0), qx)), hn::Mul(qy, hn::Sub(box(1), qy))),
                         hn::Mul(qz, hn::Sub(box(2), qz)));
    const VI valid = hn::LoadU(di, row.valid + x);
    const VI k = hn::Sub(box(3), valid);  // 0..8
    const VF z = hn::LoadU(df, row.z + x);
    const VF inf = hn::Set(df, std::numeric_limits<float>::infinity());
    VF dmin = inf;
    VF dmax = hn::Zero(df);
    const auto neighbour = [&](const float* at) {
        const VF zj = hn::LoadU(df, at);
        const VF dd = hn::Abs(hn::Sub(z, zj));
        dmin = hn::Min(dmin, dd);
        dmax = hn::IfThenElse(hn::Lt(zj, inf), hn::Max(dmax, dd), dmax);
    };
    if constexpr (kAbove) {
        neighbour(above.z + x - 1);
        neighbour(above.z + x);
        neighbour(above.z + x + 1);
    }
    neighbour(row.z + x - 1);
    neighbour(row.z + x + 1);
    if constexpr (kBelow) {
        neighbour(below.z + x - 1);
        neighbour(below.z + x);
        neighbour(below.z + x + 1);
    }
    // k * tc fits int32: k <= 8, tc in [-2^28, 2^26].
    const MI curvature_ok = hn::Not(hn::Lt(s, hn::Mul(k, tc)));
    const MI depth_ok = hn::RebindMask(di, hn::Le(hn::Sub(dmax, dmin), dt));
    const MI fillable =
        hn::And(hn::And(hn::Ne(valid, hn::Zero(di)), hn::Gt(k, hn::Zero(di))), hn::And(curvature_ok, depth_ok));
    hn::StoreU(hn::DemoteTo(d8, hn::IfThenElseZero(fillable, hn::Set(di, 1))), d8, out + x);
}

template <bool kAbove, bool kBelow>
void metric_quant_vectors(const QuantRow* above, const QuantRow& row, const QuantRow* below, std::uint32_t w,
                          std::int32_t tc, float dt, std::uint8_t* out, const ReadAhead& ahead) {
    const DF df;
    const DI di;
    const std::size_t n = hn::Lanes(df);
    const VI tcv = hn::Set(di, tc);
    const VF dtv = hn::Set(df, dt);
    // The rows' pointers in locals, which the stores cannot change; a row outside the image is not read.
    const QuantRow a = kAbove ? *above : row;
    const QuantRow m = row;
    const QuantRow b = kBelow ? *below : row;
    ReadingAhead reading(ahead, 1, std::size_t(w) - 1, n);
    for_vectors(1, std::size_t(w) - 1, n, [&](std::size_t x) {
        reading.step();
        metric_quant_vector<kAbove, kBelow>(a, m, b, x, tcv, dtv, out);
    });
}

void metric_quant_row(const QuantRow* above, const QuantRow& row, const QuantRow* below, std::uint32_t w,
                      std::int32_t tc, float dt, std::uint8_t* out, const ReadAhead& ahead) {
    const QuantRow* const rows[3] = {above, &row, below};
    // Pixels 1 .. w - 2 by vectors where the rows have their sums (sum_quant_row), the others the scalar code's.
    if (std::size_t(w) < hn::Lanes(DF()) + 2) {
        for (std::uint32_t x = 0; x < w; ++x) out[x] = metric_pixel(rows, w, x, tc, dt);
        return;
    }
    out[0] = metric_pixel(rows, w, 0, tc, dt);
    out[w - 1] = metric_pixel(rows, w, w - 1, tc, dt);
    if (above != nullptr && below != nullptr) {
        metric_quant_vectors<true, true>(above, row, below, w, tc, dt, out, ahead);
    } else if (above != nullptr) {
        metric_quant_vectors<true, false>(above, row, below, w, tc, dt, out, ahead);
    } else if (below != nullptr) {
        metric_quant_vectors<false, true>(above, row, below, w, tc, dt, out, ahead);
    } else {
        metric_quant_vectors<false, false>(above, row, below, w, tc, dt, out, ahead);
    }
}

// NOLINTEND(llvm-header-guard)
