// Step 3's and 5's label init (shaders/pyr_labels.h, PYR_INIT_INHERIT), marking the pixels step 6 can change.
// Included by cpu_simd.cpp inside each target's namespace, once per target (foreach_target.h): no include guard.
// NOLINTBEGIN(llvm-header-guard)

bool inherit_row(const std::uint8_t* mask, const std::uint32_t* parent, std::uint32_t w, std::uint32_t* out,
                 std::uint64_t* unlabelled) {
    if (unlabelled != nullptr) std::memset(unlabelled, 0, (std::size_t(w) + 63) / 64 * sizeof(std::uint64_t));
    bool any = false;
    std::size_t x = 0;
#if HWY_TARGET != HWY_SCALAR
    const DU du;
    const hn::Rebind<std::uint8_t, DU> d8;
    const hn::Repartition<std::uint64_t, DU> d64;
    const hn::Rebind<std::uint32_t, decltype(d64)> dhalf;
    const std::size_t n = hn::Lanes(du);
    const VU one = hn::Set(du, 1u);
    if (n <= 64) {
        for (; x + n <= w; x += n) {
            // Each parent label twice: widened to 64 bits, its copy shifted into the upper half (lanes are
            // little-endian on every target).
            const auto p64 = hn::PromoteTo(d64, hn::LoadU(dhalf, parent + x / 2));
            const VU p = hn::BitCast(du, hn::Or(p64, hn::ShiftLeft<32>(p64)));
            const auto fillable = hn::Ne(hn::And(hn::PromoteTo(du, hn::LoadU(d8, mask + x)), one), hn::Zero(du));
            const VU v = hn::IfThenElseZero(fillable, p);
            hn::StoreU(v, du, out + x);
            if (unlabelled == nullptr) continue;
            const auto hole = hn::And(fillable, hn::Eq(v, hn::Zero(du)));
            if (hn::AllFalse(du, hole)) continue;
            or_mask_bits(du, hole, unlabelled, x);
            any = true;
        }
    }
#endif
    for (; x < w; ++x) {
        const bool fillable = (mask[x] & PYR_MASK_FILLABLE) != 0;
        out[x] = fillable ? parent[x / 2] : 0u;
        if (unlabelled != nullptr && fillable && out[x] == 0) {
            unlabelled[x / 64] |= std::uint64_t{1} << (x % 64);
            any = true;
        }
    }
    return any;
}

// NOLINTEND(llvm-header-guard)
