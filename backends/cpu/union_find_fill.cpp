#include "backends/cpu/union_find_fill.hpp"

#include <algorithm>
#include <atomic>
#include <limits>
#include <vector>

namespace pyrseg::cpu {
namespace {

using std::size_t;
using std::uint32_t;

constexpr uint32_t kNone = std::numeric_limits<uint32_t>::max();

// A texel takes part when it is fillable and not anchored; anchored texels only contribute their labels.
bool eligible(std::uint8_t m) {
    return (m & (PYR_MASK_FILLABLE | PYR_MASK_ANCHORED)) == PYR_MASK_FILLABLE;
}

uint32_t find(uint32_t* parent, uint32_t i) {
    while (parent[i] != i) {
        parent[i] = parent[parent[i]];  // path halving
        i = parent[i];
    }
    return i;
}

// Roots are the smallest index of their tree, so a root never points past itself. A root's best is the smallest
// label of its tree's runs.
void unite(uint32_t* parent, uint32_t* best, uint32_t a, uint32_t b) {
    a = find(parent, a);
    b = find(parent, b);
    if (a == b) return;
    if (b < a) std::swap(a, b);
    parent[b] = a;
    best[a] = std::min(best[a], best[b]);
}

// The end of the run of eligible texels that starts at x (w at most).
uint32_t run_end(const std::uint8_t* row, uint32_t x, uint32_t w) {
    while (x < w && eligible(row[x])) ++x;
    return x;
}

// Joins run [a, b) of row `row` (its first texel at index s) with the runs of the row before it that touch it.
void join_above(uint32_t* parent, uint32_t* best, const std::uint8_t* above, uint32_t above_index, uint32_t s,
                uint32_t a, uint32_t b) {
    for (uint32_t x = a; x < b; ++x) {
        if (eligible(above[x]) && (x == a || !eligible(above[x - 1]))) unite(parent, best, s, above_index + x);
    }
}

}  // namespace

void union_find_fill(ThreadPool& pool, const PyrLevel& level, const std::uint8_t* mask_all, uint32_t* labels_all,
                     uint32_t* parent, uint32_t* best) {
    const uint32_t w = level.width;
    const uint32_t h = level.height;
    const std::uint8_t* mask = mask_all + level.offset;
    uint32_t* labels = labels_all + level.offset;
    const size_t stripes = std::min<size_t>(h, size_t(pool.size()) * 4);
    const auto stripe_begin = [&](size_t s) { return uint32_t(size_t(h) * s / stripes); };

    // 1. Runs of eligible texels, each one tree node (its first texel; the others point at it), joined with the
    //    runs above it within each stripe of rows, in parallel. A run's best: the smallest label on it or on an
    //    anchored texel next to it.
    pool.parallel_for(stripes, 1, [&](size_t s0, size_t s1) {
        for (size_t stripe = s0; stripe < s1; ++stripe) {
            const uint32_t y0 = stripe_begin(stripe);
            const uint32_t y1 = stripe_begin(stripe + 1);
            for (uint32_t y = y0; y < y1; ++y) {
                const uint32_t row = y * w;
                const std::uint8_t* m = mask + row;
                const uint32_t* l = labels + row;
                for (uint32_t a = 0; a < w; ++a) {
                    if (!eligible(m[a])) continue;
                    const uint32_t b = run_end(m, a, w);
                    const uint32_t s = row + a;
                    uint32_t v = kNone;  // labels minus 1: 0 wraps to kNone, which the minimum skips
                    for (uint32_t x = a; x < b; ++x) {
                        v = std::min(v, l[x] - 1u);
                        parent[row + x] = s;
                    }
                    const auto anchored = [&](uint32_t j) {
                        if ((mask[j] & PYR_MASK_ANCHORED) != 0) v = std::min(v, labels[j] - 1u);
                    };
                    if (a > 0) anchored(row + a - 1);
                    if (b < w) anchored(row + b);
                    if (y > 0) {
                        for (uint32_t x = a; x < b; ++x) anchored(row - w + x);
                    }
                    if (y + 1 < h) {
                        for (uint32_t x = a; x < b; ++x) anchored(row + w + x);
                    }
                    best[s] = v;
                    if (y > y0) join_above(parent, best, m - w, row - w, s, a, b);
                    a = b;
                }
            }
        }
    });
    // 2. Join the stripes along their borders, sequentially.
    for (size_t stripe = 1; stripe < stripes; ++stripe) {
        const uint32_t y = stripe_begin(stripe);
        const uint32_t row = y * w;
        const std::uint8_t* m = mask + row;
        for (uint32_t a = 0; a < w; ++a) {
            if (!eligible(m[a])) continue;
            const uint32_t b = run_end(m, a, w);
            join_above(parent, best, m - w, row - w, row + a, a, b);
            a = b;
        }
    }
    // 3. Every run takes its tree's best (0 when it has none). The trees no longer change: finds only read.
    const size_t grain = std::max<size_t>(1, h / (size_t(pool.size()) * 8));
    pool.parallel_for(h, grain, [&](size_t y0, size_t y1) {
        for (size_t y = y0; y < y1; ++y) {
            const uint32_t row = uint32_t(y) * w;
            const std::uint8_t* m = mask + row;
            for (uint32_t a = 0; a < w; ++a) {
                if (!eligible(m[a])) continue;
                const uint32_t b = run_end(m, a, w);
                uint32_t r = row + a;
                while (parent[r] != r) r = parent[r];
                std::fill(labels + row + a, labels + row + b, best[r] + 1u);
                a = b;
            }
        }
    });
}

}  // namespace pyrseg::cpu
