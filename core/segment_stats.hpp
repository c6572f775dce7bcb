#pragma once
// The statistics pass's words (shaders/pyr_stats.h, layout in shaders/pyr_types.h) into SegmentStats, on the host,
// once for every backend.
#include <cstdint>
#include <vector>

#include "core/plan.hpp"
#include "pyrseg/result.hpp"

namespace pyrseg::core {

// `words` holds the first `count` slots (K, the segment count). with_points: the frame was a cloud.
void decode_segment_stats(const std::uint32_t* words, std::uint32_t count, const Plan& plan, bool with_points,
                          std::vector<SegmentStats>& out);

}  // namespace pyrseg::core
