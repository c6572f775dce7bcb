// Step 6c after the final fill (with several edge rounds, or on the scalar path), and compaction's marking of each
// row once its labels are final (marks_labels_before_compact).
#include <algorithm>
#include <bit>

#include "backends/cpu/cpu_executor.hpp"

namespace pyrseg::cpu {

using std::size_t;
using std::uint32_t;

void CpuExecutor::label_edges() {
    const PassContext c = context();
    const PyrLevel full = plan_.full();
    std::fill(lut_.begin(), lut_.end(), 0u);
    const auto rounds = uint32_t(plan_.params.edge_rounds);
    if (rounds == 1) {
        rows(full.height, [&](size_t y) {
            for (uint32_t x = 0; x < full.width; ++x) {
                const uint32_t i = full.offset + uint32_t(y) * full.width + x;
                // Only edge pixels change, and no other pixel reads them: writing only changes keeps rows
                // free of races on the fillable labels they read.
                const uint32_t l = pixel::pyr_edge_label(c, full, x, uint32_t(y), 1u, 0.0f);
                if (l != labels_[i]) labels_[i] = l;
            }
            mark_row(y);
        });
        return;
    }
    // Several rounds: each one reads its neighbours' masks, which the round's own writes change, so it first
    // computes every new label and then writes them (with the round in the mask). A pixel can only take a label
    // in a round after the first when a neighbour took one in the round before (only those became candidates),
    // so a round skips the rows with no changed row next to them, and a round that labels nothing ends them.
    const size_t h = full.height;
    const size_t w = full.width;
    if (edge_next_.empty()) edge_next_.resize(plan_.pixel_count());  // once per Segmenter
    if (edge_changed_.size() < 2 * h) edge_changed_.resize(2 * h);
    std::uint8_t* changed = edge_changed_.data();  // this round's, per row
    std::uint8_t* before = changed + h;            // the round before's
    std::fill_n(changed, h, std::uint8_t{1});
    const std::uint8_t* valid = validity_bytes(c);
    const size_t words = (w + 63) / 64;
    const float depth_step = plan_.thresholds.edge_depth_step;
    if (edge_bits_.size() < h * words) edge_bits_.resize(h * words);  // once per Segmenter
    for (uint32_t round = 1; round <= rounds; ++round) {
        std::swap(changed, before);
        const auto open = [&](size_t y) {
            return round == 1 || before[y] != 0 || (y > 0 && before[y - 1] != 0) || (y + 1 < h && before[y + 1] != 0);
        };
        // Each open row's new labels (edge_next_) and the pixels that take one (edge_bits_), then written.
        rows(h, [&](size_t y) {
            changed[y] = 0;
            if (!open(y)) return;
            uint32_t* next = edge_next_.data() + y * w;
            std::uint64_t* bits = edge_bits_.data() + y * words;
            if (simd_ != nullptr) {
                const size_t i = full.offset + y * w;
                const bool up = y > 0;
                const bool down = y + 1 < h;
                const simd::EdgeDepths depths{depth_step, depth_step > 0.0f ? c.quant + kQuantWords * y * w : nullptr};
                changed[y] = std::uint8_t(simd_->edge_round_row(
                    up ? c.mask + i - w : nullptr, c.mask + i, down ? c.mask + i + w : nullptr,
                    up ? c.labels + i - w : nullptr, c.labels + i, down ? c.labels + i + w : nullptr, valid + y * w,
                    uint32_t(w), round, depths, next, bits));
                return;
            }
            std::fill_n(bits, words, std::uint64_t{0});
            for (uint32_t x = 0; x < w; ++x) {
                next[x] = pixel::pyr_edge_label(c, full, x, uint32_t(y), round, depth_step);
                if (next[x] == labels_[full.offset + y * w + x]) continue;
                bits[x / 64] |= std::uint64_t{1} << (x % 64);
                changed[y] = 1;
            }
        });
        const auto round_bits = std::uint8_t(round < rounds ? round << PYR_MASK_EDGE_SHIFT : 0u);
        rows(h, [&](size_t y) {
            if (changed[y] == 0) return;
            uint32_t* l = labels_.data() + full.offset + y * w;
            std::uint8_t* m = mask_.data() + full.offset + y * w;
            const uint32_t* next = edge_next_.data() + y * w;
            const std::uint64_t* bits = edge_bits_.data() + y * words;
            for (size_t i = 0; i < words; ++i) {
                for (std::uint64_t b = bits[i]; b != 0; b &= b - 1) {
                    const size_t x = i * 64 + size_t(std::countr_zero(b));
                    l[x] = next[x];
                    m[x] = std::uint8_t(m[x] | round_bits);
                }
            }
        });
        if (std::find(changed, changed + h, std::uint8_t{1}) == changed + h) break;
    }
    rows(h, [&](size_t y) { mark_row(y); });
}

// Validity bytes of the full level: the caller's mask's or points_to_mask's, else made from the quantized
// pixels into mask_valid_ (unused in such a frame).
const std::uint8_t* CpuExecutor::validity_bytes(const PassContext& c) {
    if (c.mask_valid != nullptr) return c.mask_valid;
    const size_t w = plan_.width;
    rows(size_t(plan_.height), [&](size_t y) {
        std::uint8_t* out = mask_valid_.data() + y * w;
        const uint32_t* q = c.quant + kQuantWords * y * w;
        for (size_t x = 0; x < w; ++x) out[x] = std::uint8_t(q[kQuantWords * x + 1] >> 16);
    });
    return mask_valid_.data();
}

}  // namespace pyrseg::cpu
