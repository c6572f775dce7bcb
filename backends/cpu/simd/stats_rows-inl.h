// The statistics' sums over a stretch of pixels (shaders/pyr_stats.h, backends/cpu/cpu_stats.cpp).
// Included by cpu_simd.cpp inside each target's namespace, once per target (foreach_target.h): no include guard.
// NOLINTBEGIN(llvm-header-guard)

// Adds the lanes of `v` to `into` and empties `v`. (SVE vectors are sizeless: no arrays or struct members of them,
// so each sum below is a variable of its own.)
template <class D, class V, typename T>
HWY_INLINE void drain_lanes(D d, V& v, T& into) {
    into += hn::GetLane(hn::SumOfLanes(d, v));
    v = hn::Zero(d);
}

// See VectorRows::stats_sums. Each 64-bit lane gets at most 2 products of coordinates below 2^26 (so below 2^53)
// per vector; the lanes are summed and emptied into the 128-bit sums every 512 / (64-bit lanes) vectors, so a
// lane, and the sum of all lanes, stays below 2^62. Lanes of pixels that are not fillable are zeros before anything
// is computed from them (their points are finite, but the tail's padding lanes are not points at all), and keep
// z_min and z_max as they are; the last partial vector runs from a copy padded with lanes that are not fillable.
std::uint32_t stats_sums(const float* points, std::size_t stride, const std::uint32_t* quant, const std::uint8_t* mask,
                         std::uint32_t count, float scale, StatsSums& sums) {
    std::uint32_t i = 0;
#if HWY_TARGET != HWY_SCALAR
    const DF df;
    const DI di;
    const DU du;
    const hn::Repartition<std::int64_t, DF> d64;
    using V64 = hn::Vec<decltype(d64)>;
    const std::size_t n = hn::Lanes(df);
    const std::size_t fold_every = std::max<std::size_t>(1, 512 / hn::Lanes(d64));
    const VF limit = hn::Set(df, PYR_STATS_POINT_LIMIT);
    const VF scales = hn::Set(df, scale);
    const VI bound = hn::Set(di, 1 << 26);
    V64 sum_x = hn::Zero(d64);
    V64 sum_y = hn::Zero(d64);
    V64 sum_z = hn::Zero(d64);
    VI normal_x = hn::Zero(di);
    VI normal_y = hn::Zero(di);
    VI normal_z = hn::Zero(di);
    V64 sum_xx = hn::Zero(d64);
    V64 sum_xy = hn::Zero(d64);
    V64 sum_xz = hn::Zero(d64);
    V64 sum_yy = hn::Zero(d64);
    V64 sum_yz = hn::Zero(d64);
    V64 sum_zz = hn::Zero(d64);
    VI z_min = hn::Set(di, sums.z_min);
    VI z_max = hn::Set(di, sums.z_max);
    // The products of the even lanes (MulEven) and of the odd lanes (shifted into the even ones) of a and b.
    const auto products = [&](VI a, VI b) {
        const VI a_odd = hn::BitCast(di, hn::ShiftRight<32>(hn::BitCast(d64, a)));
        const VI b_odd = hn::BitCast(di, hn::ShiftRight<32>(hn::BitCast(d64, b)));
        return hn::Add(hn::MulEven(a, b), hn::MulEven(a_odd, b_odd));
    };
    // The even and odd 32-bit lanes of v, each sign-extended to 64 bits, added.
    const auto lanes = [&](VI v) {
        const V64 wide = hn::BitCast(d64, v);
        return hn::Add(hn::ShiftRight<32>(hn::ShiftLeft<32>(wide)), hn::ShiftRight<32>(wide));
    };
    std::size_t since_fold = 0;
    const auto fold = [&](V64& px, V64& py, V64& pz, VI& nx, VI& ny, VI& nz, V64& xx, V64& xy, V64& xz, V64& yy,
                          V64& yz, V64& zz) {
        drain_lanes(d64, px, sums.point[0]);
        drain_lanes(d64, py, sums.point[1]);
        drain_lanes(d64, pz, sums.point[2]);
        drain_lanes(di, nx, sums.normal[0]);
        drain_lanes(di, ny, sums.normal[1]);
        drain_lanes(di, nz, sums.normal[2]);
        drain_lanes(d64, xx, sums.product[0]);
        drain_lanes(d64, xy, sums.product[1]);
        drain_lanes(d64, xz, sums.product[2]);
        drain_lanes(d64, yy, sums.product[3]);
        drain_lanes(d64, yz, sums.product[4]);
        drain_lanes(d64, zz, sums.product[5]);
        since_fold = 0;
    };
    const hn::Rebind<std::uint8_t, DI> d8;
    const VI one = hn::Set(di, 1);
    std::uint64_t fillable = 0;
    // One vector of pixels: their points (stride floats apart), quant words and mask bytes. False when a fillable
    // pixel's coordinate is 2^26 or more: nothing of the vector is added then.
    const auto add_vector = [&](const float* p, std::size_t p_stride, const std::uint32_t* qw, const std::uint8_t* m) {
        const MI fill = hn::Eq(hn::And(hn::PromoteTo(di, hn::LoadU(d8, m)), one), one);
        const hn::Mask<DF> fill_f = hn::RebindMask(df, fill);
        VF x;
        VF y;
        VF z;
        load_points(df, p, p_stride, x, y, z);
        x = hn::IfThenElseZero(fill_f, x);
        y = hn::IfThenElseZero(fill_f, y);
        z = hn::IfThenElseZero(fill_f, z);
        const VI qx = hn::NearestInt(hn::Min(hn::Max(hn::Mul(x, scales), hn::Neg(limit)), limit));
        const VI qy = hn::NearestInt(hn::Min(hn::Max(hn::Mul(y, scales), hn::Neg(limit)), limit));
        const VI qz = hn::NearestInt(hn::Min(hn::Max(hn::Mul(z, scales), hn::Neg(limit)), limit));
        const VI largest = hn::Max(hn::Max(hn::Abs(qx), hn::Abs(qy)), hn::Abs(qz));
        if (!hn::AllTrue(di, hn::Lt(largest, bound))) return false;
        VU w0;
        VU w1;
        VU w2;
        hn::LoadInterleaved3(du, qw, w0, w1, w2);
        const VI b0 = hn::IfThenElseZero(fill, hn::BitCast(di, w0));
        const VI b1 = hn::IfThenElseZero(fill, hn::BitCast(di, w1));
        normal_x = hn::Add(normal_x, hn::ShiftRight<16>(hn::ShiftLeft<16>(b0)));
        normal_y = hn::Add(normal_y, hn::ShiftRight<16>(b0));
        normal_z = hn::Add(normal_z, hn::ShiftRight<16>(hn::ShiftLeft<16>(b1)));
        z_min = hn::IfThenElse(fill, hn::Min(z_min, qz), z_min);
        z_max = hn::IfThenElse(fill, hn::Max(z_max, qz), z_max);
        fillable += hn::CountTrue(di, fill);
        sum_x = hn::Add(sum_x, lanes(qx));
        sum_y = hn::Add(sum_y, lanes(qy));
        sum_z = hn::Add(sum_z, lanes(qz));
        sum_xx = hn::Add(sum_xx, products(qx, qx));
        sum_xy = hn::Add(sum_xy, products(qx, qy));
        sum_xz = hn::Add(sum_xz, products(qx, qz));
        sum_yy = hn::Add(sum_yy, products(qy, qy));
        sum_yz = hn::Add(sum_yz, products(qy, qz));
        sum_zz = hn::Add(sum_zz, products(qz, qz));
        if (++since_fold == fold_every) {
            fold(sum_x, sum_y, sum_z, normal_x, normal_y, normal_z, sum_xx, sum_xy, sum_xz, sum_yy, sum_yz, sum_zz);
        }
        return true;
    };
    for (; i + n <= count; i += std::uint32_t(n)) {
        if (!add_vector(points + std::size_t(i) * stride, stride, quant + kQuantWords * std::size_t(i), mask + i)) {
            break;
        }
    }
    if (i < count && i + n > count) {
        HWY_ALIGN float tail_points[3 * kMaxLanes] = {};
        HWY_ALIGN std::uint32_t tail_quant[kQuantWords * kMaxLanes] = {};
        HWY_ALIGN std::uint8_t tail_mask[kMaxLanes] = {};
        const std::size_t rest = count - i;
        for (std::size_t k = 0; k < rest; ++k) {
            for (std::size_t j = 0; j < 3; ++j) tail_points[3 * k + j] = points[(std::size_t(i) + k) * stride + j];
            for (std::size_t j = 0; j < kQuantWords; ++j) {
                tail_quant[kQuantWords * k + j] = quant[kQuantWords * (std::size_t(i) + k) + j];
            }
            tail_mask[k] = mask[i + k];
        }
        if (add_vector(tail_points, 3, tail_quant, tail_mask)) i = count;
    }
    if (since_fold != 0) {
        fold(sum_x, sum_y, sum_z, normal_x, normal_y, normal_z, sum_xx, sum_xy, sum_xz, sum_yy, sum_yz, sum_zz);
    }
    sums.z_min = hn::GetLane(hn::MinOfLanes(di, z_min));
    sums.z_max = hn::GetLane(hn::MaxOfLanes(di, z_max));
    sums.fillable += fillable;
#else
    (void)points;
    (void)stride;
    (void)quant;
    (void)mask;
    (void)count;
    (void)scale;
    (void)sums;
#endif
    return i;
}

// NOLINTEND(llvm-header-guard)
