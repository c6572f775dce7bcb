#pragma once
// The GPUs' pair-table functions (shaders/pyr_merge_table.h for the merge, shaders/pyr_graph.h for the segment graph,
// shaders/pyr_track.h for the tracks' overlaps) over the words in PassContext::merge, with the accessors they need as
// relaxed atomics; and the walk over the rows the merge and the graph run, which hands them only the pixels that may
// cross a boundary.
#include <algorithm>
#include <atomic>
#include <cstddef>
#include <cstdint>

#include "backends/cpu/cpu_dialect.hpp"

#define PYR_UF_LOAD(i) std::atomic_ref<std::uint32_t>(ctx.merge[i]).load(std::memory_order_relaxed)
#define PYR_UF_STORE(i, v) std::atomic_ref<std::uint32_t>(ctx.merge[i]).store((v), std::memory_order_relaxed)
#define PYR_UF_MIN(i, v) ::pyrseg::cpu::atomic_min(ctx.merge[i], (v))
#define PYR_UF_CAS(i, e, v) ::pyrseg::cpu::atomic_cas(ctx.merge[i], (e), (v))
#define PYR_UF_ADD(i, v) std::atomic_ref<std::uint32_t>(ctx.merge[i]).fetch_add((v), std::memory_order_relaxed)

namespace pyrseg::cpu::pixel {
using std::min;                 // pyr_uf.h's GPU spelling
#include "shaders/pyr_graph.h"  // and, through it, shaders/pyr_merge_table.h
#include "shaders/pyr_track.h"
}  // namespace pyrseg::cpu::pixel

namespace pyrseg::cpu {

// body(x) for each labelled pixel x of row y of level lv whose right or lower neighbour has another label (or
// none): most pixels cross no boundary, and only these need the shared per-pixel functions.
template <class Body>
void for_each_boundary_pixel(const std::uint32_t* labels, const PyrLevel& lv, std::size_t y, const Body& body) {
    const std::uint32_t* row = labels + lv.offset + y * lv.width;
    const std::uint32_t* below = y + 1 < lv.height ? row + lv.width : row;  // the last row: no pixel below
    for (std::uint32_t x = 0; x < lv.width; ++x) {
        const std::uint32_t right = x + 1 < lv.width ? row[x + 1] : row[x];
        if (row[x] == 0 || (right == row[x] && below[x] == row[x])) continue;
        body(x);
    }
}

}  // namespace pyrseg::cpu
