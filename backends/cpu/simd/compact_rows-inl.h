// Compaction's lookup (shaders/pyr_compact.h).
// Included by cpu_simd.cpp inside each target's namespace, once per target (foreach_target.h): no include guard.
// NOLINTBEGIN(llvm-header-guard)

// Compaction's lookup over a row (cpu_simd.hpp): a vector of one run's label (most of a frame) is one store, any
// other a gather, so that no branch follows where runs end (it mispredicts on fragmented masks).
void compact_row(const std::uint32_t* raw, const std::uint32_t* lut, std::uint32_t w, std::uint32_t* out) {
    std::size_t x = 0;
#if HWY_TARGET != HWY_SCALAR
    const DU du;
    const DI di;
    const std::size_t n = hn::Lanes(du);
    std::uint32_t last_raw = 0;  // lut[0] is 0
    VU last = hn::Zero(du);
    for (; x + n <= w; x += n) {
        const VU v = hn::LoadU(du, raw + x);
        if (hn::AllTrue(du, hn::Eq(v, hn::Set(du, last_raw)))) {
            hn::StoreU(last, du, out + x);
            continue;
        }
        hn::StoreU(hn::GatherIndex(du, lut, hn::BitCast(di, v)), du, out + x);
        last_raw = raw[x + n - 1];
        last = hn::Set(du, lut[last_raw]);
    }
#endif
    for (; x < w; ++x) out[x] = lut[raw[x]];
}

// NOLINTEND(llvm-header-guard)
