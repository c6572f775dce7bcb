/* Compiles every shared pass function as OpenCL C 1.2 (clang), with accessors over global buffers, to keep
 * shaders/ within the dialect. Not a backend: the OpenCL backend's entry points are shaders/pyr_opencl.cl. */
#define PYR_CTX_PARAM __global const float* pyr_buf_points, __global const int* pyr_buf_quant, __global uint* pyr_buf_mask, \
    __global uint* pyr_buf_labels, __global uint* pyr_buf_lut
#define PYR_CTX_ARG pyr_buf_points, pyr_buf_quant, pyr_buf_mask, pyr_buf_labels, pyr_buf_lut
#define PYR_PT(x, y, c) pyr_buf_points[((y) * 64u + (x)) * 3u + (c)]
#define PYR_Q_VALID(i) ((uint)pyr_buf_quant[(i) * 4u + 3u])
#define PYR_QN(i, c) pyr_buf_quant[(i) * 4u + (c)]
#define PYR_QZ(i) pyr_buf_points[(i) * 3u + 2u]
#define PYR_MASK(i) pyr_buf_mask[i]
#define PYR_LABEL(i) pyr_buf_labels[i]
#define PYR_STORE_LABEL(i, v) (pyr_buf_labels[i] = (v))
#define PYR_VALID(p) ((uint)pyr_buf_quant[(p) * 4u + 3u])
#define PYR_LUT(l) pyr_buf_lut[l]
#define PYR_STORE_LUT(l, v) (pyr_buf_lut[l] = (v))
#define PYR_STATS_ADD(w, v) atomic_add(&pyr_buf_lut[w], v)
#define PYR_STATS_MAX(w, v) atomic_max(&pyr_buf_lut[w], v)
#define PYR_TEXEL_WORD(i) pyr_buf_lut[i]
#define PYR_STORE_TEXEL_WORD(i, v) (pyr_buf_lut[i] = (v))
#include "pyr_compact.h"
#include "pyr_depth.h"
#include "pyr_edges.h"
#include "pyr_fill.h"
#include "pyr_labels.h"
#include "pyr_metric.h"
#include "pyr_mip.h"
#include "pyr_normals.h"
#include "pyr_quantize.h"
#include "pyr_robust.h"
#include "pyr_scan.h"
#include "pyr_stats.h"

__kernel void all_passes(PYR_CTX_PARAM, __global int* out) {
    uint x = (uint)get_global_id(0);
    uint y = (uint)get_global_id(1);
    PyrLevel lv;
    lv.width = 64u;
    lv.height = 64u;
    lv.offset = 0u;
    PyrIVec3 q = pyr_normal_q(PYR_CTX_ARG, 64u, 64u, x, y, 1u);
    PyrQuant qu = pyr_quantize(1.0f, 2.0f, 3.0f, 0.0f, 0.0f, -1.0f);
    uint r = pyr_metric_fillable(PYR_CTX_ARG, 64u, 64u, x, y, 100, 1.0f);
    r += pyr_metric_robust_fillable(PYR_CTX_ARG, 64u, 64u, x, y, 4u, 100.0f, 0.5f, 1.0f, 0.25f);
    r += PYR_U32(pyr_robust_normal_q(PYR_CTX_ARG, 64u, 64u, x, y, 3u, 16.0f).z);
    pyr_robust_texel_store(PYR_CTX_ARG, y * 64u + x, pyr_robust_texel(PYR_CTX_ARG, 64u, 64u, x, y, 1u, 16.0f));
    r += pyr_mip_texel(PYR_CTX_ARG, lv, x, y);
    r += pyr_label_init_texel(PYR_CTX_ARG, lv, lv, x, y, PYR_INIT_NEW);
    r += pyr_sweep_line(PYR_CTX_ARG, y * 64u, 1u, 64u, 0u);
    r += pyr_anchor_mask(1u, 2u, 3u) + pyr_fill_relax(1u, 1u, 2u, 1u) + pyr_fill_once(0u, 1u, 1u);
    r += pyr_edge_label(PYR_CTX_ARG, lv, x, y, 2u);
    r += PYR_U32(PYR_FLOAT_BITS(pyr_depth_point(x, PYR_DEPTH_F32, 0.5f, 0.25f, -0.25f).x));
    r += pyr_compact_label(PYR_CTX_ARG, 3u);
    r += pyr_sweep_row(PYR_CTX_ARG, lv, y, 0u) + pyr_sweep_column(PYR_CTX_ARG, lv, x, 1u);
    r += pyr_count_marks(PYR_CTX_ARG, 0u, 64u);
    pyr_number_marks(PYR_CTX_ARG, 0u, 64u, r);
    pyr_stats_row_run(PYR_CTX_ARG, lv, y, 0u, 64u, 1u, 16.0f, 128u, 64u);
    pyr_stats_run(PYR_CTX_ARG, lv, x, 0u, 16.0f, 128u, 64u);
    out[y * 64u + x] = q.x + qu.qz + (int)r;
}
