/* GLSL: the dialect's buffers, push constants and macros (shaders/pyr_vulkan.comp's entry points, and
 * tests/dialect/check.comp). The includer starts with #version 450 and GL_GOOGLE_include_directive, and defines
 * PYR_GLSL. Every module sees the same descriptor set, bound once per Segmenter: the buffer table's buffers
 * (pyr_buffers.h) at their indices, then the points' and normals' upper parts; per-dispatch values come as push
 * constants: the image width, then the PyrArgs words. 1D entry points take their index over a 2D grid of
 * workgroups, because a device may allow only 65535 groups per dimension (backends/vulkan/vulkan_device.cpp
 * dispatches them so). */
#ifndef PYR_GLSL_H
#define PYR_GLSL_H
#include "pyr_kernels.h"

#define PYR_GLSL_F32 float
#define PYR_GLSL_U32 uint
#define PYR_GLSL_MASK uint
#define PYR_GLSL_PLAIN
#define PYR_GLSL_COHERENT coherent
#define PYR_GLSL_BUFFER(name, index, TYPE, QUAL)                                    \
    layout(std430, set = 0, binding = index) PYR_GLSL_##QUAL buffer PyrBuf_##name { \
        PYR_GLSL_##TYPE pyr_buf_##name[];                                           \
    };
PYR_BUFFER_TABLE(PYR_GLSL_BUFFER)
#define PYR_BUF(name) pyr_buf_##name
/* The points and normals from float pyr_push.split on: the rest of the same buffers, bound from there when a frame's
 * xyz arrays exceed one binding's range (vulkan_device.cpp). */
layout(std430, set = 0, binding = PYR_BUFFER_COUNT) buffer PyrPointsHiBuf {
    float pyr_buf_points_hi[];
};
layout(std430, set = 0, binding = PYR_BUFFER_COUNT + 1) buffer PyrNormalsHiBuf {
    float pyr_buf_normals_hi[];
};
#if defined(PYR_ENTRY_BIND_MASK)
/* A mask frame's input words share binding 0 with the points (gpu_executor.cpp: bind_mask). */
layout(std430, set = 0, binding = 0) readonly buffer PyrMaskInputBuf {
    uint pyr_buf_mask_input[];
};
#endif

layout(push_constant) uniform PyrPush {
    uint w;
    uint a[PYR_ARG_WORDS];
    uint split;
}
pyr_push;

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
#define PYR_PT(x, y, c) pyr_point(((y)*pyr_w + (x)) * 3u + (c))
#define PYR_TEXEL_WORD(i) pyr_buf_texels[i]
#define PYR_STORE_TEXEL_WORD(i, v) (pyr_buf_texels[i] = (v))
#define PYR_Q_VALID(i) (pyr_buf_quant[(i)*2u + 1u] >> 16u)
#define PYR_QN(i, c) pyr_unpack_q16(pyr_buf_quant[(i)*2u + (uint(c) >> 1u)] >> ((uint(c) & 1u) * 16u))
#define PYR_QZ(i) pyr_point((i)*3u + 2u)
#define PYR_MASK(i) pyr_buf_mask[i]
#define PYR_COLOR_WORD(j) pyr_buf_color[j]
#define PYR_LABEL(i) pyr_buf_labels[i]
#define PYR_STORE_LABEL(i, v) (pyr_buf_labels[i] = (v))
#define PYR_VALID(p) (pyr_buf_quant[(p)*2u + 1u] >> 16u)
#define PYR_LUT(l) pyr_buf_lut[l]
#define PYR_STORE_LUT(l, v) (pyr_buf_lut[l] = (v))
#define PYR_STATS_ADD(w, v) atomicAdd(pyr_buf_lut[w], (v))
#define PYR_STATS_MAX(w, v) atomicMax(pyr_buf_lut[w], (v))

#include "pyr_passes.h"

#define PYR_KERNEL_1D(name)                 \
    layout(local_size_x = PYR_GROUP_1D) in; \
    void main()
#define PYR_KERNEL_2D(name)                                              \
    layout(local_size_x = PYR_GROUP_2D, local_size_y = PYR_GROUP_2D) in; \
    void main()
#define PYR_KERNEL_GROUPS(name)             \
    layout(local_size_x = PYR_GROUP_1D) in; \
    void main()
#define PYR_I (gl_GlobalInvocationID.y * gl_NumWorkGroups.x * PYR_GROUP_1D + gl_GlobalInvocationID.x)
#define PYR_GID (gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x)
#define PYR_LID gl_LocalInvocationID.x
#define PYR_LSIZE gl_WorkGroupSize.x
#define PYR_GROUP_SHARED(type, name, count) shared type name[count];
#define PYR_LOCAL_SHARED(type, name, count)
#define PYR_BARRIER()      \
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
#define PYR_UF_CAS(i, e, v) atomicCompSwap(pyr_buf_fill[i], (e), (v))
#define PYR_UF_ADD(i, v) atomicAdd(pyr_buf_fill[i], (v))

#endif /* PYR_GLSL_H */
