#pragma once
// PCL's OrganizedMultiPlaneSegmentation, the peer the scene summary's planes are measured against (pyrseg eval
// --tabletop-synthetic): integral-image normals (as peers/pcl_segmentation.hpp estimates them), then planes of at
// least min_inliers points whose normals agree within the angular threshold and whose points lie within the
// distance threshold, with PCL's curvature filter. PCL's headers stay in the .cpp.
#include <array>
#include <cstdint>
#include <vector>

#include "peers/pcl_segmentation.hpp"

namespace pyrseg::peers {

struct PclPlaneSettings {
    PclSettings normals;                    // normal_method, normal_smoothing_size, max_depth_change_factor are used
    float angular_threshold_rad = 0.0349f;  // PCL's default: 2 degrees
    float distance_threshold_mm = 20.0f;    // PCL's default: 2 cm
    float maximum_curvature = 0.001f;       // PCL's default
    std::uint32_t min_inliers = 1000;       // PCL's default
};

struct PclPlane {
    std::array<double, 3> normal{};      // unit, as PCL's model gives it (ax + by + cz + d = 0)
    double offset_mm = 0;                // d, in millimetres
    std::vector<std::uint32_t> inliers;  // pixel indices
};

// The planes of a frame: packed xyz in millimetres (NaN: no data).
[[nodiscard]] std::vector<PclPlane> pcl_multi_plane(const float* points_mm, int width, int height,
                                                    const PclPlaneSettings& settings);

}  // namespace pyrseg::peers
