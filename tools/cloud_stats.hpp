#pragma once
#include <vector>

#include "pyrseg/depth.hpp"

namespace pyrseg::cli {

// Median of the valid (finite, > 0) depths of packed xyz points; 0 when there is none.
[[nodiscard]] double median_depth(const std::vector<float>& points);

// Cloud files do not say their unit. No depth sensor sees a frame's middle 2 cm away, so a median depth under 20
// units means metres; above it, millimetres (20 m to 100 m would be metres too, but no depth camera's frame is that
// far, while a close-up scan in millimetres is).
constexpr double kMetresBelowMedianDepth = 20.0;
// The millimetres per unit a cloud with this median depth is read in when --unit-mm is not given: 1000 or 1.
[[nodiscard]] double detected_unit_mm(double median);

// pyrseg/depth.hpp's range of depth cameras' median depths, for clouds whose unit is given.
constexpr double kPlausibleMedianMetresMin = kMedianDepthMetresMin;
constexpr double kPlausibleMedianMetresMax = kMedianDepthMetresMax;
[[nodiscard]] inline bool plausible_median_metres(double metres) {
    return metres >= kPlausibleMedianMetresMin && metres <= kPlausibleMedianMetresMax;
}

}  // namespace pyrseg::cli
