/* Metric pass (contract section 2): is pixel (x, y) fillable?
 * Needs: PYR_Q_VALID(i), PYR_QN(i, c) (c = 0, 1, 2; int), PYR_QZ(i) (float z), i = y*w + x. */
#ifndef PYR_METRIC_H
#define PYR_METRIC_H
#include "pyr_types.h"

PYR_FN pyr_u32 pyr_metric_fillable(PYR_CTX_PARAM, pyr_u32 w, pyr_u32 h, pyr_u32 x, pyr_u32 y, pyr_i32 tc, pyr_f32 dt) {
    pyr_u32 i = y * w + x;
    if (PYR_Q_VALID(i) == 0u) return 0u;
    pyr_i32 qx = PYR_QN(i, 0);
    pyr_i32 qy = PYR_QN(i, 1);
    pyr_i32 qz = PYR_QN(i, 2);
    pyr_f32 z = PYR_QZ(i);
    pyr_i32 k = 0;
    pyr_i32 s = 0; /* |s| <= 8 * 3 * 2^26 < 2^31 */
    pyr_f32 dmin = 0.0f;
    pyr_f32 dmax = 0.0f;
    for (pyr_i32 dy = -1; dy <= 1; ++dy) {
        pyr_i32 ny = PYR_I32(y) + dy;
        if (ny < 0 || ny >= PYR_I32(h)) continue;
        for (pyr_i32 dx = -1; dx <= 1; ++dx) {
            pyr_i32 nx = PYR_I32(x) + dx;
            if ((dx == 0 && dy == 0) || nx < 0 || nx >= PYR_I32(w)) continue;
            pyr_u32 j = PYR_U32(ny) * w + PYR_U32(nx);
            if (PYR_Q_VALID(j) == 0u) continue;
            s += qx * PYR_QN(j, 0) + qy * PYR_QN(j, 1) + qz * PYR_QN(j, 2);
            PYR_PRECISE pyr_f32 dd = PYR_FABS(z - PYR_QZ(j));
            dmin = (k == 0 || dd < dmin) ? dd : dmin;
            dmax = (k == 0 || dd > dmax) ? dd : dmax;
            ++k;
        }
    }
    /* k * tc stays within int32: tc is in [-2^28, 2^26] (core/plan.cpp). */
    if (k == 0 || s < k * tc) return 0u;
    PYR_PRECISE pyr_f32 d = dmax - dmin;
    return d <= dt ? 1u : 0u;
}

#endif /* PYR_METRIC_H */
