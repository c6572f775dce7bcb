// The executor's buffers (allocated once per Segmenter, none per frame) and the pyramid's passes (mip and label
// init).
#include "backends/cpu/cpu_executor.hpp"

#include <algorithm>
#include <cstdlib>
#include <cstring>

#include "backends/cpu/union_find_fill.hpp"

namespace pyrseg::cpu {

using std::size_t;
using std::uint32_t;

namespace {

// PYRSEG_CPU_FILL=sweeps runs steps 2 and 4 as repeated row/column sweeps of the shared relaxation (the GPU
// scheme) instead of union-find; both reach the contract's fixed point, and the tests check that they agree.
bool use_sweeps_for_fixed_points() {
    const char* env = std::getenv("PYRSEG_CPU_FILL");
    return env != nullptr && std::strcmp(env, "sweeps") == 0;
}

}  // namespace

size_t CpuExecutor::fill_scratch_size(const core::Plan& plan) {
    const PyrLevel& lv = plan.small_image ? plan.full() : plan.level(plan.level_count - 1);
    return union_find_scratch_size(lv.width, lv.height);
}

CpuExecutor::CpuExecutor(const core::Plan& plan, const ThreadSetting& threads)
    : plan_(plan),
      pool_(threads),
      quant_(kQuantWords * plan.pixel_count()),
      mask_valid_(plan.pixel_count()),
      mask_(plan.total_texels),
      labels_(plan.total_texels),
      lut_(plan.lut_size()),
      fill_scratch_(fill_scratch_size(plan)),
      stats_(plan.stats_words()),
      graph_words_(plan.graph_words()),
      previous_labels_(plan.track_slots != 0 ? plan.pixel_count() : 0),
      simd_(simd::rows_from_environment()),
      sweeps_(use_sweeps_for_fixed_points()) {}

PassContext CpuExecutor::context() {
    PassContext c;
    c.points = cloud_.points;
    c.row_floats = layout_.row_floats;
    c.point_floats = layout_.point_floats;
    c.quant = quant_.data();
    c.mask_valid = from_mask_ || valid_bytes_ ? mask_valid_.data() : nullptr;
    c.mask = mask_.data();
    c.labels = labels_.data();
    c.lut = lut_.data();
    c.stats = stats_.data();
    c.color = color_;
    c.color_row_bytes = color_row_bytes_;
    return c;
}

void CpuExecutor::mip(int parent_level) {
    const PassContext c = context();
    const PyrLevel parent = plan_.level(parent_level);
    const PyrLevel child = plan_.level(parent_level + 1);
    if (simd_ != nullptr) {
        rows(parent.height, [&](size_t y) {
            const size_t cy = 2 * y;
            const std::uint8_t* top = cy + 1 < child.height ? mask_.data() + child.offset + cy * child.width : nullptr;
            simd_->mip_row(top, child.width, parent.width, mask_.data() + parent.offset + y * parent.width);
        });
        return;
    }
    rows(parent.height, [&](size_t y) {
        std::uint8_t* out = mask_.data() + parent.offset + y * parent.width;
        for (uint32_t x = 0; x < parent.width; ++x)
            out[x] = std::uint8_t(pixel::pyr_mip_texel(c, child, x, uint32_t(y)));
    });
}

void CpuExecutor::init_labels(int level, uint32_t mode) {
    const PassContext c = context();
    const PyrLevel lv = plan_.level(level);
    const PyrLevel parent = level > 1 ? plan_.level(level - 1) : PyrLevel{0, 0, 0};
    if (simd_ != nullptr && mode == PYR_INIT_INHERIT && level > 1) {
        rows(lv.height, [&](size_t y) {
            simd_->inherit_row(c.mask + lv.offset + y * lv.width, c.labels + parent.offset + (y >> 1) * parent.width,
                               lv.width, c.labels + lv.offset + y * lv.width, nullptr);
        });
        return;
    }
    rows(lv.height, [&](size_t y) { init_row(c, lv, parent, uint32_t(y), mode); });
}

void CpuExecutor::init_row(const PassContext& c, const PyrLevel& lv, const PyrLevel& parent, uint32_t y,
                           uint32_t mode) {
    uint32_t* out = labels_.data() + lv.offset + size_t(y) * lv.width;
    for (uint32_t x = 0; x < lv.width; ++x) out[x] = pixel::pyr_label_init_texel(c, lv, parent, x, y, mode);
}

}  // namespace pyrseg::cpu
