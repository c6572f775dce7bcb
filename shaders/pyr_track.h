/* Tracks' overlap counts (docs/algorithm.md section 11): the pixels each pair of (previous frame's label, frame's
 * label) shares, counted in a hash table of pairs with the merge's slot claiming (shaders/pyr_merge_table.h:
 * pyr_merge_slot, PYR_UF_CAS, PYR_UF_ADD). Slot s starts at word table + PYR_TRACK_SLOT_WORDS * s; the host reads
 * the slots the frame used, skips the free ones (a first word of 0) and orders the pairs itself
 * (core/segment_tracks.cpp), so the schedule changes nothing. */
#ifndef PYR_TRACK_H
#define PYR_TRACK_H
#include "pyr_merge_table.h"

/* `count` pixels that carry the previous label j and the label k (a run of them: the counts add). */
PYR_FN void pyr_track_count(PYR_CTX_PARAM, pyr_u32 j, pyr_u32 k, pyr_u32 count, pyr_u32 table, pyr_u32 slot_mask) {
    if (j == 0u || k == 0u) return;
    pyr_u32 w = pyr_merge_slot(PYR_CTX_ARG, table, PYR_TRACK_SLOT_WORDS, slot_mask, j, k);
    if (w != PYR_MERGE_NONE) PYR_UF_ADD(w + 2u, count);
}

#endif /* PYR_TRACK_H */
