#pragma once
// Steps 2 and 4 (and the tiny-image fallback) straight to their fixed point by union-find, instead of repeating
// sweeps until nothing changes: the contract defines the result per 4-connected component of fillable,
// non-anchored texels (the smallest label inside it or on an anchored texel next to it), so a linear-time
// component labelling reaches it whatever the shape of the mask (spirals, noise speckle).
#include <cstdint>

#include "backends/cpu/thread_pool.hpp"
#include "shaders/pyr_types.h"

namespace pyrseg::cpu {

// parent and best: scratch of at least level.width * level.height entries.
void union_find_fill(ThreadPool& pool, const PyrLevel& level, const std::uint8_t* mask, std::uint32_t* labels,
                     std::uint32_t* parent, std::uint32_t* best);

}  // namespace pyrseg::cpu
