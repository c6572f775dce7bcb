#pragma once
// The CPU's shortcut for the robust normals' windows (docs/algorithm.md section 8b): where every pixel of a window
// is a member (its fixed-point depth within J of the centre's, which also rules out pixels without data), the
// window's tangent sums are box sums, read from summed-area tables in O(1); elsewhere the caller sums the window
// pixel by pixel. Integer sums in 32-bit two's complement: a box sum taken from the tables is exact whenever the
// true sum fits int32, which section 8b guarantees, so both ways give the same words.
//
// The tables are never made for the whole frame: each thread keeps the 2 R + 2 rows of them (and the 2 R + 1 rows of
// depth ranges) that the windows of its current row reach, in rings that stay in its L2 cache, summed from the first
// row its band needs rather than from the image's top (a box sum is a difference of rows, the same whatever the
// rows were summed from). Whole-frame tables moved about 170 bytes a pixel through memory; the rings read the
// texels once.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "backends/cpu/cpu_dialect.hpp"
#include "backends/cpu/simd/cpu_simd.hpp"
#include "backends/cpu/thread_pool.hpp"
#include "backends/cpu/thread_scratch.hpp"
#include "shaders/pyr_types.h"

namespace pyrseg::cpu {

class RobustWindows {
public:
    // Calls body(y, windows) for every row y of the W x H `texels`, in parallel bands of rows on `pool`, with what
    // the windows of radius `window` around row y's pixels read (simd::RobustWindowRow: box sums and depth ranges);
    // `simd`: the vector rows for the depth ranges, or null. Allocates on the first frame only (or when a caller's
    // arena has more threads than before).
    template <class Body>
    void run(ThreadPool& pool, const RobustTexelPlanes& texels, std::size_t width, std::size_t height,
             std::uint32_t window, const simd::VectorRows* simd, const Body& body) {
        prepare(pool.size(), width, height, window);
        const std::size_t grain = std::max<std::size_t>(1, height / pool.pieces());
        pool.parallel_for(height, grain, [&](std::size_t y0, std::size_t y1) {
            bands_.with([&](Band& band) {
                for (std::size_t y = y0; y < y1; ++y) body(y, advance(band, texels, simd, y));
            });
        });
    }

    // Whether every pixel of the window around pixel x of the row has |G(z) - zi| <= jump.
    [[nodiscard]] static bool all_members(const simd::RobustWindowRow& row, std::size_t x, std::int32_t zi,
                                          std::int32_t jump) {
        return row.min[x] >= zi - jump && row.max[x] <= zi + jump;
    }
    // The sums of t_h (u) and t_v (v) over the window around pixel x of the row, clipped to the image.
    void sums(const simd::RobustWindowRow& row, std::size_t x, PyrIVec3& u, PyrIVec3& v) const;

    // Bytes run allocates for `threads` threads.
    [[nodiscard]] static std::size_t scratch_bytes(std::size_t width, std::uint32_t window, std::size_t threads);

private:
    static constexpr std::size_t kComponents = 6;  // t_h x y z, t_v x y z

    // One thread's rings. Table row j (the sums of the rows above j, from the band's first row on) in slot
    // j % (2 R + 2); row j's depth ranges along the row in slot j % (2 R + 1). Both are made together, image row j
    // giving table row j + 1 and range row j, so they hold the same rows: table rows first .. last, range rows
    // first .. last - 1.
    struct Band {
        std::vector<std::uint32_t> table;            // kComponents rings of (W + 1)-word rows
        std::vector<std::int32_t> row_min, row_max;  // the ranges' rings
        std::vector<std::int32_t> min, max;          // the current row's windows' ranges
        std::size_t first = 0, last = 0;
        bool empty = true;  // nothing of this frame
    };

    void prepare(std::size_t threads, std::size_t width, std::size_t height, std::uint32_t window);
    simd::RobustWindowRow advance(Band& band, const RobustTexelPlanes& texels, const simd::VectorRows* simd,
                                  std::size_t y) const;
    [[nodiscard]] std::size_t table_slots() const { return 2 * std::size_t(window_) + 2; }
    [[nodiscard]] std::size_t range_slots() const { return 2 * std::size_t(window_) + 1; }
    [[nodiscard]] static std::uint32_t* table_row(Band& band, std::size_t slots, std::size_t width, std::size_t k,
                                                  std::size_t j) {
        return band.table.data() + (k * slots + j % slots) * (width + 1);
    }

    std::size_t width_ = 0, height_ = 0;
    std::uint32_t window_ = 0;
    ThreadScratch<Band> bands_;
};

}  // namespace pyrseg::cpu
