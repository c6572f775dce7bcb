// Step 6c's edges (shaders/pyr_edges.h): one round in place, from candidates, and the rounds of several.
// Included by cpu_simd.cpp inside each target's namespace, once per target (foreach_target.h): no include guard.
// NOLINTBEGIN(llvm-header-guard)

// Step 6c's vector loop over pixels 1 .. w - 2, shared by edge_row and edge_row_from_candidates: vectors of mask
// bytes with no valid non-fillable pixel (most of a frame) are skipped, and so is each part of one, as wide as a
// vector of labels, that has none (on fragmented masks most vectors of bytes have one, few parts do). Calls
// part(s, is_edge) for the others (s: the part's first pixel; is_edge: a mask of its lanes) and returns the first
// pixel it did not cover, from which the caller goes on one pixel at a time.
template <class Part>
HWY_INLINE std::size_t for_each_edge_part(const std::uint8_t* mask, const std::uint8_t* valid, std::uint32_t w,
                                          const Part& part) {
    const hn::ScalableTag<std::uint8_t> d8;
    const DU du;
    const std::size_t n8 = hn::Lanes(d8);
    const std::size_t n = hn::Lanes(du);
    std::size_t x = 1;
    if (n8 % n != 0 || n8 > 64) return x;
    const auto fillable_bit = hn::Set(d8, std::uint8_t{PYR_MASK_FILLABLE});
    const std::uint64_t lanes = n >= 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << n) - 1;
    for (; x + n8 + 1 <= w; x += n8) {
        const auto not_fillable = hn::Eq(hn::And(hn::LoadU(d8, mask + x), fillable_bit), hn::Zero(d8));
        const auto invalid = hn::Eq(hn::LoadU(d8, valid + x), hn::Zero(d8));
        const auto edge = hn::AndNot(invalid, not_fillable);
        if (hn::AllFalse(d8, edge)) continue;
        std::uint64_t edges = mask_to_bits(d8, edge);
        for (std::size_t s = x; s < x + n8; s += n, edges >>= n % 64) {
            const std::uint64_t bits = edges & lanes;
            if (bits != 0) part(s, bits_to_mask(du, bits));
        }
    }
    return x;
}

// The edge label of pixel x of the row (edge_row's rule), one pixel at a time: the image's borders and the tails.
std::uint32_t edge_pixel(const std::uint8_t* mask_above, const std::uint8_t* mask, const std::uint8_t* mask_below,
                         const std::uint32_t* above, const std::uint32_t* labels, const std::uint32_t* below,
                         const std::uint8_t* valid, std::uint32_t w, std::uint32_t x) {
    const std::uint32_t own = labels[x];
    if ((mask[x] & PYR_MASK_FILLABLE) != 0 || valid[x] == 0) return own;
    // Labels minus 1 (0 wraps to the largest value): the minimum then skips 0, and adding 1 back gives 0 for none.
    std::uint32_t best = own - 1u;
    const auto take = [&](std::uint8_t m, std::uint32_t l) {
        if ((m & PYR_MASK_FILLABLE) != 0) best = std::min(best, l - 1u);
    };
    if (x > 0) take(mask[x - 1], labels[x - 1]);
    if (x + 1 < w) take(mask[x + 1], labels[x + 1]);
    if (above != nullptr) take(mask_above[x], above[x]);
    if (below != nullptr) take(mask_below[x], below[x]);
    return best + 1u;
}

void edge_row(const std::uint8_t* mask_above, const std::uint8_t* mask, const std::uint8_t* mask_below,
              const std::uint32_t* above, std::uint32_t* labels, const std::uint32_t* below, const std::uint8_t* valid,
              std::uint32_t w) {
    const auto scalar = [&](std::size_t x) {
        labels[x] = edge_pixel(mask_above, mask, mask_below, above, labels, below, valid, w, std::uint32_t(x));
    };
    const DU du;
    const hn::Rebind<std::uint8_t, DU> d8q;
    const VU one = hn::Set(du, 1u);
    // Labels minus 1 of fillable neighbours, the largest value for the others (see edge_pixel).
    const auto candidate = [&](const std::uint32_t* l, const std::uint8_t* m) {
        const VU not_fillable = hn::Sub(hn::And(hn::PromoteTo(du, hn::LoadU(d8q, m)), one), one);
        return hn::Or(hn::Sub(hn::LoadU(du, l), one), not_fillable);
    };
    const std::size_t x = for_each_edge_part(mask, valid, w, [&](std::size_t s, auto is_edge) {
        const VU own = hn::LoadU(du, labels + s);
        VU best = hn::Min(hn::Sub(own, one),
                          hn::Min(candidate(labels + s - 1, mask + s - 1), candidate(labels + s + 1, mask + s + 1)));
        if (above != nullptr) best = hn::Min(best, candidate(above + s, mask_above + s));
        if (below != nullptr) best = hn::Min(best, candidate(below + s, mask_below + s));
        hn::StoreU(hn::IfThenElse(is_edge, hn::Add(best, one), own), du, labels + s);
    });
    if (w > 0) scalar(0);
    for (std::size_t i = x; i < w; ++i) scalar(i);
}

