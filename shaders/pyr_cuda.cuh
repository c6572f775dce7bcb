/* CUDA entry points of every pass: thin __global__ wrappers over the shared pass functions (shaders/pyr_*.h).
 * Every kernel takes the Segmenter's buffers as one PyrCudaCtx by value; the host (backends/cuda/cuda_backend.cu)
 * launches them on its stream. Compiled with --fmad=false: no float contraction anywhere. */
#ifndef PYR_CUDA_CUH
#define PYR_CUDA_CUH

struct PyrCudaCtx {
    const float* points;
    float* normals;
    int* quant;
    unsigned char* mask;
    unsigned* labels;
    unsigned* lut;
    unsigned* stats; /* the statistics words, PYR_STATS_WORDS per slot */
    unsigned w;
};

#define PYR_CTX_PARAM const PyrCudaCtx& pyr_ctx
#define PYR_CTX_ARG pyr_ctx
#define PYR_PT(x, y, c) pyr_ctx.points[((y)*pyr_ctx.w + (x)) * 3u + (c)]
#define PYR_Q_VALID(i) static_cast<unsigned>(pyr_ctx.quant[(i)*4u + 3u])
#define PYR_QN(i, c) pyr_ctx.quant[(i)*4u + (c)]
#define PYR_QZ(i) pyr_ctx.points[(i)*3u + 2u]
#define PYR_MASK(i) static_cast<unsigned>(pyr_ctx.mask[i])
#define PYR_LABEL(i) pyr_ctx.labels[i]
#define PYR_STORE_LABEL(i, v) (pyr_ctx.labels[i] = (v))
#define PYR_VALID(p) static_cast<unsigned>(pyr_ctx.quant[(p)*4u + 3u])
#define PYR_LUT(l) pyr_ctx.lut[l]
#define PYR_STORE_LUT(l, v) (pyr_ctx.lut[l] = (v))
#define PYR_STATS_ADD(w, v) pyr_cuda_atomic_add(&pyr_ctx.stats[w], (v))
#define PYR_STATS_MAX(w, v) pyr_cuda_atomic_max(&pyr_ctx.stats[w], (v))

#include "pyr_compact.h"
#include "pyr_edges.h"
#include "pyr_fill.h"
#include "pyr_labels.h"
#include "pyr_metric.h"
#include "pyr_mip.h"
#include "pyr_normals.h"
#include "pyr_quantize.h"
#include "pyr_scan.h"
#include "pyr_stats.h"

/* 1D kernels index over blockIdx.y * gridDim.x blocks too: a grid may hold at most 65535 blocks in y, but the
 * host keeps x below 2^31 - 1, so any frame pyrseg accepts fits. */
__device__ __forceinline__ unsigned pyr_linear_id() {
    return (blockIdx.y * gridDim.x + blockIdx.x) * blockDim.x + threadIdx.x;
}

__global__ void pyr_k_normals(PyrCudaCtx pyr_ctx, unsigned h, unsigned radius) {
    const unsigned x = blockIdx.x * blockDim.x + threadIdx.x;
    const unsigned y = blockIdx.y * blockDim.y + threadIdx.y;
    if (x >= pyr_ctx.w || y >= h) return;
    const PyrIVec3 q = pyr_normal_q(PYR_CTX_ARG, pyr_ctx.w, h, x, y, radius);
    const unsigned i = y * pyr_ctx.w + x;
    pyr_ctx.normals[i * 3u + 0u] = static_cast<float>(q.x) * PYR_NORMAL_UNIT;
    pyr_ctx.normals[i * 3u + 1u] = static_cast<float>(q.y) * PYR_NORMAL_UNIT;
    pyr_ctx.normals[i * 3u + 2u] = static_cast<float>(q.z) * PYR_NORMAL_UNIT;
}

__global__ void pyr_k_quantize(PyrCudaCtx pyr_ctx, unsigned pixels) {
    const unsigned i = pyr_linear_id();
    if (i >= pixels) return;
    const float* p = pyr_ctx.points + i * 3u;
    const float* n = pyr_ctx.normals + i * 3u;
    const PyrQuant q = pyr_quantize(p[0], p[1], p[2], n[0], n[1], n[2]);
    pyr_ctx.quant[i * 4u + 0u] = q.qx;
    pyr_ctx.quant[i * 4u + 1u] = q.qy;
    pyr_ctx.quant[i * 4u + 2u] = q.qz;
    pyr_ctx.quant[i * 4u + 3u] = static_cast<int>(q.valid);
}

__global__ void pyr_k_metric(PyrCudaCtx pyr_ctx, unsigned h, unsigned offset, int tc, float dt) {
    const unsigned x = blockIdx.x * blockDim.x + threadIdx.x;
    const unsigned y = blockIdx.y * blockDim.y + threadIdx.y;
    if (x >= pyr_ctx.w || y >= h) return;
    pyr_ctx.mask[offset + y * pyr_ctx.w + x] =
        static_cast<unsigned char>(pyr_metric_fillable(PYR_CTX_ARG, pyr_ctx.w, h, x, y, tc, dt));
}

/* The caller's mask: staging holds (fillable, valid) byte pairs per pixel. */
__global__ void pyr_k_bind_mask(PyrCudaCtx pyr_ctx, const unsigned char* staging, unsigned pixels, unsigned offset) {
    const unsigned i = pyr_linear_id();
    if (i >= pixels) return;
    pyr_ctx.mask[offset + i] = staging[2u * i] != 0 ? 1 : 0;
    pyr_ctx.quant[i * 4u + 3u] = staging[2u * i + 1u] != 0 ? 1 : 0;
}

