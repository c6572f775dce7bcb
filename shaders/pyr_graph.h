/* The segment graph (docs/algorithm.md section 10d): every boundary crossing between two segments of the final
 * labels counted in a hash table of label pairs, by kind of boundary (shaders/pyr_merge.h: the merge's own evidence),
 * then the pairs gathered into a dense list. The table and list live in the fill scratch buffer on GPUs (which
 * nothing needs after the merge) and in a vector of their own on the CPU; the accessors are the merge's
 * (shaders/pyr_merge_table.h: PYR_UF_LOAD, PYR_UF_STORE, PYR_UF_CAS, PYR_UF_ADD), and PYR_LUT for the compacted
 * labels. Layout: word `counter` counts the pairs gathered, slot s of the table starts at word table +
 * PYR_GRAPH_SLOT_WORDS * s, and pair i of the list at word list + PYR_GRAPH_SLOT_WORDS * i. The list's order
 * depends on the schedule; the host sorts it (core/segment_graph.cpp). */
#ifndef PYR_GRAPH_H
#define PYR_GRAPH_H
#include "pyr_compact.h"
#include "pyr_merge_table.h"

/* Pixel (x, y) of level N: its crossings to the right and downwards, each counted in its pair's slot, the pair
 * named by the labels of the output (compacted when `apply`). with_points: 0 for a caller's mask, whose crossings
 * have no kind. */
PYR_FN void pyr_graph_count(PYR_CTX_PARAM, PyrLevel lv, pyr_u32 x, pyr_u32 y, pyr_u32 with_points, pyr_u32 apply,
                            pyr_u32 reach, pyr_f32 scale, pyr_f32 tolerance_base, pyr_f32 tolerance_growth,
                            pyr_u32 table, pyr_u32 slot_mask) {
    for (pyr_u32 down = 0u; down < 2u; ++down) {
        pyr_u32 qx = x + 1u - down;
        pyr_u32 qy = y + down;
        if (qx >= lv.width || qy >= lv.height) continue;
        pyr_u32 a = PYR_LABEL(lv.offset + y * lv.width + x);
        pyr_u32 b = PYR_LABEL(lv.offset + qy * lv.width + qx);
        if (a == 0u || b == 0u || a == b) continue;
        pyr_u32 kind = PYR_MERGE_NONE;
        if (with_points != 0u) {
            kind = pyr_merge_crossing_kind(PYR_CTX_ARG, lv, x, y, 1u - down, down, reach, scale, tolerance_base,
                                           tolerance_growth);
        }
        if (apply != 0u) {
            a = pyr_compact_label(PYR_CTX_ARG, a);
            b = pyr_compact_label(PYR_CTX_ARG, b);
        }
        pyr_u32 w = pyr_merge_slot(PYR_CTX_ARG, table, PYR_GRAPH_SLOT_WORDS, slot_mask, a < b ? a : b, a < b ? b : a);
        if (w == PYR_MERGE_NONE) continue;
        PYR_UF_ADD(w + PYR_GRAPH_LENGTH, 1u);
        if (kind != PYR_MERGE_NONE) PYR_UF_ADD(w + PYR_GRAPH_KINDS + kind, 1u);
    }
}

/* Slot s (after every crossing is counted): a pair it holds is appended to the list. */
PYR_FN void pyr_graph_gather(PYR_CTX_PARAM, pyr_u32 table, pyr_u32 s, pyr_u32 list, pyr_u32 counter) {
    pyr_slot_gather(PYR_CTX_ARG, table, PYR_GRAPH_SLOT_WORDS, s, list, counter);
}

#endif /* PYR_GRAPH_H */
