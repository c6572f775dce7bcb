/* Per-segment statistics (docs/algorithm.md section 10): pixel count, bounding box, exact integer sums of the
 * fixed-point points, of their pairwise products (the second moments) and of the quantized normals, and the
 * fixed-point depth range of every compacted label. Integer sums do not depend on the order
 * of the additions, so every backend gets the same words whatever its scheduling.
 * Each invocation walks one run of a row and adds each stretch of equal labels to its slot at once, so a large
 * segment costs one atomic per stretch, not per pixel.
 * The sums of points, normals and products and the depth range run over the fillable pixels only (the edge pixels
 * of step 6c hold mixed pixels and the sides of depth steps); the count and the box over every labelled pixel.
 * Needs: PYR_LABEL(i), PYR_MASK(i), PYR_LUT(l), PYR_PT(x, y, c), PYR_QN(i, c), and on the statistics words (a uint32
 * array): PYR_STATS_ADD(w, v) (atomic add, evaluates to the old value) and PYR_STATS_MAX(w, v) (atomic max). */
#ifndef PYR_STATS_H
#define PYR_STATS_H
#include "pyr_types.h"

/* A 64-bit two's-complement sum in two words. */
PYR_TYPEDEF(PyrSum64)
struct PyrSum64 {
    pyr_u32 lo;
    pyr_u32 hi;
};

PYR_FN PyrSum64 pyr_sum64(pyr_u32 lo, pyr_u32 hi) {
    PyrSum64 s;
    s.lo = lo;
    s.hi = hi;
    return s;
}

PYR_FN PyrSum64 pyr_sum64_add(PyrSum64 s, pyr_i32 v) {
    pyr_u32 lo = s.lo + PYR_U32(v);
    s.hi = s.hi + (v < 0 ? 0xffffffffu : 0u) + (lo < s.lo ? 1u : 0u);
    s.lo = lo;
    return s;
}

/* Adds s to the two words at w, w + 1. The low word's carry is counted by whoever makes it wrap, so concurrent
 * additions in any order give the exact sum modulo 2^64. */
PYR_FN void pyr_stats_add64(PYR_CTX_PARAM, pyr_u32 w, PyrSum64 s) {
    pyr_u32 old = PYR_STATS_ADD(w, s.lo);
    pyr_u32 hi = s.hi + (old + s.lo < old ? 1u : 0u);
    if (hi != 0u) PYR_STATS_ADD(w + 1u, hi);
}

/* A 96-bit two's-complement sum in three words: the sums of products, which overflow 64 bits on a large frame of
 * far points. */
PYR_TYPEDEF(PyrSum96)
struct PyrSum96 {
    pyr_u32 lo;
    pyr_u32 mid;
    pyr_u32 hi;
};

PYR_FN PyrSum96 pyr_sum96_zero() {
    PyrSum96 s;
    s.lo = 0u;
    s.mid = 0u;
    s.hi = 0u;
    return s;
}

/* s + a * b, the product exact in 64 bits (its low word wraps in uint32, its high word is the signed high half). */
PYR_FN PyrSum96 pyr_sum96_add_product(PyrSum96 s, pyr_i32 a, pyr_i32 b) {
    pyr_u32 product_lo = PYR_U32(a) * PYR_U32(b);
    pyr_i32 product_hi = PYR_MUL_HI_I32(a, b);
    pyr_u32 lo = s.lo + product_lo;
    pyr_u32 carry_lo = lo < s.lo ? 1u : 0u;
    pyr_u32 mid_part = s.mid + PYR_U32(product_hi);
    pyr_u32 carry_mid = mid_part < s.mid ? 1u : 0u;
    pyr_u32 mid = mid_part + carry_lo;
    carry_mid += mid < mid_part ? 1u : 0u;
    s.hi = s.hi + (product_hi < 0 ? 0xffffffffu : 0u) + carry_mid;
    s.mid = mid;
    s.lo = lo;
    return s;
}

/* Adds s to the three words at w .. w + 2, each word's carry counted by whoever makes it wrap (as in
 * pyr_stats_add64), so concurrent additions in any order give the exact sum modulo 2^96. */
PYR_FN void pyr_stats_add96(PYR_CTX_PARAM, pyr_u32 w, PyrSum96 s) {
    pyr_u32 old = PYR_STATS_ADD(w, s.lo);
    pyr_u32 carry = old + s.lo < old ? 1u : 0u;
    pyr_u32 mid = s.mid + carry;
    pyr_u32 hi = s.hi + (mid < carry ? 1u : 0u); /* s.mid + carry wrapped to zero: its carry goes up */
    if (mid != 0u) {
        pyr_u32 old_mid = PYR_STATS_ADD(w + 1u, mid);
        hi += old_mid + mid < old_mid ? 1u : 0u;
    }
    if (hi != 0u) PYR_STATS_ADD(w + 2u, hi);
}

