/* The robust metric (docs/algorithm.md sections 2b and 8b): normals from window sums of fixed-point tangents, and
 * a fillable test whose curvature term looks at stride s and whose thresholds grow with z^2. Integers wherever
 * values are summed; the only float operations are correctly rounded ones (scale, clamp, multiply, add, compare).
 * Needs: PYR_PT(x, y, c) for the normals; PYR_Q_VALID(i), PYR_QN(i, c), PYR_QZ(i) for the metric. */
#ifndef PYR_ROBUST_H
#define PYR_ROBUST_H
#include "pyr_normals.h"
#include "pyr_types.h"
#include "pyr_validity.h"

#define PYR_ROBUST_COORD_LIMIT 4194304.0f   /* 2^22 fixed-point steps */
#define PYR_ROBUST_CURVATURE_PASS 268435456 /* 2^28: the curvature test passes whatever the normals */

/* G(v): rint(clamp(v * 2^e, -2^22, 2^22)); the scale is the exact float 2^e. */
PYR_FN pyr_i32 pyr_robust_fixed(pyr_f32 v, pyr_f32 scale) {
    PYR_PRECISE pyr_f32 p = v * scale;
    p = p < -PYR_ROBUST_COORD_LIMIT ? -PYR_ROBUST_COORD_LIMIT
                                    : (p > PYR_ROBUST_COORD_LIMIT ? PYR_ROBUST_COORD_LIMIT : p);
    return PYR_I32(PYR_RINT(p));
}

PYR_FN pyr_u32 pyr_robust_point_valid(PYR_CTX_PARAM, pyr_u32 x, pyr_u32 y) {
    return pyr_point_valid(PYR_PT(x, y, 0), PYR_PT(x, y, 1), PYR_PT(x, y, 2));
}

/* G(P(a)) - G(P(b)), component c. */
PYR_FN pyr_i32 pyr_robust_tangent(PYR_CTX_PARAM, pyr_u32 xa, pyr_u32 ya, pyr_u32 xb, pyr_u32 yb, pyr_u32 c,
                                  pyr_f32 scale) {
    return pyr_robust_fixed(PYR_PT(xa, ya, c), scale) - pyr_robust_fixed(PYR_PT(xb, yb, c), scale);
}

/* The vector's magnitudes shifted so that the largest lies in [2^14, 2^15), signs kept; m > 0 is that largest. */
PYR_FN PyrIVec3 pyr_robust_to_15_bits(PyrIVec3 v) {
    pyr_i32 m = pyr_iabs(v.x);
    m = pyr_iabs(v.y) > m ? pyr_iabs(v.y) : m;
    m = pyr_iabs(v.z) > m ? pyr_iabs(v.z) : m;
    pyr_i32 s = PYR_MSB(PYR_U32(m)) - 14;
    PyrIVec3 r;
    r.x = pyr_shift_magnitude(v.x, s);
    r.y = pyr_shift_magnitude(v.y, s);
    r.z = pyr_shift_magnitude(v.z, s);
    return r;
}

PYR_FN pyr_u32 pyr_robust_is_zero(PyrIVec3 v) {
    return (v.x == 0 && v.y == 0 && v.z == 0) ? 1u : 0u;
}

