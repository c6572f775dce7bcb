// Step 6's fill on the pixels it can change (shaders/pyr_fill.h): the column step (6b) and the row runs (6a).
// Included by cpu_simd.cpp inside each target's namespace, once per target (foreach_target.h): no include guard.
// NOLINTBEGIN(llvm-header-guard)

// Step 6b's column step on one row's marked pixels (cpu_simd.hpp): a marked pixel takes the label of the pixel
// next to it in the row the sweep comes from when that one is fillable and labelled (pyr_fill_step, once).
bool column_step(const std::uint8_t* from_mask, const std::uint32_t* from, std::uint32_t* row, std::uint64_t* marked,
                 std::uint32_t w) {
    bool any = false;
    const std::size_t words = (std::size_t(w) + 63) / 64;
    for (std::size_t i = 0; i < words; ++i) {
        const std::uint64_t bits = marked[i];
        if (bits == 0) continue;
        const std::size_t base = i * 64;
        std::uint64_t took = 0;
#if HWY_TARGET != HWY_SCALAR
        const DU du;
        const hn::Rebind<std::uint8_t, DU> d8;
        const std::size_t n = hn::Lanes(du);
        if (n < 64 && 64 % n == 0 && base + 64 <= w) {
            // Whole words a vector at a time, without a branch on the pixels (taking or not is as good as random).
            const VU one = hn::Set(du, 1u);
            const std::uint64_t lanes = (std::uint64_t{1} << n) - 1;
            for (std::size_t k = 0; k < 64; k += n) {
                const std::uint64_t part = (bits >> k) & lanes;
                if (part == 0) continue;
                const VU label = hn::LoadU(du, from + base + k);
                const VU fillable = hn::And(hn::PromoteTo(du, hn::LoadU(d8, from_mask + base + k)), one);
                const auto take = hn::And(bits_to_mask(du, part),
                                          hn::And(hn::Ne(fillable, hn::Zero(du)), hn::Ne(label, hn::Zero(du))));
                if (hn::AllFalse(du, take)) continue;
                hn::StoreU(hn::IfThenElse(take, label, hn::LoadU(du, row + base + k)), du, row + base + k);
                took |= (mask_to_bits(du, take) & lanes) << k;
            }
        } else
#endif
        {
            for (std::uint64_t rest = bits; rest != 0; rest &= rest - 1) {
                const auto k = unsigned(std::countr_zero(rest));
                const std::size_t x = base + k;
                if ((from_mask[x] & PYR_MASK_FILLABLE) != 0 && from[x] != 0) {
                    row[x] = from[x];
                    took |= std::uint64_t{1} << k;
                }
            }
        }
        if (took == 0) continue;
        marked[i] = bits & ~took;
        any = true;
    }
    return any;
}

// Whether this target's BlendedStore writes only the lanes its mask selects. On NEON (and Highway's SSE4, SSSE3
// and emulated targets) it loads the whole vector, blends and stores it back: lanes past a run would be written
// again, past the row (another thread's row: its new labels lost) and past the buffer.
#if HWY_TARGET == HWY_NEON || HWY_TARGET == HWY_SSE4 || HWY_TARGET == HWY_SSSE3 || HWY_TARGET == HWY_EMU128 || \
    HWY_TARGET == HWY_SCALAR
constexpr bool kMaskedStores = false;
#else
constexpr bool kMaskedStores = true;  // AVX2, AVX-512: masked moves; SVE: predicated stores
#endif

// count copies of value from p on, nothing past them.
HWY_INLINE void fill_run(std::uint32_t* p, std::size_t count, std::uint32_t value) {
    if constexpr (kMaskedStores) {
        const DU du;
        const std::size_t n = hn::Lanes(du);
        const VU v = hn::Set(du, value);
        std::size_t k = 0;
        for (; k + n <= count; k += n) hn::StoreU(v, du, p + k);
        if (k < count) hn::BlendedStore(v, hn::FirstN(du, count - k), du, p + k);
    } else {
        std::fill_n(p, count, value);
    }
}

// Step 6a on one row (cpu_simd.hpp), run by run: on noisy masks a row has hundreds of runs, short ones, so nothing
// branches on a run's pixels or neighbours (which neighbour gives the label, whether one does, how long the run is).
bool row_runs(const std::uint8_t* mask, std::uint32_t* row, std::uint64_t* marked, std::uint32_t w) {
    const std::size_t words = (std::size_t(w) + 63) / 64;
    bool remain = false;
    std::size_t i = 0;
    std::uint64_t word = words != 0 ? marked[0] : 0;
    for (;;) {
        while (word == 0) {
            if (++i == words) return remain;
            word = marked[i];
        }
        const std::size_t x = i * 64 + std::size_t(std::countr_zero(word));
        // The run's end: the first unmarked pixel after x, maybe in a later word.
        std::size_t j = i;
        std::uint64_t unmarked = ~word & (~std::uint64_t{0} << (x % 64));
        while (unmarked == 0 && ++j < words) unmarked = ~marked[j];
        const std::size_t end =
            j < words ? std::min(std::size_t(w), j * 64 + std::size_t(std::countr_zero(unmarked))) : w;
        // The pixels next to the run; at the row's ends the run's own first one, which is unlabelled.
        const std::size_t before = x > 0 ? x - 1 : x;
        const std::size_t after = end < w ? end : x;
        const std::uint32_t left = (mask[before] & PYR_MASK_FILLABLE) != 0 ? row[before] : 0u;
        const std::uint32_t right = (mask[after] & PYR_MASK_FILLABLE) != 0 ? row[after] : 0u;
        const std::uint32_t label = left != 0 ? left : right;
        fill_run(row + x, end - x, label);  // the run is unlabelled: 0 leaves it as it is
        const std::uint64_t keep = label != 0 ? 0 : ~std::uint64_t{0};
        if (j == i) {
            const std::size_t length = end - x;
            const std::uint64_t run = (length == 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << length) - 1) << (x % 64);
            marked[i] &= ~run | keep;
        } else if (keep == 0) {
            for (std::size_t k = i; k <= j && k < words; ++k) {
                const std::size_t lo = std::max(x, k * 64);
                const std::size_t hi = std::min(end, k * 64 + 64);
                const std::size_t length = hi - lo;
                marked[k] &= ~((length == 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << length) - 1) << (lo % 64));
            }
        }
        remain |= label == 0;
        if (end >= w) return remain;
        i = end / 64;
        word = marked[i] & (~std::uint64_t{0} << (end % 64));
    }
}

// NOLINTEND(llvm-header-guard)
