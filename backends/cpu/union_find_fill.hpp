#pragma once
// Steps 2 and 4 (and the tiny-image fallback) straight to their fixed point by union-find, instead of repeating
// sweeps until nothing changes: the contract defines the result per 4-connected component of fillable,
// non-anchored texels (the smallest label inside it or on an anchored texel next to it), so a linear-time
// component labelling reaches it whatever the shape of the mask (spirals, noise speckle).
//
// The union-find nodes are the horizontal runs of such texels, not the texels, so that the cost follows the runs:
// noisy masks have runs of three texels on average. Rows are read as words of 64 eligibility bits, whose bit tricks
// find the runs, the stretches where two rows' runs overlap (one union each) and the few anchored texels next to a
// run, without a branch per texel; each run is found by counting the run starts before a texel. Stripes of rows
// are labelled in parallel, then joined along their borders, then every run is filled with its tree's label.
#include <cstddef>
#include <cstdint>

#include "backends/cpu/thread_pool.hpp"
#include "shaders/pyr_types.h"

namespace pyrseg::cpu {

// Entries of the scratch union_find_fill needs on a level of this size; a larger level needs no fewer.
std::size_t union_find_scratch_size(std::uint32_t width, std::uint32_t height);

// anchors: whether texels of the level may carry PYR_MASK_ANCHORED (step 4). Without, the fill does not read the
// runs' neighbours for anchored labels. scratch: union_find_scratch_size(level.width, level.height) entries.
void union_find_fill(ThreadPool& pool, const PyrLevel& level, const std::uint8_t* mask, std::uint32_t* labels,
                     bool anchors, std::uint32_t* scratch);

}  // namespace pyrseg::cpu
