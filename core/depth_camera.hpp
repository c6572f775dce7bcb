#pragma once
// The depth camera checks of pyrseg/depth.hpp's check_depth_camera, in parts for the library's own frames.
#include "pyrseg/depth.hpp"

namespace pyrseg::core {

// The checks that need no samples (metres_per_unit, the intrinsics' ranges, the principal point, the field of
// view), cheap enough for every frame. Throws pyrseg::Error (invalid_parameter).
void check_depth_intrinsics(const DepthView& depth);

// The camera of a frame a Segmenter last checked whole: a frame with the same one skips the sampled median.
struct CheckedDepthCamera {
    bool valid = false;
    double metres_per_unit = 0, fx = 0, fy = 0, cx = 0, cy = 0;
    DepthFormat format = DepthFormat::u16;
    [[nodiscard]] bool same(const DepthView& depth) const;
    void remember(const DepthView& depth);
};

}  // namespace pyrseg::core
