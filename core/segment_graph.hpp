#pragma once
// The segment graph's gathered pairs (shaders/pyr_graph.h) into Result::graph, on the host, once for every backend.
#include <cstdint>
#include <vector>

#include "pyrseg/result.hpp"

namespace pyrseg::core {

// `words` holds `count` pairs of PYR_GRAPH_SLOT_WORDS words each, in the order the device gathered them; `out` gets
// them by increasing (a, b), the same on every backend.
void decode_segment_graph(const std::uint32_t* words, std::uint32_t count, std::vector<SegmentEdge>& out);

}  // namespace pyrseg::core
