/* Step 6d, the merge (docs/algorithm.md section 5b): every crossing of a boundary between two segments of level N
 * is measured on the pixels up to `reach` steps each side of it, and is good (convex or flat: each side lies at
 * most the tolerance above the other's tangent plane) or bad (a concave crease or a depth step). Integers decide;
 * the only float operations are correctly rounded ones (scale, clamp, multiply, add, compare).
 * Needs: PYR_LABEL(i) (the all-levels labels), PYR_PT(x, y, c), PYR_QN(i, c). */
#ifndef PYR_MERGE_H
#define PYR_MERGE_H
#include "pyr_normals.h"
#include "pyr_robust.h"
#include "pyr_types.h"

#define PYR_MERGE_SPAN_LIMIT 65536         /* 2^16 fixed-point steps: a pair farther apart is a step */
#define PYR_MERGE_TOLERANCE_MAX 1073741824 /* 2^30 */
#define PYR_MERGE_NONE 0xffffffffu         /* pyr_merge_crossing: no crossing */

/* How many steps, 0..reach-1, the side of label l reaches from pixel (x, y) along (dx, dy) through pixels that
 * carry l. */
PYR_FN pyr_i32 pyr_merge_reach(PYR_CTX_PARAM, PyrLevel lv, pyr_i32 x, pyr_i32 y, pyr_i32 dx, pyr_i32 dy, pyr_u32 l,
                               pyr_u32 reach) {
    pyr_i32 k = 0;
    while (PYR_U32(k) + 1u < reach) {
        pyr_i32 nx = x + (k + 1) * dx;
        pyr_i32 ny = y + (k + 1) * dy;
        if (nx < 0 || ny < 0 || nx >= PYR_I32(lv.width) || ny >= PYR_I32(lv.height)) break;
        if (PYR_LABEL(lv.offset + PYR_U32(ny) * lv.width + PYR_U32(nx)) != l) break;
        ++k;
    }
    return k;
}

/* The quantized normal of pixel (x, y), turned toward the camera at the origin (section 8, step 5). */
PYR_FN PyrIVec3 pyr_merge_normal(PYR_CTX_PARAM, pyr_u32 w, pyr_u32 x, pyr_u32 y) {
    pyr_u32 i = y * w + x;
    PyrIVec3 q;
    q.x = PYR_QN(i, 0u);
    q.y = PYR_QN(i, 1u);
    q.z = PYR_QN(i, 2u);
    PyrIVec3 f = pyr_to_fixed(PYR_PT(x, y, 0u), PYR_PT(x, y, 1u), PYR_PT(x, y, 2u));
    if (q.x * f.x + q.y * f.y + q.z * f.z > 0) {
        q.x = -q.x;
        q.y = -q.y;
        q.z = -q.z;
    }
    return q;
}

/* min(floor(base + growth * z^2), 2^30): the tolerance at depth z, in units of 2^-(e + 13) input units. */
PYR_FN pyr_i32 pyr_merge_tolerance(pyr_f32 z, pyr_f32 base, pyr_f32 growth) {
    PYR_PRECISE pyr_f32 zz = z * z;
    PYR_PRECISE pyr_f32 g = growth * zz;
    PYR_PRECISE pyr_f32 t = growth == 0.0f ? base : base + g;
    return t >= PYR_F32(PYR_MERGE_TOLERANCE_MAX) ? PYR_MERGE_TOLERANCE_MAX : PYR_I32(t);
}

/* The kind of boundary between the pixels a, b (both labelled, so valid). */
PYR_FN pyr_u32 pyr_merge_pair_kind(PYR_CTX_PARAM, pyr_u32 w, pyr_u32 xa, pyr_u32 ya, pyr_u32 xb, pyr_u32 yb,
                                   pyr_f32 scale, pyr_f32 tolerance_base, pyr_f32 tolerance_growth) {
    PyrIVec3 d;
    d.x = pyr_robust_tangent(PYR_CTX_ARG, xb, yb, xa, ya, 0u, scale);
    d.y = pyr_robust_tangent(PYR_CTX_ARG, xb, yb, xa, ya, 1u, scale);
    d.z = pyr_robust_tangent(PYR_CTX_ARG, xb, yb, xa, ya, 2u, scale);
    if (pyr_iabs(d.x) > PYR_MERGE_SPAN_LIMIT || pyr_iabs(d.y) > PYR_MERGE_SPAN_LIMIT ||
        pyr_iabs(d.z) > PYR_MERGE_SPAN_LIMIT) {
        return PYR_BOUNDARY_STEP;
    }
    PyrIVec3 na = pyr_merge_normal(PYR_CTX_ARG, w, xa, ya);
    PyrIVec3 nb = pyr_merge_normal(PYR_CTX_ARG, w, xb, yb);
    pyr_i32 above_a = na.x * d.x + na.y * d.y + na.z * d.z;    /* b over a's tangent plane */
    pyr_i32 above_b = -(nb.x * d.x + nb.y * d.y + nb.z * d.z); /* a over b's */
    pyr_f32 za = PYR_PT(xa, ya, 2u);
    pyr_f32 zb = PYR_PT(xb, yb, 2u);
    pyr_i32 tolerance = pyr_merge_tolerance(za < zb ? za : zb, tolerance_base, tolerance_growth);
    pyr_i32 high = above_a > above_b ? above_a : above_b;
    pyr_i32 low = above_a > above_b ? above_b : above_a;
    if (high <= tolerance) return low < -tolerance ? PYR_BOUNDARY_CONVEX : PYR_BOUNDARY_FLAT;
    return low < -tolerance ? PYR_BOUNDARY_STEP : PYR_BOUNDARY_CONCAVE;
}

