// The frame's input: a cloud or a depth image (back-projected into points this executor owns), or a caller's mask.
#include <cstring>

#include "backends/cpu/cpu_executor.hpp"

namespace pyrseg::cpu {

using std::size_t;
using std::uint32_t;

void CpuExecutor::bind_cloud(const CloudView& cloud) {
    fill_rounds_ = 0;
    color_ = nullptr;
    cloud_ = cloud;
    layout_ = core::cloud_layout(cloud);
    normals_estimated_ = false;
    valid_bytes_ = false;
    from_mask_ = false;
}

// The depth image stays where the caller has it; depth_to_points writes the points this backend owns.
void CpuExecutor::bind_depth(const DepthView& depth, const core::DepthTables& tables) {
    fill_rounds_ = 0;
    color_ = nullptr;
    depth_ = depth;
    depth_tables_ = &tables;
    normals_estimated_ = false;
    valid_bytes_ = false;
    from_mask_ = false;
}

// The colour image, like the cloud, stays where the caller has it.
void CpuExecutor::bind_color(const std::uint8_t* rgb, std::size_t row_step_bytes) {
    color_ = rgb;
    color_row_bytes_ = row_step_bytes;
}

void CpuExecutor::depth_to_points() {
    const size_t w = size_t(plan_.width);
    if (depth_points_.empty()) depth_points_.resize(3 * plan_.pixel_count());  // once per Segmenter
    const size_t sample = core::DepthTables::sample_bytes(depth_.format);
    const size_t step = depth_.row_step_bytes == 0 ? w * sample : depth_.row_step_bytes;
    const auto format = depth_.format == DepthFormat::u16 ? PYR_DEPTH_U16 : PYR_DEPTH_F32;
    const core::DepthTables& t = *depth_tables_;
    if (simd_ != nullptr) {
        rows(size_t(plan_.height), [&](size_t y) {
            simd_->depth_row(static_cast<const unsigned char*>(depth_.depth) + y * step, format, uint32_t(w), t.scale,
                             t.ku.data(), t.kv[y], depth_points_.data() + 3 * y * w);
        });
    } else {
        rows(size_t(plan_.height), [&](size_t y) {
            const auto* row = static_cast<const unsigned char*>(depth_.depth) + y * step;
            for (size_t x = 0; x < w; ++x) {
                uint32_t bits = 0;
                if (format == PYR_DEPTH_U16) {
                    std::uint16_t d = 0;
                    std::memcpy(&d, row + 2 * x, 2);  // rows may start at any byte
                    bits = d;
                } else {
                    std::memcpy(&bits, row + 4 * x, 4);
                }
                const PyrFVec3 p = pixel::pyr_depth_point(bits, format, t.scale, t.ku[x], t.kv[y]);
                float* out = depth_points_.data() + 3 * (y * w + x);
                out[0] = p.x;
                out[1] = p.y;
                out[2] = p.z;
            }
        });
    }
    CloudView cloud;
    cloud.points = depth_points_.data();
    cloud.width = plan_.width;
    cloud.height = plan_.height;
    cloud_ = cloud;
    layout_ = core::cloud_layout(cloud);
}

void CpuExecutor::bind_mask(const MaskView& mask) {
    fill_rounds_ = 0;
    color_ = nullptr;
    from_mask_ = true;
    const size_t w = size_t(plan_.width);
    const size_t stride = mask.row_stride == 0 ? w : mask.row_stride;
    std::uint8_t* full = mask_.data() + plan_.full().offset;
    std::uint8_t* valid = mask_valid_.data();
    const std::uint8_t* in_fillable = mask.fillable;
    const std::uint8_t* in_valid = mask.valid;
    rows(size_t(plan_.height), [&](size_t y) {
        // Everything the loops read in locals: byte stores may alias anything, so a captured reference (the
        // width too) would be reloaded per pixel and the loops would not vectorise.
        const size_t n = w;
        const std::uint8_t* in = in_fillable + y * stride;
        std::uint8_t* out = full + y * n;
        for (size_t x = 0; x < n; ++x) out[x] = in[x] != 0 ? 1 : 0;
        std::uint8_t* out_valid = valid + y * n;
        if (in_valid == nullptr) {
            std::memset(out_valid, 1, n);
            return;
        }
        const std::uint8_t* in_v = in_valid + y * stride;
        for (size_t x = 0; x < n; ++x) out_valid[x] = in_v[x] != 0 ? 1 : 0;
    });
}

}  // namespace pyrseg::cpu
