#include "backends/cpu/robust_windows.hpp"

#include <algorithm>

namespace pyrseg::cpu {
namespace {

// The smallest (lo) and largest (hi) of in[x - r .. x + r], clipped to the row (robust_range_row's scalar twin).
void row_range(const std::int32_t* in, std::size_t w, std::size_t r, std::int32_t* lo, std::int32_t* hi) {
    for (std::size_t x = 0; x < w; ++x) {
        const std::size_t x0 = x >= r ? x - r : 0;
        const std::size_t x1 = std::min(x + r, w - 1);
        std::int32_t least = in[x0];
        std::int32_t greatest = in[x0];
        for (std::size_t j = x0 + 1; j <= x1; ++j) {
            least = std::min(least, in[j]);
            greatest = std::max(greatest, in[j]);
        }
        lo[x] = least;
        hi[x] = greatest;
    }
}

}  // namespace

std::size_t RobustWindows::scratch_bytes(std::size_t width, std::uint32_t window, std::size_t threads) {
    const std::size_t r = window;
    const std::size_t words = kComponents * (2 * r + 2) * (width + 1) + 2 * (2 * r + 1) * width + 2 * width;
    return threads * words * sizeof(std::uint32_t);
}

void RobustWindows::prepare(std::size_t threads, std::size_t width, std::size_t height, std::uint32_t window) {
    width_ = width;
    height_ = height;
    window_ = window;
    const std::size_t table_words = kComponents * table_slots() * (width + 1);
    const auto make = [&](Band& band) {
        band.table.assign(table_words, 0u);
        band.row_min.assign(range_slots() * width, 0);
        band.row_max.assign(range_slots() * width, 0);
        band.min.assign(width, 0);
        band.max.assign(width, 0);
    };
    bands_.reserve(threads, make);
    bands_.for_each([&](Band& band) {
        if (band.table.size() != table_words || band.min.size() != width) make(band);  // never within a Segmenter
        band.empty = true;  // nothing of the last frame's rows
    });
}

simd::RobustWindowRow RobustWindows::advance(Band& band, const RobustTexelPlanes& texels, const simd::VectorRows* simd,
                                             std::size_t y) const {
    const std::size_t r = window_;
    const std::size_t w = width_;
    const std::size_t ts = table_slots();
    const std::size_t rs = range_slots();
    const std::size_t top = y >= r ? y - r : 0;                   // table rows top and bottom bound the windows
    const std::size_t bottom = std::min(y + r, height_ - 1) + 1;  // of row y: its image rows top .. bottom - 1
    // The rings go on from the thread's last row when they still hold row `top` (its last chunk ended where this
    // one starts); else they start again there, from zeros.
    if (band.empty || top < band.first || top > band.last) {
        for (std::size_t k = 0; k < kComponents; ++k) std::fill_n(table_row(band, ts, w, k, top), w + 1, 0u);
        band.first = band.last = top;
        band.empty = false;
    }
    // Missing tangents are zeros in a texel (pyr_robust_texel), so they add nothing.
    const std::int32_t* const components[kComponents] = {texels.th[0], texels.th[1], texels.th[2],
                                                         texels.tv[0], texels.tv[1], texels.tv[2]};
    while (band.last < bottom) {
        const std::size_t j = band.last;  // image row j makes table row j + 1 and range row j
        for (std::size_t k = 0; k < kComponents; ++k) {
            const std::int32_t* in = components[k] + j * w;
            const std::uint32_t* above = table_row(band, ts, w, k, j);
            std::uint32_t* out = table_row(band, ts, w, k, j + 1);
            std::uint32_t sum = 0;
            out[0] = 0;
            for (std::size_t x = 0; x < w; ++x) out[x + 1] = above[x + 1] + (sum += std::uint32_t(in[x]));
        }
        std::int32_t* lo = band.row_min.data() + (j % rs) * w;
        std::int32_t* hi = band.row_max.data() + (j % rs) * w;
        if (simd != nullptr) {
            simd->robust_range_row(texels.gz + j * w, std::uint32_t(w), window_, lo, hi);
        } else {
            row_range(texels.gz + j * w, w, r, lo, hi);
        }
        ++band.last;
        if (band.last + 1 > ts) band.first = std::max(band.first, band.last + 1 - ts);
    }
    // The ranges over the window's rows top .. bottom - 1.
    std::int32_t* lo = band.min.data();
    std::int32_t* hi = band.max.data();
    std::copy_n(band.row_min.data() + (top % rs) * w, w, lo);
    std::copy_n(band.row_max.data() + (top % rs) * w, w, hi);
    for (std::size_t j = top + 1; j < bottom; ++j) {
        const std::int32_t* in_lo = band.row_min.data() + (j % rs) * w;
        const std::int32_t* in_hi = band.row_max.data() + (j % rs) * w;
        for (std::size_t x = 0; x < w; ++x) {
            lo[x] = std::min(lo[x], in_lo[x]);
            hi[x] = std::max(hi[x], in_hi[x]);
        }
    }
    simd::RobustWindowRow out;
    for (std::size_t k = 0; k < kComponents; ++k) {
        out.top[k] = table_row(band, ts, w, k, top);
        out.bottom[k] = table_row(band, ts, w, k, bottom);
    }
    out.min = lo;
    out.max = hi;
    return out;
}

void RobustWindows::sums(const simd::RobustWindowRow& row, std::size_t x, PyrIVec3& u, PyrIVec3& v) const {
    const auto r = std::size_t(window_);
    const std::size_t x0 = x >= r ? x - r : 0;
    const std::size_t x1 = std::min(x + r, width_ - 1) + 1;
    std::int32_t s[kComponents];
    for (std::size_t k = 0; k < kComponents; ++k) {
        s[k] = std::int32_t(row.bottom[k][x1] - row.top[k][x1] - row.bottom[k][x0] + row.top[k][x0]);
    }
    u = PyrIVec3{s[0], s[1], s[2]};
    v = PyrIVec3{s[3], s[4], s[5]};
}

}  // namespace pyrseg::cpu
