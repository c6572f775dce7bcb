/* Tracks' overlap counts (docs/algorithm.md section 11): the pixels each pair of (previous frame's label, frame's
 * label) shares, counted in a hash table of pairs with the merge's slot claiming (shaders/pyr_merge_table.h:
 * pyr_merge_slot, PYR_UF_LOAD, PYR_UF_STORE, PYR_UF_CAS, PYR_UF_ADD), then the pairs gathered into a dense list.
 * Layout: word `counter` counts the pairs gathered, slot s of the table starts at word table +
 * PYR_TRACK_SLOT_WORDS * s, and pair i of the list at word list + PYR_TRACK_SLOT_WORDS * i. The list's order
 * depends on the schedule; the host sorts it (core/segment_tracks.cpp). */
#ifndef PYR_TRACK_H
#define PYR_TRACK_H
#include "pyr_merge_table.h"

/* `count` pixels that carry the previous label j and the label k (a run of them: the counts add). */
PYR_FN void pyr_track_count(PYR_CTX_PARAM, pyr_u32 j, pyr_u32 k, pyr_u32 count, pyr_u32 table, pyr_u32 slot_mask) {
    if (j == 0u || k == 0u) return;
    pyr_u32 w = pyr_merge_slot(PYR_CTX_ARG, table, PYR_TRACK_SLOT_WORDS, slot_mask, j, k);
    if (w != PYR_MERGE_NONE) PYR_UF_ADD(w + 2u, count);
}

/* Slot s (after every pixel is counted): a pair it holds is appended to the list. */
PYR_FN void pyr_track_gather(PYR_CTX_PARAM, pyr_u32 table, pyr_u32 s, pyr_u32 list, pyr_u32 counter) {
    pyr_u32 w = table + PYR_TRACK_SLOT_WORDS * s;
    if (PYR_UF_LOAD(w) == 0u) return;
    pyr_u32 to = list + PYR_TRACK_SLOT_WORDS * PYR_UF_ADD(counter, 1u);
    for (pyr_u32 i = 0u; i < PYR_TRACK_SLOT_WORDS; ++i) PYR_UF_STORE(to + i, PYR_UF_LOAD(w + i));
}

#endif /* PYR_TRACK_H */
