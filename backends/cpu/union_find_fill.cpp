#include "backends/cpu/union_find_fill.hpp"

#include <algorithm>
#include <bit>
#include <cstring>
#include <limits>
#include <utility>

namespace pyrseg::cpu {
namespace {

using std::size_t;
using std::uint32_t;
using std::uint64_t;

// Labels are kept minus 1: 0 (no label) wraps to kNone, which every minimum skips.
constexpr uint32_t kNone = std::numeric_limits<uint32_t>::max();
constexpr uint64_t kByteLows = 0x0101010101010101u;

// The scratch, carved into arrays. Rows are cut into words of 64 texels: per row, bit planes of the eligible
// texels (fillable, not anchored) and of the anchored ones (kept in the uint32 scratch as two halves a word).
// The union-find nodes are the runs of eligible texels; a row of w texels has at most cap = (w + 1) / 2 of them, so
// each stripe of rows owns room for cap runs a row and packs its rows' runs one after the other, without a
// counting pass.
struct Work {
    uint32_t w;
    uint32_t h;
    uint32_t words;      // 64-texel words a row
    uint32_t* eligible;  // bit planes: row y's word i at (y * words + i) * 2
    uint32_t* anchored;
    uint32_t* begin;   // first texel of each run
    uint32_t* end;     // one past its last texel
    uint32_t* parent;  // union-find tree: a root is the smallest node of its tree
    uint32_t* best;    // the smallest label minus 1 on a run or next to it; a root's: of its whole tree
    uint32_t* first;   // node of each row's first run
    uint32_t* count;   // runs a row

