/* The numbering step of compaction (contract step 7) on a device, in chunks of the label table run in parallel:
 * count the marked entries of each chunk, scan the counts on one invocation (backend code), then number each
 * chunk's marks from its scanned start, in table order, so new ids follow the order of raw labels.
 * Needs: PYR_LUT(l), and PYR_STORE_LUT(l, v) for pyr_number_marks. */
#ifndef PYR_SCAN_H
#define PYR_SCAN_H
#include "pyr_types.h"

/* How many entries in [begin, end) of the table are marked (non-zero). */
PYR_FN pyr_u32 pyr_count_marks(PYR_CTX_PARAM, pyr_u32 begin, pyr_u32 end) {
    pyr_u32 n = 0u;
    for (pyr_u32 i = begin; i < end; ++i) n += PYR_LUT(i) != 0u ? 1u : 0u;
    return n;
}

/* Gives the marked entries in [begin, end) the ids first_id + 1, first_id + 2, ... in order. */
PYR_FN void pyr_number_marks(PYR_CTX_PARAM, pyr_u32 begin, pyr_u32 end, pyr_u32 first_id) {
    pyr_u32 id = first_id;
    for (pyr_u32 i = begin; i < end; ++i) {
        if (PYR_LUT(i) != 0u) {
            ++id;
            PYR_STORE_LUT(i, id);
        }
    }
}

#endif /* PYR_SCAN_H */
