/* Step 0c, the colour edge term (docs/algorithm.md section 2c): with a colour image registered to the depth, a pixel
 * whose two neighbours `stride` pixels before and after it along its row, or along its column, differ in colour by
 * more than the threshold is not fillable, whatever the metric says. The difference of two colours is the sum of the
 * absolute differences of their R, G and B (0..765): integers only.
 * With a curvature gate, a colour edge counts only where the normals across the pixel show a crease.
 * Needs: PYR_RGB_AT(x, y, w), the colour of pixel (x, y) as 0x00BBGGRR, and what pyr_robust.h's curvature pairs
 * need. A GPU dialect that defines PYR_COLOR_WORD(j), the j-th word of the frame's colour bytes packed row by row
 * (3 bytes a pixel, little-endian words), gets PYR_RGB_AT from here. */
#ifndef PYR_COLOR_H
#define PYR_COLOR_H
#include "pyr_robust.h"
#include "pyr_types.h"

#define PYR_COLOR_DIFFERENCE_MAX 765u

#ifdef PYR_COLOR_WORD
/* The colour of pixel i from the packed bytes: its three bytes start at byte 3i, in one word or across two. */
PYR_FN pyr_u32 pyr_color_packed(PYR_CTX_PARAM, pyr_u32 i) {
    pyr_u32 k = 3u * i;
    pyr_u32 shift = (k & 3u) * 8u;
    pyr_u32 rgb = PYR_COLOR_WORD(k >> 2u) >> shift;
    if (shift > 8u) rgb = rgb | (PYR_COLOR_WORD((k + 2u) >> 2u) << (32u - shift));
    return rgb & 0xffffffu;
}
#define PYR_RGB_AT(x, y, w) pyr_color_packed(PYR_CTX_ARG, (y) * (w) + (x))
#endif

PYR_FN pyr_u32 pyr_color_channel_difference(pyr_u32 a, pyr_u32 b, pyr_u32 shift) {
    pyr_u32 ca = (a >> shift) & 0xffu;
    pyr_u32 cb = (b >> shift) & 0xffu;
    return ca > cb ? ca - cb : cb - ca;
}

/* |R_a - R_b| + |G_a - G_b| + |B_a - B_b|. */
PYR_FN pyr_u32 pyr_color_difference(pyr_u32 a, pyr_u32 b) {
    return pyr_color_channel_difference(a, b, 0u) + pyr_color_channel_difference(a, b, 8u) +
           pyr_color_channel_difference(a, b, 16u);
}

/* 1 if pixel (x, y) of a w x h frame is a colour edge: along x or along y, both neighbours `stride` pixels away lie in
 * the image and their colours differ by more than `threshold`; 0 if not. */
PYR_FN pyr_u32 pyr_color_edge(PYR_CTX_PARAM, pyr_u32 w, pyr_u32 h, pyr_u32 x, pyr_u32 y, pyr_u32 stride,
                              pyr_u32 threshold) {
    if (x >= stride && x + stride < w &&
        pyr_color_difference(PYR_RGB_AT(x - stride, y, w), PYR_RGB_AT(x + stride, y, w)) > threshold) {
        return 1u;
    }
    if (y >= stride && y + stride < h &&
        pyr_color_difference(PYR_RGB_AT(x, y - stride, w), PYR_RGB_AT(x, y + stride, w)) > threshold) {
        return 1u;
    }
    return 0u;
}

/* The curvature gate (section 2c): 1 if the colour edge at fillable pixel (x, y) counts. With gate G = 0 every colour
 * edge counts; else only where the pixel fails section 2b's curvature test with the limit Lg = floor(L * G / 256),
 * L its own limit: a crease, however weak. (L >> 8) * G <= 2^21 * 2^8: exact in 32 bits. */
PYR_FN pyr_u32 pyr_color_edge_counts(PYR_CTX_PARAM, pyr_u32 w, pyr_u32 h, pyr_u32 x, pyr_u32 y, pyr_u32 gate,
                                     pyr_u32 curvature_stride, pyr_f32 curvature_base, pyr_f32 curvature_growth) {
    if (gate == 0u) return 1u;
    pyr_i32 limit = pyr_robust_curvature_limit(PYR_QZ(y * w + x), curvature_base, curvature_growth);
    pyr_i32 gated = (limit >> 8) * PYR_I32(gate) + (((limit & 255) * PYR_I32(gate)) >> 8);
    PyrCurvaturePairs pairs = pyr_robust_curvature_pairs(PYR_CTX_ARG, w, h, x, y, curvature_stride);
    return pyr_robust_curvature_passes(pairs, gated) == 0u ? 1u : 0u;
}

#endif /* PYR_COLOR_H */
