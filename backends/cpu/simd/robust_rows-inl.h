// The robust metric's vector rows (docs/algorithm.md sections 2b and 8b; shaders/pyr_robust.h): texels, normals from
// window sums and the fillable test, each the scalar function's operations lane by lane. They use the helpers of the
// paper metric's families (point_loads-inl.h, normals_rows-inl.h, metric_rows-inl.h, pixel_bits-inl.h).
// Included by cpu_simd.cpp inside each target's namespace, once per target (foreach_target.h): no include guard.
// NOLINTBEGIN(llvm-header-guard)

// G(v) (pyr_robust_fixed) of n values: the product by the power of two `scale` is exact where it does not overflow,
// the clamp takes +-infinity to +-2^22, and the rounding is half to even.
HWY_INLINE VI robust_fixed(VF v, VF scale) {
    const DF df;
    const DI di;
    const VF limit = hn::Set(df, PYR_ROBUST_COORD_LIMIT);
    return hn::ConvertTo(di, hn::Round(hn::Min(hn::Max(hn::Mul(v, scale), hn::Neg(limit)), limit)));
}

void robust_texels_row(const PassContext& c, std::uint32_t w, std::uint32_t h, std::uint32_t y, std::uint32_t r,
                       float scale) {
    const RobustTexelPlanes& t = c.robust_texels;
    const std::size_t row0 = std::size_t(y) * w;
    const auto scalar = [&](std::uint32_t x) { t.store(row0 + x, pixel::pyr_robust_texel(c, w, h, x, y, r, scale)); };
    const DF df;
    const DI di;
    const std::size_t n = hn::Lanes(df);
    const std::size_t pf = c.point_floats;
    const float* row = c.points + std::size_t(y) * c.row_floats;
    const bool vertical = y >= r && std::size_t(y) + r < h;
    const float* up = vertical ? row - std::size_t(r) * c.row_floats : row;
    const float* down = vertical ? row + std::size_t(r) * c.row_floats : row;
    const MI has_vertical = hn::Ne(hn::Set(di, vertical ? 1 : 0), hn::Zero(di));
    const VF s = hn::Set(df, scale);
    interior_vectors(w, r, n, scalar, [&](std::size_t x) {
        VF cx, cy, cz, rx, ry, rz, lx, ly, lz, ux, uy, uz, dx, dy, dz;  // NOLINT(readability-isolate-declaration)
        load_points(df, row + x * pf, pf, cx, cy, cz);
        load_points(df, row + (x + r) * pf, pf, rx, ry, rz);
        load_points(df, row + (x - r) * pf, pf, lx, ly, lz);
        load_points(df, up + x * pf, pf, ux, uy, uz);
        load_points(df, down + x * pf, pf, dx, dy, dz);
        const MI valid = point_valid(cx, cy, cz);
        const MI horizontal = hn::And(valid, hn::And(point_valid(rx, ry, rz), point_valid(lx, ly, lz)));
        const MI across =
            hn::And(hn::And(valid, has_vertical), hn::And(point_valid(dx, dy, dz), point_valid(ux, uy, uz)));
        const std::size_t i = row0 + x;
        hn::StoreU(hn::IfThenElse(valid, robust_fixed(cz, s), hn::Set(di, -1)), di, t.gz + i);
        hn::StoreU(hn::Or(hn::IfThenElseZero(horizontal, hn::Set(di, 1)), hn::IfThenElseZero(across, hn::Set(di, 2))),
                   di, reinterpret_cast<std::int32_t*>(t.tangents + i));
        // (No arrays of vectors: SVE's are sizeless.)
        const auto tangents = [&](VF a, VF b, MI exists, std::int32_t* out) {
            hn::StoreU(hn::IfThenElseZero(exists, hn::Sub(robust_fixed(a, s), robust_fixed(b, s))), di, out + i);
        };
        tangents(rx, lx, horizontal, t.th[0]);
        tangents(ry, ly, horizontal, t.th[1]);
        tangents(rz, lz, horizontal, t.th[2]);
        tangents(dx, ux, across, t.tv[0]);
        tangents(dy, uy, across, t.tv[1]);
        tangents(dz, uz, across, t.tv[2]);
    });
}

