#pragma once
// Overlap test of two convex solids (Gilbert-Johnson-Keerthi on their support mappings), for contact placement.
#include "solid.hpp"

namespace pyrseg::synthetic::detail {

// True when a, grown by margin (mm) in every direction, overlaps b. Neither may be a plane. Undecided cases (exact
// touching that the iteration cannot settle) count as overlap, so that placement errs towards a tiny gap.
bool overlaps(const Solid& a, const Solid& b, double margin = 0);

}  // namespace pyrseg::synthetic::detail
