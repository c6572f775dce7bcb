/* OpenCL C 1.2: the dialect of the entry points (shaders/pyr_entries.h). Every kernel takes the Segmenter's buffers
 * (the buffer table, pyr_buffers.h) and the image width first (PYR_CTX_PARAM, set once per Segmenter by the host),
 * then one PyrArgs by value. */
#include "pyr_kernels.h"

#define PYR_CL_F32 float
#define PYR_CL_U32 uint
#define PYR_CL_MASK uchar
#define PYR_CL_BUFFER_PARAM(name, index, TYPE, QUAL) __global PYR_CL_##TYPE *pyr_buf_##name,
#define PYR_CL_BUFFER_ARG(name, index, TYPE, QUAL) pyr_buf_##name,
#define PYR_CTX_PARAM PYR_BUFFER_TABLE(PYR_CL_BUFFER_PARAM) uint pyr_w
#define PYR_CTX_ARG PYR_BUFFER_TABLE(PYR_CL_BUFFER_ARG) pyr_w
#define PYR_BUF(name) pyr_buf_##name
#define PYR_PT(x, y, c) pyr_buf_points[((y)*pyr_w + (x)) * 3u + (c)]
#define PYR_TEXEL_WORD(i) pyr_buf_texels[i]
#define PYR_STORE_TEXEL_WORD(i, v) (pyr_buf_texels[i] = (v))
#define PYR_Q_VALID(i) (pyr_buf_quant[(i)*2u + 1u] >> 16u)
#define PYR_QN(i, c) pyr_unpack_q16(pyr_buf_quant[(i)*2u + ((uint)(c) >> 1u)] >> (((uint)(c)&1u) * 16u))
#define PYR_QZ(i) pyr_buf_points[(i)*3u + 2u]
#define PYR_MASK(i) ((uint)pyr_buf_mask[i])
#define PYR_COLOR_WORD(j) pyr_buf_color[j]
#define PYR_LABEL(i) pyr_buf_labels[i]
#define PYR_STORE_LABEL(i, v) (pyr_buf_labels[i] = (v))
#define PYR_VALID(p) (pyr_buf_quant[(p)*2u + 1u] >> 16u)
#define PYR_LUT(l) pyr_buf_lut[l]
#define PYR_STORE_LUT(l, v) (pyr_buf_lut[l] = (v))
/* The statistics words follow the label table in its buffer (the host passes where they start). */
#define PYR_STATS_ADD(w, v) atomic_add(&pyr_buf_lut[w], (v))
#define PYR_STATS_MAX(w, v) atomic_max(&pyr_buf_lut[w], (v))

#include "pyr_passes.h"

typedef struct PyrArgs {
    uint a[PYR_ARG_WORDS];
} PyrArgs;

#define PYR_KERNEL_1D(name) __kernel void pyr_k_##name(PYR_CTX_PARAM, PyrArgs pyr_args)
#define PYR_KERNEL_2D(name) __kernel void pyr_k_##name(PYR_CTX_PARAM, PyrArgs pyr_args)
#define PYR_KERNEL_GROUPS(name) __kernel void pyr_k_##name(PYR_CTX_PARAM, PyrArgs pyr_args)
#define PYR_I ((uint)(get_global_id(1) * get_global_size(0) + get_global_id(0)))
#define PYR_GID ((uint)(get_group_id(1) * get_num_groups(0) + get_group_id(0)))
#define PYR_LID ((uint)get_local_id(0))
#define PYR_LSIZE ((uint)get_local_size(0))
#define PYR_GROUP_SHARED(type, name, count)
#define PYR_LOCAL_SHARED(type, name, count) __local type name[count];
#define PYR_BARRIER() barrier(CLK_LOCAL_MEM_FENCE)
#define PYR_X ((uint)get_global_id(0))
#define PYR_Y ((uint)get_global_id(1))
#define PYR_ARG(k) pyr_args.a[k]
#define PYR_ARG_I32(k) as_int(pyr_args.a[k])
#define PYR_ARG_F32(k) as_float(pyr_args.a[k])
#define PYR_W pyr_w
#define PYR_ENTRY_CTX PYR_CTX_ARG
#define PYR_STORE_MASK(i, v) (pyr_buf_mask[i] = (uchar)(v))
#define PYR_POINT(k) pyr_buf_points[k]
#define PYR_NORMAL(k) pyr_buf_normals[k]
#define PYR_STORE_NORMAL(k, v) (pyr_buf_normals[k] = (v))
#define PYR_STORE_POINT(k, v) (pyr_buf_points[k] = (v))
#define PYR_MASK_INPUT(i) (((__global const uint*)pyr_buf_points)[i])
#define PYR_UF_LOAD(i) (((volatile __global uint*)pyr_buf_fill)[i])
#define PYR_UF_STORE(i, v) (pyr_buf_fill[i] = (v))
#define PYR_UF_MIN(i, v) atomic_min(&pyr_buf_fill[i], (v))
#define PYR_UF_CAS(i, e, v) atomic_cmpxchg(&pyr_buf_fill[i], (e), (v))
#define PYR_UF_ADD(i, v) atomic_add(&pyr_buf_fill[i], (v))
#define PYR_ENTRY_ALL 1

#include "pyr_entries.h"
