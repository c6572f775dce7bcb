/* Compaction (contract step 7): labels are marked in a table indexed by raw label, the table is turned into
 * new ids 1..K by an exclusive-then-inclusive prefix count (backend-specific), and every pixel is mapped.
 * Needs: PYR_LUT(label) -> new id. */
#ifndef PYR_COMPACT_H
#define PYR_COMPACT_H
#include "pyr_types.h"

PYR_FN pyr_u32 pyr_compact_label(PYR_CTX_PARAM, pyr_u32 raw) {
    return raw == 0u ? 0u : PYR_LUT(raw);
}

#endif /* PYR_COMPACT_H */
