// The fused front end's rows (backends/cpu/points_to_mask.hpp; cpu_simd.hpp: PointRow, QuantRow): points split into
// structures of arrays, and the paper metric's normals with their quantized pixels unpacked.
// Included by cpu_simd.cpp inside each target's namespace, once per target (foreach_target.h): no include guard.
// NOLINTBEGIN(llvm-header-guard)

// f(x) for vectors of n pixels from x covering begin .. end - 1 (end - begin >= n): the first at begin, the next ones
// at multiples of n (where the rows' arrays start on a cache line, loads at x then do not straddle two), the last
// ending at end. They overlap: f must write the same wherever they do.
template <class F>
HWY_INLINE void for_vectors(std::size_t begin, std::size_t end, std::size_t n, const F& f) {
    f(begin);
    if (begin + n >= end) return;
    for (std::size_t x = (begin / n + 1) * n; x < end; x += n) f(std::min(x, end - n));
}

// A ReadAhead's lines, spread over the vectors of for_vectors(begin, end, n): step() with each vector reads the next
// few (for_vectors calls f at least (end - begin) / n times, rounded up).
class ReadingAhead {
public:
    ReadingAhead(const ReadAhead& ahead, std::size_t begin, std::size_t end, std::size_t n)
        : ahead_(ahead), lines_((ahead.bytes + kLine - 1) / kLine) {
        const std::size_t vectors = (end - begin + n - 1) / n;
        per_vector_ = (lines_ + vectors - 1) / vectors;
    }

    HWY_INLINE void step() {
        const std::size_t end = std::min(lines_, next_ + per_vector_);
        for (; next_ < end; ++next_) {
            for (const void* at : ahead_.at) {
                // Read, into the L2 cache (locality 2): the L1 cache is smaller than a row or two of points.
                if (at != nullptr) __builtin_prefetch(static_cast<const char*>(at) + kLine * next_, 0, 2);
            }
        }
    }

private:
    static constexpr std::size_t kLine = 64;
    const ReadAhead& ahead_;
    std::size_t lines_;
    std::size_t per_vector_ = 0;
    std::size_t next_ = 0;
};

// Points x .. x + n - 1 of a row of w points, `stride` floats apart: components 0, 1, 2. PCL's padded points
// (stride 4) are deinterleaved too, except in the vector that holds the row's last point (whose padding float may
// lie past the cloud's end); other layouts go through load_points.
HWY_INLINE void load_row_points(DF df, const float* HWY_RESTRICT row, std::size_t stride, std::size_t x, std::size_t w,
                                VF& px, VF& py, VF& pz) {
    if (stride == 4 && x + hn::Lanes(df) < w) {
        VF padding;
        hn::LoadInterleaved4(df, row + 4 * x, px, py, pz, padding);
        return;
    }
    load_points(df, row + x * stride, stride, px, py, pz);
}

void split_points_row(const float* points, std::size_t point_floats, std::uint32_t w, const PointRow& out) {
    const DF df;
    const DI di;
    const std::size_t n = hn::Lanes(df);
    if (w < n) {
        for (std::size_t x = 0; x < w; ++x) {
            const float* p = points + x * point_floats;
            out.x[x] = p[0];
            out.y[x] = p[1];
            out.z[x] = p[2];
            out.valid[x] = pixel::pyr_point_valid(p[0], p[1], p[2]) != 0 ? -1 : 0;
        }
        return;
    }
    for (std::size_t x = 0;; x += n) {
        x = std::min(x, std::size_t(w) - n);
        VF px, py, pz;  // NOLINT(readability-isolate-declaration)
        load_row_points(df, points, point_floats, x, w, px, py, pz);
        hn::StoreU(px, df, out.x + x);
        hn::StoreU(py, df, out.y + x);
        hn::StoreU(pz, df, out.z + x);
        hn::StoreU(hn::VecFromMask(di, point_valid(px, py, pz)), di, out.valid + x);
        if (x + n >= w) break;
    }
}