void robust_range_row(const std::int32_t* in, std::uint32_t w, std::uint32_t r, std::int32_t* lo, std::int32_t* hi) {
    const auto scalar = [&](std::size_t x) {
        const std::size_t x0 = x >= r ? x - r : 0;
        const std::size_t x1 = std::min(x + r, std::size_t(w) - 1);
        std::int32_t a = in[x0];
        std::int32_t b = in[x0];
        for (std::size_t j = x0 + 1; j <= x1; ++j) {
            a = std::min(a, in[j]);
            b = std::max(b, in[j]);
        }
        lo[x] = a;
        hi[x] = b;
    };
    const DI di;
    interior_vectors(w, r, hn::Lanes(di), scalar, [&](std::size_t x) {
        VI a = hn::LoadU(di, in + x - r);
        VI b = a;
        for (std::size_t j = x - r + 1; j <= x + r; ++j) {
            const VI v = hn::LoadU(di, in + j);
            a = hn::Min(a, v);
            b = hn::Max(b, v);
        }
        hn::StoreU(a, di, lo + x);
        hn::StoreU(b, di, hi + x);
    });
}

// pyr_robust_to_15_bits of (x, y, z), for lanes with |components| < 2^31; lanes of (0, 0, 0) compute with m = 1 (their
// results are not used) so that no shift is out of range.
HWY_INLINE void robust_to_15_bits(VI& x, VI& y, VI& z) {
    const DI di;
    const VI m = hn::Max(hn::Max(hn::Abs(x), hn::Abs(y)), hn::Abs(z));
    const VI s = hn::Sub(msb(hn::Max(m, hn::Set(di, 1))), hn::Set(di, 14));
    x = shift_magnitude(x, s);
    y = shift_magnitude(y, s);
    z = shift_magnitude(z, s);
}

// Takes from the box sums s of the windows of radius r around pixels x .. x + n - 1 (rows y0 .. y1, columns inside
// the image) the tangents of their pixels that are not members, which leaves the members' sums pyr_robust_normal_q
// adds (the tables' sums wrap like it; missing tangents are zeros in the texels). Most windows that hold one
// non-member hold few, so only their columns' loads and subtractions are done.
HWY_INLINE void subtract_non_members(const RobustTexelPlanes& t, std::size_t w, std::size_t x, std::size_t y0,
                                     std::size_t y1, std::size_t r, VI zi, VI jump, VI& ux, VI& uy, VI& uz, VI& vx,
                                     VI& vy, VI& vz) {
    const DI di;
    const std::int32_t* const th0 = t.th[0];
    const std::int32_t* const th1 = t.th[1];
    const std::int32_t* const th2 = t.th[2];
    const std::int32_t* const tv0 = t.tv[0];
    const std::int32_t* const tv1 = t.tv[1];
    const std::int32_t* const tv2 = t.tv[2];
    for (std::size_t jy = y0; jy <= y1; ++jy) {
        for (std::size_t jx = x - r; jx <= x + r; ++jx) {
            const std::size_t j = jy * w + jx;
            const VI gz = hn::LoadU(di, t.gz + j);
            const MI outside = hn::Or(hn::Lt(gz, hn::Zero(di)), hn::Gt(hn::Abs(hn::Sub(gz, zi)), jump));
            if (hn::AllFalse(di, outside)) continue;
            ux = hn::Sub(ux, hn::IfThenElseZero(outside, hn::LoadU(di, th0 + j)));
            uy = hn::Sub(uy, hn::IfThenElseZero(outside, hn::LoadU(di, th1 + j)));
            uz = hn::Sub(uz, hn::IfThenElseZero(outside, hn::LoadU(di, th2 + j)));
            vx = hn::Sub(vx, hn::IfThenElseZero(outside, hn::LoadU(di, tv0 + j)));
            vy = hn::Sub(vy, hn::IfThenElseZero(outside, hn::LoadU(di, tv1 + j)));
            vz = hn::Sub(vz, hn::IfThenElseZero(outside, hn::LoadU(di, tv2 + j)));
        }
    }
}

