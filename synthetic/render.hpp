#pragma once
// Ray casting of a layout into an organized point cloud, with the sensor's noise and missing data.
#include "layout.hpp"
#include "pyrseg/synthetic.hpp"

namespace pyrseg::synthetic::detail {

// The focal length (pixels) for an image size: the image always fits a fixed 60 x 46.8 degree (4:3) field of view,
// so the scene looks the same at every resolution and at any aspect ratio.
double focal_length(int width, int height);

// Fills points, normals and object_id of scene (whose size and intrinsics are set) from the layout's solids, which
// must already be in camera space.
void render(const std::vector<Solid>& solids, const SceneOptions& options, Scene& scene);

}  // namespace pyrseg::synthetic::detail
