// The fills' worst cases: one long winding region, a square spiral and a maze, whose labels must travel the whole
// corridor. Union-find (the CPU) does not care; sweeping backends need a round per turn or so, and report how many
// (fill_rounds). Corridors are 8 pixels wide with 8-pixel walls, so that they survive to level M = N - 2 where the
// step-2 fill runs.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstdint>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "bench/bench_scenes.hpp"
#include "pyrseg/backend.hpp"

namespace pyrseg::bench {
namespace {

constexpr int kCell = 16;  // a corridor (8 px) and a wall (8 px)
constexpr int kPath = 8;

struct Mask {
    int width = 0, height = 0;
    std::vector<std::uint8_t> fillable;
    void fill(int x0, int y0, int x1, int y1) {  // inclusive-exclusive, clipped
        for (int y = std::max(0, y0); y < std::min(height, y1); ++y) {
            for (int x = std::max(0, x0); x < std::min(width, x1); ++x) fillable[std::size_t(y) * width + x] = 1;
        }
    }
};

// A square spiral from the border inwards: each lap turns four times.
Mask spiral(int width, int height) {
    Mask m{width, height, std::vector<std::uint8_t>(std::size_t(width) * height, 0)};
    int left = 0, top = 0, right = width - kPath, bottom = height - kPath;
    while (left <= right && top <= bottom) {
        m.fill(left, top, right + kPath, top + kPath);      // along the top
        m.fill(right, top, right + kPath, bottom + kPath);  // down the right
        if (top + kCell > bottom) break;
        m.fill(left, bottom, right + kPath, bottom + kPath);  // back along the bottom
        if (left + kCell > right) break;
        m.fill(left, top + kCell, left + kPath, bottom + kPath);  // up the left, short of the top
        left += kCell;
        top += kCell;
        right -= kCell;
        bottom -= kCell;
        m.fill(left - kCell, top, left + kPath, top + kPath);  // into the next lap
    }
    return m;
}

// A perfect maze (depth-first, fixed seed) on a grid of 16-pixel cells.
Mask maze(int width, int height) {
    Mask m{width, height, std::vector<std::uint8_t>(std::size_t(width) * height, 0)};
    const int cols = width / kCell;
    const int rows = height / kCell;
    std::vector<std::uint8_t> seen(std::size_t(cols) * rows, 0);
    std::mt19937 rng(12345);
    std::vector<std::pair<int, int>> stack = {{0, 0}};
    seen[0] = 1;
    m.fill(0, 0, kPath, kPath);
    while (!stack.empty()) {
        const auto [cx, cy] = stack.back();
        std::vector<std::pair<int, int>> next;
        for (const auto& [dx, dy] : {std::pair{1, 0}, std::pair{-1, 0}, std::pair{0, 1}, std::pair{0, -1}}) {
            const int nx = cx + dx;
            const int ny = cy + dy;
            if (nx >= 0 && ny >= 0 && nx < cols && ny < rows && seen[std::size_t(ny) * cols + nx] == 0)
                next.emplace_back(nx, ny);
        }
        if (next.empty()) {
            stack.pop_back();
            continue;
        }
        const auto [nx, ny] = next[rng() % next.size()];
        seen[std::size_t(ny) * cols + nx] = 1;
        m.fill(std::min(cx, nx) * kCell, std::min(cy, ny) * kCell, std::max(cx, nx) * kCell + kPath,
               std::max(cy, ny) * kCell + kPath);
        stack.emplace_back(nx, ny);
    }
    return m;
}

const Mask& worst_case(const std::string& kind, int width, int height) {
    static std::map<std::string, std::unique_ptr<Mask>> cache;
    auto& slot = cache[kind + size_name(width, height)];
    if (!slot) slot = std::make_unique<Mask>(kind == "spiral" ? spiral(width, height) : maze(width, height));
    return *slot;
}

void fill_worst_case(benchmark::State& state, const std::string& backend, const std::string& kind, int width,
                     int height) {
    const Mask& m = worst_case(kind, width, height);
    const MaskView view{m.fillable.data(), nullptr, width, height};
    time_frames(state, backend, width, height, std::size_t(width) * std::size_t(height),
                [&](Segmenter& segmenter, Result& result) { segmenter.segment_mask(view, result); });
}

int register_all() {
    for (const auto& size : {std::pair{640, 480}, std::pair{2064, 1544}}) {
        for (const std::string kind : {"spiral", "maze"}) {
            for (const BackendInfo& b : list_backends()) {
                if (!b.available) continue;
                const std::string name = "fills/" + kind + "/" + b.name + "/" + size_name(size.first, size.second);
                benchmark::RegisterBenchmark(
                    name.c_str(),
                    [=](benchmark::State& st) { fill_worst_case(st, b.name, kind, size.first, size.second); })
                    ->Unit(benchmark::kMillisecond)
                    ->UseRealTime();
            }
        }
    }
    return 0;
}

const int registered = register_all();

}  // namespace
}  // namespace pyrseg::bench
