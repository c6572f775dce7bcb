#pragma once
// Segmentation parameters. Defaults are the algorithm contract's (docs/algorithm.md).
#include <optional>

namespace pyrseg {

inline constexpr double kDefaultCurvatureThreshold = 0.25;  // ct, radians
inline constexpr double kDefaultDepthThresholdMm = 10.0;    // dt, millimetres
inline constexpr int kDefaultBridgeLevels = 2;              // b
inline constexpr int kDefaultUnjoinableGap = 2;             // g
inline constexpr int kDefaultNormalRadius = 2;              // normals pass neighbour offset, pixels

struct Params {
    double ct = kDefaultCurvatureThreshold;  // curvature threshold in radians; >= pi disables curvature edges
    double dt = kDefaultDepthThresholdMm;    // depth-difference threshold in millimetres (+inf disables)
    double unit_mm = 1.0;                    // millimetres per input unit (1000 for metres)
    // Unset means the default (2) with the contract's small-image fallback; a value set explicitly that does
    // not fit the image is rejected instead.
    std::optional<int> bridge_levels;
    std::optional<int> unjoinable_gap;
    bool label_edges = true;                   // step 6c: valid edge pixels join their smallest labelled neighbour
    bool compact = true;                       // step 7: renumber labels 1..K
    int normal_radius = kDefaultNormalRadius;  // used only when normals are estimated
};

}  // namespace pyrseg
