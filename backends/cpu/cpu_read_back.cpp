// The frame's results to the caller's Result: labels (renumbered through the compaction table when asked for), and
// the raw labels, fillable mask, statistics and normals each when asked for.
#include <algorithm>

#include "backends/cpu/cpu_executor.hpp"
#include "core/segment_graph.hpp"
#include "core/segment_stats.hpp"

namespace pyrseg::cpu {

using std::size_t;
using std::uint32_t;

void CpuExecutor::read_back(Result& out, const Outputs& outputs) {
    const size_t pixels = plan_.pixel_count();
    const uint32_t* raw = labels_.data() + plan_.full().offset;
    out.width = plan_.width;
    out.height = plan_.height;
    out.segment_count = segment_count_;
    out.labels.resize(pixels);
    const PassContext c = context();
    uint32_t* labels = out.labels.data();
    const bool compacted = compacted_;
    const size_t width = size_t(plan_.width);
    if (!compacted) {
        std::copy_n(raw, pixels, labels);
    } else {
        // lut_[0] is 0 (compact): every pixel is one lookup.
        const uint32_t* lut = c.lut;
        const bool vector = simd_ != nullptr && lut_.size() <= (size_t{1} << 31);
        rows(size_t(plan_.height), [&](size_t y) {
            const uint32_t* in = raw + y * width;
            uint32_t* to = labels + y * width;
            if (vector) {
                simd_->compact_row(in, lut, uint32_t(width), to);
            } else {
                for (size_t x = 0; x < width; ++x) to[x] = lut[in[x]];
            }
        });
    }
    if (outputs.raw_labels) {
        out.raw_labels.assign(raw, raw + pixels);
    } else {
        out.raw_labels.clear();
    }
    if (outputs.fillable_mask) {
        const std::uint8_t* m = mask_.data() + plan_.full().offset;
        out.fillable_mask.resize(pixels);
        // Bit 0 is B; edge labelling's rounds live in the bits above it.
        std::transform(m, m + pixels, out.fillable_mask.begin(),
                       [](std::uint8_t v) { return std::uint8_t(v & PYR_MASK_FILLABLE); });
    } else {
        out.fillable_mask.clear();
    }
    out.segments.clear();
    if (plan_.stats_slots != 0)
        core::decode_segment_stats(stats_.data(), segment_count_, plan_, !from_mask_, out.segments);
    out.graph.clear();
    if (plan_.graph_slots != 0)
        core::decode_segment_graph(graph_words_.data() + graph_list_, graph_words_[0], out.graph);
    out.normals.clear();
    if (outputs.normals && !from_mask_) {
        out.normals.resize(3 * pixels);
        const size_t w = size_t(plan_.width);
        for (size_t y = 0; y < size_t(plan_.height); ++y) {
            for (size_t x = 0; x < w; ++x) std::copy_n(normal(x, y), 3, out.normals.data() + 3 * (y * w + x));
        }
    }
}

}  // namespace pyrseg::cpu
