// The segment graph (docs/algorithm.md section 10d) with the GPUs' functions (shaders/pyr_graph.h) over words of its
// own: every row's crossings counted into the pair table at once, then the pairs gathered, in the slots K segments can
// need (pyr_graph_slots, as every backend).
#include <algorithm>
#include <atomic>

#include "backends/cpu/cpu_executor.hpp"
#include "backends/cpu/cpu_pair_table.hpp"

namespace pyrseg::cpu {

using std::size_t;
using std::uint32_t;

void CpuExecutor::segment_graph() {
    const PyrLevel lv = plan_.full();
    const core::Thresholds& t = plan_.thresholds;
    const uint32_t slots = pyr_graph_slots(segment_count_, plan_.graph_slots);
    const size_t list = 1 + size_t(PYR_GRAPH_SLOT_WORDS) * slots;
    std::fill_n(graph_words_.begin(), list, 0u);
    PassContext c = context();
    c.merge = graph_words_.data();
    const uint32_t with_points = from_mask_ ? 0u : 1u;
    const uint32_t apply = plan_.params.compact ? 1u : 0u;
    const auto reach = uint32_t(plan_.params.merge_reach);
    rows(lv.height, [&](size_t y) {
        for_each_boundary_pixel(labels_.data(), lv, y, [&](uint32_t x) {
            pixel::pyr_graph_count(c, lv, x, uint32_t(y), with_points, apply, reach, t.merge_point_scale,
                                   t.merge_tolerance_base, t.merge_tolerance_growth, 1u, slots - 1);
        });
    });
    for (uint32_t s = 0; s < slots; ++s) pixel::pyr_graph_gather(c, 1u, s, uint32_t(list), 0u);
    graph_list_ = list;
}

}  // namespace pyrseg::cpu