/* The tangents of pixel (x, y) and its fixed-point depth (section 8b). */
PYR_FN PyrRobustTexel pyr_robust_texel(PYR_CTX_PARAM, pyr_u32 w, pyr_u32 h, pyr_u32 x, pyr_u32 y, pyr_u32 r,
                                       pyr_f32 scale) {
    PyrRobustTexel t;
    t.gz = -1;
    t.tangents = 0u;
    t.th = pyr_ivec3_zero();
    t.tv = t.th;
    if (pyr_robust_point_valid(PYR_CTX_ARG, x, y) == 0u) return t;
    t.gz = pyr_robust_fixed(PYR_PT(x, y, 2), scale);
    if (x >= r && x + r < w && pyr_robust_point_valid(PYR_CTX_ARG, x + r, y) != 0u &&
        pyr_robust_point_valid(PYR_CTX_ARG, x - r, y) != 0u) {
        t.tangents |= 1u;
        t.th.x = pyr_robust_tangent(PYR_CTX_ARG, x + r, y, x - r, y, 0u, scale);
        t.th.y = pyr_robust_tangent(PYR_CTX_ARG, x + r, y, x - r, y, 1u, scale);
        t.th.z = pyr_robust_tangent(PYR_CTX_ARG, x + r, y, x - r, y, 2u, scale);
    }
    if (y >= r && y + r < h && pyr_robust_point_valid(PYR_CTX_ARG, x, y + r) != 0u &&
        pyr_robust_point_valid(PYR_CTX_ARG, x, y - r) != 0u) {
        t.tangents |= 2u;
        t.tv.x = pyr_robust_tangent(PYR_CTX_ARG, x, y + r, x, y - r, 0u, scale);
        t.tv.y = pyr_robust_tangent(PYR_CTX_ARG, x, y + r, x, y - r, 1u, scale);
        t.tv.z = pyr_robust_tangent(PYR_CTX_ARG, x, y + r, x, y - r, 2u, scale);
    }
    return t;
}

/* Where a window reads its texels: every backend computes each pixel's texel once per frame (pyr_robust_texel) and
 * the windows read them. The CPU defines PYR_ROBUST_TEXEL over its own array; a GPU dialect defines
 * PYR_TEXEL_WORD(i) and PYR_STORE_TEXEL_WORD(i, v) over a buffer of PYR_TEXEL_WORDS words per pixel (the
 * robust_texels kernel writes them). The macro expands inside pyr_robust_normal_q, whose parameter w it names. */
#ifdef PYR_TEXEL_WORD
PYR_FN void pyr_robust_texel_store(PYR_CTX_PARAM, pyr_u32 i, PyrRobustTexel t) {
    pyr_u32 k = i * PYR_TEXEL_WORDS;
    PYR_STORE_TEXEL_WORD(k + 0u, PYR_U32(t.gz));
    PYR_STORE_TEXEL_WORD(k + 1u, t.tangents);
    PYR_STORE_TEXEL_WORD(k + 2u, PYR_U32(t.th.x));
    PYR_STORE_TEXEL_WORD(k + 3u, PYR_U32(t.th.y));
    PYR_STORE_TEXEL_WORD(k + 4u, PYR_U32(t.th.z));
    PYR_STORE_TEXEL_WORD(k + 5u, PYR_U32(t.tv.x));
    PYR_STORE_TEXEL_WORD(k + 6u, PYR_U32(t.tv.y));
    PYR_STORE_TEXEL_WORD(k + 7u, PYR_U32(t.tv.z));
}

PYR_FN PyrRobustTexel pyr_robust_texel_load(PYR_CTX_PARAM, pyr_u32 i) {
    pyr_u32 k = i * PYR_TEXEL_WORDS;
    PyrRobustTexel t;
    t.gz = PYR_I32(PYR_TEXEL_WORD(k + 0u));
    t.tangents = PYR_TEXEL_WORD(k + 1u);
    t.th.x = PYR_I32(PYR_TEXEL_WORD(k + 2u));
    t.th.y = PYR_I32(PYR_TEXEL_WORD(k + 3u));
    t.th.z = PYR_I32(PYR_TEXEL_WORD(k + 4u));
    t.tv.x = PYR_I32(PYR_TEXEL_WORD(k + 5u));
    t.tv.y = PYR_I32(PYR_TEXEL_WORD(k + 6u));
    t.tv.z = PYR_I32(PYR_TEXEL_WORD(k + 7u));
    return t;
}
#define PYR_ROBUST_TEXEL(jx, jy) pyr_robust_texel_load(PYR_CTX_ARG, (jy)*w + (jx))
#endif
#ifndef PYR_ROBUST_TEXEL
#error "define PYR_ROBUST_TEXEL (the CPU) or PYR_TEXEL_WORD and PYR_STORE_TEXEL_WORD (a GPU dialect)"
#endif

