/* CUDA: the dialect of the entry points (shaders/pyr_entries.h). Every kernel takes the Segmenter's buffers (the buffer
 * table, pyr_buffers.h) as one PyrCudaCtx by value, then one PyrArgs; the host (backends/cuda/cuda_backend.cu) launches
 * them on its stream. Compiled with --fmad=false: no float contraction anywhere. */
#ifndef PYR_CUDA_CUH
#define PYR_CUDA_CUH

#include "pyr_kernels.h"

#define PYR_CUDA_F32 float
#define PYR_CUDA_U32 unsigned
#define PYR_CUDA_MASK unsigned char
/* The buffer table's buffers (pyr_buffers.h), in its order, then the image width. */
struct PyrCudaCtx {
#define PYR_CUDA_BUFFER_MEMBER(name, index, TYPE, QUAL) PYR_CUDA_##TYPE* name;
    PYR_BUFFER_TABLE(PYR_CUDA_BUFFER_MEMBER)
#undef PYR_CUDA_BUFFER_MEMBER
    unsigned w;
};

struct PyrArgs {
    unsigned a[PYR_ARG_WORDS];
};

#define PYR_CTX_PARAM const PyrCudaCtx& pyr_ctx
#define PYR_CTX_ARG pyr_ctx
#define PYR_PT(x, y, c) pyr_ctx.points[((y)*pyr_ctx.w + (x)) * 3u + (c)]
#define PYR_TEXEL_WORD(i) pyr_ctx.texels[i]
#define PYR_STORE_TEXEL_WORD(i, v) (pyr_ctx.texels[i] = (v))
#define PYR_Q_VALID(i) (pyr_ctx.quant[(i)*2u + 1u] >> 16u)
#define PYR_QN(i, c) \
    pyr_unpack_q16(pyr_ctx.quant[(i)*2u + (static_cast<unsigned>(c) >> 1u)] >> ((static_cast<unsigned>(c) & 1u) * 16u))
#define PYR_QZ(i) pyr_ctx.points[(i)*3u + 2u]
#define PYR_MASK(i) static_cast<unsigned>(pyr_ctx.mask[i])
#define PYR_COLOR_WORD(j) pyr_ctx.color[j]
#define PYR_LABEL(i) pyr_ctx.labels[i]
#define PYR_STORE_LABEL(i, v) (pyr_ctx.labels[i] = (v))
#define PYR_VALID(p) (pyr_ctx.quant[(p)*2u + 1u] >> 16u)
#define PYR_LUT(l) pyr_ctx.lut[l]
#define PYR_STORE_LUT(l, v) (pyr_ctx.lut[l] = (v))
#define PYR_STATS_ADD(w, v) pyr_cuda_atomic_add(&pyr_ctx.lut[w], (v))
#define PYR_STATS_MAX(w, v) pyr_cuda_atomic_max(&pyr_ctx.lut[w], (v))

#include "pyr_passes.h"

/* 1D kernels index over blockIdx.y * gridDim.x blocks too: a grid may hold at most 65535 blocks in y, but the
 * host keeps x below 2^31 - 1, so any frame pyrseg accepts fits. */
__device__ __forceinline__ unsigned pyr_linear_id() {
    return (blockIdx.y * gridDim.x + blockIdx.x) * blockDim.x + threadIdx.x;
}

#define PYR_BUF(name) pyr_ctx.name

#define PYR_KERNEL_1D(name) __global__ void pyr_k_##name(PyrCudaCtx pyr_ctx, PyrArgs pyr_args)
#define PYR_KERNEL_2D(name) __global__ void pyr_k_##name(PyrCudaCtx pyr_ctx, PyrArgs pyr_args)
#define PYR_KERNEL_GROUPS(name) __global__ void pyr_k_##name(PyrCudaCtx pyr_ctx, PyrArgs pyr_args)
#define PYR_I pyr_linear_id()
#define PYR_GID (blockIdx.y * gridDim.x + blockIdx.x)
#define PYR_LID threadIdx.x
#define PYR_LSIZE blockDim.x
#define PYR_GROUP_SHARED(type, name, count)
#define PYR_LOCAL_SHARED(type, name, count) __shared__ type name[count];
#define PYR_BARRIER() __syncthreads()
#define PYR_X (blockIdx.x * blockDim.x + threadIdx.x)
#define PYR_Y (blockIdx.y * blockDim.y + threadIdx.y)
#define PYR_ARG(k) pyr_args.a[k]
#define PYR_ARG_I32(k) static_cast<int>(pyr_args.a[k])
#define PYR_ARG_F32(k) __uint_as_float(pyr_args.a[k])
#define PYR_W pyr_ctx.w
#define PYR_ENTRY_CTX pyr_ctx
#define PYR_STORE_MASK(i, v) (pyr_ctx.mask[i] = static_cast<unsigned char>(v))
#define PYR_POINT(k) pyr_ctx.points[k]
#define PYR_NORMAL(k) pyr_ctx.normals[k]
#define PYR_STORE_NORMAL(k, v) (pyr_ctx.normals[k] = (v))
#define PYR_STORE_POINT(k, v) (pyr_ctx.points[k] = (v))
#define PYR_MASK_INPUT(i) (reinterpret_cast<const unsigned*>(pyr_ctx.points)[i])
#define PYR_UF_LOAD(i) (*static_cast<volatile unsigned*>(&pyr_ctx.fill[i]))
#define PYR_UF_STORE(i, v) (pyr_ctx.fill[i] = (v))
#define PYR_UF_MIN(i, v) pyr_cuda_atomic_min(&pyr_ctx.fill[i], (v))
#define PYR_UF_CAS(i, e, v) pyr_cuda_atomic_cas(&pyr_ctx.fill[i], (e), (v))
#define PYR_UF_ADD(i, v) pyr_cuda_atomic_add(&pyr_ctx.fill[i], (v))
#define PYR_ENTRY_ALL 1

#include "pyr_entries.h"

#endif /* PYR_CUDA_CUH */
