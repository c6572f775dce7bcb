/* OpenCL C 1.2 entry points of every pass: thin wrappers over the shared pass functions (shaders/pyr_*.h).
 * Every kernel takes the same leading arguments (PYR_CTX_PARAM: the Segmenter's buffers and the image width), so
 * the host binds them once per Segmenter and sets only the per-dispatch arguments that follow. */
#define PYR_CTX_PARAM                                                                                       \
    __global const float *pyr_buf_points, __global float *pyr_buf_normals, __global int *pyr_buf_quant,   \
        __global uchar *pyr_buf_mask, __global uint *pyr_buf_labels, __global uint *pyr_buf_lut, uint pyr_w
#define PYR_CTX_ARG pyr_buf_points, pyr_buf_normals, pyr_buf_quant, pyr_buf_mask, pyr_buf_labels, pyr_buf_lut, pyr_w
#define PYR_PT(x, y, c) pyr_buf_points[((y) * pyr_w + (x)) * 3u + (c)]
#define PYR_Q_VALID(i) ((uint)pyr_buf_quant[(i) * 4u + 3u])
#define PYR_QN(i, c) pyr_buf_quant[(i) * 4u + (c)]
#define PYR_QZ(i) pyr_buf_points[(i) * 3u + 2u]
#define PYR_MASK(i) ((uint)pyr_buf_mask[i])
#define PYR_LABEL(i) pyr_buf_labels[i]
#define PYR_STORE_LABEL(i, v) (pyr_buf_labels[i] = (v))
#define PYR_VALID(p) ((uint)pyr_buf_quant[(p) * 4u + 3u])
#define PYR_LUT(l) pyr_buf_lut[l]
#define PYR_STORE_LUT(l, v) (pyr_buf_lut[l] = (v))
/* The statistics words follow the label table in its buffer (the host passes where they start). */
#define PYR_STATS_ADD(w, v) atomic_add(&pyr_buf_lut[w], (v))
#define PYR_STATS_MAX(w, v) atomic_max(&pyr_buf_lut[w], (v))

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

__kernel void pyr_k_normals(PYR_CTX_PARAM, uint h, uint radius) {
    uint x = (uint)get_global_id(0);
    uint y = (uint)get_global_id(1);
    if (x >= pyr_w || y >= h) return;
    PyrIVec3 q = pyr_normal_q(PYR_CTX_ARG, pyr_w, h, x, y, radius);
    uint i = y * pyr_w + x;
    pyr_buf_normals[i * 3u + 0u] = (float)q.x * PYR_NORMAL_UNIT;
    pyr_buf_normals[i * 3u + 1u] = (float)q.y * PYR_NORMAL_UNIT;
    pyr_buf_normals[i * 3u + 2u] = (float)q.z * PYR_NORMAL_UNIT;
}

__kernel void pyr_k_quantize(PYR_CTX_PARAM, uint pixels) {
    uint i = (uint)get_global_id(0);
    if (i >= pixels) return;
    PyrQuant q = pyr_quantize(pyr_buf_points[i * 3u], pyr_buf_points[i * 3u + 1u], pyr_buf_points[i * 3u + 2u],
                              pyr_buf_normals[i * 3u], pyr_buf_normals[i * 3u + 1u], pyr_buf_normals[i * 3u + 2u]);
    pyr_buf_quant[i * 4u + 0u] = q.qx;
    pyr_buf_quant[i * 4u + 1u] = q.qy;
    pyr_buf_quant[i * 4u + 2u] = q.qz;
    pyr_buf_quant[i * 4u + 3u] = (int)q.valid;
}

__kernel void pyr_k_metric(PYR_CTX_PARAM, uint h, uint offset, int tc, float dt) {
    uint x = (uint)get_global_id(0);
    uint y = (uint)get_global_id(1);
    if (x >= pyr_w || y >= h) return;
    pyr_buf_mask[offset + y * pyr_w + x] = (uchar)pyr_metric_fillable(PYR_CTX_ARG, pyr_w, h, x, y, tc, dt);
}

/* The caller's mask: staging holds (fillable, valid) byte pairs per pixel. */
__kernel void pyr_k_bind_mask(PYR_CTX_PARAM, __global const uchar *staging, uint pixels, uint offset) {
    uint i = (uint)get_global_id(0);
    if (i >= pixels) return;
    pyr_buf_mask[offset + i] = staging[2u * i] != 0 ? (uchar)1 : (uchar)0;
    pyr_buf_quant[i * 4u + 3u] = staging[2u * i + 1u] != 0 ? 1 : 0;
}

__kernel void pyr_k_mip(PYR_CTX_PARAM, uint pw, uint ph, uint poffset, uint cw, uint ch, uint coffset) {
    uint x = (uint)get_global_id(0);
    uint y = (uint)get_global_id(1);
    if (x >= pw || y >= ph) return;
    pyr_buf_mask[poffset + y * pw + x] = (uchar)pyr_mip_texel(PYR_CTX_ARG, pyr_level(cw, ch, coffset), x, y);
}

