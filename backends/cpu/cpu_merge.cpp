// Step 6d, the merge (docs/algorithm.md section 5b), with the GPUs' functions (shaders/pyr_merge_table.h) over a
// table sized once per Segmenter: every row's crossings counted into the pair table at once, then the pairs that
// join united and every label of level N given its group's smallest label, each row marked for step 7 as it is
// relabelled.
#include <algorithm>
#include <atomic>

#include "backends/cpu/cpu_executor.hpp"
#include "backends/cpu/cpu_pair_table.hpp"

namespace pyrseg::cpu {

using std::size_t;
using std::uint32_t;

void CpuExecutor::merge_segments() {
    const PyrLevel lv = plan_.full();
    const core::Thresholds& t = plan_.thresholds;
    const uint32_t labels = plan_.lut_size();
    const uint32_t slots = plan_.merge_slots;
    merge_words_.resize(size_t(labels) + size_t(PYR_MERGE_SLOT_WORDS) * slots);  // once per Segmenter
    for (uint32_t l = 0; l < labels; ++l) merge_words_[l] = l;
    std::fill(merge_words_.begin() + labels, merge_words_.end(), 0u);
    PassContext c = context();
    c.merge = merge_words_.data();
    const auto reach = uint32_t(plan_.params.merge_reach);
    rows(lv.height, [&](size_t y) {
        for_each_boundary_pixel(labels_.data(), lv, y, [&](uint32_t x) {
            pixel::pyr_merge_count(c, lv, x, uint32_t(y), reach, t.merge_point_scale, t.merge_tolerance_base,
                                   t.merge_tolerance_growth, labels, slots - 1);
        });
    });
    const auto min_crossings = uint32_t(plan_.params.merge_min_crossings);
    for (uint32_t s = 0; s < slots; ++s) pixel::pyr_merge_link(c, labels, s, min_crossings, t.merge_share);
    // Parents are smaller labels, so in increasing order each parent is already its root.
    bool joined = false;
    for (uint32_t l = 0; l < labels; ++l) {
        merge_words_[l] = merge_words_[merge_words_[l]];
        joined = joined || merge_words_[l] != l;
    }
    // Each row relabelled (when any group joined) and its labels marked for step 7 (marks_labels_in_merge).
    std::fill(lut_.begin(), lut_.end(), 0u);
    rows(lv.height, [&](size_t y) {
        uint32_t* row = labels_.data() + lv.offset + y * lv.width;
        if (joined) {
            for (size_t x = 0; x < lv.width; ++x) row[x] = merge_words_[row[x]];
        }
        mark_row_labels(row, lv.width);
    });
}

}  // namespace pyrseg::cpu
