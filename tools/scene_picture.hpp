#pragma once
// The scene summary (pyrseg/scene.hpp) drawn over a picture of the frame: each object's box (its 12 edges in its
// segment's colour) and each support's outline (white), projected through the camera's pinhole intrinsics.
#include <optional>

#include "pyrseg/io.hpp"
#include "pyrseg/scene.hpp"
#include "tools/figures.hpp"

namespace pyrseg::cli {

struct PinholeCamera {
    double fx = 0, fy = 0, cx = 0, cy = 0;
};

// `base` with the scene drawn over it; lengths of the scene in the units the camera's points are in. Edges behind
// the camera are left out.
[[nodiscard]] RgbImage scene_picture(const RgbImage& base, const Scene& scene, const PinholeCamera& camera);

// The picture in gray, darkened: what the scene's boxes are drawn over.
[[nodiscard]] RgbImage dimmed_gray(const RgbImage& image);

// The pinhole an organized cloud was back-projected through (u = fx x / z + cx, v = fy y / z + cy, least squares
// over its valid points), for a cloud file that does not say; nullopt when fewer than 100 points are valid or the
// points miss their pixels by more than half a pixel (RMS): not a camera's organized cloud.
[[nodiscard]] std::optional<PinholeCamera> fit_pinhole(const io::PointCloud& cloud);

}  // namespace pyrseg::cli
