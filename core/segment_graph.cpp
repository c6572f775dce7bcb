#include "core/segment_graph.hpp"

#include <algorithm>

#include "shaders/pyr_types.h"

namespace pyrseg::core {

void decode_segment_graph(const std::uint32_t* words, std::uint32_t count, std::vector<SegmentEdge>& out) {
    out.resize(count);
    for (std::uint32_t i = 0; i < count; ++i) {
        const std::uint32_t* w = words + std::size_t(PYR_GRAPH_SLOT_WORDS) * i;
        SegmentEdge& e = out[i];
        e.a = w[0];
        e.b = w[1];
        e.length = w[PYR_GRAPH_LENGTH];
        e.flat = w[PYR_GRAPH_KINDS + PYR_BOUNDARY_FLAT];
        e.convex = w[PYR_GRAPH_KINDS + PYR_BOUNDARY_CONVEX];
        e.concave = w[PYR_GRAPH_KINDS + PYR_BOUNDARY_CONCAVE];
        e.step = w[PYR_GRAPH_KINDS + PYR_BOUNDARY_STEP];
    }
    std::sort(out.begin(), out.end(),
              [](const SegmentEdge& x, const SegmentEdge& y) { return x.a != y.a ? x.a < y.a : x.b < y.b; });
}

}  // namespace pyrseg::core
