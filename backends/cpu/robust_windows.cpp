#include "backends/cpu/robust_windows.hpp"

#include <algorithm>

namespace pyrseg::cpu {
namespace {

constexpr std::size_t kComponents = 6;

void add_texel(std::uint32_t* dst, const PyrRobustTexel& t) {
    // Missing tangents are zeros in a texel (pyr_robust_texel), so they add nothing.
    dst[0] += std::uint32_t(t.th.x);
    dst[1] += std::uint32_t(t.th.y);
    dst[2] += std::uint32_t(t.th.z);
    dst[3] += std::uint32_t(t.tv.x);
    dst[4] += std::uint32_t(t.tv.y);
    dst[5] += std::uint32_t(t.tv.z);
}

}  // namespace

void RobustWindows::size(std::size_t width, std::size_t height, std::uint32_t window) {
    width_ = width;
    height_ = height;
    window_ = window;
    const std::size_t stride = (width + 1) * kComponents;
    table_.resize(stride * (height + 1));
    row_min_.resize(width * height);
    row_max_.resize(width * height);
    min_.resize(width * height);
    max_.resize(width * height);
    std::fill_n(table_.begin(), stride, 0u);
}

void RobustWindows::prefix_row(const PyrRobustTexel* texels, std::size_t y) {
    const std::size_t stride = (width_ + 1) * kComponents;
    std::uint32_t* row = table_.data() + (y + 1) * stride;
    std::fill_n(row, kComponents, 0u);
    for (std::size_t x = 0; x < width_; ++x) {
        std::copy_n(row + x * kComponents, kComponents, row + (x + 1) * kComponents);
        add_texel(row + (x + 1) * kComponents, texels[y * width_ + x]);
    }
}

void RobustWindows::accumulate_columns() {
    const std::size_t stride = (width_ + 1) * kComponents;
    for (std::size_t y = 1; y <= height_; ++y) {
        std::uint32_t* row = table_.data() + y * stride;
        const std::uint32_t* above = row - stride;
        for (std::size_t k = 0; k < stride; ++k) row[k] += above[k];
    }
}

void RobustWindows::row_range(const PyrRobustTexel* texels, std::size_t y) {
    const auto r = std::size_t(window_);
    const PyrRobustTexel* in = texels + y * width_;
    for (std::size_t x = 0; x < width_; ++x) {
        const std::size_t x0 = x >= r ? x - r : 0;
        const std::size_t x1 = std::min(x + r, width_ - 1);
        std::int32_t lo = in[x0].gz;
        std::int32_t hi = in[x0].gz;
        for (std::size_t j = x0 + 1; j <= x1; ++j) {
            lo = std::min(lo, in[j].gz);
            hi = std::max(hi, in[j].gz);
        }
        row_min_[y * width_ + x] = lo;
        row_max_[y * width_ + x] = hi;
    }
}

void RobustWindows::column_range(std::size_t y) {
    const auto r = std::size_t(window_);
    const std::size_t w = width_;
    const std::size_t y0 = y >= r ? y - r : 0;
    const std::size_t y1 = std::min(y + r, height_ - 1);
    std::int32_t* lo = min_.data() + y * w;
    std::int32_t* hi = max_.data() + y * w;
    std::copy_n(row_min_.data() + y0 * w, w, lo);
    std::copy_n(row_max_.data() + y0 * w, w, hi);
    for (std::size_t j = y0 + 1; j <= y1; ++j) {
        const std::int32_t* in_lo = row_min_.data() + j * w;
        const std::int32_t* in_hi = row_max_.data() + j * w;
        for (std::size_t x = 0; x < w; ++x) {
            lo[x] = std::min(lo[x], in_lo[x]);
            hi[x] = std::max(hi[x], in_hi[x]);
        }
    }
}

void RobustWindows::sums(std::size_t x, std::size_t y, PyrIVec3& u, PyrIVec3& v) const {
    const auto r = std::size_t(window_);
    const std::size_t x0 = x >= r ? x - r : 0;
    const std::size_t x1 = std::min(x + r, width_ - 1) + 1;
    const std::size_t y0 = y >= r ? y - r : 0;
    const std::size_t y1 = std::min(y + r, height_ - 1) + 1;
    const std::size_t stride = (width_ + 1) * kComponents;
    const std::uint32_t* a = table_.data() + y1 * stride + x1 * kComponents;
    const std::uint32_t* b = table_.data() + y0 * stride + x1 * kComponents;
    const std::uint32_t* c = table_.data() + y1 * stride + x0 * kComponents;
    const std::uint32_t* d = table_.data() + y0 * stride + x0 * kComponents;
    std::int32_t s[kComponents];
    for (std::size_t k = 0; k < kComponents; ++k) s[k] = std::int32_t(a[k] - b[k] - c[k] + d[k]);
    u.x = s[0];
    u.y = s[1];
    u.z = s[2];
    v.x = s[3];
    v.y = s[4];
    v.z = s[5];
}

}  // namespace pyrseg::cpu
