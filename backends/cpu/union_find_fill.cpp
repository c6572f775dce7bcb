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

// Roots are the smallest index of their tree, so a root never points past itself.
void unite(uint32_t* parent, uint32_t a, uint32_t b) {
    a = find(parent, a);
    b = find(parent, b);
    if (a < b) {
        parent[b] = a;
    } else if (b < a) {
        parent[a] = b;
    }
}

uint32_t load(uint32_t& v) {
    return std::atomic_ref<uint32_t>(v).load(std::memory_order_relaxed);
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

    // 1. Components within each stripe of rows, in parallel.
    pool.parallel_for(stripes, 1, [&](size_t s0, size_t s1) {
        for (size_t s = s0; s < s1; ++s) {
            const uint32_t y0 = stripe_begin(s);
            const uint32_t y1 = stripe_begin(s + 1);
            for (uint32_t y = y0; y < y1; ++y) {
                for (uint32_t x = 0; x < w; ++x) {
                    const uint32_t i = y * w + x;
                    if (!eligible(mask[i])) continue;
                    parent[i] = i;
                    if (x > 0 && eligible(mask[i - 1])) unite(parent, i, i - 1);
                    if (y > y0 && eligible(mask[i - w])) unite(parent, i, i - w);
                }
            }
        }
    });
    // 2. Join the stripes along their borders, sequentially.
    for (size_t s = 1; s < stripes; ++s) {
        const uint32_t y = stripe_begin(s);
        for (uint32_t x = 0; x < w; ++x) {
            const uint32_t i = y * w + x;
            if (eligible(mask[i]) && eligible(mask[i - w])) unite(parent, i, i - w);
        }
    }
    // 3. Point every texel at its root. Other threads may shorten a chain being followed, only ever to an
    //    ancestor, so relaxed atomic accesses suffice.
    const size_t grain = std::max<size_t>(1, h / (size_t(pool.size()) * 8));
    pool.parallel_for(h, grain, [&](size_t y0, size_t y1) {
        for (size_t i = y0 * w; i < y1 * w; ++i) {
            if (!eligible(mask[i])) continue;
            uint32_t r = uint32_t(i);
            for (uint32_t p = load(parent[r]); p != r; p = load(parent[r])) r = p;
            std::atomic_ref<uint32_t>(parent[i]).store(r, std::memory_order_relaxed);
            best[i] = kNone;
        }
    });
    // 4. The smallest label per component: its own labels and those of anchored 4-neighbours.
    pool.parallel_for(h, grain, [&](size_t y0, size_t y1) {
        for (size_t y = y0; y < y1; ++y) {
            for (size_t x = 0; x < w; ++x) {
                const size_t i = y * w + x;
                if (!eligible(mask[i])) continue;
                uint32_t v = labels[i] != 0 ? labels[i] : kNone;
                const auto anchored = [&](size_t j) {
                    if ((mask[j] & PYR_MASK_ANCHORED) != 0) v = std::min(v, labels[j]);
                };
                if (x > 0) anchored(i - 1);
                if (x + 1 < w) anchored(i + 1);
                if (y > 0) anchored(i - w);
                if (y + 1 < h) anchored(i + w);
                if (v == kNone) continue;
                std::atomic_ref<uint32_t> slot(best[parent[i]]);
                uint32_t cur = slot.load(std::memory_order_relaxed);
                while (v < cur && !slot.compare_exchange_weak(cur, v, std::memory_order_relaxed)) {
                }
            }
        }
    });
    // 5. Every texel takes its component's label (0 when the component has none).
    pool.parallel_for(h, grain, [&](size_t y0, size_t y1) {
        for (size_t i = y0 * w; i < y1 * w; ++i) {
            if (!eligible(mask[i])) continue;
            const uint32_t b = best[parent[i]];
            labels[i] = b == kNone ? 0 : b;
        }
    });
}

}  // namespace pyrseg::cpu
