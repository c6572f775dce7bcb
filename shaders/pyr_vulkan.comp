#version 450
/* GLSL compute entry points of every pass: thin wrappers over the shared pass functions (shaders/pyr_*.h).
 * The build compiles this file once per entry point, with -DPYR_ENTRY_<NAME>, to SPIR-V (glslangValidator), checks
 * it with spirv-val and embeds it (cmake/CompileSpirv.cmake). Every module sees the same descriptor set, bound once
 * per Segmenter; per-dispatch values come as push constants, whose first member is always the image width.
 * 1D entry points take their index over a 2D grid of workgroups, because a device may allow only 65535 groups per
 * dimension (backends/vulkan/vulkan_backend.cpp dispatches them so). */
#extension GL_GOOGLE_include_directive : require
#define PYR_GLSL 1

layout(std430, set = 0, binding = 0) readonly buffer PyrPointsBuf { float pyr_buf_points[]; };
layout(std430, set = 0, binding = 1) buffer PyrNormalsBuf { float pyr_buf_normals[]; };
layout(std430, set = 0, binding = 2) buffer PyrQuantBuf { int pyr_buf_quant[]; };
layout(std430, set = 0, binding = 3) buffer PyrMaskBuf { uint pyr_buf_mask[]; }; /* one uint per texel */
layout(std430, set = 0, binding = 4) buffer PyrLabelsBuf { uint pyr_buf_labels[]; };
layout(std430, set = 0, binding = 5) buffer PyrLutBuf { uint pyr_buf_lut[]; }; /* then the statistics words */
layout(std430, set = 0, binding = 6) buffer PyrSumsBuf { uint pyr_buf_sums[]; };   /* compaction scan; K last */
layout(std430, set = 0, binding = 7) buffer PyrFlagsBuf { uint pyr_buf_flags[]; }; /* fill convergence */
layout(std430, set = 0, binding = 8) buffer PyrOutBuf { uint pyr_buf_out[]; };     /* compacted labels */

#define PYR_CTX_PARAM uint pyr_w
#define PYR_CTX_ARG pyr_w
#define PYR_PT(x, y, c) pyr_buf_points[((y) * pyr_w + (x)) * 3u + (c)]
#define PYR_Q_VALID(i) uint(pyr_buf_quant[(i) * 4u + 3u])
#define PYR_QN(i, c) pyr_buf_quant[(i) * 4u + (c)]
#define PYR_QZ(i) pyr_buf_points[(i) * 3u + 2u]
#define PYR_MASK(i) pyr_buf_mask[i]
#define PYR_LABEL(i) pyr_buf_labels[i]
#define PYR_STORE_LABEL(i, v) (pyr_buf_labels[i] = (v))
#define PYR_VALID(p) uint(pyr_buf_quant[(p) * 4u + 3u])
#define PYR_LUT(l) pyr_buf_lut[l]
#define PYR_STORE_LUT(l, v) (pyr_buf_lut[l] = (v))
#define PYR_STATS_ADD(w, v) atomicAdd(pyr_buf_lut[w], (v))
#define PYR_STATS_MAX(w, v) atomicMax(pyr_buf_lut[w], (v))

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

#define PYR_GROUP_1D 64u
#define PYR_GROUP_2D 8u
#define PYR_LINEAR_ID (gl_GlobalInvocationID.y * gl_NumWorkGroups.x * PYR_GROUP_1D + gl_GlobalInvocationID.x)

#if defined(PYR_ENTRY_NORMALS)
layout(local_size_x = PYR_GROUP_2D, local_size_y = PYR_GROUP_2D) in;
layout(push_constant) uniform PyrArgs { uint w; uint h; uint radius; } args;
void main() {
    uint pyr_w = args.w;
    uint x = gl_GlobalInvocationID.x;
    uint y = gl_GlobalInvocationID.y;
    if (x >= pyr_w || y >= args.h) return;
    PyrIVec3 q = pyr_normal_q(PYR_CTX_ARG, pyr_w, args.h, x, y, args.radius);
    uint i = y * pyr_w + x;
    pyr_buf_normals[i * 3u + 0u] = float(q.x) * PYR_NORMAL_UNIT;
    pyr_buf_normals[i * 3u + 1u] = float(q.y) * PYR_NORMAL_UNIT;
    pyr_buf_normals[i * 3u + 2u] = float(q.z) * PYR_NORMAL_UNIT;
}

