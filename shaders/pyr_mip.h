/* Mip pass (contract section 3): texel (x, y) of the level above `child` is fillable iff its four children exist
 * and are fillable. Needs: PYR_MASK(i) (0 or 1), i an index into the all-levels mask buffer. */
#ifndef PYR_MIP_H
#define PYR_MIP_H
#include "pyr_types.h"

PYR_FN pyr_u32 pyr_mip_texel(PYR_CTX_PARAM, PyrLevel child, pyr_u32 x, pyr_u32 y) {
    pyr_u32 cx = 2u * x;
    pyr_u32 cy = 2u * y;
    if (cx + 1u >= child.width || cy + 1u >= child.height) return 0u;
    pyr_u32 top = child.offset + cy * child.width + cx;
    pyr_u32 bottom = top + child.width;
    return PYR_MASK(top) & PYR_MASK(top + 1u) & PYR_MASK(bottom) & PYR_MASK(bottom + 1u) & PYR_MASK_FILLABLE;
}

#endif /* PYR_MIP_H */
