/* Steps 2 and 4 (and the small-image fallback) on GPUs: the fixed point of a fill computed directly, by a concurrent
 * union-find over the 4-connected components of eligible texels (fillable, not anchored), in five dispatches whatever
 * the mask and no host synchronisation (docs/algorithm.md section 9). GPU dialects only: the CPU backend has its own
 * union-find (backends/cpu/union_find_fill.cpp). The including entry points define, over the fill scratch buffer, where
 * the level's texel k has its parent at word k and its component's minimum at word n + k: PYR_UF_LOAD(i)      a load
 * that sees other invocations' atomics (volatile / coherent); PYR_UF_STORE(i, v)  a plain store; PYR_UF_MIN(i, v)    an
 * atomic 32-bit unsigned min, returning the old value. uf_init points each texel at the start of its run in the row;
 * uf_merge joins the rows. Parents always point to a smaller index (P[k] <= k), so there are no cycles; a link is an
 * atomic min on a root, and a union whose root was linked meanwhile follows the old parent and tries again (Playne and
 * Hawick 2018; Oliveira and Lotufo 2010). Which texel ends up the root depends on the schedule; the label a component
 * takes (the minimum of its candidates) does not. */
#ifndef PYR_UF_H
#define PYR_UF_H
#include "pyr_types.h"

#define PYR_UF_NONE 0xffffffffu

PYR_FN pyr_u32 pyr_uf_eligible(pyr_u32 mask) {
    return (mask & (PYR_MASK_FILLABLE | PYR_MASK_ANCHORED)) == PYR_MASK_FILLABLE ? 1u : 0u;
}

/* The root of k's tree, without writing (links are still being made). */
PYR_FN pyr_u32 pyr_uf_root(PYR_CTX_PARAM, pyr_u32 k) {
    pyr_u32 p = PYR_UF_LOAD(k);
    while (p != k) {
        k = p;
        p = PYR_UF_LOAD(k);
    }
    return k;
}

/* Joins the trees of a and b: the larger root goes under the smaller one. */
PYR_FN void pyr_uf_union(PYR_CTX_PARAM, pyr_u32 a, pyr_u32 b) {
    for (;;) {
        a = pyr_uf_root(PYR_CTX_ARG, a);
        b = pyr_uf_root(PYR_CTX_ARG, b);
        if (a == b) return;
        if (a < b) {
            pyr_u32 t = a;
            a = b;
            b = t;
        }
        pyr_u32 old = PYR_UF_MIN(a, b);
        if (old == a) return;
        a = old; /* a was linked meanwhile: join its new parent's tree instead */
    }
}

/* Merge: texel (x, y) of the level with its eligible upper neighbour (uf_init joined each row's runs already, every
 * texel of a run under its first one). The upper union is implied, and skipped, when the left and upper-left texels
 * are eligible too: the texel is joined to its left one by its run, the left one to the upper-left one by its own
 * upper union (or, recursively, by its left one's), and the upper-left one to the upper one by their run. */
PYR_FN void pyr_uf_merge(PYR_CTX_PARAM, PyrLevel lv, pyr_u32 x, pyr_u32 y) {
    pyr_u32 k = y * lv.width + x;
    if (y == 0u || pyr_uf_eligible(PYR_MASK(lv.offset + k)) == 0u) return;
    if (pyr_uf_eligible(PYR_MASK(lv.offset + k - lv.width)) == 0u) return;
    if (x > 0u && pyr_uf_eligible(PYR_MASK(lv.offset + k - 1u)) != 0u &&
        pyr_uf_eligible(PYR_MASK(lv.offset + k - lv.width - 1u)) != 0u)
        return;
    pyr_uf_union(PYR_CTX_ARG, k, k - lv.width);
}

/* A texel's candidate label: its own when non-zero, and those of anchored 4-neighbours (contract section 5,
 * step 4); PYR_UF_NONE when there is none. */
PYR_FN pyr_u32 pyr_uf_candidate(PYR_CTX_PARAM, PyrLevel lv, pyr_u32 x, pyr_u32 y) {
    pyr_u32 i = lv.offset + y * lv.width + x;
    pyr_u32 c = PYR_LABEL(i) != 0u ? PYR_LABEL(i) : PYR_UF_NONE;
    if (x > 0u && (PYR_MASK(i - 1u) & PYR_MASK_ANCHORED) != 0u) c = min(c, PYR_LABEL(i - 1u));
    if (x + 1u < lv.width && (PYR_MASK(i + 1u) & PYR_MASK_ANCHORED) != 0u) c = min(c, PYR_LABEL(i + 1u));
    if (y > 0u && (PYR_MASK(i - lv.width) & PYR_MASK_ANCHORED) != 0u) c = min(c, PYR_LABEL(i - lv.width));
    if (y + 1u < lv.height && (PYR_MASK(i + lv.width) & PYR_MASK_ANCHORED) != 0u) c = min(c, PYR_LABEL(i + lv.width));
    return c;
}

/* Flatten (after every merge): the first texel of each run walks to its root, halving the path on the way (the
 * forest no longer changes, so plain stores of ancestors are safe), and points at it. The other texels of the run
 * still point at that first texel: merges only ever link roots, which are first texels or lone ones. */
PYR_FN void pyr_uf_flatten(PYR_CTX_PARAM, PyrLevel lv, pyr_u32 x, pyr_u32 y) {
    pyr_u32 k = y * lv.width + x;
    if (pyr_uf_eligible(PYR_MASK(lv.offset + k)) == 0u) return;
    if (x > 0u && pyr_uf_eligible(PYR_MASK(lv.offset + k - 1u)) != 0u) return; /* not the first of its run */
    pyr_u32 r = k;
    pyr_u32 p = PYR_UF_LOAD(r);
    while (p != r) {
        pyr_u32 gp = PYR_UF_LOAD(p);
        if (gp != p) PYR_UF_STORE(r, gp);
        r = gp;
        p = PYR_UF_LOAD(r);
    }
    PYR_UF_STORE(k, r);
}

/* Resolve (after flatten): the texel's root is two steps away at most (its run's first texel, then the root); the
 * texel points at it, and its candidate goes into the root's minimum. */
PYR_FN void pyr_uf_resolve(PYR_CTX_PARAM, PyrLevel lv, pyr_u32 n, pyr_u32 x, pyr_u32 y) {
    pyr_u32 k = y * lv.width + x;
    if (pyr_uf_eligible(PYR_MASK(lv.offset + k)) == 0u) return;
    pyr_u32 r = PYR_UF_LOAD(PYR_UF_LOAD(k));
    PYR_UF_STORE(k, r);
    pyr_u32 c = pyr_uf_candidate(PYR_CTX_ARG, lv, x, y);
    if (c != PYR_UF_NONE && c < PYR_UF_LOAD(n + r)) PYR_UF_MIN(n + r, c);
}

#endif /* PYR_UF_H */
