// Depth images to points (shaders/pyr_depth.h).
// Included by cpu_simd.cpp inside each target's namespace, once per target (foreach_target.h): no include guard.
// NOLINTBEGIN(llvm-header-guard)

// pyr_depth_point lane by lane: bit tests, then the three correctly rounded products; the tests pick NaN points
// where the scalar code returns `none`, so every lane computes (products of non-finite values included are thrown
// away, and float products never trap).
HWY_INLINE void depth_vector(VU value, bool u16, float scale, const float* ku, float kv, float* out) {
    const DF df;
    const DI di;
    const DU du;
    MI none;
    VF zs;
    if (u16) {
        none = hn::RebindMask(di, hn::Eq(value, hn::Zero(du)));
        zs = hn::ConvertTo(df, hn::BitCast(di, value));  // < 2^16: exact
    } else {
        const VU e = hn::And(hn::ShiftRight<23>(value), hn::Set(du, 255u));
        none = hn::RebindMask(di, hn::Or(hn::Ne(hn::ShiftRight<31>(value), hn::Zero(du)),
                                         hn::Or(hn::Eq(e, hn::Zero(du)), hn::Eq(e, hn::Set(du, 255u)))));
        zs = hn::BitCast(df, value);
    }
    const VF z = hn::Mul(zs, hn::Set(df, scale));
    const VU ez = hn::And(hn::ShiftRight<23>(hn::BitCast(du, z)), hn::Set(du, 255u));
    none = hn::Or(none, hn::RebindMask(di, hn::Or(hn::Eq(ez, hn::Zero(du)), hn::Eq(ez, hn::Set(du, 255u)))));
    // pyr_depth_flush: a product whose exponent field is 0 keeps only its sign bit.
    const auto flush = [&](VF v) {
        const VU bits = hn::BitCast(du, v);
        const MI subnormal = hn::RebindMask(di, hn::Eq(hn::And(bits, hn::Set(du, 0x7f800000u)), hn::Zero(du)));
        return hn::BitCast(
            df, hn::IfThenElse(hn::RebindMask(du, subnormal), hn::And(bits, hn::Set(du, 0x80000000u)), bits));
    };
    const VF x = flush(hn::Mul(z, hn::LoadU(df, ku)));
    const VF y = flush(hn::Mul(z, hn::Set(df, kv)));
    const VF nan = hn::BitCast(df, hn::Set(du, PYR_DEPTH_NAN));
    const auto nonef = hn::RebindMask(df, none);
    hn::StoreInterleaved3(hn::IfThenElse(nonef, nan, x), hn::IfThenElse(nonef, nan, y), hn::IfThenElse(nonef, nan, z),
                          df, out);
}

void depth_row(const void* samples, std::uint32_t format, std::uint32_t w, float scale, const float* ku, float kv,
               float* out) {
    const DF df;
    const DU du;
    const std::size_t n = hn::Lanes(df);
    const bool u16 = format == PYR_DEPTH_U16;
    const auto* bytes = static_cast<const unsigned char*>(samples);
    const std::size_t sample = u16 ? 2 : 4;
    const auto value_at = [&](std::size_t x) {
        std::uint32_t v = 0;
        if (u16) {
            std::uint16_t d = 0;
            std::memcpy(&d, bytes + 2 * x, 2);  // rows may start at any byte
            v = d;
        } else {
            std::memcpy(&v, bytes + 4 * x, 4);
        }
        return v;
    };
    const auto scalar = [&](std::size_t x) {
        const PyrFVec3 p = pixel::pyr_depth_point(value_at(x), format, scale, ku[x], kv);
        out[3 * x] = p.x;
        out[3 * x + 1] = p.y;
        out[3 * x + 2] = p.z;
    };
    // A row that does not start on its samples' alignment is read sample by sample (the vector loads below go
    // through typed pointers).
    if (w < n || reinterpret_cast<std::uintptr_t>(samples) % sample != 0) {
        for (std::size_t x = 0; x < w; ++x) scalar(x);
        return;
    }
    for (std::size_t x = 0;; x += n) {
        x = std::min(x, std::size_t(w) - n);
        VU value;
        if (u16) {
            const hn::Rebind<std::uint16_t, DU> d16;
            value = hn::PromoteTo(du, hn::LoadU(d16, static_cast<const std::uint16_t*>(samples) + x));
        } else {
            value = hn::LoadU(du, static_cast<const std::uint32_t*>(samples) + x);
        }
        depth_vector(value, u16, scale, ku + x, kv, out + 3 * x);
        if (x + n >= w) break;
    }
}

// NOLINTEND(llvm-header-guard)