void robust_normals_row(const PassContext& c, const RobustWindowRow& sums, std::uint32_t w, std::uint32_t h,
                        std::uint32_t y, std::uint32_t window, float* out, std::uint64_t* rest) {
    const std::size_t words = (std::size_t(w) + 63) / 64;
    std::memset(rest, 0, words * sizeof(std::uint64_t));
    const auto leave = [&](std::size_t x) { rest[x / 64] |= std::uint64_t{1} << (x % 64); };
    const DF df;
    const DI di;
    const std::size_t n = hn::Lanes(df);
    const std::size_t r = window;
    // Pixels r .. w - r - 1 have their window's columns inside the image; the others are the caller's (box sums
    // and windows clipped to the image).
    if (std::size_t(w) < 2 * r + n || n > 64) {
        for (std::size_t x = 0; x < w; ++x) leave(x);
        return;
    }
    const std::size_t x_end = w - r;
    for (std::size_t x = 0; x < r; ++x) leave(x);
    for (std::size_t x = x_end; x < w; ++x) leave(x);
    const std::size_t pf = c.point_floats;
    const float* points = c.points + std::size_t(y) * c.row_floats;
    const std::int32_t* gz = c.robust_texels.gz + std::size_t(y) * w;
    const std::size_t y0 = y >= r ? y - r : 0;
    const std::size_t y1 = std::min(std::size_t(y) + r, std::size_t(h) - 1);
    for (std::size_t x = r;; x += n) {
        x = std::min(x, x_end - n);
        VF px, py, pz;  // NOLINT(readability-isolate-declaration)
        load_points(df, points + x * pf, pf, px, py, pz);
        const MI valid = point_valid(px, py, pz);
        // A valid point's G(z) (its texel's) is its window's centre zi; jump J = zi >> 4.
        const VI zi = hn::LoadU(di, gz + x);
        const VI jump = hn::ShiftRight<4>(zi);
        const MI members = hn::And(hn::Not(hn::Lt(hn::LoadU(di, sums.min + x), hn::Sub(zi, jump))),
                                   hn::Not(hn::Gt(hn::LoadU(di, sums.max + x), hn::Add(zi, jump))));
        // The box sums (wrapping, as the tables do) over columns x - r .. x + r, less the non-members where a
        // window holds any.
        const auto box = [&](std::size_t k) {
            const VU a = hn::LoadU(DU(), sums.bottom[k] + x + r + 1);
            const VU b = hn::LoadU(DU(), sums.top[k] + x + r + 1);
            const VU cc = hn::LoadU(DU(), sums.bottom[k] + x - r);
            const VU d = hn::LoadU(DU(), sums.top[k] + x - r);
            return hn::BitCast(di, hn::Add(hn::Sub(hn::Sub(a, b), cc), d));
        };
        // (Six vectors, not an array: SVE's are sizeless.)
        VI ux = box(0);
        VI uy = box(1);
        VI uz = box(2);
        VI vx = box(3);
        VI vy = box(4);
        VI vz = box(5);
        if (!hn::AllFalse(di, hn::AndNot(members, valid)))
            subtract_non_members(c.robust_texels, w, x, y0, y1, r, zi, jump, ux, uy, uz, vx, vy, vz);
        const MI u_zero = hn::Eq(hn::Or(hn::Or(ux, uy), uz), hn::Zero(di));
        const MI v_zero = hn::Eq(hn::Or(hn::Or(vx, vy), vz), hn::Zero(di));
        const MI defined = hn::AndNot(hn::Or(u_zero, v_zero), valid);
        robust_to_15_bits(ux, uy, uz);
        robust_to_15_bits(vx, vy, vz);
        VI dx, dy, dz, qx, qy, qz;  // NOLINT(readability-isolate-declaration)
        MI some;
        normal_direction(ux, uy, uz, vx, vy, vz, defined, dx, dy, dz, some);
        normal_from_direction(dx, dy, dz, some, px, py, pz, qx, qy, qz);
        store_normals(qx, qy, qz, out + 3 * x);
        if (x + n >= x_end) break;
    }
}

