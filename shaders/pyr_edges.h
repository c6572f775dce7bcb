/* Edge labelling (step 6c), round k: a valid, non-fillable, unlabelled pixel takes the smallest label of its
 * labelled 4-neighbours that are fillable or were labelled in an earlier round (their mask holds the round, bits 2
 * and up); in rounds k >= 2 with a depth step share s > 0, only of those whose depth differs from its own by at most
 * s times it. A round writes only such pixels, and what it writes (a label, its own round) is never read in the same
 * round, so it can run in place. Needs: PYR_MASK(i), PYR_LABEL(i) (all-levels index), PYR_VALID(p) and, with s > 0,
 * PYR_QZ(p) (pixel index y*w + x). */
#ifndef PYR_EDGES_H
#define PYR_EDGES_H
#include "pyr_types.h"

/* Whether neighbour depth zq lies within s * zp of zp: two correctly rounded float operations. */
PYR_FN pyr_u32 pyr_edge_depth_near(pyr_f32 zp, pyr_f32 zq, pyr_f32 s) {
    PYR_PRECISE pyr_f32 dz = PYR_FABS(zp - zq);
    PYR_PRECISE pyr_f32 limit = s * zp;
    return dz <= limit ? 1u : 0u;
}

PYR_FN pyr_u32 pyr_edge_candidate(PYR_CTX_PARAM, pyr_u32 j, pyr_u32 round, pyr_u32 best) {
    pyr_u32 mask = PYR_MASK(j);
    pyr_u32 labelled_round = mask >> PYR_MASK_EDGE_SHIFT;
    pyr_u32 usable = (mask & PYR_MASK_FILLABLE) != 0u || (labelled_round != 0u && labelled_round < round) ? 1u : 0u;
    pyr_u32 label = usable != 0u ? PYR_LABEL(j) : 0u;
    return (label != 0u && (best == 0u || label < best)) ? label : best;
}

/* pyr_edge_candidate for the neighbour at pixel index q (all-levels index j), with the depth test when s > 0. */
PYR_FN pyr_u32 pyr_edge_candidate_near(PYR_CTX_PARAM, pyr_u32 j, pyr_u32 q, pyr_u32 round, pyr_u32 best, pyr_f32 zp,
                                       pyr_f32 s) {
    if (s > 0.0f && pyr_edge_depth_near(zp, PYR_QZ(q), s) == 0u) return best;
    return pyr_edge_candidate(PYR_CTX_ARG, j, round, best);
}

/* depth_step: s, the depth test's share in rounds >= 2 (0: none). */
PYR_FN pyr_u32 pyr_edge_label(PYR_CTX_PARAM, PyrLevel level, pyr_u32 x, pyr_u32 y, pyr_u32 round, pyr_f32 depth_step) {
    pyr_u32 pixel = y * level.width + x;
    pyr_u32 i = level.offset + pixel;
    pyr_u32 own = PYR_LABEL(i);
    if ((PYR_MASK(i) & PYR_MASK_FILLABLE) != 0u || own != 0u || PYR_VALID(pixel) == 0u) return own;
    pyr_f32 s = round >= 2u ? depth_step : 0.0f;
    pyr_f32 zp = s > 0.0f ? PYR_QZ(pixel) : 0.0f;
    pyr_u32 w = level.width;
    pyr_u32 best = 0u;
    if (x > 0u) best = pyr_edge_candidate_near(PYR_CTX_ARG, i - 1u, pixel - 1u, round, best, zp, s);
    if (x + 1u < w) best = pyr_edge_candidate_near(PYR_CTX_ARG, i + 1u, pixel + 1u, round, best, zp, s);
    if (y > 0u) best = pyr_edge_candidate_near(PYR_CTX_ARG, i - w, pixel - w, round, best, zp, s);
    if (y + 1u < level.height) best = pyr_edge_candidate_near(PYR_CTX_ARG, i + w, pixel + w, round, best, zp, s);
    return best;
}

#endif /* PYR_EDGES_H */
