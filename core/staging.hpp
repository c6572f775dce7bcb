#pragma once
// Copying a caller's cloud into packed xyz staging memory: in one memcpy when it is packed already, point by point
// when it is strided (PCL point types, interleaved normals). Shared by the backends that upload frames.
#include <cstddef>
#include <cstring>

#include "pyrseg/cloud.hpp"

namespace pyrseg::core {

// `data` is cloud.points or cloud.normals (same layout); dst holds 3 * width * height floats.
inline void pack_xyz(const CloudView& cloud, const float* data, float* dst) {
    const std::size_t w = std::size_t(cloud.width);
    const std::size_t h = std::size_t(cloud.height);
    const std::size_t row_stride = cloud.row_stride == 0 ? w : cloud.row_stride;
    const std::size_t ps = std::size_t(cloud.point_stride);
    if (ps == 3 && row_stride == w) {
        std::memcpy(dst, data, 3 * w * h * sizeof(float));
        return;
    }
    for (std::size_t y = 0; y < h; ++y) {
        for (std::size_t x = 0; x < w; ++x) {
            std::memcpy(dst + 3 * (y * w + x), data + (y * row_stride + x) * ps, 3 * sizeof(float));
        }
    }
}

// Whether pack_xyz would only copy (the backend may then upload straight from the caller's memory).
inline bool is_packed_xyz(const CloudView& cloud) {
    return cloud.point_stride == 3 && (cloud.row_stride == 0 || cloud.row_stride == std::size_t(cloud.width));
}

}  // namespace pyrseg::core