// Pixels x .. x + n - 1 of an unpacked row, from qn (0 where not valid), validity and z; and their validity bytes
// unless `valid_bytes` is null.
HWY_INLINE void store_quant_row(VI qx, VI qy, VI qz, MI valid, VF z, const QuantRow& out, std::size_t x,
                                std::uint8_t* valid_bytes) {
    const DF df;
    const DI di;
    const VI one = hn::IfThenElseZero(valid, hn::Set(di, 1));
    hn::StoreU(qx, di, out.q[0] + x);
    hn::StoreU(qy, di, out.q[1] + x);
    hn::StoreU(qz, di, out.q[2] + x);
    hn::StoreU(one, di, out.valid + x);
    hn::StoreU(hn::IfThenElse(hn::RebindMask(df, valid), z, hn::Set(df, std::numeric_limits<float>::infinity())), df,
               out.z + x);
    if (valid_bytes != nullptr) {
        const hn::Rebind<std::uint8_t, DI> d8;
        hn::StoreU(hn::DemoteTo(d8, one), d8, valid_bytes + x);
    }
}

// Pixel x of an unpacked row from the scalar code's quantized pixel of a point with depth z.
void store_quant_pixel(const PyrQuant& q, float z, const QuantRow& out, std::size_t x) {
    out.q[0][x] = q.qx;
    out.q[1][x] = q.qy;
    out.q[2][x] = q.qz;
    out.valid[x] = q.valid != 0 ? 1 : 0;
    out.z[x] = q.valid != 0 ? z : std::numeric_limits<float>::infinity();
}

// The sums of an unpacked row (QuantRow::sum) for pixels 1 .. w - 2 (the metric's vectors read them where the row is
// at least a vector and two wide).
void sum_quant_row(const QuantRow& r, std::uint32_t w) {
    const DI di;
    const std::size_t n = hn::Lanes(di);
    const std::int32_t* const fields[4] = {r.q[0], r.q[1], r.q[2], r.valid};
    std::int32_t* const sums[4] = {r.sum[0], r.sum[1], r.sum[2], r.sum[3]};
    if (std::size_t(w) < n + 2) {
        for (std::size_t x = 1; x + 1 < w; ++x) {
            for (int f = 0; f < 4; ++f) sums[f][x] = fields[f][x - 1] + fields[f][x] + fields[f][x + 1];
        }
        return;
    }
    for_vectors(1, std::size_t(w) - 1, n, [&](std::size_t x) {
        for (int f = 0; f < 4; ++f) {
            const std::int32_t* v = fields[f];
            hn::StoreU(hn::Add(hn::Add(hn::LoadU(di, v + x - 1), hn::LoadU(di, v + x)), hn::LoadU(di, v + x + 1)), di,
                       sums[f] + x);
        }
    });
}

