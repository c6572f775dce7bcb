/* Types and constants shared by host code (core/) and every pass. */
#ifndef PYR_TYPES_H
#define PYR_TYPES_H
#include "pyr_shim.h"

/* One pyramid level: its size and where its texels start in the all-levels buffers. A new label for the texel
 * at buffer index i is i + 1 (contract section 4), since the buffers use the labels' offsets. */
PYR_TYPEDEF(PyrLevel)
struct PyrLevel {
    pyr_u32 width;
    pyr_u32 height;
    pyr_u32 offset;
};

/* A level from its size and offset (GLSL has no brace initialisers for structs in every version). */
PYR_FN PyrLevel pyr_level(pyr_u32 width, pyr_u32 height, pyr_u32 offset) {
    PyrLevel lv;
    lv.width = width;
    lv.height = height;
    lv.offset = offset;
    return lv;
}

PYR_TYPEDEF(PyrFVec3)
struct PyrFVec3 {
    pyr_f32 x;
    pyr_f32 y;
    pyr_f32 z;
};

PYR_TYPEDEF(PyrIVec3)
struct PyrIVec3 {
    pyr_i32 x;
    pyr_i32 y;
    pyr_i32 z;
};

PYR_FN PyrIVec3 pyr_ivec3_zero() {
    PyrIVec3 v;
    v.x = 0;
    v.y = 0;
    v.z = 0;
    return v;
}

/* One pixel's share of the robust normals' windows (docs/algorithm.md section 8b): its fixed-point depth G(z) (-1
 * when the point is not point-valid) and its tangents, bit 0 of `tangents` when t_h exists, bit 1 when t_v does. */
/* The words of a texel in a GPU buffer (shaders/pyr_robust.h: pyr_robust_texel_store). */
#define PYR_TEXEL_WORDS 8u
PYR_TYPEDEF(PyrRobustTexel)
struct PyrRobustTexel {
    pyr_i32 gz;
    pyr_u32 tangents;
    PyrIVec3 th;
    PyrIVec3 tv;
};

/* The robust metric's curvature pairs across a pixel (docs/algorithm.md section 2b): the sum S of the dot products of
 * their normals and their count kp. */
PYR_TYPEDEF(PyrCurvaturePairs)
struct PyrCurvaturePairs {
    pyr_i32 sum;
    pyr_i32 count;
};

/* A quantized pixel: validity and qn (contract section 2). */
PYR_TYPEDEF(PyrQuant)
struct PyrQuant {
    pyr_i32 qx;
    pyr_i32 qy;
    pyr_i32 qz;
    pyr_u32 valid;
};

/* Normals are quantized to multiples of 2^-13. */
#define PYR_NORMAL_SCALE 8192.0f
#define PYR_NORMAL_UNIT 0.0001220703125f /* 2^-13, exact */

/* The GPU backends keep a quantized pixel in two words: qx and qy, then qz and validity, 16 bits each (a component
 * lies in -8192..8192, pyr_quantize_component). Half the bytes of four int32, and a 4128 x 3088 frame's quantized
 * normals fit in one 128 MiB storage buffer. Sign extension by arithmetic, not by shifting a negative int. */
PYR_FN pyr_u32 pyr_pack_q16(pyr_i32 lo, pyr_i32 hi) {
    return (PYR_U32(lo) & 0xffffu) | ((PYR_U32(hi) & 0xffffu) << 16u);
}
PYR_FN pyr_i32 pyr_unpack_q16(pyr_u32 half_word) {
    return PYR_I32((half_word & 0xffffu) ^ 0x8000u) - 32768;
}

/* Mask bits of a texel. Only the fill at level N-1 (step 4) sets the anchor bit. */
#define PYR_MASK_FILLABLE 1u
#define PYR_MASK_ANCHORED 2u
/* Level N only: the round of step 6c that labelled an edge pixel, 1..63, in bits 2..7 (0: none). */
#define PYR_MASK_EDGE_SHIFT 2u

/* Compaction's scan numbers the label table in chunks of this many entries, one invocation per chunk
 * (shaders/pyr_scan.h; core/plan.hpp sizes the table and the chunk sums once for every backend). */
#define PYR_SCAN_CHUNK 1024u

/* Per-segment statistics (docs/algorithm.md section 10): one slot of PYR_STATS_WORDS uint32 words per compacted
 * label, slot K-1 for label K, zeroed before the pass. Bounding-box minima are kept as the maximum of their
 * complement, so that zero is the neutral start of every word and the pass needs only atomic add and max. Sums
 * are 64-bit two's complement in two words (96-bit in three for the products), low word first. */
#define PYR_STATS_COUNT 0u
#define PYR_STATS_NOT_X_MIN 1u
#define PYR_STATS_NOT_Y_MIN 2u
#define PYR_STATS_X_MAX 3u
#define PYR_STATS_Y_MAX 4u
#define PYR_STATS_RAW_LABEL 5u
#define PYR_STATS_POINT_SUM 6u   /* x, y, z: 6 words, sums of rint(p * 2^point_shift) */
#define PYR_STATS_NORMAL_SUM 12u /* x, y, z: 6 words, sums of qn */
/* The fixed-point z's range, as the maxima of its order-preserving key (the int32's bits with the sign bit
 * flipped) and of the key's complement. */