__global__ void pyr_k_mip(PyrCudaCtx pyr_ctx, PyrLevel parent, PyrLevel child) {
    const unsigned x = blockIdx.x * blockDim.x + threadIdx.x;
    const unsigned y = blockIdx.y * blockDim.y + threadIdx.y;
    if (x >= parent.width || y >= parent.height) return;
    pyr_ctx.mask[parent.offset + y * parent.width + x] =
        static_cast<unsigned char>(pyr_mip_texel(PYR_CTX_ARG, child, x, y));
}

__global__ void pyr_k_init_labels(PyrCudaCtx pyr_ctx, PyrLevel level, PyrLevel parent, unsigned mode) {
    const unsigned x = blockIdx.x * blockDim.x + threadIdx.x;
    const unsigned y = blockIdx.y * blockDim.y + threadIdx.y;
    if (x >= level.width || y >= level.height) return;
    pyr_ctx.labels[level.offset + y * level.width + x] = pyr_label_init_texel(PYR_CTX_ARG, level, parent, x, y, mode);
}

__global__ void pyr_k_anchor(PyrCudaCtx pyr_ctx, unsigned offset, unsigned count, unsigned anchor_max) {
    unsigned i = pyr_linear_id();
    if (i >= count) return;
    i += offset;
    pyr_ctx.mask[i] = static_cast<unsigned char>(pyr_anchor_mask(pyr_ctx.mask[i], pyr_ctx.labels[i], anchor_max));
}

/* One thread per line, there and back. Rounds are launched ahead in batches: round `slot` sets flags[slot] when it
 * changed a label, and returns at once when round slot - 1 of the same batch (from `first`) changed nothing. */
__global__ void pyr_k_sweep_rows(PyrCudaCtx pyr_ctx, PyrLevel level, unsigned once, unsigned* flags, unsigned slot,
                                 unsigned first) {
    const unsigned y = pyr_linear_id();
    if (y >= level.height || (slot != first && flags[slot - 1u] == 0u)) return;
    if (pyr_sweep_row(PYR_CTX_ARG, level, y, once) != 0u) flags[slot] = 1u;
}

__global__ void pyr_k_sweep_columns(PyrCudaCtx pyr_ctx, PyrLevel level, unsigned once, unsigned* flags, unsigned slot,
                                    unsigned first) {
    const unsigned x = pyr_linear_id();
    if (x >= level.width || (slot != first && flags[slot - 1u] == 0u)) return;
    if (pyr_sweep_column(PYR_CTX_ARG, level, x, once) != 0u) flags[slot] = 1u;
}

/* In place: only valid, non-fillable, unlabelled pixels change, and no pixel reads those. */
__global__ void pyr_k_edges(PyrCudaCtx pyr_ctx, PyrLevel full) {
    const unsigned x = blockIdx.x * blockDim.x + threadIdx.x;
    const unsigned y = blockIdx.y * blockDim.y + threadIdx.y;
    if (x >= full.width || y >= full.height) return;
    const unsigned i = full.offset + y * full.width + x;
    const unsigned l = pyr_edge_label(PYR_CTX_ARG, full, x, y);
    if (l != pyr_ctx.labels[i]) pyr_ctx.labels[i] = l;
}

/* Every thread that marks a label writes the same value: the race is benign. */
__global__ void pyr_k_lut_mark(PyrCudaCtx pyr_ctx, unsigned pixels, unsigned offset) {
    const unsigned i = pyr_linear_id();
    if (i >= pixels) return;
    const unsigned l = pyr_ctx.labels[offset + i];
    if (l != 0u) pyr_ctx.lut[l] = 1u;
}

__global__ void pyr_k_scan_count(PyrCudaCtx pyr_ctx, unsigned count, unsigned chunk, unsigned chunks, unsigned* sums) {
    const unsigned c = pyr_linear_id();
    if (c >= chunks) return;
    const unsigned begin = c * chunk;
    sums[c] = pyr_count_marks(PYR_CTX_ARG, begin, min(count, begin + chunk));
}

__global__ void pyr_k_scan_sums(unsigned* sums, unsigned chunks) {
    unsigned running = 0u;
    for (unsigned c = 0u; c < chunks; ++c) {
        const unsigned n = sums[c];
        sums[c] = running;
        running += n;
    }
    sums[chunks] = running; /* K */
}

__global__ void pyr_k_scan_number(PyrCudaCtx pyr_ctx, unsigned count, unsigned chunk, unsigned chunks,
                                  const unsigned* sums) {
    const unsigned c = pyr_linear_id();
    if (c >= chunks) return;
    const unsigned begin = c * chunk;
    pyr_number_marks(PYR_CTX_ARG, begin, min(count, begin + chunk), sums[c]);
}

__global__ void pyr_k_compact(PyrCudaCtx pyr_ctx, unsigned pixels, unsigned offset, unsigned apply, unsigned* out) {
    const unsigned i = pyr_linear_id();
    if (i >= pixels) return;
    const unsigned raw = pyr_ctx.labels[offset + i];
    out[i] = apply != 0u ? pyr_compact_label(PYR_CTX_ARG, raw) : raw;
}

__global__ void pyr_k_stats(PyrCudaCtx pyr_ctx, PyrLevel full, unsigned runs, unsigned with_points, float point_scale,
                            unsigned slots) {
    const unsigned run = pyr_linear_id();
    if (run >= runs) return;
    pyr_stats_run(PYR_CTX_ARG, full, run, with_points, point_scale, 0u, slots);
}

#endif /* PYR_CUDA_CUH */
