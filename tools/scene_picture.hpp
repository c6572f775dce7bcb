#pragma once
// The scene summary (pyrseg/scene.hpp) drawn over a picture of the frame: each object's box (its 12 edges in its
// segment's colour) and each support's outline (white), projected through the camera's pinhole intrinsics.
#include "pyrseg/scene.hpp"
#include "tools/figures.hpp"

namespace pyrseg::cli {

struct PinholeCamera {
    double fx = 0, fy = 0, cx = 0, cy = 0;
};

// `base` with the scene drawn over it; lengths of the scene in the units the camera's points are in. Edges behind
// the camera are left out.
[[nodiscard]] RgbImage scene_picture(const RgbImage& base, const Scene& scene, const PinholeCamera& camera);

}  // namespace pyrseg::cli