#define PYR_STATS_Z_KEY_MAX 18u
#define PYR_STATS_NOT_Z_KEY_MIN 19u
/* xx, xy, xz, yy, yz, zz: 18 words, sums of the products of the fixed-point coordinates, each 96-bit two's
 * complement in three words (a product is below 2^62 in magnitude, a frame has fewer than 2^32 pixels). */
#define PYR_STATS_PRODUCT_SUM 20u
/* The fillable pixels, over which the sums of points, normals and products and the depth range run. */
#define PYR_STATS_FILLABLE_COUNT 38u
#define PYR_STATS_WORDS 39u

/* The merge's pair table on GPUs (shaders/pyr_merge_table.h): words per slot. */
#define PYR_MERGE_SLOT_WORDS 4u
/* The kind of boundary a crossing shows (shaders/pyr_merge.h: pyr_merge_pair_kind; docs/algorithm.md sections 5b
 * and 10d): flat (each side within the tolerance of the other's tangent plane), convex (neither side above the
 * other's plane, one clearly below it), concave (one side clearly above the other's plane, neither clearly below) or
 * a depth step (one clearly above and the other clearly below, or too far apart). The merge's good crossings are the
 * flat and convex ones. */
#define PYR_BOUNDARY_FLAT 0u
#define PYR_BOUNDARY_CONVEX 1u
#define PYR_BOUNDARY_CONCAVE 2u
#define PYR_BOUNDARY_STEP 3u
/* The segment graph's pair table (shaders/pyr_graph.h, docs/algorithm.md section 10d): words per slot, and where
 * each word is: the pair's smaller and larger label (as in the output; 0: a free slot), its crossings, and its
 * crossings of each kind (PYR_BOUNDARY_*, shaders/pyr_merge.h; zero for a caller's mask). */
#define PYR_GRAPH_SLOT_WORDS 7u
#define PYR_GRAPH_LENGTH 2u
#define PYR_GRAPH_KINDS 3u
/* The tracks' pair table (shaders/pyr_track.h, docs/algorithm.md section 11): words per slot: the previous
 * frame's label and the frame's (0: a free slot), and the pixels they share. */
#define PYR_TRACK_SLOT_WORDS 3u
/* After the table (at its largest): a header of PYR_TRACK_HEADER_WORDS words, then the pairs gathered from the table
 * (PYR_TRACK_SLOT_WORDS words each, at most one per pixel): the frame's number in its stream, K', K, and how many
 * pairs were gathered. */
#define PYR_TRACK_HEADER_WORDS 4u
#define PYR_TRACK_FRAME 0u
#define PYR_TRACK_PREVIOUS_COUNT 1u
#define PYR_TRACK_COUNT 2u
#define PYR_TRACK_PAIRS 3u
/* The statistics pass walks rows in runs of this many pixels, one invocation per run. */
#define PYR_STATS_RUN 32u
/* Points are clamped to +-(2^31 - 128), the largest float magnitude below 2^31, before rounding to int32. */
#define PYR_STATS_POINT_LIMIT 2147483520.0f

/* Label init modes (contract section 5). */
#define PYR_INIT_NEW 0u         /* steps 1: parent's label, else a new one */
#define PYR_INIT_INHERIT 1u     /* steps 3 and 5: parent's label, maybe 0 */
#define PYR_INIT_PIXEL_INDEX 2u /* tiny-image fallback: 1 + the pixel's own index */

/* The segment graph's slots for K segments: the smallest power of two above twice the 3 K + 3 pairs they can have
 * (core/plan.cpp), at most max_slots (the plan's, for the largest K). Every backend sizes its table with it once K
 * is known, so a frame's table costs what its segments need. */
PYR_FN pyr_u32 pyr_graph_slots(pyr_u32 count, pyr_u32 max_slots) {
    pyr_u32 slots = 1u;
    while (slots < max_slots && slots <= 6u * count + 6u) slots = slots * 2u;
    return slots;
}

/* The tracks' slots for a frame of K segments after one of K' (docs/algorithm.md section 11): the smallest power of
 * two above twice the K' K pairs they can have, at most max_slots (the plan's, above twice the pixels, which bound
 * the pairs too). */
PYR_FN pyr_u32 pyr_track_slots(pyr_u32 previous_count, pyr_u32 count, pyr_u32 max_slots) {
    pyr_u32 limit = max_slots / 2u;
    pyr_u32 pairs = limit;
    if (previous_count == 0u || count <= limit / previous_count) pairs = previous_count * count;
    pyr_u32 slots = 1u;
    while (slots < max_slots && slots <= 2u * pairs) slots = slots * 2u;
    return slots;
}

#endif /* PYR_TYPES_H */