// Round `round` of step 6c with several rounds (pyr_edge_label) on one row (cpu_simd.hpp): the same minimum over
// candidates as edge_row, where a neighbour is a candidate when it is fillable or its mask holds an earlier round
// (and, with the depth test, lies near in depth). Only the pixels that take a label are written (few: a round labels
// the edge pixels next to the last one's).
bool edge_round_row(const std::uint8_t* mask_above, const std::uint8_t* mask, const std::uint8_t* mask_below,
                    const std::uint32_t* above, const std::uint32_t* labels, const std::uint32_t* below,
                    const std::uint8_t* valid, std::uint32_t w, std::uint32_t round, const EdgeDepths& depths,
                    std::uint32_t* out, std::uint64_t* changed) {
    std::memset(changed, 0, (std::size_t(w) + 63) / 64 * sizeof(std::uint64_t));
    bool any = false;
    const float step = round >= 2 ? depths.step : 0.0f;
    const auto usable = [&](std::uint8_t m) {
        const std::uint32_t labelled_round = std::uint32_t(m) >> PYR_MASK_EDGE_SHIFT;
        return (m & PYR_MASK_FILLABLE) != 0 || (labelled_round != 0 && labelled_round < round);
    };
    const auto depth = [&](std::size_t x, std::ptrdiff_t rows) {
        return std::bit_cast<float>(
            depths.quant[std::ptrdiff_t(kQuantWords * x) + rows * std::ptrdiff_t(kQuantWords * w) + 2]);
    };
    const auto scalar = [&](std::size_t x) {
        if ((mask[x] & PYR_MASK_FILLABLE) != 0 || labels[x] != 0 || valid[x] == 0) return;
        const float z = step > 0.0f ? depth(x, 0) : 0.0f;
        // Labels minus 1 (0 wraps to the largest value): the minimum then skips 0, and adding 1 back gives 0 for none.
        std::uint32_t best = ~0u;
        const auto take = [&](std::uint8_t m, std::uint32_t l, std::size_t nx, std::ptrdiff_t rows) {
            if (!usable(m)) return;
            if (step > 0.0f && pixel::pyr_edge_depth_near(z, depth(nx, rows), step) == 0u) return;
            best = std::min(best, l - 1u);
        };
        if (x > 0) take(mask[x - 1], labels[x - 1], x - 1, 0);
        if (x + 1 < w) take(mask[x + 1], labels[x + 1], x + 1, 0);
        if (above != nullptr) take(mask_above[x], above[x], x, -1);
        if (below != nullptr) take(mask_below[x], below[x], x, 1);
        if (best == ~0u) return;
        out[x] = best + 1u;
        changed[x / 64] |= std::uint64_t{1} << (x % 64);
        any = true;
    };
    const DU du;
    const hn::Rebind<std::uint8_t, DU> d8q;
    const VU one = hn::Set(du, 1u);
    const VU none = hn::Set(du, ~0u);
    const VU fillable_bit = hn::Set(du, PYR_MASK_FILLABLE);
    const VU this_round = hn::Set(du, round);
    const DF df;
    const VF step_v = hn::Set(df, step);
    // The z of the lanes' pixels `dx` columns and `rows` rows away (the third word of each quantized pixel).
    const auto depth_at = [&](std::size_t s, std::ptrdiff_t dx, std::ptrdiff_t rows) {
        VU w0;
        VU w1;
        VU w2;
        const std::ptrdiff_t pixel = std::ptrdiff_t(s) + dx + rows * std::ptrdiff_t(w);
        hn::LoadInterleaved3(du, depths.quant + std::ptrdiff_t(kQuantWords) * pixel, w0, w1, w2);
        return hn::BitCast(df, w2);
    };
    // Labels minus 1 of usable neighbours, the largest value for the others; with the depth test (pyr_edge_depth_near:
    // |z_p - z_q| <= s * z_p, the same correctly rounded float operations lane by lane) only of those near in depth.
    const bool test = step > 0.0f;
    const auto candidate = [&](const std::uint32_t* l, const std::uint8_t* m, const VF& z, std::size_t s,
                               std::ptrdiff_t dx, std::ptrdiff_t rows) {
        const VU bits = hn::PromoteTo(du, hn::LoadU(d8q, m));
        const VU labelled_round = hn::ShiftRight<PYR_MASK_EDGE_SHIFT>(bits);
        auto use = hn::Or(hn::Ne(hn::And(bits, fillable_bit), hn::Zero(du)),
                          hn::And(hn::Ne(labelled_round, hn::Zero(du)), hn::Lt(labelled_round, this_round)));
        if (test) {
            const VF dz = hn::Abs(hn::Sub(z, depth_at(s, dx, rows)));
            use = hn::And(use, hn::RebindMask(du, hn::Le(dz, hn::Mul(step_v, z))));
        }
        return hn::IfThenElse(use, hn::Sub(hn::LoadU(du, l), one), none);
    };
    const std::size_t x = for_each_edge_part(mask, valid, w, [&](std::size_t s, auto is_edge) {
        const auto open = hn::And(is_edge, hn::Eq(hn::LoadU(du, labels + s), hn::Zero(du)));
        if (hn::AllFalse(du, open)) return;
        const VF z = test ? depth_at(s, 0, 0) : hn::Zero(df);
        VU best = hn::Min(candidate(labels + s - 1, mask + s - 1, z, s, -1, 0),
                          candidate(labels + s + 1, mask + s + 1, z, s, 1, 0));
        if (above != nullptr) best = hn::Min(best, candidate(above + s, mask_above + s, z, s, 0, -1));
        if (below != nullptr) best = hn::Min(best, candidate(below + s, mask_below + s, z, s, 0, 1));
        const auto takes = hn::And(open, hn::Ne(best, none));
        if (hn::AllFalse(du, takes)) return;
        hn::StoreU(hn::Add(best, one), du, out + s);
        or_mask_bits(du, takes, changed, s);
        any = true;
    });
    if (w > 0) scalar(0);
    for (std::size_t i = x; i < w; ++i) scalar(i);
    return any;
}