#elif defined(PYR_ENTRY_QUANTIZE)
layout(local_size_x = PYR_GROUP_1D) in;
layout(push_constant) uniform PyrArgs { uint w; uint pixels; } args;
void main() {
    uint i = PYR_LINEAR_ID;
    if (i >= args.pixels) return;
    PyrQuant q = pyr_quantize(pyr_buf_points[i * 3u], pyr_buf_points[i * 3u + 1u], pyr_buf_points[i * 3u + 2u],
                              pyr_buf_normals[i * 3u], pyr_buf_normals[i * 3u + 1u], pyr_buf_normals[i * 3u + 2u]);
    pyr_buf_quant[i * 4u + 0u] = q.qx;
    pyr_buf_quant[i * 4u + 1u] = q.qy;
    pyr_buf_quant[i * 4u + 2u] = q.qz;
    pyr_buf_quant[i * 4u + 3u] = int(q.valid);
}

#elif defined(PYR_ENTRY_METRIC)
layout(local_size_x = PYR_GROUP_2D, local_size_y = PYR_GROUP_2D) in;
layout(push_constant) uniform PyrArgs { uint w; uint h; uint offset; int tc; float dt; } args;
void main() {
    uint pyr_w = args.w;
    uint x = gl_GlobalInvocationID.x;
    uint y = gl_GlobalInvocationID.y;
    if (x >= pyr_w || y >= args.h) return;
    pyr_buf_mask[args.offset + y * pyr_w + x] = pyr_metric_fillable(PYR_CTX_ARG, pyr_w, args.h, x, y, args.tc, args.dt);
}

#elif defined(PYR_ENTRY_BIND_MASK)
/* The caller's mask arrives in binding 0, one uint per pixel: bit 0 fillable, bit 1 valid. */
layout(std430, set = 0, binding = 0) readonly buffer PyrMaskInputBuf { uint pyr_buf_mask_input[]; };
layout(local_size_x = PYR_GROUP_1D) in;
layout(push_constant) uniform PyrArgs { uint w; uint pixels; uint offset; } args;
void main() {
    uint i = PYR_LINEAR_ID;
    if (i >= args.pixels) return;
    uint packed = pyr_buf_mask_input[i];
    pyr_buf_mask[args.offset + i] = packed & 1u;
    pyr_buf_quant[i * 4u + 3u] = int((packed >> 1u) & 1u);
}

#elif defined(PYR_ENTRY_MIP)
layout(local_size_x = PYR_GROUP_2D, local_size_y = PYR_GROUP_2D) in;
layout(push_constant) uniform PyrArgs { uint w; uint pw; uint ph; uint poffset; uint cw; uint ch; uint coffset; } args;
void main() {
    uint pyr_w = args.w;
    uint x = gl_GlobalInvocationID.x;
    uint y = gl_GlobalInvocationID.y;
    if (x >= args.pw || y >= args.ph) return;
    pyr_buf_mask[args.poffset + y * args.pw + x] =
        pyr_mip_texel(PYR_CTX_ARG, pyr_level(args.cw, args.ch, args.coffset), x, y);
}

#elif defined(PYR_ENTRY_INIT_LABELS)
layout(local_size_x = PYR_GROUP_2D, local_size_y = PYR_GROUP_2D) in;
layout(push_constant) uniform PyrArgs {
    uint w;
    uint lw;
    uint lh;
    uint loffset;
    uint pw;
    uint ph;
    uint poffset;
    uint mode;
} args;
void main() {
    uint pyr_w = args.w;
    uint x = gl_GlobalInvocationID.x;
    uint y = gl_GlobalInvocationID.y;
    if (x >= args.lw || y >= args.lh) return;
    pyr_buf_labels[args.loffset + y * args.lw + x] =
        pyr_label_init_texel(PYR_CTX_ARG, pyr_level(args.lw, args.lh, args.loffset),
                             pyr_level(args.pw, args.ph, args.poffset), x, y, args.mode);
}

#elif defined(PYR_ENTRY_ANCHOR)
layout(local_size_x = PYR_GROUP_1D) in;
layout(push_constant) uniform PyrArgs { uint w; uint offset; uint count; uint anchor_max; } args;
void main() {
    uint i = PYR_LINEAR_ID;
    if (i >= args.count) return;
    i += args.offset;
    pyr_buf_mask[i] = pyr_anchor_mask(pyr_buf_mask[i], pyr_buf_labels[i], args.anchor_max);
}

#elif defined(PYR_ENTRY_SWEEP_ROWS) || defined(PYR_ENTRY_SWEEP_COLUMNS)
/* One invocation per line: there and back. A round (rows, then columns) sets flags[slot] when a label changed.
 * Rounds are recorded ahead in one command buffer; a round whose predecessor (flags[slot - 1]) changed nothing
 * has reached the fixed point already and returns at once. */
