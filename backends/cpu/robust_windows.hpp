#pragma once
// The CPU's shortcut for the robust normals' windows (docs/algorithm.md section 8b): where every pixel of a window
// is a member (its fixed-point depth within J of the centre's, which also rules out pixels without data), the
// window's tangent sums are box sums, read from summed-area tables in O(1); elsewhere the caller sums the window
// pixel by pixel. Integer sums in 32-bit two's complement: a box sum taken from the tables is exact whenever the
// true sum fits int32, which section 8b guarantees, so both ways give the same words.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "backends/cpu/cpu_dialect.hpp"
#include "backends/cpu/simd/cpu_simd.hpp"
#include "shaders/pyr_types.h"

namespace pyrseg::cpu {

class RobustWindows {
public:
    // Tables for `texels` (W x H) and windows of radius `window`; `rows(n, fn)` runs fn(y) for y in [0, n), in
    // parallel; `simd`: the vector rows to use, or null. Reuses its memory from frame to frame (nothing allocates
    // once sized).
    template <class Rows>
    void build(const RobustTexelPlanes& texels, std::size_t width, std::size_t height, std::uint32_t window,
               const simd::VectorRows* simd, const Rows& rows) {
        size(width, height, window);
        rows(height, [&](std::size_t y) { prefix_row(texels, y); });
        rows(kComponents, [&](std::size_t k) { accumulate_columns(k); });
        rows(height, [&](std::size_t y) {
            if (simd != nullptr) {
                simd->robust_range_row(texels.gz + y * width, std::uint32_t(width), window, row_min_.data() + y * width,
                                       row_max_.data() + y * width);
            } else {
                row_range(texels, y);
            }
        });
        rows(height, [&](std::size_t y) { column_range(y); });
    }

    // Whether every pixel of the window around (x, y) has |G(z) - zi| <= jump.
    [[nodiscard]] bool all_members(std::size_t x, std::size_t y, std::int32_t zi, std::int32_t jump) const {
        const std::size_t i = y * width_ + x;
        return min_[i] >= zi - jump && max_[i] <= zi + jump;
    }
    // The sums of t_h (u) and t_v (v) over the window around (x, y), clipped to the image.
    void sums(std::size_t x, std::size_t y, PyrIVec3& u, PyrIVec3& v) const;
    // What the vector rows read of the windows of row y (simd::RobustWindowRow).
    [[nodiscard]] simd::RobustWindowRow row(std::size_t y) const;

private:
    static constexpr std::size_t kComponents = 6;  // t_h x y z, t_v x y z

    void size(std::size_t width, std::size_t height, std::uint32_t window);
    void prefix_row(const RobustTexelPlanes& texels, std::size_t y);  // row y's prefix sums
    void accumulate_columns(std::size_t k);                           // then component k's down the columns
    void row_range(const RobustTexelPlanes& texels, std::size_t y);   // G(z) range over each row window
    void column_range(std::size_t y);                                 // then over each whole window
    [[nodiscard]] const std::uint32_t* table_row(std::size_t k, std::size_t y) const {
        return table_.data() + (k * (height_ + 1) + y) * (width_ + 1);
    }

    std::size_t width_ = 0, height_ = 0;
    std::uint32_t window_ = 0;
    // Per component a (W + 1) x (H + 1) table summed from the origin.
    std::vector<std::uint32_t> table_;
    std::vector<std::int32_t> row_min_, row_max_;  // G(z) over each row's window
    std::vector<std::int32_t> min_, max_;          // G(z) over each whole window
};

}  // namespace pyrseg::cpu
