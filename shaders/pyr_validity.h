/* Validity tests on float bit patterns: the IEEE meaning (subnormals included) whatever a device's denormal mode. */
#ifndef PYR_VALIDITY_H
#define PYR_VALIDITY_H
#include "pyr_shim.h"

PYR_FN pyr_u32 pyr_is_finite(pyr_f32 v) {
    return ((PYR_FLOAT_BITS(v) >> 23) & 255) != 255 ? 1u : 0u;
}

/* z > 0: sign bit clear and not +0 (NaN is excluded by pyr_is_finite). */
PYR_FN pyr_u32 pyr_is_positive(pyr_f32 v) {
    return PYR_FLOAT_BITS(v) > 0 ? 1u : 0u;
}

PYR_FN pyr_u32 pyr_is_nonzero(pyr_f32 v) {
    return (PYR_FLOAT_BITS(v) & 0x7fffffff) != 0 ? 1u : 0u;
}

PYR_FN pyr_u32 pyr_point_valid(pyr_f32 x, pyr_f32 y, pyr_f32 z) {
    return pyr_is_finite(x) & pyr_is_finite(y) & pyr_is_finite(z) & pyr_is_positive(z);
}

PYR_FN pyr_u32 pyr_normal_valid(pyr_f32 nx, pyr_f32 ny, pyr_f32 nz) {
    return pyr_is_finite(nx) & pyr_is_finite(ny) & pyr_is_finite(nz) &
           (pyr_is_nonzero(nx) | pyr_is_nonzero(ny) | pyr_is_nonzero(nz));
}

#endif /* PYR_VALIDITY_H */