void metric_robust_row(const PassContext& c, std::uint32_t w, std::uint32_t h, std::uint32_t y, std::uint32_t stride,
                       float curvature_base, float curvature_growth, float dt, float depth_growth, std::uint8_t* out) {
    const auto scalar = [&](std::uint32_t x) {
        out[x] = std::uint8_t(pixel::pyr_metric_robust_fillable(c, w, h, x, y, stride, curvature_base, curvature_growth,
                                                                dt, depth_growth));
    };
    const DF df;
    const DI di;
    const hn::Rebind<std::uint8_t, DI> d8;
    const std::size_t n = hn::Lanes(df);
    // Pixels m .. w - m - 1 have every neighbour column the test reads (x +- 1 and x +- stride).
    const std::size_t m = std::max<std::size_t>(stride, 1);
    if (std::size_t(w) < 2 * m + n) {
        for (std::uint32_t x = 0; x < w; ++x) scalar(x);
        return;
    }
    const std::size_t x_end = w - m;
    for (std::uint32_t x = 0; x < m; ++x) scalar(x);
    for (std::size_t x = x_end; x < w; ++x) scalar(std::uint32_t(x));
    // Row y + dy's quantized words, or null outside the image.
    const auto row_at = [&](std::int64_t dy) -> const std::uint32_t* {
        const std::int64_t ry = std::int64_t(y) + dy;
        return ry >= 0 && ry < std::int64_t(h) ? c.quant + kQuantWords * std::size_t(ry) * w : nullptr;
    };
    const auto s = std::int64_t(stride);
    const std::uint32_t* depth_rows[3] = {row_at(-1), row_at(0), row_at(1)};
    // The four axes' pairs: the rows of a (y + s dy) and b (y - s dy), and the column step dx.
    struct Axis {
        const std::uint32_t* a;
        const std::uint32_t* b;
        std::int64_t dx;
    };
    const Axis axes[4] = {
        {row_at(0), row_at(0), s}, {row_at(s), row_at(-s), 0}, {row_at(s), row_at(-s), s}, {row_at(-s), row_at(s), s}};
    const bool growing_curvature = curvature_growth != 0.0f;
    const bool growing_depth = depth_growth != 0.0f;
    const VF pass = hn::Set(df, float(PYR_ROBUST_CURVATURE_PASS));
    for (std::size_t x = m;; x += n) {
        x = std::min(x, x_end - n);
        VI qx, qy, qz, valid;  // NOLINT(readability-isolate-declaration)
        VF z;
        load_quant(depth_rows[1] + kQuantWords * x, qx, qy, qz, valid, z);
        // Depth: the valid 8-neighbours at stride 1 (finite depths: Min / Max are the scalar comparisons).
        VF dmin = hn::Set(df, hwy::HighestValue<float>());
        VF dmax = hn::Zero(df);
        VI k1 = hn::Zero(di);
        for (int row = 0; row < 3; ++row) {
            if (depth_rows[row] == nullptr) continue;
            for (std::size_t j = x - 1; j <= x + 1; ++j) {
                if (row == 1 && j == x) continue;
                VI nx, ny, nz, nvalid;  // NOLINT(readability-isolate-declaration)
                VF nzd;
                load_quant(depth_rows[row] + kQuantWords * j, nx, ny, nz, nvalid, nzd);
                const MI use = hn::Ne(nvalid, hn::Zero(di));
                const auto use_f = hn::RebindMask(df, use);
                const VF dd = hn::Abs(hn::Sub(z, nzd));
                dmin = hn::IfThenElse(use_f, hn::Min(dmin, dd), dmin);
                dmax = hn::IfThenElse(use_f, hn::Max(dmax, dd), dmax);
                k1 = hn::Sub(k1, nvalid);  // nvalid is -1 where valid
            }
        }
        // Curvature: the pairs across the pixel whose two pixels exist and are valid (qn is 0 where not valid).
        VI sum = hn::Zero(di);
        VI kp = hn::Zero(di);
        for (const Axis& axis : axes) {
            if (axis.a == nullptr || axis.b == nullptr) continue;
            VI ax, ay, az, av, bx, by, bz, bv;  // NOLINT(readability-isolate-declaration)
            VF unused;
            load_quant(axis.a + kQuantWords * std::size_t(std::int64_t(x) + axis.dx), ax, ay, az, av, unused);
            load_quant(axis.b + kQuantWords * std::size_t(std::int64_t(x) - axis.dx), bx, by, bz, bv, unused);
            const VI both = hn::And(av, bv);  // -1 where both are valid
            const VI dot = hn::Add(hn::Add(hn::Mul(ax, bx), hn::Mul(ay, by)), hn::Mul(az, bz));
            sum = hn::Add(sum, hn::And(both, dot));
            kp = hn::Sub(kp, both);
        }
        // The limits (pyr_robust_curvature_limit, pyr_robust_depth_limit): float products and sums, no contraction.
        const VF zz = hn::Mul(z, z);
        const VF t = growing_curvature
                         ? hn::Add(hn::Set(df, curvature_base), hn::Mul(hn::Set(df, curvature_growth), zz))
                         : hn::Set(df, curvature_base);
        const auto below_pass = hn::RebindMask(di, hn::Lt(t, pass));
        const VI limit = hn::IfThenElse(below_pass, hn::ConvertTo(di, t), hn::Set(di, PYR_ROBUST_CURVATURE_PASS));
        const VF depth_limit =
            growing_depth ? hn::Add(hn::Set(df, dt), hn::Mul(hn::Set(df, depth_growth), zz)) : hn::Set(df, dt);
        // kp (2^26 - L) lies in [-3 * 2^28, 2^28].
        const MI curvature_ok = hn::Not(hn::Lt(sum, hn::Mul(kp, hn::Sub(hn::Set(di, 1 << 26), limit))));
        const MI depth_ok = hn::RebindMask(di, hn::Le(hn::Sub(dmax, dmin), depth_limit));
        const MI counted = hn::And(hn::Gt(k1, hn::Zero(di)), hn::Gt(kp, hn::Zero(di)));
        const MI fillable = hn::And(hn::And(hn::Ne(valid, hn::Zero(di)), counted), hn::And(curvature_ok, depth_ok));
        hn::StoreU(hn::DemoteTo(d8, hn::IfThenElseZero(fillable, hn::Set(di, 1))), d8, out + x);
        if (x + n >= x_end) break;
    }
}

// NOLINTEND(llvm-header-guard)
