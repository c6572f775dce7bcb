#include "backends/cpu/robust_windows.hpp"

#include <algorithm>

namespace pyrseg::cpu {

void RobustWindows::size(std::size_t width, std::size_t height, std::uint32_t window) {
    width_ = width;
    height_ = height;
    window_ = window;
    table_.resize(kComponents * (width + 1) * (height + 1));
    row_min_.resize(width * height);
    row_max_.resize(width * height);
    min_.resize(width * height);
    max_.resize(width * height);
    for (std::size_t k = 0; k < kComponents; ++k) {
        std::fill_n(table_.begin() + std::ptrdiff_t(k * (height + 1) * (width + 1)), width + 1, 0u);
    }
}

void RobustWindows::prefix_row(const RobustTexelPlanes& texels, std::size_t y) {
    // Missing tangents are zeros in a texel (pyr_robust_texel), so they add nothing.
    const std::int32_t* const components[kComponents] = {texels.th[0], texels.th[1], texels.th[2],
                                                         texels.tv[0], texels.tv[1], texels.tv[2]};
    for (std::size_t k = 0; k < kComponents; ++k) {
        const std::int32_t* in = components[k] + y * width_;
        std::uint32_t* row = table_.data() + (k * (height_ + 1) + y + 1) * (width_ + 1);
        std::uint32_t sum = 0;
        row[0] = 0;
        for (std::size_t x = 0; x < width_; ++x) row[x + 1] = sum += std::uint32_t(in[x]);
    }
}

void RobustWindows::accumulate_columns(std::size_t k) {
    const std::size_t stride = width_ + 1;
    std::uint32_t* plane = table_.data() + k * (height_ + 1) * stride;
    for (std::size_t y = 1; y <= height_; ++y) {
        std::uint32_t* row = plane + y * stride;
        const std::uint32_t* above = row - stride;
        for (std::size_t x = 0; x < stride; ++x) row[x] += above[x];
    }
}

void RobustWindows::row_range(const RobustTexelPlanes& texels, std::size_t y) {
    const auto r = std::size_t(window_);
    const std::int32_t* in = texels.gz + y * width_;
    for (std::size_t x = 0; x < width_; ++x) {
        const std::size_t x0 = x >= r ? x - r : 0;
        const std::size_t x1 = std::min(x + r, width_ - 1);
        std::int32_t lo = in[x0];
        std::int32_t hi = in[x0];
        for (std::size_t j = x0 + 1; j <= x1; ++j) {
            lo = std::min(lo, in[j]);
            hi = std::max(hi, in[j]);
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
    std::int32_t s[kComponents];
    for (std::size_t k = 0; k < kComponents; ++k) {
        const std::uint32_t* top = table_row(k, y0);
        const std::uint32_t* bottom = table_row(k, y1);
        s[k] = std::int32_t(bottom[x1] - top[x1] - bottom[x0] + top[x0]);
    }
    u = PyrIVec3{s[0], s[1], s[2]};
    v = PyrIVec3{s[3], s[4], s[5]};
}

simd::RobustWindowRow RobustWindows::row(std::size_t y) const {
    const auto r = std::size_t(window_);
    const std::size_t y0 = y >= r ? y - r : 0;
    const std::size_t y1 = std::min(y + r, height_ - 1) + 1;
    simd::RobustWindowRow out;
    for (std::size_t k = 0; k < kComponents; ++k) {
        out.top[k] = table_row(k, y0);
        out.bottom[k] = table_row(k, y1);
    }
    out.min = min_.data() + y * width_;
    out.max = max_.data() + y * width_;
    return out;
}

}  // namespace pyrseg::cpu
