/* Quantize pass (contract section 2): validity and the integer normal qn of one pixel. Pure. */
#ifndef PYR_QUANTIZE_H
#define PYR_QUANTIZE_H
#include "pyr_types.h"
#include "pyr_validity.h"

PYR_FN pyr_i32 pyr_quantize_component(pyr_f32 n) {
    PYR_PRECISE pyr_f32 c = n < -1.0f ? -1.0f : (n > 1.0f ? 1.0f : n);
    return PYR_I32(PYR_RINT(c * PYR_NORMAL_SCALE));
}

PYR_FN PyrQuant pyr_quantize(pyr_f32 px, pyr_f32 py, pyr_f32 pz, pyr_f32 nx, pyr_f32 ny, pyr_f32 nz) {
    PyrQuant q;
    q.valid = pyr_point_valid(px, py, pz) & pyr_normal_valid(nx, ny, nz);
    /* Only finite values are converted: converting NaN to an integer is undefined in C++. */
    q.qx = q.valid != 0u ? pyr_quantize_component(nx) : 0;
    q.qy = q.valid != 0u ? pyr_quantize_component(ny) : 0;
    q.qz = q.valid != 0u ? pyr_quantize_component(nz) : 0;
    return q;
}

#endif /* PYR_QUANTIZE_H */
