/* Normals pass (docs/algorithm.md section 8): float subtraction for the tangents, then integers only, so the
 * result is the same bit for bit on every backend. Needs: PYR_PT(x, y, c), component c of the point at (x, y).
 * Returns q with n = q * 2^-13, or (0, 0, 0) where no normal is defined. */
#ifndef PYR_NORMALS_H
#define PYR_NORMALS_H
#include "pyr_types.h"
#include "pyr_validity.h"

PYR_FN pyr_i32 pyr_fixed_exponent(pyr_f32 v) {
    pyr_i32 e = (PYR_FLOAT_BITS(v) >> 23) & 255;
    return e == 255 ? 0 : e; /* 0: zero, subnormal, or not finite; all read as zero */
}

PYR_FN pyr_i32 pyr_fixed_component(pyr_f32 v, pyr_i32 max_exponent) {
    pyr_i32 bits = PYR_FLOAT_BITS(v);
    pyr_i32 e = (bits >> 23) & 255;
    if (e == 0 || e == 255) return 0;
    pyr_i32 shift = 9 + max_exponent - e;
    if (shift > 31) return 0;
    pyr_i32 magnitude = ((bits & 0x7fffff) | 0x800000) >> shift;
    return bits < 0 ? -magnitude : magnitude;
}

/* F(v): 15 significant bits, the largest magnitude in [2^14, 2^15). */
PYR_FN PyrIVec3 pyr_to_fixed(pyr_f32 x, pyr_f32 y, pyr_f32 z) {
    pyr_i32 e = pyr_fixed_exponent(x);
    pyr_i32 ey = pyr_fixed_exponent(y);
    pyr_i32 ez = pyr_fixed_exponent(z);
    e = ey > e ? ey : e;
    e = ez > e ? ez : e;
    PyrIVec3 r;
    r.x = pyr_fixed_component(x, e);
    r.y = pyr_fixed_component(y, e);
    r.z = pyr_fixed_component(z, e);
    return r;
}

PYR_FN pyr_i32 pyr_iabs(pyr_i32 v) {
    return v < 0 ? -v : v;
}

/* Magnitude shifted right (s > 0) or left (s < 0), sign kept. */
PYR_FN pyr_i32 pyr_shift_magnitude(pyr_i32 v, pyr_i32 s) {
    pyr_i32 m = s > 0 ? (pyr_iabs(v) >> s) : (pyr_iabs(v) << (-s));
    return v < 0 ? -m : m;
}

/* floor(sqrt(n)), exact for n < 3 * 2^30: a float estimate (whatever the device's sqrt accuracy) corrected with
 * integer comparisons; (r + 1)^2 stays below 2^32 in this range. */
PYR_FN pyr_u32 pyr_isqrt(pyr_u32 n) {
    pyr_u32 r = PYR_U32(PYR_SQRT(PYR_F32(n)));
    while (r * r > n) --r;
    while ((r + 1u) * (r + 1u) <= n) ++r;
    return r;
}

/* |d| * 8192 / len rounded half up, sign kept; len >= |d| so the magnitude is at most 8192. */
PYR_FN pyr_i32 pyr_unit_component(pyr_i32 d, pyr_u32 len) {
    pyr_i32 q = PYR_I32(((PYR_U32(pyr_iabs(d)) << 14) + len) / (2u * len));
    return d < 0 ? -q : q;
}

/* Steps 2 to 6 of section 8 from the fixed-point tangents U and V (each with at most 15 significant bits): the
 * unit normal q (|q_c| <= 2^13) toward the camera at the origin, seen from the point P, or (0, 0, 0). Shared by the
 * robust normals (section 8b). */