__kernel void pyr_k_init_labels(PYR_CTX_PARAM, uint lw, uint lh, uint loffset, uint pw, uint ph, uint poffset,
                                uint mode) {
    uint x = (uint)get_global_id(0);
    uint y = (uint)get_global_id(1);
    if (x >= lw || y >= lh) return;
    pyr_buf_labels[loffset + y * lw + x] =
        pyr_label_init_texel(PYR_CTX_ARG, pyr_level(lw, lh, loffset), pyr_level(pw, ph, poffset), x, y, mode);
}

__kernel void pyr_k_anchor(PYR_CTX_PARAM, uint offset, uint count, uint anchor_max) {
    uint i = (uint)get_global_id(0);
    if (i >= count) return;
    i += offset;
    pyr_buf_mask[i] = (uchar)pyr_anchor_mask(pyr_buf_mask[i], pyr_buf_labels[i], anchor_max);
}

/* One work-item per row: left to right, then right to left. changed[slot] is set when a label changed; the host
 * gives each iteration of a batch its own slot and reads them all at once. */
__kernel void pyr_k_sweep_rows(PYR_CTX_PARAM, uint lw, uint lh, uint loffset, uint once, __global int *changed,
                               uint slot) {
    uint y = (uint)get_global_id(0);
    if (y >= lh) return;
    if (pyr_sweep_row(PYR_CTX_ARG, pyr_level(lw, lh, loffset), y, once) != 0u) changed[slot] = 1;
}

/* One work-item per column (neighbouring work-items read neighbouring texels): down, then up. */
__kernel void pyr_k_sweep_columns(PYR_CTX_PARAM, uint lw, uint lh, uint loffset, uint once, __global int *changed,
                                  uint slot) {
    uint x = (uint)get_global_id(0);
    if (x >= lw) return;
    if (pyr_sweep_column(PYR_CTX_ARG, pyr_level(lw, lh, loffset), x, once) != 0u) changed[slot] = 1;
}

/* In place: only valid, non-fillable, unlabelled pixels change, and no pixel reads those. */
__kernel void pyr_k_edges(PYR_CTX_PARAM, uint h, uint offset) {
    uint x = (uint)get_global_id(0);
    uint y = (uint)get_global_id(1);
    if (x >= pyr_w || y >= h) return;
    uint i = offset + y * pyr_w + x;
    uint l = pyr_edge_label(PYR_CTX_ARG, pyr_level(pyr_w, h, offset), x, y);
    if (l != pyr_buf_labels[i]) pyr_buf_labels[i] = l;
}

__kernel void pyr_k_lut_clear(PYR_CTX_PARAM, uint count) {
    uint i = (uint)get_global_id(0);
    if (i < count) pyr_buf_lut[i] = 0u;
}

/* Every work-item that marks a label writes the same value: the race is benign. */
__kernel void pyr_k_lut_mark(PYR_CTX_PARAM, uint pixels, uint offset) {
    uint i = (uint)get_global_id(0);
    if (i >= pixels) return;
    uint l = pyr_buf_labels[offset + i];
    if (l != 0u) pyr_buf_lut[l] = 1u;
}

/* Marks to new ids 1..K in three steps: count marks per chunk, scan the chunk counts, number within chunks. */
__kernel void pyr_k_scan_count(PYR_CTX_PARAM, uint count, uint chunk, __global uint *sums) {
    uint c = (uint)get_global_id(0);
    uint begin = c * chunk;
    if (begin >= count) return;
    sums[c] = pyr_count_marks(PYR_CTX_ARG, begin, min(count, begin + chunk));
}

__kernel void pyr_k_scan_sums(__global uint *sums, uint chunks) {
    if (get_global_id(0) != 0) return;
    uint running = 0u;
    for (uint c = 0u; c < chunks; ++c) {
        uint n = sums[c];
        sums[c] = running;
        running += n;
    }
    sums[chunks] = running; /* K */
}

__kernel void pyr_k_scan_number(PYR_CTX_PARAM, uint count, uint chunk, __global const uint *sums) {
    uint c = (uint)get_global_id(0);
    uint begin = c * chunk;
    if (begin >= count) return;
    pyr_number_marks(PYR_CTX_ARG, begin, min(count, begin + chunk), sums[c]);
}

__kernel void pyr_k_compact(PYR_CTX_PARAM, uint pixels, uint offset, uint apply, __global uint *out) {
    uint i = (uint)get_global_id(0);
    if (i >= pixels) return;
    uint raw = pyr_buf_labels[offset + i];
    out[i] = apply != 0u ? pyr_compact_label(PYR_CTX_ARG, raw) : raw;
}

__kernel void pyr_k_stats(PYR_CTX_PARAM, uint h, uint offset, uint runs, uint with_points, float point_scale,
                          uint base, uint slots) {
    uint run = (uint)get_global_id(0);
    if (run >= runs) return;
    pyr_stats_run(PYR_CTX_ARG, pyr_level(pyr_w, h, offset), run, with_points, point_scale, base, slots);
}
