#pragma once
// A ground truth for a real tabletop depth frame, made from the depth the way the OCID dataset was annotated
// (docs/quality.md, "Real frames"): the support plane (RANSAC, refined by least squares; the highest such plane
// parallel to the first with at least a tenth of the valid pixels, so that a table wins over the floor); the table =
// the plane's inliers in their largest image component; the objects = the pixels that stand min_height..max_height
// above the plane and project into the table's outline on it (the convex hull of the table's points in the plane),
// split into depth-continuous components of at least min_object_pixels pixels. Touching objects stay one object.
//
// Deterministic: the RANSAC samples come from a seeded generator of its own, so a frame always gets the same truth.
// Plain C++, no dependency on the library (the frame is a depth array in metres and the pinhole intrinsics).
#include <array>
#include <cstdint>
#include <span>
#include <vector>

namespace pyrseg::eval {

struct TabletopCamera {
    double fx = 0;
    double fy = 0;
    double cx = 0;
    double cy = 0;
};

struct TabletopTruthParams {
    double plane_tolerance = 0.010;  // metres from the plane that count as the plane's
    double min_height = 0.015;       // metres above the plane where objects begin ...
    double max_height = 0.400;       // ... and end
    // Two 4-neighbours are depth-continuous when their depths differ by at most step_base + step_growth * depth.
    double step_base = 0.005;
    double step_growth = 0.02;
    std::uint32_t min_object_pixels = 300;
    std::uint32_t ransac_iterations = 400;
    // The support is the highest plane parallel to the first one found (within support_parallel_degrees) that holds
    // at least min_support_share of the valid pixels: a table above the floor it stands on.
    double min_support_share = 0.1;
    double support_parallel_degrees = 10.0;
    std::uint64_t seed = 1;
};

// The plane n . p + d = 0 with n a unit vector towards the camera (d > 0): n . p + d is a point's height above it.
struct SupportPlane {
    std::array<double, 3> normal{0, 0, 1};
    double offset = 0;
    std::uint64_t inliers = 0;  // pixels within plane_tolerance of it (the table is the largest component of them)
};

inline constexpr std::uint32_t kTruthNone = 0;  // no truth: no depth, background, fragments under the minimum
inline constexpr std::uint32_t kTruthTable =
    1;  // the table; objects are 2, 3, ... in raster order of their first pixel

struct TabletopTruth {
    std::vector<std::uint32_t> labels;  // one per pixel
    SupportPlane plane;
    std::uint32_t objects = 0;  // labels 2 .. objects + 1
    bool found_plane = false;   // false: fewer than 3 valid pixels, or no plane had any inlier beyond its sample
};

// depth: width * height depths in metres, row by row; 0 or not finite is no depth. Throws std::invalid_argument
// when the sizes disagree or the camera is not finite and positive.
[[nodiscard]] TabletopTruth make_tabletop_truth(int width, int height, std::span<const float> depth,
                                                const TabletopCamera& camera, const TabletopTruthParams& params = {});

}  // namespace pyrseg::eval
