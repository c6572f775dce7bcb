// Organized clouds as NumPy arrays: what Python pipelines (Open3D, numpy) hand over most easily.
#include <cstring>
#include <string>

#include "file_util.hpp"
#include "pyrseg/io.hpp"

namespace pyrseg::io {

namespace {

// Before the data is read: a wrong shape or dtype costs no memory.
void check_cloud_array(const std::filesystem::path& path, const NpyArray& a) {
    std::string shape;
    for (std::size_t d : a.shape) shape += (shape.empty() ? "" : " x ") + std::to_string(d);
    if (a.shape.size() != 3 || (a.shape[2] != 3 && a.shape[2] != 6) || a.shape[0] < 1 || a.shape[1] < 1) {
        detail::fail(ErrorCode::format, path,
                     "a cloud array is H x W x 3 (points) or H x W x 6 (points and normals), this one is " +
                         (shape.empty() ? std::string("0-d") : shape));
    }
    if (a.dtype != "<f4" && a.dtype != "<f8") {
        detail::fail(ErrorCode::format, path,
                     "a cloud array holds float32 or float64 ('<f4', '<f8'), not '" + a.dtype + "'");
    }
    if (a.shape[0] > (1u << 16) || a.shape[1] > (1u << 16)) {
        detail::fail(ErrorCode::format, path, "a " + shape + " array is too large for a depth-camera frame");
    }
}

}  // namespace

PointCloud read_npy_cloud(const std::filesystem::path& path) {
    return detail::guard_reader(path, [&] {
        const NpyArray a = detail::read_npy(path, [&](const NpyArray& header) { check_cloud_array(path, header); });
        PointCloud cloud;
        cloud.height = int(a.shape[0]);
        cloud.width = int(a.shape[1]);
        const std::size_t pixels = a.shape[0] * a.shape[1];
        const std::size_t channels = a.shape[2];
        const bool doubles = a.dtype == "<f8";
        const auto value = [&](std::size_t k) {
            if (doubles) {
                double v = 0;
                std::memcpy(&v, a.bytes.data() + 8 * k, 8);
                return float(v);
            }
            float v = 0;
            std::memcpy(&v, a.bytes.data() + 4 * k, 4);
            return v;
        };
        cloud.points.resize(3 * pixels);
        if (channels == 6) cloud.normals.resize(3 * pixels);
        for (std::size_t i = 0; i < pixels; ++i) {
            for (std::size_t c = 0; c < 3; ++c) {
                cloud.points[3 * i + c] = value(channels * i + c);
                if (channels == 6) cloud.normals[3 * i + c] = value(channels * i + 3 + c);
            }
        }
        return cloud;
    });
}

}  // namespace pyrseg::io
