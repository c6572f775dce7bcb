// Compiles every shared pass function as CUDA device code (nvcc), with accessors over device pointers, to keep
// shaders/ within the dialect. The backend's own kernels (shaders/pyr_cuda.cuh) are compiled by the build.
struct Ctx {
    const float* pts;
    const int* quant;
    unsigned* mask;
    unsigned* labels;
    unsigned* lut;
};
#define PYR_CTX_PARAM const Ctx& ctx
#define PYR_CTX_ARG ctx
#define PYR_PT(x, y, c) ctx.pts[((y)*64u + (x)) * 3u + (c)]
#define PYR_Q_VALID(i) static_cast<unsigned>(ctx.quant[(i)*4u + 3u])
#define PYR_QN(i, c) ctx.quant[(i)*4u + (c)]
#define PYR_QZ(i) ctx.pts[(i)*3u + 2u]
#define PYR_MASK(i) ctx.mask[i]
#define PYR_LABEL(i) ctx.labels[i]
#define PYR_STORE_LABEL(i, v) (ctx.labels[i] = (v))
#define PYR_VALID(p) static_cast<unsigned>(ctx.quant[(p)*4u + 3u])
#define PYR_LUT(l) ctx.lut[l]
#define PYR_STORE_LUT(l, v) (ctx.lut[l] = (v))
#define PYR_STATS_ADD(w, v) pyr_cuda_atomic_add(&ctx.lut[w], v)
#define PYR_STATS_MAX(w, v) pyr_cuda_atomic_max(&ctx.lut[w], v)
#define PYR_TEXEL_WORD(i) ctx.lut[i]
#define PYR_STORE_TEXEL_WORD(i, v) (ctx.lut[i] = (v))
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

__global__ void all_passes(Ctx ctx, int* out) {
    const unsigned x = blockIdx.x * blockDim.x + threadIdx.x;
    const unsigned y = blockIdx.y * blockDim.y + threadIdx.y;
    PyrLevel lv{64u, 64u, 0u};
    const PyrIVec3 q = pyr_normal_q(ctx, 64u, 64u, x, y, 1u);
    const PyrQuant qu = pyr_quantize(1.0f, 2.0f, 3.0f, 0.0f, 0.0f, -1.0f);
    unsigned r = pyr_metric_fillable(ctx, 64u, 64u, x, y, 100, 1.0f);
    r += pyr_metric_robust_fillable(ctx, 64u, 64u, x, y, 4u, 100.0f, 0.5f, 1.0f, 0.25f);
    r += PYR_U32(pyr_robust_normal_q(ctx, 64u, 64u, x, y, 3u, 16.0f).z);
    pyr_robust_texel_store(ctx, y * 64u + x, pyr_robust_texel(ctx, 64u, 64u, x, y, 1u, 16.0f));
    r += pyr_mip_texel(ctx, lv, x, y);
    r += pyr_label_init_texel(ctx, lv, lv, x, y, PYR_INIT_NEW);
    r += pyr_sweep_line(ctx, y * 64u, 1u, 64u, 0u);
    r += pyr_anchor_mask(1u, 2u, 3u) + pyr_fill_relax(1u, 1u, 2u, 1u) + pyr_fill_once(0u, 1u, 1u);
    r += pyr_edge_label(ctx, lv, x, y, 2u);
    r += PYR_U32(PYR_FLOAT_BITS(pyr_depth_point(x, PYR_DEPTH_F32, 0.5f, 0.25f, -0.25f).x));
    r += pyr_compact_label(ctx, 3u);
    r += pyr_sweep_row(ctx, lv, y, 0u) + pyr_sweep_column(ctx, lv, x, 1u);
    r += pyr_count_marks(ctx, 0u, 64u);
    pyr_number_marks(ctx, 0u, 64u, r);
    pyr_stats_row_run(ctx, lv, y, 0u, 64u, 1u, 16.0f, 128u, 64u);
    pyr_stats_run(ctx, lv, x, 0u, 16.0f, 128u, 64u);
    out[y * 64u + x] = q.x + qu.qz + static_cast<int>(r);
}
