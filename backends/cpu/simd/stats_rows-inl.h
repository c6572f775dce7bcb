// The statistics' sums over a stretch of pixels (shaders/pyr_stats.h, backends/cpu/cpu_stats.cpp).
// Included by cpu_simd.cpp inside each target's namespace, once per target (foreach_target.h): no include guard.
// NOLINTBEGIN(llvm-header-guard)

// See VectorRows::stats_sums. Each 64-bit lane gets at most 2 products of coordinates below 2^26 (so below 2^53)
// per vector; the lanes are summed and emptied into the 128-bit sums every 512 / (64-bit lanes) vectors, so a
// lane, and the sum of all lanes, stays below 2^62.
std::uint32_t stats_sums(const float* points, std::size_t stride, const std::uint32_t* quant, std::uint32_t count,
                         float scale, StatsSums& sums) {
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
    V64 point_sum[3] = {hn::Zero(d64), hn::Zero(d64), hn::Zero(d64)};
    VI normal_sum[3] = {hn::Zero(di), hn::Zero(di), hn::Zero(di)};
    V64 product_sum[6] = {hn::Zero(d64), hn::Zero(d64), hn::Zero(d64), hn::Zero(d64), hn::Zero(d64), hn::Zero(d64)};
    VI z_min = hn::Set(di, sums.z_min);
    VI z_max = hn::Set(di, sums.z_max);
    const auto fold = [&] {
        for (std::size_t k = 0; k < 3; ++k) {
            sums.point[k] += hn::GetLane(hn::SumOfLanes(d64, point_sum[k]));
            point_sum[k] = hn::Zero(d64);
            sums.normal[k] += hn::GetLane(hn::SumOfLanes(di, normal_sum[k]));
            normal_sum[k] = hn::Zero(di);
        }
        for (std::size_t k = 0; k < 6; ++k) {
            sums.product[k] += hn::GetLane(hn::SumOfLanes(d64, product_sum[k]));
            product_sum[k] = hn::Zero(d64);
        }
    };
    // The even and odd 32-bit lanes of v, each sign-extended to 64 bits.
    const auto even = [&](VI v) { return hn::ShiftRight<32>(hn::ShiftLeft<32>(hn::BitCast(d64, v))); };
    const auto odd = [&](VI v) { return hn::ShiftRight<32>(hn::BitCast(d64, v)); };
    std::size_t since_fold = 0;
    for (; i + n <= count; i += std::uint32_t(n)) {
        VF x;
        VF y;
        VF z;
        load_points(df, points + std::size_t(i) * stride, stride, x, y, z);
        const VI q[3] = {hn::NearestInt(hn::Min(hn::Max(hn::Mul(x, scales), hn::Neg(limit)), limit)),
                         hn::NearestInt(hn::Min(hn::Max(hn::Mul(y, scales), hn::Neg(limit)), limit)),
                         hn::NearestInt(hn::Min(hn::Max(hn::Mul(z, scales), hn::Neg(limit)), limit))};
        const VI largest = hn::Max(hn::Max(hn::Abs(q[0]), hn::Abs(q[1])), hn::Abs(q[2]));
        if (!hn::AllTrue(di, hn::Lt(largest, bound))) break;
        VU w0;
        VU w1;
        VU w2;
        hn::LoadInterleaved3(du, quant + kQuantWords * std::size_t(i), w0, w1, w2);
        const VI b0 = hn::BitCast(di, w0);
        const VI b1 = hn::BitCast(di, w1);
        normal_sum[0] = hn::Add(normal_sum[0], hn::ShiftRight<16>(hn::ShiftLeft<16>(b0)));
        normal_sum[1] = hn::Add(normal_sum[1], hn::ShiftRight<16>(b0));
        normal_sum[2] = hn::Add(normal_sum[2], hn::ShiftRight<16>(hn::ShiftLeft<16>(b1)));
        z_min = hn::Min(z_min, q[2]);
        z_max = hn::Max(z_max, q[2]);
        const V64 qe[3] = {even(q[0]), even(q[1]), even(q[2])};
        const V64 qo[3] = {odd(q[0]), odd(q[1]), odd(q[2])};
        const VI qo32[3] = {hn::BitCast(di, qo[0]), hn::BitCast(di, qo[1]), hn::BitCast(di, qo[2])};
        for (std::size_t k = 0; k < 3; ++k) point_sum[k] = hn::Add(point_sum[k], hn::Add(qe[k], qo[k]));
        std::size_t product = 0;
        for (std::size_t a = 0; a < 3; ++a) {
            for (std::size_t b = a; b < 3; ++b) {
                product_sum[product] =
                    hn::Add(product_sum[product], hn::Add(hn::MulEven(q[a], q[b]), hn::MulEven(qo32[a], qo32[b])));
                ++product;
            }
        }
        if (++since_fold == fold_every) {
            fold();
            since_fold = 0;
        }
    }
    if (since_fold != 0) fold();
    sums.z_min = hn::GetLane(hn::MinOfLanes(di, z_min));
    sums.z_max = hn::GetLane(hn::MaxOfLanes(di, z_max));
#else
    (void)points;
    (void)stride;
    (void)quant;
    (void)count;
    (void)scale;
    (void)sums;
#endif
    return i;
}

// NOLINTEND(llvm-header-guard)