// Step 6c's candidates of a row (cpu_simd.hpp): label - 1 where fillable (0 wraps to the largest value), the largest
// value elsewhere, so that an edge pixel's label is one minimum of its neighbours' candidates.
void edge_candidates(const std::uint8_t* mask, const std::uint32_t* labels, std::uint32_t w, std::uint32_t* out) {
    std::size_t x = 0;
#if HWY_TARGET != HWY_SCALAR
    const DU du;
    const hn::Rebind<std::uint8_t, DU> d8q;
    const std::size_t n = hn::Lanes(du);
    const VU one = hn::Set(du, 1u);
    for (; x + n <= w; x += n) {
        const VU not_fillable = hn::Sub(hn::And(hn::PromoteTo(du, hn::LoadU(d8q, mask + x)), one), one);
        hn::StoreU(hn::Or(hn::Sub(hn::LoadU(du, labels + x), one), not_fillable), du, out + x);
    }
#endif
    for (; x < w; ++x) out[x] = (mask[x] & PYR_MASK_FILLABLE) != 0 ? labels[x] - 1u : ~0u;
}

// edge_row from the rows' candidates (edge_candidates): the same labels with five loads and four minima a vector.
void edge_row_from_candidates(const std::uint32_t* above, const std::uint32_t* row, const std::uint32_t* below,
                              const std::uint8_t* mask, const std::uint8_t* valid, std::uint32_t* labels,
                              std::uint32_t w) {
    const auto scalar = [&](std::size_t x) {
        if ((mask[x] & PYR_MASK_FILLABLE) != 0 || valid[x] == 0) return;
        std::uint32_t best = labels[x] - 1u;
        if (x > 0) best = std::min(best, row[x - 1]);
        if (x + 1 < w) best = std::min(best, row[x + 1]);
        if (above != nullptr) best = std::min(best, above[x]);
        if (below != nullptr) best = std::min(best, below[x]);
        labels[x] = best + 1u;
    };
    const DU du;
    const VU one = hn::Set(du, 1u);
    const VU none = hn::Set(du, ~0u);
    const std::size_t x = for_each_edge_part(mask, valid, w, [&](std::size_t s, auto is_edge) {
        const VU own = hn::LoadU(du, labels + s);
        const VU vertical = hn::Min(above != nullptr ? hn::LoadU(du, above + s) : none,
                                    below != nullptr ? hn::LoadU(du, below + s) : none);
        const VU best = hn::Min(hn::Min(hn::Sub(own, one), vertical),
                                hn::Min(hn::LoadU(du, row + s - 1), hn::LoadU(du, row + s + 1)));
        hn::StoreU(hn::IfThenElse(is_edge, hn::Add(best, one), own), du, labels + s);
    });
    if (w > 0) scalar(0);
    for (std::size_t i = x; i < w; ++i) scalar(i);
}

// NOLINTEND(llvm-header-guard)
