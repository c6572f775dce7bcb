// The loads of points every family of rows shares, and pyr_point_valid / pyr_normal_valid (shaders/pyr_validity.h)
// on the floats' bit patterns.
// Included by cpu_simd.cpp inside each target's namespace, once per target (foreach_target.h): no include guard.
// NOLINTBEGIN(llvm-header-guard)

// Components 0, 1, 2 of n = Lanes(df) points, the first at p, each `stride` floats after the one before.
HWY_INLINE void load_points(DF df, const float* HWY_RESTRICT p, std::size_t stride, VF& x, VF& y, VF& z) {
    if (stride == 3) {
        hn::LoadInterleaved3(df, p, x, y, z);
        return;
    }
    // Any other layout (PCL's padded points, interleaved normals, byte steps): lane by lane. Only the three floats
    // of each point are read, never a padding float past the last point of a row.
    HWY_ALIGN float buffer[3][kMaxLanes];
    const std::size_t n = hn::Lanes(df);
    for (std::size_t i = 0; i < n; ++i) {
        buffer[0][i] = p[i * stride];
        buffer[1][i] = p[i * stride + 1];
        buffer[2][i] = p[i * stride + 2];
    }
    x = hn::Load(df, buffer[0]);
    y = hn::Load(df, buffer[1]);
    z = hn::Load(df, buffer[2]);
}

// ---- Validity (shaders/pyr_validity.h), on the float bit patterns

HWY_INLINE MI is_finite(VI bits) {
    const DI di;
    const VI exponent_field = hn::Set(di, 0x7f800000);
    return hn::Ne(hn::And(bits, exponent_field), exponent_field);  // (bits >> 23) & 255 != 255
}

HWY_INLINE MI point_valid(VF x, VF y, VF z) {
    const DI di;
    const VI bz = hn::BitCast(di, z);
    return hn::And(hn::And(is_finite(hn::BitCast(di, x)), is_finite(hn::BitCast(di, y))),
                   hn::And(is_finite(bz), hn::Gt(bz, hn::Zero(di))));
}

HWY_INLINE MI normal_valid(VF x, VF y, VF z) {
    const DI di;
    const VI bx = hn::BitCast(di, x);
    const VI by = hn::BitCast(di, y);
    const VI bz = hn::BitCast(di, z);
    const VI magnitudes = hn::And(hn::Or(hn::Or(bx, by), bz), hn::Set(di, 0x7fffffff));
    return hn::And(hn::And(is_finite(bx), is_finite(by)), hn::And(is_finite(bz), hn::Ne(magnitudes, hn::Zero(di))));
}

// NOLINTEND(llvm-header-guard)