void normals_quant_row(const PassContext& c, const PointRow& up, const PointRow& row, const PointRow& down,
                       std::uint32_t w, std::uint32_t h, std::uint32_t y, std::uint32_t r, float* normals,
                       std::uint32_t* quant, std::uint8_t* valid, const QuantRow& out, const ReadAhead& ahead) {
    const DF df;
    const DI di;
    const std::size_t n = hn::Lanes(df);
    const auto scalar = [&](std::uint32_t x) {
        const PyrIVec3 q = pixel::pyr_normal_q(c, w, h, x, y, r);
        float v[3];
        store_normal(q, v);
        if (normals != nullptr) std::copy_n(v, 3, normals + 3 * std::size_t(x));
        const float* p = c.points + std::size_t(y) * c.row_floats + std::size_t(x) * c.point_floats;
        const PyrQuant pq = pixel::pyr_quantize(p[0], p[1], p[2], v[0], v[1], v[2]);
        if (quant != nullptr) store_quant(quant + kQuantWords * x, pq.qx, pq.qy, pq.qz, pq.valid, p[2]);
        if (valid != nullptr) valid[x] = std::uint8_t(pq.valid);
        store_quant_pixel(pq, p[2], out, x);
    };
    // Pixels r .. w - r - 1 have both horizontal neighbours; the others are the scalar code's.
    if (std::size_t(w) < 2 * std::size_t(r) + n) {
        for (std::uint32_t x = 0; x < w; ++x) scalar(x);
        sum_quant_row(out, w);
        return;
    }
    const std::uint32_t x_end = w - r;
    for (std::uint32_t x = 0; x < r; ++x) scalar(x);
    for (std::uint32_t x = x_end; x < w; ++x) scalar(x);
    const MI has_up_row = hn::Ne(hn::Set(di, y >= r ? 1 : 0), hn::Zero(di));
    const MI has_down_row = hn::Ne(hn::Set(di, std::size_t(y) + r < h ? 1 : 0), hn::Zero(di));
    const auto valid_at = [&](const PointRow& p, std::size_t x) { return hn::MaskFromVec(hn::LoadU(di, p.valid + x)); };
    // Whole vectors (for_vectors), a block of them at a time in two loops: the first to the normals' directions
    // (normal_direction_of), kept in `block`, the second from them to q and the stores. Each loop's chain of
    // dependent operations is half the whole one, so the core overlaps more vectors (the whole chain, through a
    // square root and a division, is longer than its out-of-order window holds). The rows' pointers are in locals,
    // which the stores cannot change.
    const PointRow u = up;
    const PointRow m = row;
    const PointRow d = down;
    const QuantRow o = out;
    constexpr std::size_t kBlock = 8;
    HWY_ALIGN std::int32_t block[4][kBlock * kMaxLanes];  // dx, dy, dz, some (-1 or 0)
    std::size_t at[kBlock];
    std::size_t count = 0;
    const auto run_block = [&] {
        for (std::size_t k = 0; k < count; ++k) {
            const std::size_t x = at[k];
            const std::size_t xr = x + r;
            const std::size_t xl = x - r;
            VI dx, dy, dz;  // NOLINT(readability-isolate-declaration)
            MI some;
            normal_direction_of(hn::LoadU(df, m.x + x), hn::LoadU(df, m.y + x), hn::LoadU(df, m.z + x), valid_at(m, x),
                                hn::LoadU(df, m.x + xr), hn::LoadU(df, m.y + xr), hn::LoadU(df, m.z + xr),
                                valid_at(m, xr), hn::LoadU(df, m.x + xl), hn::LoadU(df, m.y + xl),
                                hn::LoadU(df, m.z + xl), valid_at(m, xl), hn::LoadU(df, u.x + x),
                                hn::LoadU(df, u.y + x), hn::LoadU(df, u.z + x), hn::And(has_up_row, valid_at(u, x)),
                                hn::LoadU(df, d.x + x), hn::LoadU(df, d.y + x), hn::LoadU(df, d.z + x),
                                hn::And(has_down_row, valid_at(d, x)), dx, dy, dz, some);
            hn::Store(dx, di, block[0] + k * n);
            hn::Store(dy, di, block[1] + k * n);
            hn::Store(dz, di, block[2] + k * n);
            hn::Store(hn::VecFromMask(di, some), di, block[3] + k * n);
        }
        for (std::size_t k = 0; k < count; ++k) {
            const std::size_t x = at[k];
            const VF cz = hn::LoadU(df, m.z + x);
            VI qx, qy, qz;  // NOLINT(readability-isolate-declaration)
            normal_from_direction(hn::Load(di, block[0] + k * n), hn::Load(di, block[1] + k * n),
                                  hn::Load(di, block[2] + k * n), hn::MaskFromVec(hn::Load(di, block[3] + k * n)),
                                  hn::LoadU(df, m.x + x), hn::LoadU(df, m.y + x), cz, qx, qy, qz);
            if (normals != nullptr) store_normals(qx, qy, qz, normals + 3 * x);
            if (quant != nullptr) store_quant_of_normal(qx, qy, qz, cz, quant + kQuantWords * x);
            // Valid where q != 0 (store_quant_of_normal).
            store_quant_row(qx, qy, qz, hn::Ne(hn::Or(hn::Or(qx, qy), qz), hn::Zero(di)), cz, o, x, valid);
        }
        count = 0;
    };
    ReadingAhead reading(ahead, r, x_end, n);
    for_vectors(r, x_end, n, [&](std::size_t x) {
        reading.step();
        at[count++] = x;
        if (count == kBlock) run_block();
    });
    run_block();
    sum_quant_row(out, w);
}

// NOLINTEND(llvm-header-guard)
