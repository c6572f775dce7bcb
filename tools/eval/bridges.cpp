#include "tools/eval/bridges.hpp"

#include <algorithm>
#include <cstdlib>
#include <map>
#include <stdexcept>
#include <utility>

namespace pyrseg::eval {
namespace {

void check_sizes(std::size_t a, std::size_t b, int width, int height) {
    if (width < 1 || height < 1) throw std::invalid_argument("image size must be positive");
    const std::size_t n = std::size_t(width) * std::size_t(height);
    if (a != n || b != n) throw std::invalid_argument("image buffers do not match the size");
}

// Labels the 4-connected components of pixels for which joins(i, j) holds between neighbours i and j (and
// member(i) for the pixels themselves), 1.. in row-major order of first pixel; returns the labels.
template <typename Member, typename Joins>
std::vector<std::uint32_t> components(int width, int height, Member member, Joins joins, std::uint32_t* count) {
    const std::size_t w = std::size_t(width);
    const std::size_t n = w * std::size_t(height);
    std::vector<std::uint32_t> labels(n, 0);
    std::vector<std::size_t> stack;
    std::uint32_t next = 0;
    for (std::size_t start = 0; start < n; ++start) {
        if (labels[start] != 0 || !member(start)) continue;
        labels[start] = ++next;
        stack.push_back(start);
        while (!stack.empty()) {
            const std::size_t i = stack.back();
            stack.pop_back();
            const std::size_t x = i % w;
            const auto visit = [&](std::size_t j) {
                if (labels[j] == 0 && member(j) && joins(i, j)) {
                    labels[j] = next;
                    stack.push_back(j);
                }
            };
            if (x > 0) visit(i - 1);
            if (x + 1 < w) visit(i + 1);
            if (i >= w) visit(i - w);
            if (i + w < n) visit(i + w);
        }
    }
    if (count != nullptr) *count = next;
    return labels;
}

// For every pixel, the truth id when it belongs to its object's core, else 0.
std::vector<std::uint32_t> cores(const std::vector<std::uint32_t>& truth, const std::vector<std::uint8_t>& fillable,
                                 int width, int height) {
    std::uint32_t count = 0;
    const std::vector<std::uint32_t> comp = components(
        width, height, [&](std::size_t i) { return fillable[i] != 0 && truth[i] != 0; },
        [&](std::size_t i, std::size_t j) { return truth[i] == truth[j]; }, &count);
    std::vector<std::uint64_t> size(std::size_t(count) + 1, 0);
    std::vector<std::uint32_t> id(std::size_t(count) + 1, 0);
    for (std::size_t i = 0; i < comp.size(); ++i) {
        if (comp[i] == 0) continue;
        ++size[comp[i]];
        id[comp[i]] = truth[i];
    }
    // Per truth id, the largest component; components are numbered by first pixel, so strict > keeps the first.
    std::map<std::uint32_t, std::uint32_t> best;
    for (std::uint32_t c = 1; c <= count; ++c) {
        const auto [it, added] = best.try_emplace(id[c], c);
        if (!added && size[c] > size[it->second]) it->second = c;
    }
    std::vector<std::uint8_t> is_core(std::size_t(count) + 1, 0);
    for (const auto& [truth_id, c] : best) is_core[c] = 1;
    std::vector<std::uint32_t> core(comp.size(), 0);
    for (std::size_t i = 0; i < comp.size(); ++i) {
        if (comp[i] != 0 && is_core[comp[i]] != 0) core[i] = truth[i];
    }
    return core;
}

bool path_has_data(const std::vector<std::uint32_t>& truth, int x0, int y0, int x1, int y1, int width) {
    const std::vector<std::size_t> path = digital_path(x0, y0, x1, y1, width);
    return std::all_of(path.begin(), path.end(), [&](std::size_t i) { return truth[i] != 0; });
}

}  // namespace

std::vector<std::size_t> digital_path(int x0, int y0, int x1, int y1, int width) {
    const std::int64_t dx = std::abs(std::int64_t{x1} - x0);
    const std::int64_t dy = std::abs(std::int64_t{y1} - y0);
    const int sx = x1 >= x0 ? 1 : -1;
    const int sy = y1 >= y0 ? 1 : -1;
    std::vector<std::size_t> path;
    path.reserve(std::size_t(dx + dy + 1));
    int x = x0;
    int y = y0;
    path.push_back(std::size_t(y) * std::size_t(width) + std::size_t(x));
    std::int64_t ix = 0;
    std::int64_t iy = 0;
    while (ix < dx || iy < dy) {
        // The segment crosses the next vertical pixel border at t = (ix + 1/2) / dx and the next horizontal one at
        // (iy + 1/2) / dy: step across whichever comes first (x on a tie).
        if (iy == dy || (ix < dx && (1 + 2 * ix) * dy <= (1 + 2 * iy) * dx)) {
            x += sx;
            ++ix;
        } else {
            y += sy;
            ++iy;
        }
        path.push_back(std::size_t(y) * std::size_t(width) + std::size_t(x));
    }
    return path;
}

std::vector<BridgeSite> find_bridge_sites(const std::vector<std::uint32_t>& truth,
                                          const std::vector<std::uint8_t>& fillable, int width, int height,
                                          int max_gap) {
    check_sizes(truth.size(), fillable.size(), width, height);
    if (max_gap < 1) throw std::invalid_argument("max_gap must be >= 1");
    const std::vector<std::uint32_t> core = cores(truth, fillable, width, height);
    const std::size_t w = std::size_t(width);
    // Closest pairs of two sets lie on their borders: a core pixel whose 4-neighbours are all in its core has a
    // neighbour closer to any outside pixel.
    std::vector<std::uint32_t> border(core.size(), 0);
    std::vector<std::size_t> border_pixels;
    for (std::size_t i = 0; i < core.size(); ++i) {
        if (core[i] == 0) continue;
        const std::size_t x = i % w;
        const bool inner = (x == 0 || core[i - 1] == core[i]) && (x + 1 == w || core[i + 1] == core[i]) &&
                           (i < w || core[i - w] == core[i]) && (i + w >= core.size() || core[i + w] == core[i]);
        if (!inner) {
            border[i] = core[i];
            border_pixels.push_back(i);
        }
    }
    struct Best {
        std::int64_t d2 = 0;
        BridgeSite site;
    };
    std::map<std::pair<std::uint32_t, std::uint32_t>, Best> best;
    for (const std::size_t p : border_pixels) {
        const int px = int(p % w);
        const int py = int(p / w);
        const std::uint32_t a = border[p];
        for (int qy = std::max(0, py - max_gap); qy <= std::min(height - 1, py + max_gap); ++qy) {
            for (int qx = std::max(0, px - max_gap); qx <= std::min(width - 1, px + max_gap); ++qx) {
                const std::uint32_t b = border[std::size_t(qy) * w + std::size_t(qx)];
                if (b <= a) continue;
                const std::int64_t d2 = std::int64_t(qx - px) * (qx - px) + std::int64_t(qy - py) * (qy - py);
                const auto it = best.find({a, b});
                if (it != best.end() && it->second.d2 <= d2) continue;
                if (!path_has_data(truth, px, py, qx, qy, width)) continue;
                best[{a, b}] = Best{d2, BridgeSite{a, b, px, py, qx, qy}};
            }
        }
    }
    std::vector<BridgeSite> sites;
    sites.reserve(best.size());
    for (const auto& [pair, b] : best) sites.push_back(b.site);
    return sites;
}

void draw_bridges(const std::vector<BridgeSite>& sites, int bridge_width, const std::vector<std::uint32_t>& truth,
                  int width, int height, std::vector<std::uint8_t>& fillable, std::vector<std::uint8_t>& valid) {
    check_sizes(truth.size(), fillable.size(), width, height);
    check_sizes(truth.size(), valid.size(), width, height);
    if (bridge_width < 1) throw std::invalid_argument("bridge width must be >= 1");
    const int lo = -(bridge_width - 1) / 2;
    const int hi = bridge_width / 2;
    const std::size_t w = std::size_t(width);
    for (const BridgeSite& s : sites) {
        for (const std::size_t i : digital_path(s.x0, s.y0, s.x1, s.y1, width)) {
            const int x = int(i % w);
            const int y = int(i / w);
            for (int y2 = std::max(0, y + lo); y2 <= std::min(height - 1, y + hi); ++y2) {
                for (int x2 = std::max(0, x + lo); x2 <= std::min(width - 1, x + hi); ++x2) {
                    const std::size_t j = std::size_t(y2) * w + std::size_t(x2);
                    if (truth[j] == 0) continue;
                    fillable[j] = 1;
                    valid[j] = 1;
                }
            }
        }
    }
}

std::vector<std::uint32_t> connected_components(const std::vector<std::uint8_t>& fillable, int width, int height,
                                                std::uint32_t* count) {
    check_sizes(fillable.size(), fillable.size(), width, height);
    return components(
        width, height, [&](std::size_t i) { return fillable[i] != 0; },
        [](std::size_t /*i*/, std::size_t /*j*/) { return true; }, count);
}

void label_edges(std::vector<std::uint32_t>& labels, const std::vector<std::uint8_t>& fillable,
                 const std::vector<std::uint8_t>& valid, int width, int height) {
    check_sizes(labels.size(), fillable.size(), width, height);
    if (!valid.empty()) check_sizes(valid.size(), labels.size(), width, height);
    const std::size_t w = std::size_t(width);
    const std::size_t n = labels.size();
    // Only non-fillable pixels are written and only fillable ones read, so one pass in place is exact.
    for (std::size_t i = 0; i < n; ++i) {
        if (fillable[i] != 0 || labels[i] != 0 || (!valid.empty() && valid[i] == 0)) continue;
        std::uint32_t smallest = 0;
        const auto take = [&](std::size_t j) {
            if (fillable[j] != 0 && labels[j] != 0 && (smallest == 0 || labels[j] < smallest)) smallest = labels[j];
        };
        const std::size_t x = i % w;
        if (x > 0) take(i - 1);
        if (x + 1 < w) take(i + 1);
        if (i >= w) take(i - w);
        if (i + w < n) take(i + w);
        labels[i] = smallest;
    }
}

}  // namespace pyrseg::eval
