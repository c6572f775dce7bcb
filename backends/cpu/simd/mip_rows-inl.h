// Mip (shaders/pyr_mip.h): a level from the level below it.
// Included by cpu_simd.cpp inside each target's namespace, once per target (foreach_target.h): no include guard.
// NOLINTBEGIN(llvm-header-guard)

void mip_row(const std::uint8_t* child_top, std::uint32_t child_width, std::uint32_t parent_width, std::uint8_t* out) {
    if (child_top == nullptr) {
        std::memset(out, 0, parent_width);
        return;
    }
    const hn::ScalableTag<std::uint8_t> d8;
    const std::size_t n = hn::Lanes(d8);
    // Texels 0 .. full - 1 have both child columns; a texel past them (odd child width) is 0.
    const std::size_t full = child_width / 2;
    const std::uint8_t* bottom = child_top + child_width;
    std::size_t done = 0;
    if (full >= n) {
        const auto one = hn::Set(d8, std::uint8_t{PYR_MASK_FILLABLE});
        for (std::size_t x = 0;; x += n) {
            x = std::min(x, full - n);
            hn::Vec<decltype(d8)> te, to, be, bo;  // NOLINT(readability-isolate-declaration)
            hn::LoadInterleaved2(d8, child_top + 2 * x, te, to);
            hn::LoadInterleaved2(d8, bottom + 2 * x, be, bo);
            hn::StoreU(hn::And(hn::And(hn::And(te, to), hn::And(be, bo)), one), d8, out + x);
            if (x + n >= full) break;
        }
        done = full;
    }
    for (std::size_t x = done; x < full; ++x) {
        out[x] = std::uint8_t(child_top[2 * x] & child_top[2 * x + 1] & bottom[2 * x] & bottom[2 * x + 1] &
                              PYR_MASK_FILLABLE);
    }
    for (std::size_t x = full; x < parent_width; ++x) out[x] = 0;
}

// NOLINTEND(llvm-header-guard)
