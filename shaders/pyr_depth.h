/* Depth images (docs/algorithm.md section 1b): a value to a point, by bit tests and correctly rounded float32
 * multiplications only, so every backend computes the same point whatever its denormal mode. Pure. */
#ifndef PYR_DEPTH_H
#define PYR_DEPTH_H
#include "pyr_types.h"

#define PYR_DEPTH_U16 0u
#define PYR_DEPTH_F32 1u
#define PYR_DEPTH_NAN 0x7fc00000u

PYR_FN pyr_u32 pyr_depth_exponent(pyr_f32 v) {
    return PYR_U32(PYR_FLOAT_BITS(v) >> 23) & 255u;
}

/* A subnormal becomes a zero of its sign. */
PYR_FN pyr_f32 pyr_depth_flush(pyr_f32 v) {
    return pyr_depth_exponent(v) == 0u ? PYR_BITS_FLOAT(PYR_U32(PYR_FLOAT_BITS(v)) & 0x80000000u) : v;
}

/* `value`: the u16 value, or the f32 value's bits. */
PYR_FN PyrFVec3 pyr_depth_point(pyr_u32 value, pyr_u32 format, pyr_f32 scale, pyr_f32 ku, pyr_f32 kv) {
    PyrFVec3 none;
    none.x = PYR_BITS_FLOAT(PYR_DEPTH_NAN);
    none.y = none.x;
    none.z = none.x;
    pyr_f32 zs;
    if (format == PYR_DEPTH_U16) {
        if (value == 0u) return none;
        zs = PYR_F32(value);
    } else {
        pyr_u32 e = (value >> 23) & 255u;
        if ((value & 0x80000000u) != 0u || e == 0u || e == 255u) return none;
        zs = PYR_BITS_FLOAT(value);
    }
    PYR_PRECISE pyr_f32 z = zs * scale;
    pyr_u32 ez = pyr_depth_exponent(z);
    if (ez == 0u || ez == 255u) return none;
    PYR_PRECISE pyr_f32 x = z * ku;
    PYR_PRECISE pyr_f32 y = z * kv;
    PyrFVec3 p;
    p.x = pyr_depth_flush(x);
    p.y = pyr_depth_flush(y);
    p.z = z;
    return p;
}

#endif /* PYR_DEPTH_H */
