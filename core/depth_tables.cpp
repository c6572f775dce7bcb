#include "core/depth_tables.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>

#include "core/depth_camera.hpp"
#include "pyrseg/error.hpp"

namespace pyrseg::core {
namespace {

[[noreturn]] void bad(ErrorCode code, const std::string& what) {
    throw Error(code, "the depth image's " + what);
}

}  // namespace

void make_depth_tables(const DepthView& depth, double unit_mm, DepthTables& tables, bool samples_on_device) {
    if (samples_on_device && depth.depth != nullptr) {
        bad(ErrorCode::invalid_argument, "depth pointer must be null: the samples are in the device buffer");
    }
    if (!samples_on_device && depth.depth == nullptr) bad(ErrorCode::invalid_argument, "depth pointer is null");
    if (depth.format != DepthFormat::u16 && depth.format != DepthFormat::f32) {
        bad(ErrorCode::invalid_argument, "format is neither u16 nor f32");
    }
    const std::size_t row_bytes = std::size_t(depth.width) * DepthTables::sample_bytes(depth.format);
    if (depth.row_step_bytes != 0 && depth.row_step_bytes < row_bytes) {
        bad(ErrorCode::invalid_argument, "row_step_bytes " + std::to_string(depth.row_step_bytes) +
                                             " is smaller than a row of samples (" + std::to_string(row_bytes) +
                                             " bytes)");
    }
    if (depth.row_step_bytes > std::numeric_limits<std::size_t>::max() / std::size_t(std::max(depth.height, 1))) {
        bad(ErrorCode::invalid_argument, "row_step_bytes " + std::to_string(depth.row_step_bytes) + " is too large");
    }
    check_depth_intrinsics(depth);
    const auto scale = static_cast<float>((depth.metres_per_unit * 1000.0) / unit_mm);
    if (!std::isfinite(scale) || scale < std::numeric_limits<float>::min()) {
        bad(ErrorCode::invalid_parameter, "metres_per_unit " + std::to_string(depth.metres_per_unit) +
                                              " with unit_mm " + std::to_string(unit_mm) +
                                              " gives a scale outside float32's normal range");
    }
    tables.scale = scale;
    tables.ku.resize(std::size_t(depth.width));
    tables.kv.resize(std::size_t(depth.height));
    for (std::size_t u = 0; u < tables.ku.size(); ++u)
        tables.ku[u] = static_cast<float>((double(u) - depth.cx) / depth.fx);
    for (std::size_t v = 0; v < tables.kv.size(); ++v)
        tables.kv[v] = static_cast<float>((double(v) - depth.cy) / depth.fy);
}

void pack_depth(const DepthView& depth, std::vector<std::uint32_t>& words) {
    const std::size_t sample = DepthTables::sample_bytes(depth.format);
    const std::size_t w = std::size_t(depth.width);
    const std::size_t h = std::size_t(depth.height);
    const std::size_t row_bytes = w * sample;
    const std::size_t step = depth.row_step_bytes == 0 ? row_bytes : depth.row_step_bytes;
    words.assign((w * h * sample + 3) / 4, 0u);
    auto* dst = reinterpret_cast<unsigned char*>(words.data());
    const auto* src = static_cast<const unsigned char*>(depth.depth);
    if (step == row_bytes) {
        std::memcpy(dst, src, row_bytes * h);
        return;
    }
    for (std::size_t y = 0; y < h; ++y) std::memcpy(dst + y * row_bytes, src + y * step, row_bytes);
}

}  // namespace pyrseg::core
