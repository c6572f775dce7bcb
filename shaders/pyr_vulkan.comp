#version 450
/* GLSL: the dialect of the entry points (shaders/pyr_entries.h). The build compiles this file once per kernel of
 * the table (shaders/pyr_kernels.h), with -DPYR_ENTRY_<NAME>, to SPIR-V (glslangValidator), checks it with spirv-val
 * and embeds it (cmake/CompileSpirv.cmake). Every module sees the same descriptor set, bound once per Segmenter;
 * per-dispatch values come as push constants: the image width, then the PyrArgs words.
 * 1D entry points take their index over a 2D grid of workgroups, because a device may allow only 65535 groups per
 * dimension (backends/vulkan/vulkan_backend.cpp dispatches them so). */
#extension GL_GOOGLE_include_directive : require
#define PYR_GLSL 1
#include "pyr_kernels.h"

layout(std430, set = 0, binding = 0) buffer PyrPointsBuf { float pyr_buf_points[]; }; /* depth frames write it */
layout(std430, set = 0, binding = 1) buffer PyrNormalsBuf { float pyr_buf_normals[]; };
layout(std430, set = 0, binding = 2) buffer PyrQuantBuf { uint pyr_buf_quant[]; }; /* two words per pixel */
layout(std430, set = 0, binding = 3) buffer PyrMaskBuf { uint pyr_buf_mask[]; }; /* one uint per texel */
layout(std430, set = 0, binding = 4) buffer PyrLabelsBuf { uint pyr_buf_labels[]; };
layout(std430, set = 0, binding = 5) buffer PyrLutBuf { uint pyr_buf_lut[]; }; /* then the statistics words */
layout(std430, set = 0, binding = 6) buffer PyrSumsBuf { uint pyr_buf_sums[]; };   /* compaction scan; K last */
layout(std430, set = 0, binding = 7) coherent buffer PyrFillBuf { uint pyr_buf_fill[]; }; /* fills' union-find */
layout(std430, set = 0, binding = 8) buffer PyrOutBuf { uint pyr_buf_out[]; };     /* compacted labels */
layout(std430, set = 0, binding = 9) buffer PyrTexelsBuf { uint pyr_buf_texels[]; }; /* robust normals' texels */
/* The points and normals from float pyr_push.split on: the rest of the same buffers, bound from there when a frame's
 * xyz arrays exceed one binding's range (vulkan_backend.cpp). */
layout(std430, set = 0, binding = 10) buffer PyrPointsHiBuf { float pyr_buf_points_hi[]; };
layout(std430, set = 0, binding = 11) buffer PyrNormalsHiBuf { float pyr_buf_normals_hi[]; };
#if defined(PYR_ENTRY_BIND_MASK)
/* A mask frame's input words share binding 0 with the points (gpu_executor.cpp: bind_mask). */
layout(std430, set = 0, binding = 0) readonly buffer PyrMaskInputBuf { uint pyr_buf_mask_input[]; };
#endif

layout(push_constant) uniform PyrPush {
    uint w;
    uint a[PYR_ARG_WORDS];
    uint split;
} pyr_push;

float pyr_point(uint k) {
    return k < pyr_push.split ? pyr_buf_points[k] : pyr_buf_points_hi[k - pyr_push.split];
}
float pyr_normal(uint k) {
    return k < pyr_push.split ? pyr_buf_normals[k] : pyr_buf_normals_hi[k - pyr_push.split];
}
void pyr_store_point(uint k, float v) {
    if (k < pyr_push.split) {
        pyr_buf_points[k] = v;
    } else {
        pyr_buf_points_hi[k - pyr_push.split] = v;
    }
}
void pyr_store_normal(uint k, float v) {
    if (k < pyr_push.split) {
        pyr_buf_normals[k] = v;
    } else {
        pyr_buf_normals_hi[k - pyr_push.split] = v;
    }
}

#define PYR_CTX_PARAM uint pyr_w
#define PYR_CTX_ARG pyr_w
#define PYR_PT(x, y, c) pyr_point(((y) * pyr_w + (x)) * 3u + (c))
#define PYR_TEXEL_WORD(i) pyr_buf_texels[i]
#define PYR_STORE_TEXEL_WORD(i, v) (pyr_buf_texels[i] = (v))
#define PYR_Q_VALID(i) (pyr_buf_quant[(i) * 2u + 1u] >> 16u)
#define PYR_QN(i, c) pyr_unpack_q16(pyr_buf_quant[(i) * 2u + (uint(c) >> 1u)] >> ((uint(c) & 1u) * 16u))
#define PYR_QZ(i) pyr_point((i) * 3u + 2u)
#define PYR_MASK(i) pyr_buf_mask[i]
#define PYR_LABEL(i) pyr_buf_labels[i]
#define PYR_STORE_LABEL(i, v) (pyr_buf_labels[i] = (v))
#define PYR_VALID(p) (pyr_buf_quant[(p) * 2u + 1u] >> 16u)
#define PYR_LUT(l) pyr_buf_lut[l]
#define PYR_STORE_LUT(l, v) (pyr_buf_lut[l] = (v))
#define PYR_STATS_ADD(w, v) atomicAdd(pyr_buf_lut[w], (v))
#define PYR_STATS_MAX(w, v) atomicMax(pyr_buf_lut[w], (v))

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

#define PYR_KERNEL_1D(name) layout(local_size_x = PYR_GROUP_1D) in; void main()
#define PYR_KERNEL_2D(name) layout(local_size_x = PYR_GROUP_2D, local_size_y = PYR_GROUP_2D) in; void main()
#define PYR_KERNEL_GROUPS(name) layout(local_size_x = PYR_GROUP_1D) in; void main()
#define PYR_I (gl_GlobalInvocationID.y * gl_NumWorkGroups.x * PYR_GROUP_1D + gl_GlobalInvocationID.x)
#define PYR_GID (gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x)
#define PYR_LID gl_LocalInvocationID.x
#define PYR_LSIZE gl_WorkGroupSize.x
#define PYR_GROUP_SHARED(type, name, count) shared type name[count];
#define PYR_LOCAL_SHARED(type, name, count)
#define PYR_BARRIER() \
    memoryBarrierShared(); \
    barrier()
#define PYR_X gl_GlobalInvocationID.x
#define PYR_Y gl_GlobalInvocationID.y
#define PYR_ARG(k) pyr_push.a[k]
#define PYR_ARG_I32(k) int(pyr_push.a[k])
#define PYR_ARG_F32(k) uintBitsToFloat(pyr_push.a[k])
#define PYR_W pyr_push.w
#define PYR_ENTRY_CTX pyr_push.w
#define PYR_STORE_MASK(i, v) (pyr_buf_mask[i] = (v))
#define PYR_MASK_INPUT(i) pyr_buf_mask_input[i]
#define PYR_POINT(k) pyr_point(k)
#define PYR_NORMAL(k) pyr_normal(k)
#define PYR_STORE_NORMAL(k, v) pyr_store_normal((k), (v))
#define PYR_STORE_POINT(k, v) pyr_store_point((k), (v))
#define PYR_UF_LOAD(i) pyr_buf_fill[i]
#define PYR_UF_STORE(i, v) (pyr_buf_fill[i] = (v))
#define PYR_UF_MIN(i, v) atomicMin(pyr_buf_fill[i], (v))

#include "pyr_entries.h"
