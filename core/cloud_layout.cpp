#include "core/cloud_layout.hpp"

#include <algorithm>
#include <cstdint>
#include <limits>
#include <string>

#include "pyrseg/error.hpp"

namespace pyrseg::core {
namespace {

[[noreturn]] void bad(const std::string& what) {
    throw Error(ErrorCode::invalid_argument, "the cloud's " + what);
}

void check_aligned(const float* p, const char* name) {
    if (p != nullptr && reinterpret_cast<std::uintptr_t>(p) % alignof(float) != 0) {
        bad(std::string(name) + " pointer is not 4-byte aligned: floats are read in place");
    }
}

}  // namespace

CloudLayout cloud_layout(const CloudView& cloud) {
    const auto width = std::size_t(cloud.width);
    const auto height = std::size_t(cloud.height);
    CloudLayout l;
    if (cloud.point_step_bytes != 0) {
        if (cloud.point_stride != 3) bad("point_step_bytes and point_stride are both given; give one");
        if (cloud.point_step_bytes % sizeof(float) != 0) {
            bad("point_step_bytes " + std::to_string(cloud.point_step_bytes) + " is not a multiple of 4");
        }
        if (cloud.point_step_bytes < 3 * sizeof(float)) {
            bad("point_step_bytes " + std::to_string(cloud.point_step_bytes) + " is smaller than 12 (x, y, z)");
        }
        l.point_floats = cloud.point_step_bytes / sizeof(float);
    } else {
        if (cloud.point_stride < 3) bad("point_stride " + std::to_string(cloud.point_stride) + " is smaller than 3");
        l.point_floats = std::size_t(cloud.point_stride);
    }
    // Every step below is bounded so that the last float read, at(width - 1, height - 1) + 2, is addressable.
    const std::size_t limit = std::numeric_limits<std::size_t>::max() / sizeof(float) / 2;
    if (l.point_floats > limit / std::max<std::size_t>(width, 1))
        bad("point step (point_step_bytes or point_stride) is too large to address");
    const std::size_t row_floats_needed = width == 0 ? 0 : (width - 1) * l.point_floats + 3;  // one row's floats
    if (cloud.row_step_bytes != 0) {
        if (cloud.row_stride != 0) bad("row_step_bytes and row_stride are both given; give one");
        if (cloud.row_step_bytes % sizeof(float) != 0) {
            bad("row_step_bytes " + std::to_string(cloud.row_step_bytes) + " is not a multiple of 4");
        }
        l.row_floats = cloud.row_step_bytes / sizeof(float);
        if (height > 1 && l.row_floats < row_floats_needed) {
            bad("row_step_bytes " + std::to_string(cloud.row_step_bytes) + " is smaller than a row of " +
                std::to_string(width) + " points (" + std::to_string(row_floats_needed * sizeof(float)) + " bytes)");
        }
    } else {
        if (cloud.row_stride != 0 && cloud.row_stride < width) {
            bad("row_stride " + std::to_string(cloud.row_stride) + " is smaller than the width " +
                std::to_string(width));
        }
        const std::size_t points = cloud.row_stride == 0 ? width : cloud.row_stride;
        if (points > limit / l.point_floats)
            bad("row_stride " + std::to_string(cloud.row_stride) + " is too large to address");
        l.row_floats = points * l.point_floats;
    }
    if (height > 0 && l.row_floats > (limit - row_floats_needed) / height)
        bad("row step (row_step_bytes or row_stride) is too large to address");
    check_aligned(cloud.points, "points");
    check_aligned(cloud.normals, "normals");
    return l;
}

}  // namespace pyrseg::core
