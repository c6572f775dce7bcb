/* Edge labelling (step 6c), round k: a valid, non-fillable, unlabelled pixel takes the smallest label of its
 * labelled 4-neighbours that are fillable or were labelled in an earlier round (their mask holds the round, bits 2
 * and up). A round writes only such pixels, and what it writes (a label, its own round) is never read in the same
 * round, so it can run in place. Needs: PYR_MASK(i), PYR_LABEL(i) (all-levels index), PYR_VALID(p) (pixel index
 * y*w + x). */
#ifndef PYR_EDGES_H
#define PYR_EDGES_H
#include "pyr_types.h"

PYR_FN pyr_u32 pyr_edge_candidate(PYR_CTX_PARAM, pyr_u32 j, pyr_u32 round, pyr_u32 best) {
    pyr_u32 mask = PYR_MASK(j);
    pyr_u32 labelled_round = mask >> PYR_MASK_EDGE_SHIFT;
    pyr_u32 usable = (mask & PYR_MASK_FILLABLE) != 0u || (labelled_round != 0u && labelled_round < round) ? 1u : 0u;
    pyr_u32 label = usable != 0u ? PYR_LABEL(j) : 0u;
    return (label != 0u && (best == 0u || label < best)) ? label : best;
}

PYR_FN pyr_u32 pyr_edge_label(PYR_CTX_PARAM, PyrLevel level, pyr_u32 x, pyr_u32 y, pyr_u32 round) {
    pyr_u32 pixel = y * level.width + x;
    pyr_u32 i = level.offset + pixel;
    pyr_u32 own = PYR_LABEL(i);
    if ((PYR_MASK(i) & PYR_MASK_FILLABLE) != 0u || own != 0u || PYR_VALID(pixel) == 0u) return own;
    pyr_u32 best = 0u;
    if (x > 0u) best = pyr_edge_candidate(PYR_CTX_ARG, i - 1u, round, best);
    if (x + 1u < level.width) best = pyr_edge_candidate(PYR_CTX_ARG, i + 1u, round, best);
    if (y > 0u) best = pyr_edge_candidate(PYR_CTX_ARG, i - level.width, round, best);
    if (y + 1u < level.height) best = pyr_edge_candidate(PYR_CTX_ARG, i + level.width, round, best);
    return best;
}

#endif /* PYR_EDGES_H */
