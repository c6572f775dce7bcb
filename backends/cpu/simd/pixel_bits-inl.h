// The bitmaps of pixels (a bit each, 64 to a word) that the label, edge, fill and robust rows mark pixels in.
// Included by cpu_simd.cpp inside each target's namespace, once per target (foreach_target.h): no include guard.
// NOLINTBEGIN(llvm-header-guard)

// ORs n mask bits for pixels x .. x + n - 1 into the pixel bitmap (n <= 64; SVE's lane counts need not divide 64).
HWY_INLINE void or_bits(std::uint64_t* words, std::size_t x, std::uint64_t bits, std::size_t n) {
    if (n < 64) bits &= (std::uint64_t{1} << n) - 1;
    const std::size_t shift = x % 64;
    words[x / 64] |= bits << shift;
    if (shift != 0 && shift + n > 64) words[x / 64 + 1] |= bits >> (64 - shift);
}

// A mask of at most 64 lanes as the low bits of a word, lane i in bit i, and back: Highway stores mask bits as
// bytes, and lanes are little-endian bits on every target.
template <class D, class M>
HWY_INLINE std::uint64_t mask_to_bits(D d, M mask) {
    std::uint8_t bytes[8] = {};
    hn::StoreMaskBits(d, mask, bytes);
    std::uint64_t bits = 0;
    std::memcpy(&bits, bytes, sizeof bits);
    return bits;
}

template <class D>
HWY_INLINE auto bits_to_mask(D d, std::uint64_t bits) {
    std::uint8_t bytes[8] = {};
    std::memcpy(bytes, &bits, sizeof bits);
    return hn::LoadMaskBits(d, bytes);
}

// ORs the lanes of `mask` (pixels x .. x + Lanes(d) - 1) into the pixel bitmap.
template <class D, class M>
HWY_INLINE void or_mask_bits(D d, M mask, std::uint64_t* words, std::size_t x) {
    or_bits(words, x, mask_to_bits(d, mask), hn::Lanes(d));
}

// NOLINTEND(llvm-header-guard)
