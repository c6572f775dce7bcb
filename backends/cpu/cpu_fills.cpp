// Steps 2 and 4: fills to the contract's fixed point, by union-find (backends/cpu/union_find_fill.hpp) or, with
// PYRSEG_CPU_FILL=sweeps, by the shared relaxation's row and column sweeps, which the tests check union-find
// against; the sweeps also run steps 5 and 6 a, b on the scalar path (cpu_final_fill.cpp).
#include <algorithm>
#include <atomic>

#include "backends/cpu/cpu_executor.hpp"
#include "backends/cpu/union_find_fill.hpp"

namespace pyrseg::cpu {

using std::size_t;
using std::uint32_t;

namespace {

constexpr size_t kColumnBlock = 64;  // the narrowest strip of columns swept together, row by row

// Step 6 changes only fillable pixels without a label (labelled ones never change), so a block of a row that
// has none stays as it is whatever its neighbours do: the sweeps skip such blocks after a vectorised check.
constexpr uint32_t kSkipBlock = 64;

[[nodiscard]] bool has_unlabelled_fillable(const std::uint8_t* mask, const uint32_t* labels, uint32_t count) {
    bool any = false;
    for (uint32_t x = 0; x < count; ++x) any |= ((mask[x] & PYR_MASK_FILLABLE) != 0) & (labels[x] == 0);
    return any;
}

bool column_block(const PassContext& c, uint32_t row, uint32_t from, uint32_t x0, uint32_t x1, bool once) {
    const std::uint8_t* m = c.mask;
    uint32_t* l = c.labels;
    bool ch = false;
    for (uint32_t x = x0; x < x1; ++x) {
        if ((m[row + x] & PYR_MASK_FILLABLE) == 0) continue;
        const uint32_t cur = l[row + x];
        const uint32_t next = pixel::pyr_fill_step(cur, m[row + x], l[from + x], m[from + x], once ? 1u : 0u);
        if (next != cur) {
            l[row + x] = next;
            ch = true;
        }
    }
    return ch;
}

}  // namespace

void CpuExecutor::fill_to_fixed_point(int level, uint32_t anchor_max) {
    const PyrLevel lv = plan_.level(level);
    if (anchor_max != 0) {
        std::uint8_t* mask = mask_.data();
        const uint32_t* labels = labels_.data();
        rows(lv.height, [&](size_t y) {
            // Locals: byte stores may alias the captured references, which would be reloaded per texel.
            std::uint8_t* m = mask + lv.offset + y * lv.width;
            const uint32_t* l = labels + lv.offset + y * lv.width;
            const uint32_t n = lv.width;
            const uint32_t max = anchor_max;
            for (uint32_t x = 0; x < n; ++x) m[x] = std::uint8_t(pixel::pyr_anchor_mask(m[x], l[x], max));
        });
    }
    if (sweeps_) {
        do {
            ++fill_rounds_;
        } while (sweep(lv, false));
    } else {
        union_find_fill(pool_, lv, mask_.data(), labels_.data(), anchor_max != 0, fill_scratch_.data());
    }
}

// One round of the four directional sweeps (rows left-right then right-left, then columns top-down then
// bottom-up). Rows are independent, and so are columns: each runs in parallel. Returns whether a label changed.
// init_rows_first: run step 5's label init of each row just before its sweep (the row is then in cache).
bool CpuExecutor::sweep(const PyrLevel& lv, bool once, bool init_rows_first) {
    const PassContext c = context();
    const uint32_t onceu = once ? 1u : 0u;
    std::atomic<bool> changed{false};
    const PyrLevel parent = plan_.level(std::max(1, plan_.level_count - 1));
    rows(lv.height, [&](size_t y) {
        if (init_rows_first) init_row(c, lv, parent, uint32_t(y), PYR_INIT_INHERIT);
        const bool row_changed =
            once ? sweep_row_once(c, lv, uint32_t(y)) : pixel::pyr_sweep_row(c, lv, uint32_t(y), onceu) != 0u;
        if (row_changed) changed.store(true, std::memory_order_relaxed);
    });
    // Columns in strips at least kColumnBlock wide, one per task: each row of a strip is a contiguous run.
    const size_t strips = pool_.pieces();
    const size_t strip = std::max(kColumnBlock, (size_t(lv.width) + strips - 1) / strips);
    const size_t blocks = (size_t(lv.width) + strip - 1) / strip;
    pool_.parallel_for(blocks, 1, [&](size_t b0, size_t b1) {
        const uint32_t x0 = uint32_t(b0 * strip);
        const uint32_t x1 = uint32_t(std::min(size_t(lv.width), b1 * strip));
        bool ch = false;
        // Row by row, each column's sequential order is kept: row y reads row y -/+ 1 already updated.
        for (uint32_t y = 1; y < lv.height; ++y) ch |= column_step(c, lv, y, y - 1, x0, x1, once);
        for (uint32_t y = lv.height - 1; y-- > 0;) ch |= column_step(c, lv, y, y + 1, x0, x1, once);
        if (ch) changed.store(true, std::memory_order_relaxed);
    });
    return changed.load();
}

// Step 6a on row y: the shared sweep, there and back, over the blocks that can change (with the pixel before
// each block, which the sweep reads first).
bool CpuExecutor::sweep_row_once(const PassContext& c, const PyrLevel& lv, uint32_t y) {
    const uint32_t row = lv.offset + y * lv.width;
    bool changed = false;
    for (uint32_t b = 0; b < lv.width; b += kSkipBlock) {
        const uint32_t n = std::min(kSkipBlock, lv.width - b);
        if (!has_unlabelled_fillable(c.mask + row + b, c.labels + row + b, n)) continue;
        const uint32_t start = b == 0 ? row : row + b - 1;
        changed |= pixel::pyr_sweep_line(c, start, 1u, b == 0 ? n : n + 1, 1u) != 0u;
    }
    for (uint32_t e = lv.width; e > 0; e -= std::min(kSkipBlock, e)) {
        const uint32_t n = std::min(kSkipBlock, e);
        const uint32_t b = e - n;
        if (!has_unlabelled_fillable(c.mask + row + b, c.labels + row + b, n)) continue;
        const uint32_t start = e == lv.width ? row + e - 1 : row + e;
        changed |= pixel::pyr_sweep_line(c, start, 0xffffffffu, e == lv.width ? n : n + 1, 1u) != 0u;
    }
    return changed;
}

bool CpuExecutor::column_step(const PassContext& c, const PyrLevel& lv, uint32_t y, uint32_t from_y, uint32_t x0,
                              uint32_t x1, bool once) {
    const uint32_t row = lv.offset + y * lv.width;
    const uint32_t from = lv.offset + from_y * lv.width;
    const std::uint8_t* m = c.mask;
    uint32_t* l = c.labels;
    if (once) {
        bool ch = false;
        for (uint32_t b = x0; b < x1; b += kSkipBlock) {
            const uint32_t e = std::min(x1, b + kSkipBlock);
            if (has_unlabelled_fillable(m + row + b, l + row + b, e - b)) ch |= column_block(c, row, from, b, e, true);
        }
        return ch;
    }
    return column_block(c, row, from, x0, x1, false);
}

}  // namespace pyrseg::cpu