layout(local_size_x = PYR_GROUP_1D) in;
layout(push_constant) uniform PyrArgs { uint w; uint lw; uint lh; uint loffset; uint once; uint slot; uint first; } args;
void main() {
    uint pyr_w = args.w;
    uint line = PYR_LINEAR_ID;
    if (args.slot != args.first && pyr_buf_flags[args.slot - 1u] == 0u) return;
    PyrLevel lv = pyr_level(args.lw, args.lh, args.loffset);
#if defined(PYR_ENTRY_SWEEP_ROWS)
    if (line >= args.lh) return;
    uint ch = pyr_sweep_row(PYR_CTX_ARG, lv, line, args.once);
#else
    if (line >= args.lw) return;
    uint ch = pyr_sweep_column(PYR_CTX_ARG, lv, line, args.once);
#endif
    if (ch != 0u) pyr_buf_flags[args.slot] = 1u;
}

#elif defined(PYR_ENTRY_EDGES)
/* In place: only valid, non-fillable, unlabelled pixels change, and no pixel reads those. */
layout(local_size_x = PYR_GROUP_2D, local_size_y = PYR_GROUP_2D) in;
layout(push_constant) uniform PyrArgs { uint w; uint h; uint offset; } args;
void main() {
    uint pyr_w = args.w;
    uint x = gl_GlobalInvocationID.x;
    uint y = gl_GlobalInvocationID.y;
    if (x >= pyr_w || y >= args.h) return;
    uint i = args.offset + y * pyr_w + x;
    uint l = pyr_edge_label(PYR_CTX_ARG, pyr_level(pyr_w, args.h, args.offset), x, y);
    if (l != pyr_buf_labels[i]) pyr_buf_labels[i] = l;
}

#elif defined(PYR_ENTRY_LUT_MARK)
/* Every invocation that marks a label writes the same value: the race is benign. */
layout(local_size_x = PYR_GROUP_1D) in;
layout(push_constant) uniform PyrArgs { uint w; uint pixels; uint offset; } args;
void main() {
    uint i = PYR_LINEAR_ID;
    if (i >= args.pixels) return;
    uint l = pyr_buf_labels[args.offset + i];
    if (l != 0u) pyr_buf_lut[l] = 1u;
}

#elif defined(PYR_ENTRY_SCAN_COUNT)
/* Marks to new ids 1..K in three steps: count marks per chunk, scan the chunk counts, number within chunks. */
layout(local_size_x = PYR_GROUP_1D) in;
layout(push_constant) uniform PyrArgs { uint w; uint count; uint chunk; uint chunks; } args;
void main() {
    uint pyr_w = args.w;
    uint c = PYR_LINEAR_ID;
    if (c >= args.chunks) return;
    uint begin = c * args.chunk;
    pyr_buf_sums[c] = pyr_count_marks(PYR_CTX_ARG, begin, min(args.count, begin + args.chunk));
}

#elif defined(PYR_ENTRY_SCAN_SUMS)
layout(local_size_x = 1) in;
layout(push_constant) uniform PyrArgs { uint w; uint chunks; } args;
void main() {
    uint running = 0u;
    for (uint c = 0u; c < args.chunks; ++c) {
        uint n = pyr_buf_sums[c];
        pyr_buf_sums[c] = running;
        running += n;
    }
    pyr_buf_sums[args.chunks] = running; /* K */
}

#elif defined(PYR_ENTRY_SCAN_NUMBER)
layout(local_size_x = PYR_GROUP_1D) in;
layout(push_constant) uniform PyrArgs { uint w; uint count; uint chunk; uint chunks; } args;
void main() {
    uint pyr_w = args.w;
    uint c = PYR_LINEAR_ID;
    if (c >= args.chunks) return;
    uint begin = c * args.chunk;
    pyr_number_marks(PYR_CTX_ARG, begin, min(args.count, begin + args.chunk), pyr_buf_sums[c]);
}

#elif defined(PYR_ENTRY_COMPACT)
layout(local_size_x = PYR_GROUP_1D) in;
layout(push_constant) uniform PyrArgs { uint w; uint pixels; uint offset; uint apply; } args;
void main() {
    uint pyr_w = args.w;
    uint i = PYR_LINEAR_ID;
    if (i >= args.pixels) return;
    uint raw = pyr_buf_labels[args.offset + i];
    pyr_buf_out[i] = args.apply != 0u ? pyr_compact_label(PYR_CTX_ARG, raw) : raw;
}

#elif defined(PYR_ENTRY_STATS)
/* The statistics words follow the label table in binding 5, from word args.base. */
layout(local_size_x = PYR_GROUP_1D) in;
layout(push_constant) uniform PyrArgs {
    uint w;
    uint h;
    uint offset;
    uint runs;
    uint with_points;
    float point_scale;
    uint base;
    uint slots;
} args;
void main() {
    uint pyr_w = args.w;
    uint run = PYR_LINEAR_ID;
    if (run >= args.runs) return;
    pyr_stats_run(PYR_CTX_ARG, pyr_level(pyr_w, args.h, args.offset), run, args.with_points, args.point_scale,
                  args.base, args.slots);
}

#else
#error "define one PYR_ENTRY_<NAME> (cmake/CompileSpirv.cmake does)"
#endif