    [[nodiscard]] uint64_t word(const uint32_t* plane, uint32_t y, uint32_t i) const {
        uint64_t v = 0;
        std::memcpy(&v, plane + (size_t(y) * words + i) * 2, sizeof v);
        return v;
    }
};

// Bits of the runs' first texels in word e, given whether the texel before the word is eligible.
uint64_t starts(uint64_t e, uint64_t carry) {
    return e & ~((e << 1) | carry);
}

// The number of set bits (std::popcount calls a library function on x86-64 without -mpopcnt).
uint32_t popcount(uint64_t x) {
    x = x - ((x >> 1) & 0x5555555555555555u);
    x = (x & 0x3333333333333333u) + ((x >> 2) & 0x3333333333333333u);
    x = (x + (x >> 4)) & 0x0f0f0f0f0f0f0f0fu;
    return uint32_t((x * kByteLows) >> 56);
}

// Row y's bit planes. Eight texels at a time: bit 0 of each byte becomes the texel's bit, and the multiplication
// gathers the eight bits into the top byte (its partial products never overlap, so never carry).
void bit_planes(const Work& k, const std::uint8_t* m, uint32_t y, bool anchors) {
    static_assert(PYR_MASK_FILLABLE == 1u && PYR_MASK_ANCHORED == 2u);
    constexpr uint64_t kGather = 0x0102040810204080u;
    for (uint32_t i = 0; i < k.words; ++i) {
        const uint32_t x0 = i * 64;
        const uint32_t n = std::min(64u, k.w - x0);
        uint64_t e = 0;
        uint64_t a = 0;
        if (std::endian::native == std::endian::little && n == 64) {
            for (uint32_t j = 0; j < 64; j += 8) {
                uint64_t x = 0;
                std::memcpy(&x, m + x0 + j, sizeof x);
                e |= ((x & ~(x >> 1) & kByteLows) * kGather) >> 56 << j;
                a |= (((x >> 1) & kByteLows) * kGather) >> 56 << j;
            }
        } else {  // bits past the row stay clear
            for (uint32_t j = 0; j < n; ++j) {
                e |= uint64_t((m[x0 + j] & (PYR_MASK_FILLABLE | PYR_MASK_ANCHORED)) == PYR_MASK_FILLABLE) << j;
                a |= uint64_t((m[x0 + j] & PYR_MASK_ANCHORED) != 0) << j;
            }
        }
        const size_t at = (size_t(y) * k.words + i) * 2;
        std::memcpy(k.eligible + at, &e, sizeof e);
        if (anchors) std::memcpy(k.anchored + at, &a, sizeof a);
    }
}

// Row y's runs from its eligible bits: a run begins on a set bit whose previous bit is clear and ends on a clear bit
// whose previous bit is set, so this costs a few operations a run, not a texel.
uint32_t find_runs(const Work& k, uint32_t y, uint32_t* begin, uint32_t* end) {
    uint32_t n_begin = 0;
    uint32_t n_end = 0;
    uint64_t carry = 0;  // whether the texel before the word is eligible
    for (uint32_t i = 0; i < k.words; ++i) {
        const uint64_t e = k.word(k.eligible, y, i);
        const uint64_t before = (e << 1) | carry;
        carry = e >> 63;
        for (uint64_t b = e & ~before; b != 0; b &= b - 1) begin[n_begin++] = i * 64 + uint32_t(std::countr_zero(b));
        for (uint64_t b = ~e & before; b != 0; b &= b - 1) end[n_end++] = i * 64 + uint32_t(std::countr_zero(b));
    }
    if (carry != 0) end[n_end++] = k.w;  // a full last word whose last texel is eligible
    return n_begin;
}

// Each run's own best: the smallest label on it. Most runs are short, so their first four texels are read at
// clamped positions (a texel read twice changes no minimum) rather than by a loop whose end the CPU mispredicts.
void own_bests(const Work& k, const uint32_t* l, size_t k0, uint32_t n) {
    for (size_t r = k0; r < k0 + n; ++r) {
        const uint32_t a = k.begin[r];
        const uint32_t b = k.end[r];
        uint32_t v = kNone;
        for (uint32_t i = 0; i < 4; ++i) v = std::min(v, l[std::min(a + i, b - 1)] - 1u);
        for (uint32_t x = a + 4; x < b; ++x) v = std::min(v, l[x] - 1u);
        k.parent[r] = uint32_t(r);
        k.best[r] = v;
    }
}

// Folds into row y's runs' bests the labels of the anchored texels next to them. Few anchored texels touch an
// eligible one (anchors are old regions; eligible texels are holes and new ground), so they are found by bits, and
// each one's run by counting the run starts before it.
void anchor_bests(const Work& k, const uint32_t* labels, uint32_t y) {
    const size_t row = size_t(y) * k.w;
    uint32_t base = k.first[y] - 1u;  // the run before the word's first start (wraps; only used with a start)
    uint64_t carry_e = 0;
    uint64_t carry_a = 0;
    for (uint32_t i = 0; i < k.words; ++i) {
        const uint64_t e = k.word(k.eligible, y, i);
        const uint64_t a = k.word(k.anchored, y, i);
        const uint64_t next_a = i + 1 < k.words ? k.word(k.anchored, y, i + 1) : 0;
        const uint64_t s = starts(e, carry_e);
        carry_e = e >> 63;
        const size_t x0 = row + size_t(i) * 64;
        const auto fold = [&](uint64_t bits, size_t source_offset) {
            for (; bits != 0; bits &= bits - 1) {
                const uint32_t x = uint32_t(std::countr_zero(bits));
                const uint32_t r = base + popcount(s & (bits ^ (bits - 1)));
                k.best[r] = std::min(k.best[r], labels[x0 + x + source_offset] - 1u);
            }
        };
        fold(((a << 1) | carry_a) & e, size_t(0) - 1);                       // anchored on the left
        fold(((a >> 1) | (next_a << 63)) & e, 1);                            // on the right
        if (y > 0) fold(k.word(k.anchored, y - 1, i) & e, size_t(0) - k.w);  // above
        if (y + 1 < k.h) fold(k.word(k.anchored, y + 1, i) & e, k.w);        // below
        carry_a = a >> 63;
        base += popcount(s);
    }
}

// A root; nodes close to theirs (most are) are read without a loop. Halves the path on the way.
uint32_t find(uint32_t* parent, uint32_t i) {
    uint32_t r = parent[parent[i]];
    while (parent[r] != r) r = parent[r] = parent[parent[r]];
    parent[i] = r;
    return r;
}

// Roots are the smallest node of their tree, so a root never points past itself; without a branch, since whether
// two runs are joined already is a coin toss on noise.
void unite(const Work& k, uint32_t a, uint32_t b) {
    a = find(k.parent, a);
    b = find(k.parent, b);
    const uint32_t lo = std::min(a, b);
    const uint32_t hi = std::max(a, b);
    k.parent[hi] = lo;
    k.best[lo] = std::min(k.best[lo], k.best[hi]);
}

// Joins the runs of row y with those of row y - 1 they overlap. Two runs overlap on one stretch of texels eligible in
// both rows (two intervals meet in one interval), so one union per stretch does it; each run is found by counting
// its row's run starts up to the stretch's first texel.
void join_rows(const Work& k, uint32_t y) {
    uint32_t i_base = k.first[y - 1] - 1u;  // the runs before each word's first start (wrap; used with a start)
    uint32_t j_base = k.first[y] - 1u;
    uint64_t carry_a = 0;
    uint64_t carry_c = 0;
    uint64_t carry_b = 0;  // a stretch going on from the word before is not a new one (it would only cost a union)
    for (uint32_t i = 0; i < k.words; ++i) {
        const uint64_t ea = k.word(k.eligible, y - 1, i);
        const uint64_t ec = k.word(k.eligible, y, i);
        const uint64_t sa = starts(ea, carry_a);
        const uint64_t sc = starts(ec, carry_c);
        for (uint64_t b = starts(ea & ec, carry_b); b != 0; b &= b - 1) {
            const uint64_t upto = b ^ (b - 1);
            unite(k, i_base + popcount(sa & upto), j_base + popcount(sc & upto));
        }
        carry_a = ea >> 63;
        carry_c = ec >> 63;
        carry_b = (ea & ec) >> 63;
        i_base += popcount(sa);
        j_base += popcount(sc);
    }
}

}  // namespace

size_t union_find_scratch_size(uint32_t width, uint32_t height) {
    const size_t runs = size_t(height) * ((size_t(width) + 1) / 2);
    const size_t words = size_t(height) * ((size_t(width) + 63) / 64);
    // Two bit planes of 64-bit words; begin, end, parent, best; first, count.
    return 2 * (words * 2) + 4 * runs + 2 * size_t(height);
}

void union_find_fill(ThreadPool& pool, const PyrLevel& level, const std::uint8_t* mask_all, uint32_t* labels_all,
                     bool anchors, uint32_t* scratch) {
    const uint32_t w = level.width;
    const uint32_t h = level.height;
    if (w == 0 || h == 0) return;
    const std::uint8_t* mask = mask_all + level.offset;
    uint32_t* labels = labels_all + level.offset;
    const uint32_t cap = (w + 1) / 2;
    const uint32_t words = (w + 63) / 64;
    const size_t runs = size_t(h) * cap;
    const size_t plane = size_t(h) * words * 2;
    uint32_t* p = scratch;
    const auto carve = [&p](size_t n) { return std::exchange(p, p + n); };
    const Work k{w,           h,           words,       carve(plane), carve(plane), carve(runs),
                 carve(runs), carve(runs), carve(runs), carve(h),     carve(h)};
    const size_t grain = std::max<size_t>(1, h / pool.pieces());
    const size_t stripes = std::min<size_t>(h, pool.pieces());
    const auto stripe_begin = [&](size_t s) { return uint32_t(size_t(h) * s / stripes); };

    // 0. The bit planes, in parallel: a row's runs read the anchored bits of the rows above and below it.
    pool.parallel_for(h, grain, [&](size_t y0, size_t y1) {
        for (size_t y = y0; y < y1; ++y) bit_planes(k, mask + y * w, uint32_t(y), anchors);
    });
    // 1. Each row's runs and their bests, joined with the runs above them within each stripe of rows, in parallel.
    pool.parallel_for(stripes, 1, [&](size_t s0, size_t s1) {
        for (size_t stripe = s0; stripe < s1; ++stripe) {
            const uint32_t y0 = stripe_begin(stripe);
            const uint32_t y1 = stripe_begin(stripe + 1);
            for (uint32_t y = y0; y < y1; ++y) {
                k.first[y] = y == y0 ? y0 * cap : k.first[y - 1] + k.count[y - 1];
                k.count[y] = find_runs(k, y, k.begin + k.first[y], k.end + k.first[y]);
                own_bests(k, labels + size_t(y) * w, k.first[y], k.count[y]);
                if (anchors) anchor_bests(k, labels, y);
                if (y > y0) join_rows(k, y);
            }
            // Every node of the stripe straight to its root: a node's parent is an earlier node, flattened already.
            for (size_t r = k.first[y0]; r < k.first[y1 - 1] + k.count[y1 - 1]; ++r)
                k.parent[r] = k.parent[k.parent[r]];
        }
    });
    // 2. Join the stripes along their borders, sequentially.
    for (size_t stripe = 1; stripe < stripes; ++stripe) join_rows(k, stripe_begin(stripe));
    // 3. Every run takes its tree's best (0 when it has none). The trees no longer change: finds only read.
    pool.parallel_for(h, grain, [&](size_t y0, size_t y1) {
        for (size_t y = y0; y < y1; ++y) {
            uint32_t* l = labels + y * w;
            for (size_t r = k.first[y]; r < k.first[y] + k.count[y]; ++r) {
                uint32_t root = k.parent[r];
                while (k.parent[root] != root) root = k.parent[root];
                const uint32_t v = k.best[root] + 1u;
                const uint32_t a = k.begin[r];
                const uint32_t len = k.end[r] - a;
                if (len <= 8) {
                    // Eight stores at clamped positions rather than a loop whose length the CPU would mispredict.
                    for (uint32_t i = 0; i < 8; ++i) l[a + std::min(i, len - 1)] = v;
                } else {
                    std::fill(l + a, l + a + len, v);
                }
            }
        }
    });
}

}  // namespace pyrseg::cpu