/* The normal from a window's tangent sums U and V (section 8b, from "If U or V is (0, 0, 0)"). */
PYR_FN PyrIVec3 pyr_robust_normal_from_sums(PyrIVec3 u, PyrIVec3 v, pyr_f32 px, pyr_f32 py, pyr_f32 pz) {
    if (pyr_robust_is_zero(u) != 0u || pyr_robust_is_zero(v) != 0u) return pyr_ivec3_zero();
    return pyr_unit_normal_from_tangents(pyr_robust_to_15_bits(u), pyr_robust_to_15_bits(v), px, py, pz);
}

PYR_FN PyrIVec3 pyr_robust_normal_q(PYR_CTX_PARAM, pyr_u32 w, pyr_u32 h, pyr_u32 x, pyr_u32 y, pyr_u32 window,
                                    pyr_f32 scale) {
    PyrIVec3 none = pyr_ivec3_zero();
    pyr_f32 px = PYR_PT(x, y, 0);
    pyr_f32 py = PYR_PT(x, y, 1);
    pyr_f32 pz = PYR_PT(x, y, 2);
    if (pyr_point_valid(px, py, pz) == 0u) return none;
    pyr_i32 zi = pyr_robust_fixed(pz, scale);
    pyr_i32 jump = zi >> 4;

    PyrIVec3 u = none;
    PyrIVec3 v = none;
    pyr_u32 y0 = y >= window ? y - window : 0u;
    pyr_u32 y1 = y + window < h ? y + window : h - 1u;
    pyr_u32 x0 = x >= window ? x - window : 0u;
    pyr_u32 x1 = x + window < w ? x + window : w - 1u;
    for (pyr_u32 jy = y0; jy <= y1; ++jy) {
        for (pyr_u32 jx = x0; jx <= x1; ++jx) {
            PyrRobustTexel t = PYR_ROBUST_TEXEL(jx, jy);
            if (t.gz < 0 || pyr_iabs(t.gz - zi) > jump) continue;
            if ((t.tangents & 1u) != 0u) {
                u.x += t.th.x;
                u.y += t.th.y;
                u.z += t.th.z;
            }
            if ((t.tangents & 2u) != 0u) {
                v.x += t.tv.x;
                v.y += t.tv.y;
                v.z += t.tv.z;
            }
        }
    }
    return pyr_robust_normal_from_sums(u, v, px, py, pz);
}

/* min(A + Bc * z^2, 2^28) as an int32, per section 2b; growth == 0 means A alone. */
PYR_FN pyr_i32 pyr_robust_curvature_limit(pyr_f32 z, pyr_f32 base, pyr_f32 growth) {
    PYR_PRECISE pyr_f32 zz = z * z;
    PYR_PRECISE pyr_f32 g = growth * zz;
    PYR_PRECISE pyr_f32 t = growth == 0.0f ? base : base + g;
    return t >= PYR_F32(PYR_ROBUST_CURVATURE_PASS) ? PYR_ROBUST_CURVATURE_PASS : PYR_I32(t);
}

PYR_FN pyr_f32 pyr_robust_depth_limit(pyr_f32 z, pyr_f32 dt, pyr_f32 growth) {
    PYR_PRECISE pyr_f32 zz = z * z;
    PYR_PRECISE pyr_f32 g = growth * zz;
    PYR_PRECISE pyr_f32 d = dt + g;
    return growth == 0.0f ? dt : d;
}

/* Whether the pixel at (x + dx, y + dy) exists and is valid; its index in j. */
PYR_FN pyr_u32 pyr_robust_valid_at(PYR_CTX_PARAM, pyr_u32 w, pyr_u32 h, pyr_i32 x, pyr_i32 y) {
    if (x < 0 || x >= PYR_I32(w) || y < 0 || y >= PYR_I32(h)) return 0u;
    return PYR_Q_VALID(PYR_U32(y) * w + PYR_U32(x));
}

PYR_FN pyr_i32 pyr_robust_dot(PYR_CTX_PARAM, pyr_u32 a, pyr_u32 b) {
    return PYR_QN(a, 0) * PYR_QN(b, 0) + PYR_QN(a, 1) * PYR_QN(b, 1) + PYR_QN(a, 2) * PYR_QN(b, 2);
}

/* The curvature pairs of pixel (x, y): the normals `stride` pixels before and after it along the 4 axes (horizontal,
 * vertical, both diagonals), each pair whose two pixels exist and are valid. |sum| <= 4 * 3 * 2^26 < 2^31. */
