/* Fill passes (contract section 5).
 * Steps 2 and 4 relax a texel toward the fixed point from one 4-neighbour; any order of relaxations repeated
 * until nothing changes reaches it. Step 6 is one pass in a fixed schedule: labelled texels never change.
 * Both assume the texel itself is fillable; non-fillable texels never change in any fill. */
#ifndef PYR_FILL_H
#define PYR_FILL_H
#include "pyr_types.h"

/* Step 4 anchors are fixed by the labels after step 3, not by labels adopted during the fill (a texel that has
 * just taken an old label must still take a smaller one): a fillable texel whose label is old (1..anchor_max) gets
 * PYR_MASK_ANCHORED in its mask before the fill starts. Returns the texel's new mask value. */
PYR_FN pyr_u32 pyr_anchor_mask(pyr_u32 mask, pyr_u32 label, pyr_u32 anchor_max) {
    return ((mask & PYR_MASK_FILLABLE) != 0u && label != 0u && label <= anchor_max) ? (mask | PYR_MASK_ANCHORED) : mask;
}

PYR_FN pyr_u32 pyr_fill_relax(pyr_u32 self_label, pyr_u32 self_mask, pyr_u32 nb_label, pyr_u32 nb_mask) {
    if ((self_mask & PYR_MASK_ANCHORED) != 0u) return self_label;
    if ((nb_mask & PYR_MASK_FILLABLE) == 0u || nb_label == 0u) return self_label;
    return (self_label == 0u || nb_label < self_label) ? nb_label : self_label;
}

PYR_FN pyr_u32 pyr_fill_once(pyr_u32 self_label, pyr_u32 nb_label, pyr_u32 nb_mask) {
    return (self_label == 0u && (nb_mask & PYR_MASK_FILLABLE) != 0u) ? nb_label : self_label;
}

/* One update of a fillable texel from the neighbour before it in a sweep: step 6 (once != 0) or steps 2 and 4. */
PYR_FN pyr_u32 pyr_fill_step(pyr_u32 self_label, pyr_u32 self_mask, pyr_u32 nb_label, pyr_u32 nb_mask, pyr_u32 once) {
    return once != 0u ? pyr_fill_once(self_label, nb_label, nb_mask)
                      : pyr_fill_relax(self_label, self_mask, nb_label, nb_mask);
}

/* One sweep along a line of `count` texels starting at buffer index `start`, `step` apart (step may be the
 * two's-complement of a negative stride: unsigned arithmetic wraps). Each update is visible to the next texel.
 * Needs PYR_MASK, PYR_LABEL, PYR_STORE_LABEL. Returns 1 when a label changed. once != 0 selects step 6. */
PYR_FN pyr_u32 pyr_sweep_line(PYR_CTX_PARAM, pyr_u32 start, pyr_u32 step, pyr_u32 count, pyr_u32 once) {
    pyr_u32 changed = 0u;
    pyr_u32 prev = start;
    pyr_u32 prev_label = PYR_LABEL(prev);
    pyr_u32 prev_mask = PYR_MASK(prev);
    for (pyr_u32 n = 1u; n < count; ++n) {
        pyr_u32 i = prev + step;
        pyr_u32 mask = PYR_MASK(i);
        pyr_u32 label = PYR_LABEL(i);
        if ((mask & PYR_MASK_FILLABLE) != 0u) {
            pyr_u32 next = pyr_fill_step(label, mask, prev_label, prev_mask, once);
            if (next != label) {
                PYR_STORE_LABEL(i, next);
                label = next;
                changed = 1u;
            }
        }
        prev = i;
        prev_label = label;
        prev_mask = mask;
    }
    return changed;
}

/* Row y of a level, there and back (left to right, then right to left). Returns 1 when a label changed. */
PYR_FN pyr_u32 pyr_sweep_row(PYR_CTX_PARAM, PyrLevel lv, pyr_u32 y, pyr_u32 once) {
    pyr_u32 start = lv.offset + y * lv.width;
    pyr_u32 changed = pyr_sweep_line(PYR_CTX_ARG, start, 1u, lv.width, once);
    changed |= pyr_sweep_line(PYR_CTX_ARG, start + lv.width - 1u, 0xffffffffu, lv.width, once);
    return changed;
}

/* Column x of a level, there and back (down, then up). Returns 1 when a label changed. */
PYR_FN pyr_u32 pyr_sweep_column(PYR_CTX_PARAM, PyrLevel lv, pyr_u32 x, pyr_u32 once) {
    pyr_u32 changed = pyr_sweep_line(PYR_CTX_ARG, lv.offset + x, lv.width, lv.height, once);
    changed |= pyr_sweep_line(PYR_CTX_ARG, lv.offset + (lv.height - 1u) * lv.width + x, 0u - lv.width, lv.height, once);
    return changed;
}

#endif /* PYR_FILL_H */
