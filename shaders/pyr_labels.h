/* Label init pass (contract section 5, steps 1, 3, 5, and the tiny-image fallback).
 * Needs: PYR_MASK(i), PYR_LABEL(i) on the all-levels buffers. `parent` has width 0 for level 1. */
#ifndef PYR_LABELS_H
#define PYR_LABELS_H
#include "pyr_types.h"

PYR_FN pyr_u32 pyr_label_init_texel(PYR_CTX_PARAM, PyrLevel level, PyrLevel parent, pyr_u32 x, pyr_u32 y,
                                    pyr_u32 mode) {
    pyr_u32 pixel = y * level.width + x;
    pyr_u32 i = level.offset + pixel;
    if ((PYR_MASK(i) & PYR_MASK_FILLABLE) == 0u) return 0u;
    if (mode == PYR_INIT_PIXEL_INDEX) return pixel + 1u;
    pyr_u32 inherited = 0u;
    if (parent.width != 0u) inherited = PYR_LABEL(parent.offset + (y >> 1) * parent.width + (x >> 1));
    if (inherited != 0u || mode == PYR_INIT_INHERIT) return inherited;
    return i + 1u; /* offset_k + y*w_k + x + 1 */
}

#endif /* PYR_LABELS_H */