PYR_FN PyrCurvaturePairs pyr_robust_curvature_pairs(PYR_CTX_PARAM, pyr_u32 w, pyr_u32 h, pyr_u32 x, pyr_u32 y,
                                                    pyr_u32 stride) {
    PyrCurvaturePairs pairs;
    pairs.sum = 0;
    pairs.count = 0;
    pyr_i32 st = PYR_I32(stride);
    for (pyr_i32 axis = 0; axis < 4; ++axis) {
        pyr_i32 dx = axis == 1 ? 0 : 1;
        pyr_i32 dy = axis == 0 ? 0 : (axis == 3 ? -1 : 1);
        pyr_i32 ax = PYR_I32(x) + dx * st;
        pyr_i32 ay = PYR_I32(y) + dy * st;
        pyr_i32 bx = PYR_I32(x) - dx * st;
        pyr_i32 by = PYR_I32(y) - dy * st;
        if (pyr_robust_valid_at(PYR_CTX_ARG, w, h, ax, ay) == 0u) continue;
        if (pyr_robust_valid_at(PYR_CTX_ARG, w, h, bx, by) == 0u) continue;
        pairs.sum += pyr_robust_dot(PYR_CTX_ARG, PYR_U32(ay) * w + PYR_U32(ax), PYR_U32(by) * w + PYR_U32(bx));
        ++pairs.count;
    }
    return pairs;
}

/* Section 2b's curvature test with the limit L: 1 iff kp >= 1 and S >= kp * (2^26 - L). kp * (2^26 - L) lies in
 * [-3 * 2^28, 2^28] since 0 <= L <= 2^28. */
PYR_FN pyr_u32 pyr_robust_curvature_passes(PyrCurvaturePairs pairs, pyr_i32 limit) {
    return pairs.count >= 1 && pairs.sum >= pairs.count * (PYR_I32(1 << 26) - limit) ? 1u : 0u;
}

PYR_FN pyr_u32 pyr_metric_robust_fillable(PYR_CTX_PARAM, pyr_u32 w, pyr_u32 h, pyr_u32 x, pyr_u32 y, pyr_u32 stride,
                                          pyr_f32 curvature_base, pyr_f32 curvature_growth, pyr_f32 dt,
                                          pyr_f32 depth_growth) {
    pyr_u32 i = y * w + x;
    if (PYR_Q_VALID(i) == 0u) return 0u;
    pyr_f32 z = PYR_QZ(i);
    /* Depth: the 8 neighbours at stride 1, as section 2. */
    pyr_i32 k1 = 0;
    pyr_f32 dmin = 0.0f;
    pyr_f32 dmax = 0.0f;
    for (pyr_i32 dy = -1; dy <= 1; ++dy) {
        for (pyr_i32 dx = -1; dx <= 1; ++dx) {
            if (dx == 0 && dy == 0) continue;
            pyr_i32 nx = PYR_I32(x) + dx;
            pyr_i32 ny = PYR_I32(y) + dy;
            if (pyr_robust_valid_at(PYR_CTX_ARG, w, h, nx, ny) == 0u) continue;
            PYR_PRECISE pyr_f32 dd = PYR_FABS(z - PYR_QZ(PYR_U32(ny) * w + PYR_U32(nx)));
            dmin = (k1 == 0 || dd < dmin) ? dd : dmin;
            dmax = (k1 == 0 || dd > dmax) ? dd : dmax;
            ++k1;
        }
    }
    if (k1 == 0) return 0u;
    PyrCurvaturePairs pairs = pyr_robust_curvature_pairs(PYR_CTX_ARG, w, h, x, y, stride);
    if (pyr_robust_curvature_passes(pairs, pyr_robust_curvature_limit(z, curvature_base, curvature_growth)) == 0u) {
        return 0u; /* no pair (kp = 0) fails too */
    }
    PYR_PRECISE pyr_f32 d = dmax - dmin;
    return d <= pyr_robust_depth_limit(z, dt, depth_growth) ? 1u : 0u;
}

#endif /* PYR_ROBUST_H */