/* The crossing from pixel (x, y) to its neighbour (x + dx, y + dy), dx + dy == 1, on level N: PYR_MERGE_NONE when
 * there is none (the neighbour does not exist, or either label is 0, or they are equal), else its kind. */
PYR_FN pyr_u32 pyr_merge_crossing_kind(PYR_CTX_PARAM, PyrLevel lv, pyr_u32 x, pyr_u32 y, pyr_u32 dx, pyr_u32 dy,
                                       pyr_u32 reach, pyr_f32 scale, pyr_f32 tolerance_base, pyr_f32 tolerance_growth) {
    pyr_u32 qx = x + dx;
    pyr_u32 qy = y + dy;
    if (qx >= lv.width || qy >= lv.height) return PYR_MERGE_NONE;
    pyr_u32 a = PYR_LABEL(lv.offset + y * lv.width + x);
    pyr_u32 b = PYR_LABEL(lv.offset + qy * lv.width + qx);
    if (a == 0u || b == 0u || a == b) return PYR_MERGE_NONE;
    pyr_i32 sx = PYR_I32(dx);
    pyr_i32 sy = PYR_I32(dy);
    pyr_i32 ka = pyr_merge_reach(PYR_CTX_ARG, lv, PYR_I32(x), PYR_I32(y), -sx, -sy, a, reach);
    pyr_i32 kb = pyr_merge_reach(PYR_CTX_ARG, lv, PYR_I32(qx), PYR_I32(qy), sx, sy, b, reach);
    return pyr_merge_pair_kind(PYR_CTX_ARG, lv.width, PYR_U32(PYR_I32(x) - ka * sx), PYR_U32(PYR_I32(y) - ka * sy),
                               PYR_U32(PYR_I32(qx) + kb * sx), PYR_U32(PYR_I32(qy) + kb * sy), scale, tolerance_base,
                               tolerance_growth);
}

/* The same crossing for the merge: PYR_MERGE_NONE, else 1 if it is good (flat or convex), 0 if bad. */
PYR_FN pyr_u32 pyr_merge_crossing(PYR_CTX_PARAM, PyrLevel lv, pyr_u32 x, pyr_u32 y, pyr_u32 dx, pyr_u32 dy,
                                  pyr_u32 reach, pyr_f32 scale, pyr_f32 tolerance_base, pyr_f32 tolerance_growth) {
    pyr_u32 kind =
        pyr_merge_crossing_kind(PYR_CTX_ARG, lv, x, y, dx, dy, reach, scale, tolerance_base, tolerance_growth);
    if (kind == PYR_MERGE_NONE) return PYR_MERGE_NONE;
    return kind <= PYR_BOUNDARY_CONVEX ? 1u : 0u;
}

/* Whether a boundary with `good` and `bad` crossings joins its two segments: at least min_crossings of them, and
 * bad * 256 <= share * (good + bad) for share in 0..256, compared exactly in 48 bits (the counts are 32-bit). */
PYR_FN pyr_u32 pyr_merge_joins(pyr_u32 good, pyr_u32 bad, pyr_u32 min_crossings, pyr_u32 share) {
    pyr_u32 total = good + bad;
    if (total < good) total = 0xffffffffu; /* saturate: good + bad never wraps in practice */
    if (total < min_crossings) return 0u;
    /* left = bad * 2^8 as (hi, lo) with lo < 2^24 .. : split at 2^16. */
    pyr_u32 left_hi = bad >> 8u; /* bad * 256 = left_hi * 2^16 + left_lo */
    pyr_u32 left_lo = (bad & 0xffu) << 8u;
    pyr_u32 right_lo_full = (total & 0xffffu) * share; /* < 2^25 */
    pyr_u32 right_hi = (total >> 16u) * share + (right_lo_full >> 16u);
    pyr_u32 right_lo = right_lo_full & 0xffffu;
    if (left_hi != right_hi) return left_hi < right_hi ? 1u : 0u;
    return left_lo <= right_lo ? 1u : 0u;
}

#endif /* PYR_MERGE_H */
