/* Fill passes (contract section 5).
 * Steps 2 and 4 relax a texel toward the fixed point from one 4-neighbour; any order of relaxations repeated
 * until nothing changes reaches it. Step 6 is one pass in a fixed schedule: labelled texels never change.
 * Both assume the texel itself is fillable; non-fillable texels never change in any fill. */
#ifndef PYR_FILL_H
#define PYR_FILL_H
#include "pyr_types.h"

/* anchor_max: labels 1..anchor_max are old and their texels anchored (0 in step 2: nothing is anchored). */
PYR_FN pyr_u32 pyr_fill_relax(pyr_u32 self_label, pyr_u32 nb_label, pyr_u32 nb_fillable, pyr_u32 anchor_max) {
    if (nb_fillable == 0u || nb_label == 0u) return self_label;
    if (self_label != 0u && self_label <= anchor_max) return self_label;
    return (self_label == 0u || nb_label < self_label) ? nb_label : self_label;
}

PYR_FN pyr_u32 pyr_fill_once(pyr_u32 self_label, pyr_u32 nb_label, pyr_u32 nb_fillable) {
    return (self_label == 0u && nb_fillable != 0u) ? nb_label : self_label;
}

/* One sweep along a line of `count` texels starting at buffer index `start`, `step` apart (step may be the
 * two's-complement of a negative stride: unsigned arithmetic wraps). Each update is visible to the next texel.
 * Needs PYR_MASK, PYR_LABEL, PYR_STORE_LABEL. Returns 1 when a label changed. once != 0 selects step 6. */
PYR_FN pyr_u32 pyr_sweep_line(PYR_CTX_PARAM, pyr_u32 start, pyr_u32 step, pyr_u32 count, pyr_u32 anchor_max,
                              pyr_u32 once) {
    pyr_u32 changed = 0u;
    pyr_u32 prev = start;
    pyr_u32 prev_label = PYR_LABEL(prev);
    pyr_u32 prev_fillable = PYR_MASK(prev);
    for (pyr_u32 n = 1u; n < count; ++n) {
        pyr_u32 i = prev + step;
        pyr_u32 fillable = PYR_MASK(i);
        pyr_u32 label = PYR_LABEL(i);
        if (fillable != 0u) {
            pyr_u32 next = once != 0u ? pyr_fill_once(label, prev_label, prev_fillable)
                                      : pyr_fill_relax(label, prev_label, prev_fillable, anchor_max);
            if (next != label) {
                PYR_STORE_LABEL(i, next);
                label = next;
                changed = 1u;
            }
        }
        prev = i;
        prev_label = label;
        prev_fillable = fillable;
    }
    return changed;
}

#endif /* PYR_FILL_H */
