/* Step 6d on GPUs (docs/algorithm.md section 9): each boundary crossing counted into a hash table of label pairs in
 * the fill scratch buffer, then the pairs that join united over the labels, in five dispatches whatever the frame.
 * The CPU backend counts and unites on the host (backends/cpu/cpu_merge.cpp). Layout of the fill buffer: word l,
 * for l < lut_size, is label l's parent; from word `table` on, slot s holds 4 words: the pair's smaller label (0: a
 * free slot), its larger one, and its good and bad crossings. The includer defines, besides pyr_uf.h's accessors,
 * PYR_UF_CAS(i, expected, v) (an atomic 32-bit compare-and-swap, evaluating to the old value) and PYR_UF_ADD(i, v)
 * (an atomic add). */
#ifndef PYR_MERGE_TABLE_H
#define PYR_MERGE_TABLE_H
#include "pyr_merge.h"
#include "pyr_uf.h"

PYR_FN pyr_u32 pyr_merge_hash(pyr_u32 a, pyr_u32 b) {
    pyr_u32 h = (a * 0x9e3779b1u) ^ (b * 0x85ebca77u);
    return h ^ (h >> 15u);
}

/* The first word of pair (a, b)'s slot (a < b) in a table of `stride` words a slot, claimed if the pair has none
 * yet (the segment graph's table, shaders/pyr_graph.h, is another). Every invocation with the pair
 * walks the same probe sequence and stops at the first slot that holds the pair or that it claims; a slot's words
 * are set once, by compare-and-swap from 0, and whoever sets a slot's first word goes on to its second, so no
 * invocation passes a slot that ends up holding its pair: one pair, one slot, whatever the schedule. The table has
 * more than twice as many slots as a frame can have pairs (core/plan.cpp), so a free slot always comes. */
PYR_FN pyr_u32 pyr_merge_slot(PYR_CTX_PARAM, pyr_u32 table, pyr_u32 stride, pyr_u32 slot_mask, pyr_u32 a, pyr_u32 b) {
    pyr_u32 s = pyr_merge_hash(a, b) & slot_mask;
    for (pyr_u32 probe = 0u; probe <= slot_mask; ++probe) {
        pyr_u32 w = table + stride * s;
        pyr_u32 first = PYR_UF_CAS(w, 0u, a);
        if (first == 0u || first == a) {
            pyr_u32 second = PYR_UF_CAS(w + 1u, 0u, b);
            if (second == 0u || second == b) return w;
        }
        s = (s + 1u) & slot_mask;
    }
    return PYR_MERGE_NONE;
}

/* Slot s of a table of `stride` words a slot (after every count): a pair it holds is appended to the list at word
 * `list`, word `counter` counting them (the list's order depends on the schedule; the host sorts it). */
PYR_FN void pyr_slot_gather(PYR_CTX_PARAM, pyr_u32 table, pyr_u32 stride, pyr_u32 s, pyr_u32 list, pyr_u32 counter) {
    pyr_u32 w = table + stride * s;
    if (PYR_UF_LOAD(w) == 0u) return;
    pyr_u32 to = list + stride * PYR_UF_ADD(counter, 1u);
    for (pyr_u32 k = 0u; k < stride; ++k) PYR_UF_STORE(to + k, PYR_UF_LOAD(w + k));
}

/* Pixel (x, y) of level N: its crossings to the right and downwards, each counted in its pair's slot. */
PYR_FN void pyr_merge_count(PYR_CTX_PARAM, PyrLevel lv, pyr_u32 x, pyr_u32 y, pyr_u32 reach, pyr_f32 scale,
                            pyr_f32 tolerance_base, pyr_f32 tolerance_growth, pyr_u32 table, pyr_u32 slot_mask) {
    for (pyr_u32 down = 0u; down < 2u; ++down) {
        pyr_u32 good =
            pyr_merge_crossing(PYR_CTX_ARG, lv, x, y, 1u - down, down, reach, scale, tolerance_base, tolerance_growth);
        if (good == PYR_MERGE_NONE) continue;
        pyr_u32 a = PYR_LABEL(lv.offset + y * lv.width + x);
        pyr_u32 b = PYR_LABEL(lv.offset + (y + down) * lv.width + x + 1u - down);
        pyr_u32 w = pyr_merge_slot(PYR_CTX_ARG, table, PYR_MERGE_SLOT_WORDS, slot_mask, a < b ? a : b, a < b ? b : a);
        if (w != PYR_MERGE_NONE) PYR_UF_ADD(w + (good != 0u ? 2u : 3u), 1u);
    }
}

/* Slot s (after every crossing is counted): a pair that joins unites its labels' trees. */
PYR_FN void pyr_merge_link(PYR_CTX_PARAM, pyr_u32 table, pyr_u32 s, pyr_u32 min_crossings, pyr_u32 share) {
    pyr_u32 w = table + PYR_MERGE_SLOT_WORDS * s;
    pyr_u32 a = PYR_UF_LOAD(w);
    if (a == 0u) return;
    if (pyr_merge_joins(PYR_UF_LOAD(w + 2u), PYR_UF_LOAD(w + 3u), min_crossings, share) == 0u) return;
    pyr_uf_union(PYR_CTX_ARG, a, PYR_UF_LOAD(w + 1u));
}

#endif /* PYR_MERGE_TABLE_H */
