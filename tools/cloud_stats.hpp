#pragma once
#include <vector>

namespace pyrseg::cli {

// Median of the valid (finite, > 0) depths of packed xyz points; 0 when there is none. Used to notice clouds in
// metres given without --unit-mm 1000.
[[nodiscard]] double median_depth(const std::vector<float>& points);

}  // namespace pyrseg::cli
