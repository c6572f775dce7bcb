// The fills' worst cases (include/pyrseg/synthetic.hpp): a spiral and a maze of 8-pixel corridors.
#include <algorithm>
#include <random>
#include <utility>
#include <vector>

#include "pyrseg/synthetic.hpp"

namespace pyrseg::synthetic {
namespace {

constexpr int kCell = 16;  // a corridor (8 px) and a wall (8 px)
constexpr int kPath = 8;

FillMask empty_mask(int width, int height) {
    return FillMask{width, height, std::vector<std::uint8_t>(std::size_t(width) * std::size_t(height), 0)};
}

// [x0, x1) x [y0, y1), clipped to the mask.
void fill(FillMask& m, int x0, int y0, int x1, int y1) {
    for (int y = std::max(0, y0); y < std::min(m.height, y1); ++y) {
        for (int x = std::max(0, x0); x < std::min(m.width, x1); ++x) {
            m.fillable[std::size_t(y) * std::size_t(m.width) + std::size_t(x)] = 1;
        }
    }
}

}  // namespace

FillMask spiral_mask(int width, int height) {
    FillMask m = empty_mask(width, height);
    int left = 0;
    int top = 0;
    int right = width - kPath;
    int bottom = height - kPath;
    while (left <= right && top <= bottom) {
        fill(m, left, top, right + kPath, top + kPath);      // along the top
        fill(m, right, top, right + kPath, bottom + kPath);  // down the right
        if (top + kCell > bottom) break;
        fill(m, left, bottom, right + kPath, bottom + kPath);  // back along the bottom
        if (left + kCell > right) break;
        fill(m, left, top + kCell, left + kPath, bottom + kPath);  // up the left, short of the top
        left += kCell;
        top += kCell;
        right -= kCell;
        bottom -= kCell;
        fill(m, left - kCell, top, left + kPath, top + kPath);  // into the next lap
    }
    return m;
}

FillMask maze_mask(int width, int height, std::uint32_t seed) {
    FillMask m = empty_mask(width, height);
    const int cols = width / kCell;
    const int rows = height / kCell;
    if (cols == 0 || rows == 0) return m;
    std::vector<std::uint8_t> seen(std::size_t(cols) * std::size_t(rows), 0);
    std::mt19937 rng(seed);
    std::vector<std::pair<int, int>> stack = {{0, 0}};
    seen[0] = 1;
    fill(m, 0, 0, kPath, kPath);
    while (!stack.empty()) {
        const auto [cx, cy] = stack.back();
        std::vector<std::pair<int, int>> next;
        for (const auto& [dx, dy] : {std::pair{1, 0}, std::pair{-1, 0}, std::pair{0, 1}, std::pair{0, -1}}) {
            const int nx = cx + dx;
            const int ny = cy + dy;
            if (nx >= 0 && ny >= 0 && nx < cols && ny < rows && seen[std::size_t(ny) * std::size_t(cols) + nx] == 0)
                next.emplace_back(nx, ny);
        }
        if (next.empty()) {
            stack.pop_back();
            continue;
        }
        const auto [nx, ny] = next[rng() % next.size()];
        seen[std::size_t(ny) * std::size_t(cols) + std::size_t(nx)] = 1;
        fill(m, std::min(cx, nx) * kCell, std::min(cy, ny) * kCell, std::max(cx, nx) * kCell + kPath,
             std::max(cy, ny) * kCell + kPath);
        stack.emplace_back(nx, ny);
    }
    return m;
}

}  // namespace pyrseg::synthetic
