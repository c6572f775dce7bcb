// Steps 5 and 6 a, b (and 6c with one edge round) on level N. The scalar path runs each row's step-5 labels just
// before its row sweeps (cpu_fills.cpp), while the row is in cache; the vector path runs final_fill_rows below.
#include <algorithm>

#include "backends/cpu/cpu_executor.hpp"

namespace pyrseg::cpu {

using std::size_t;
using std::uint32_t;

namespace {

// The bits of pending_.
constexpr std::uint8_t kPending = 1;  // marked pixels remain after the band pass
constexpr std::uint8_t kLate = 2;     // the upward crossing changed the row

[[nodiscard]] bool any_bits(const uint64_t* bits, size_t words) {
    uint64_t any = 0;
    for (size_t i = 0; i < words; ++i) any |= bits[i];
    return any != 0;
}

}  // namespace

void CpuExecutor::final_fill(int level) {
    if (simd_ == nullptr) {
        sweep(plan_.level(level), true, true);
        return;
    }
    final_fill_rows(plan_.level(level), plan_.level(level - 1), false);
}

void CpuExecutor::final_fill_with_edges(int level) {
    final_fill_rows(plan_.level(level), plan_.level(level - 1), true);
}

// Step 6 changes only the pixels that are fillable and unlabelled after step 5, few of them (the children of
// non-fillable texels at the regions' borders), and its schedule reduces to runs of them: a row's run takes the
// label of the pixel left of it when that one is fillable (so labelled), else of the one right of it, else stays
// 0; then a column's run of those still unlabelled takes the label above it, else the one below it. So one pass
// over the rows runs step 5 with a vector row that also marks those pixels in a bitmap, and steps 6 a and the
// downward sweep then touch only the marked pixels; the upward sweep visits the pixels still marked, bottom up.

// Row y's validity bytes: the mask's own, else from the quantized pixels into scratch.
const std::uint8_t* CpuExecutor::valid_row(const PassContext& c, size_t y, std::uint8_t* scratch) const {
    const size_t w = plan_.width;
    if (c.mask_valid != nullptr) return c.mask_valid + y * w;
    for (size_t x = 0; x < w; ++x) scratch[x] = std::uint8_t(c.quant[kQuantWords * (y * w + x) + 1] >> 16);
    return scratch;
}

void CpuExecutor::edge_row(const PassContext& c, const PyrLevel& lv, size_t y, std::uint8_t* scratch) const {
    const size_t w = lv.width;
    const size_t i = lv.offset + y * w;
    const bool up = y > 0;
    const bool down = y + 1 < lv.height;
    simd_->edge_row(up ? c.mask + i - w : nullptr, c.mask + i, down ? c.mask + i + w : nullptr,
                    up ? c.labels + i - w : nullptr, c.labels + i, down ? c.labels + i + w : nullptr,
                    valid_row(c, y, scratch), lv.width);
}

void CpuExecutor::final_fill_rows(const PyrLevel& lv, const PyrLevel& parent, bool edges) {
    const PassContext c = context();
    const size_t w = lv.width;
    const size_t h = lv.height;
    const size_t words = (w + 63) / 64;
    if (unlabelled_.size() < h * words) unlabelled_.resize(h * words);  // once per Segmenter
    if (pending_.size() < h) pending_.resize(h);
    // Bands of rows run in parallel; the column sweeps cross their borders afterwards, in order.
    const size_t bands = std::min(h, pool_.pieces());
    if (edges && c.mask_valid == nullptr && valid_scratch_.size() < bands * w) valid_scratch_.resize(bands * w);
    const auto band_begin = [&](size_t b) { return h * b / bands; };
    const auto row_of = [&](size_t y) { return c.labels + lv.offset + y * w; };
    const auto mask_of = [&](size_t y) { return c.mask + lv.offset + y * w; };
    const auto bits_of = [&](size_t y) { return unlabelled_.data() + y * words; };
    // One column step of row y from row `from` (y - 1 down, y + 1 up).
    const auto step = [&](size_t y, size_t from) {
        return simd_->column_step(mask_of(from), row_of(from), row_of(y), bits_of(y), uint32_t(w));
    };
    // A row is pending when marked pixels remain in it after the band pass: only those can change later, so the
    // edges next to them wait for the end, and the others' edges are final during the band pass.
    const auto settled = [&](size_t y) {
        return ((pending_[y] | (y > 0 ? pending_[y - 1] : 0) | (y + 1 < h ? pending_[y + 1] : 0)) & kPending) == 0;
    };
    pool_.parallel_for(bands, 1, [&](size_t b0, size_t b1) {
        for (size_t b = b0; b < b1; ++b) {
            const size_t y0 = band_begin(b);
            const size_t y1 = band_begin(b + 1);
            std::uint8_t* scratch = valid_scratch_.empty() ? nullptr : valid_scratch_.data() + b * w;
            for (size_t y = y0; y < y1; ++y) {
                uint32_t* row = row_of(y);
                const std::uint8_t* m = mask_of(y);
                bool marks = simd_->inherit_row(m, c.labels + parent.offset + (y >> 1) * parent.width, uint32_t(w), row,
                                                bits_of(y));
                if (marks) marks = simd_->row_runs(m, row, bits_of(y), uint32_t(w));
                if (marks && y > y0) {
                    simd_->column_step(mask_of(y - 1), row_of(y - 1), row, bits_of(y), uint32_t(w));
                    marks = any_bits(bits_of(y), words);
                }
                pending_[y] = marks ? kPending : 0;
                // Edges read rows y - 2 .. y: all of this band's.
                if (edges && y >= y0 + 2 && settled(y - 1)) edge_row(c, lv, y - 1, scratch);
            }
        }
    });
    // The downward sweep across each band's top, down as far as it changes something.
    for (size_t b = 1; b < bands; ++b) {
        for (size_t y = band_begin(b); y < h && step(y, y - 1); ++y) {
        }
    }
    // The upward sweep: inside each band in parallel (each band's last row aside), then across the bands' bottoms
    // from the last band up, each as far as it changes something. A row stepped again from a row that gained
    // labels meanwhile ends as one step from that row's final labels would leave it: labels only ever appear.
    // The edges the band pass left wait for the first part: after it only the rows the crossings reach change.
    // Those edges read each row's candidates (edge_candidates), made once a row's labels are final for the pass
    // and kept for the three rows around it, where one of them needs them.
    if (edges && candidates_.size() < bands * 3 * w) candidates_.resize(bands * 3 * w);
    const auto needs_candidates = [&](size_t y) {
        return !settled(y) || (y > 0 && !settled(y - 1)) || (y + 1 < h && !settled(y + 1));
    };
    pool_.parallel_for(bands, 1, [&](size_t b0, size_t b1) {
        for (size_t b = b0; b < b1; ++b) {
            const size_t y0 = band_begin(b);
            const size_t y1 = band_begin(b + 1);
            std::uint8_t* scratch = valid_scratch_.empty() ? nullptr : valid_scratch_.data() + b * w;
            uint32_t* ring = edges ? candidates_.data() + b * 3 * w : nullptr;
            const auto candidates_of = [&](size_t y) { return ring + (y % 3) * w; };
            const auto make_candidates = [&](size_t y) {
                if (edges && needs_candidates(y))
                    simd_->edge_candidates(mask_of(y), row_of(y), uint32_t(w), candidates_of(y));
            };
            make_candidates(y1 - 1);
            for (size_t y = y1 - 1; y-- > y0;) {
                if (pending_[y] != 0) step(y, y + 1);
                make_candidates(y);
                if (edges && y + 2 < y1 && !settled(y + 1)) {
                    simd_->edge_row_from_candidates(candidates_of(y), candidates_of(y + 1), candidates_of(y + 2),
                                                    mask_of(y + 1), valid_row(c, y + 1, scratch), row_of(y + 1),
                                                    uint32_t(w));
                }
            }
        }
    });
    for (size_t b = bands; b-- > 1;) {
        for (size_t y = band_begin(b); y-- > 0 && step(y, y + 1);) pending_[y] |= kLate;
    }
    if (!edges) return;
    // Edges again next to the rows the upward crossings changed, in parallel inside each band, then the bands'
    // first and last rows, which read their neighbour bands' rows. edge_row takes the minimum again: a row done
    // twice comes out the same.
    const auto late = [&](size_t y) {
        return ((pending_[y] | (y > 0 ? pending_[y - 1] : 0) | (y + 1 < h ? pending_[y + 1] : 0)) & kLate) != 0;
    };
    pool_.parallel_for(bands, 1, [&](size_t b0, size_t b1) {
        for (size_t b = b0; b < b1; ++b) {
            std::uint8_t* scratch = valid_scratch_.empty() ? nullptr : valid_scratch_.data() + b * w;
            for (size_t y = band_begin(b) + 1; y + 1 < band_begin(b + 1); ++y) {
                if (late(y)) edge_row(c, lv, y, scratch);
            }
        }
    });
    std::uint8_t* scratch = valid_scratch_.empty() ? nullptr : valid_scratch_.data();
    for (size_t b = 0; b < bands; ++b) {
        edge_row(c, lv, band_begin(b), scratch);
        if (band_begin(b + 1) - 1 > band_begin(b)) edge_row(c, lv, band_begin(b + 1) - 1, scratch);
    }
}

}  // namespace pyrseg::cpu