/* A point coordinate in fixed point: rint(v * 2^point_shift), with point_scale = 2^point_shift (exact), clamped.
 * Only labelled pixels are summed, and those are point-valid, so v is finite. */
PYR_FN pyr_i32 pyr_stats_fixed(pyr_f32 v, pyr_f32 point_scale) {
    PYR_PRECISE pyr_f32 scaled = v * point_scale;
    scaled = scaled < -PYR_STATS_POINT_LIMIT ? -PYR_STATS_POINT_LIMIT
                                             : (scaled > PYR_STATS_POINT_LIMIT ? PYR_STATS_POINT_LIMIT : scaled);
    return PYR_I32(PYR_RINT(scaled));
}

/* One stretch of equal labels being summed. */
PYR_TYPEDEF(PyrStatsRun)
struct PyrStatsRun {
    pyr_u32 slot; /* 0xffffffff: none */
    pyr_u32 raw;
    pyr_u32 count;
    pyr_u32 fillable;
    pyr_u32 x_min;
    pyr_u32 x_max;
    PyrSum64 px;
    PyrSum64 py;
    PyrSum64 pz;
    PyrSum64 nx;
    PyrSum64 ny;
    PyrSum64 nz;
    pyr_u32 z_key_min;
    pyr_u32 z_key_max;
    PyrSum96 xx;
    PyrSum96 xy;
    PyrSum96 xz;
    PyrSum96 yy;
    PyrSum96 yz;
    PyrSum96 zz;
};

PYR_FN PyrStatsRun pyr_stats_run_start(pyr_u32 slot, pyr_u32 raw, pyr_u32 x) {
    PyrStatsRun r;
    r.slot = slot;
    r.raw = raw;
    r.count = 0u;
    r.fillable = 0u;
    r.x_min = x;
    r.x_max = x;
    r.px = pyr_sum64(0u, 0u);
    r.py = pyr_sum64(0u, 0u);
    r.pz = pyr_sum64(0u, 0u);
    r.nx = pyr_sum64(0u, 0u);
    r.ny = pyr_sum64(0u, 0u);
    r.nz = pyr_sum64(0u, 0u);
    r.z_key_min = 0xffffffffu;
    r.z_key_max = 0u;
    r.xx = pyr_sum96_zero();
    r.xy = pyr_sum96_zero();
    r.xz = pyr_sum96_zero();
    r.yy = pyr_sum96_zero();
    r.yz = pyr_sum96_zero();
    r.zz = pyr_sum96_zero();
    return r;
}

PYR_FN void pyr_stats_flush(PYR_CTX_PARAM, pyr_u32 base, PyrStatsRun r, pyr_u32 y, pyr_u32 with_points) {
    pyr_u32 w = base + r.slot * PYR_STATS_WORDS;
    PYR_STATS_ADD(w + PYR_STATS_COUNT, r.count);
    PYR_STATS_MAX(w + PYR_STATS_NOT_X_MIN, ~r.x_min);
    PYR_STATS_MAX(w + PYR_STATS_NOT_Y_MIN, ~y);
    PYR_STATS_MAX(w + PYR_STATS_X_MAX, r.x_max);
    PYR_STATS_MAX(w + PYR_STATS_Y_MAX, y);
    PYR_STATS_MAX(w + PYR_STATS_RAW_LABEL, r.raw); /* every pixel of the slot has this raw label */
    if (with_points != 0u && r.fillable != 0u) {
        PYR_STATS_ADD(w + PYR_STATS_FILLABLE_COUNT, r.fillable);
        pyr_stats_add64(PYR_CTX_ARG, w + PYR_STATS_POINT_SUM, r.px);
        pyr_stats_add64(PYR_CTX_ARG, w + PYR_STATS_POINT_SUM + 2u, r.py);
        pyr_stats_add64(PYR_CTX_ARG, w + PYR_STATS_POINT_SUM + 4u, r.pz);
        pyr_stats_add64(PYR_CTX_ARG, w + PYR_STATS_NORMAL_SUM, r.nx);
        pyr_stats_add64(PYR_CTX_ARG, w + PYR_STATS_NORMAL_SUM + 2u, r.ny);
        pyr_stats_add64(PYR_CTX_ARG, w + PYR_STATS_NORMAL_SUM + 4u, r.nz);
        PYR_STATS_MAX(w + PYR_STATS_Z_KEY_MAX, r.z_key_max);
        PYR_STATS_MAX(w + PYR_STATS_NOT_Z_KEY_MIN, ~r.z_key_min);
        pyr_stats_add96(PYR_CTX_ARG, w + PYR_STATS_PRODUCT_SUM, r.xx);
        pyr_stats_add96(PYR_CTX_ARG, w + PYR_STATS_PRODUCT_SUM + 3u, r.xy);
        pyr_stats_add96(PYR_CTX_ARG, w + PYR_STATS_PRODUCT_SUM + 6u, r.xz);
        pyr_stats_add96(PYR_CTX_ARG, w + PYR_STATS_PRODUCT_SUM + 9u, r.yy);
        pyr_stats_add96(PYR_CTX_ARG, w + PYR_STATS_PRODUCT_SUM + 12u, r.yz);
        pyr_stats_add96(PYR_CTX_ARG, w + PYR_STATS_PRODUCT_SUM + 15u, r.zz);
    }
}

