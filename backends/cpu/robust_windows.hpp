#pragma once
// The CPU's shortcut for the robust normals' windows (docs/algorithm.md section 8b): where every pixel of a window
// is a member (its fixed-point depth within J of the centre's, which also rules out pixels without data), the
// window's tangent sums are box sums, read from summed-area tables in O(1); elsewhere the caller sums the window
// pixel by pixel. Integer sums in 32-bit two's complement: a box sum taken from the tables is exact whenever the
// true sum fits int32, which section 8b guarantees, so both ways give the same words.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "shaders/pyr_types.h"

namespace pyrseg::cpu {

class RobustWindows {
public:
    // Tables for `texels` (W x H) and windows of radius `window`; `rows(n, fn)` runs fn(y) for y in [0, n), in
    // parallel. Reuses its memory from frame to frame (nothing allocates once sized).
    template <class Rows>
    void build(const PyrRobustTexel* texels, std::size_t width, std::size_t height, std::uint32_t window,
               const Rows& rows) {
        size(width, height, window);
        rows(height, [&](std::size_t y) { prefix_row(texels, y); });
        accumulate_columns();
        rows(height, [&](std::size_t y) { row_range(texels, y); });
        rows(height, [&](std::size_t y) { column_range(y); });
    }

    // Whether every pixel of the window around (x, y) has |G(z) - zi| <= jump.
    [[nodiscard]] bool all_members(std::size_t x, std::size_t y, std::int32_t zi, std::int32_t jump) const {
        const std::size_t i = y * width_ + x;
        return min_[i] >= zi - jump && max_[i] <= zi + jump;
    }
    // The sums of t_h (u) and t_v (v) over the window around (x, y), clipped to the image.
    void sums(std::size_t x, std::size_t y, PyrIVec3& u, PyrIVec3& v) const;

private:
    void size(std::size_t width, std::size_t height, std::uint32_t window);
    void prefix_row(const PyrRobustTexel* texels, std::size_t y);  // row y's prefix sums
    void accumulate_columns();                                     // then down the columns
    void row_range(const PyrRobustTexel* texels, std::size_t y);   // G(z) range over each row window
    void column_range(std::size_t y);                              // then over each whole window

    std::size_t width_ = 0, height_ = 0;
    std::uint32_t window_ = 0;
    std::vector<std::uint32_t> table_;             // (W + 1) x (H + 1) x 6: th x y z, tv x y z, summed from the origin
    std::vector<std::int32_t> row_min_, row_max_;  // G(z) over each row's window
    std::vector<std::int32_t> min_, max_;          // G(z) over each whole window
};

}  // namespace pyrseg::cpu