PYR_FN PyrIVec3 pyr_unit_normal_from_tangents(PyrIVec3 u, PyrIVec3 v, pyr_f32 px, pyr_f32 py, pyr_f32 pz) {
    PyrIVec3 none = pyr_ivec3_zero();
    /* Each product < 2^30, each difference < 2^31. */
    PyrIVec3 c;
    c.x = u.y * v.z - u.z * v.y;
    c.y = u.z * v.x - u.x * v.z;
    c.z = u.x * v.y - u.y * v.x;
    pyr_i32 m = pyr_iabs(c.x);
    m = pyr_iabs(c.y) > m ? pyr_iabs(c.y) : m;
    m = pyr_iabs(c.z) > m ? pyr_iabs(c.z) : m;
    if (m == 0) return none;

    pyr_i32 s = PYR_MSB(PYR_U32(m)) - 14;
    PyrIVec3 d;
    d.x = pyr_shift_magnitude(c.x, s);
    d.y = pyr_shift_magnitude(c.y, s);
    d.z = pyr_shift_magnitude(c.z, s);
    pyr_u32 len = pyr_isqrt(PYR_U32(d.x * d.x) + PYR_U32(d.y * d.y) + PYR_U32(d.z * d.z));
    PyrIVec3 q;
    q.x = pyr_unit_component(d.x, len);
    q.y = pyr_unit_component(d.y, len);
    q.z = pyr_unit_component(d.z, len);

    /* Toward the camera at the origin: q . P < 0. |q| <= 2^13 and |F(P)| < 2^15, so the dot fits int32. */
    PyrIVec3 p = pyr_to_fixed(px, py, pz);
    if (q.x * p.x + q.y * p.y + q.z * p.z > 0) {
        q.x = -q.x;
        q.y = -q.y;
        q.z = -q.z;
    }
    return q;
}

PYR_FN PyrIVec3 pyr_normal_q(PYR_CTX_PARAM, pyr_u32 w, pyr_u32 h, pyr_u32 x, pyr_u32 y, pyr_u32 r) {
    PyrIVec3 none = pyr_ivec3_zero();
    pyr_f32 px = PYR_PT(x, y, 0);
    pyr_f32 py = PYR_PT(x, y, 1);
    pyr_f32 pz = PYR_PT(x, y, 2);
    if (pyr_point_valid(px, py, pz) == 0u) return none;

    pyr_u32 has_right = 0u;
    pyr_u32 has_left = 0u;
    if (x + r < w) has_right = pyr_point_valid(PYR_PT(x + r, y, 0), PYR_PT(x + r, y, 1), PYR_PT(x + r, y, 2));
    if (x >= r) has_left = pyr_point_valid(PYR_PT(x - r, y, 0), PYR_PT(x - r, y, 1), PYR_PT(x - r, y, 2));
    if (has_right == 0u && has_left == 0u) return none;
    pyr_u32 xa = has_right != 0u ? x + r : x; /* u = P(xa) - P(xb) */
    pyr_u32 xb = has_left != 0u ? x - r : x;
    PYR_PRECISE pyr_f32 ux = PYR_PT(xa, y, 0) - PYR_PT(xb, y, 0);
    PYR_PRECISE pyr_f32 uy = PYR_PT(xa, y, 1) - PYR_PT(xb, y, 1);
    PYR_PRECISE pyr_f32 uz = PYR_PT(xa, y, 2) - PYR_PT(xb, y, 2);

    pyr_u32 has_down = 0u;
    pyr_u32 has_up = 0u;
    if (y + r < h) has_down = pyr_point_valid(PYR_PT(x, y + r, 0), PYR_PT(x, y + r, 1), PYR_PT(x, y + r, 2));
    if (y >= r) has_up = pyr_point_valid(PYR_PT(x, y - r, 0), PYR_PT(x, y - r, 1), PYR_PT(x, y - r, 2));
    if (has_down == 0u && has_up == 0u) return none;
    pyr_u32 ya = has_down != 0u ? y + r : y;
    pyr_u32 yb = has_up != 0u ? y - r : y;
    PYR_PRECISE pyr_f32 vx = PYR_PT(x, ya, 0) - PYR_PT(x, yb, 0);
    PYR_PRECISE pyr_f32 vy = PYR_PT(x, ya, 1) - PYR_PT(x, yb, 1);
    PYR_PRECISE pyr_f32 vz = PYR_PT(x, ya, 2) - PYR_PT(x, yb, 2);

    return pyr_unit_normal_from_tangents(pyr_to_fixed(ux, uy, uz), pyr_to_fixed(vx, vy, vz), px, py, pz);
}

#endif /* PYR_NORMALS_H */