/* Adds pixels [x_begin, x_end) of row y of the full level to their segments' slots (words from `base`).
 * with_points: the frame was a cloud (sum points and normals); 0 for a caller's mask. slots: the slot count;
 * a label beyond it (impossible, see core/plan.cpp) is skipped rather than written out of bounds. */
PYR_FN void pyr_stats_row_run(PYR_CTX_PARAM, PyrLevel full, pyr_u32 y, pyr_u32 x_begin, pyr_u32 x_end,
                              pyr_u32 with_points, pyr_f32 point_scale, pyr_u32 base, pyr_u32 slots) {
    PyrStatsRun r = pyr_stats_run_start(0xffffffffu, 0u, x_begin);
    for (pyr_u32 x = x_begin; x < x_end; ++x) {
        pyr_u32 pixel = y * full.width + x;
        pyr_u32 raw = PYR_LABEL(full.offset + pixel);
        pyr_u32 slot = raw != 0u ? PYR_LUT(raw) - 1u : 0xffffffffu;
        if (slot >= slots) slot = 0xffffffffu;
        if (slot != r.slot) {
            if (r.slot != 0xffffffffu) pyr_stats_flush(PYR_CTX_ARG, base, r, y, with_points);
            r = pyr_stats_run_start(slot, raw, x);
        }
        if (slot == 0xffffffffu) continue;
        r.count += 1u;
        r.x_max = x;
        if (with_points != 0u && (PYR_MASK(full.offset + pixel) & PYR_MASK_FILLABLE) != 0u) {
            r.fillable += 1u;
            pyr_i32 fx = pyr_stats_fixed(PYR_PT(x, y, 0u), point_scale);
            pyr_i32 fy = pyr_stats_fixed(PYR_PT(x, y, 1u), point_scale);
            pyr_i32 fz = pyr_stats_fixed(PYR_PT(x, y, 2u), point_scale);
            r.px = pyr_sum64_add(r.px, fx);
            r.py = pyr_sum64_add(r.py, fy);
            r.pz = pyr_sum64_add(r.pz, fz);
            pyr_u32 z_key = PYR_U32(fz) ^ 0x80000000u;
            r.z_key_min = z_key < r.z_key_min ? z_key : r.z_key_min;
            r.z_key_max = z_key > r.z_key_max ? z_key : r.z_key_max;
            r.xx = pyr_sum96_add_product(r.xx, fx, fx);
            r.xy = pyr_sum96_add_product(r.xy, fx, fy);
            r.xz = pyr_sum96_add_product(r.xz, fx, fz);
            r.yy = pyr_sum96_add_product(r.yy, fy, fy);
            r.yz = pyr_sum96_add_product(r.yz, fy, fz);
            r.zz = pyr_sum96_add_product(r.zz, fz, fz);
            r.nx = pyr_sum64_add(r.nx, PYR_QN(pixel, 0u));
            r.ny = pyr_sum64_add(r.ny, PYR_QN(pixel, 1u));
            r.nz = pyr_sum64_add(r.nz, PYR_QN(pixel, 2u));
        }
    }
    if (r.slot != 0xffffffffu) pyr_stats_flush(PYR_CTX_ARG, base, r, y, with_points);
}

/* Run `run` of the frame (PYR_STATS_RUN pixels of a row; runs_per_row = ceil(width / PYR_STATS_RUN)), for the
 * devices that give each run its own invocation. */
PYR_FN void pyr_stats_run(PYR_CTX_PARAM, PyrLevel full, pyr_u32 run, pyr_u32 with_points, pyr_f32 point_scale,
                          pyr_u32 base, pyr_u32 slots) {
    pyr_u32 runs_per_row = (full.width + PYR_STATS_RUN - 1u) / PYR_STATS_RUN;
    pyr_u32 y = run / runs_per_row;
    if (y >= full.height) return;
    pyr_u32 x_begin = (run - y * runs_per_row) * PYR_STATS_RUN;
    pyr_u32 x_end = x_begin + PYR_STATS_RUN < full.width ? x_begin + PYR_STATS_RUN : full.width;
    pyr_stats_row_run(PYR_CTX_ARG, full, y, x_begin, x_end, with_points, point_scale, base, slots);
}

#endif /* PYR_STATS_H */
