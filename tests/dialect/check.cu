// Every shared pass function as CUDA device code (nvcc), over the backend's own dialect and buffers
// (shaders/pyr_cuda.cuh, whose entry points this compiles too), to keep shaders/ within the dialect.
#include "pyr_cuda.cuh"

#include "check_calls.h"

__global__ void pyr_check(PyrCudaCtx pyr_ctx, int* out) {
    const unsigned x = blockIdx.x * blockDim.x + threadIdx.x;
    const unsigned y = blockIdx.y * blockDim.y + threadIdx.y;
    out[y * 64u + x] = pyr_check_all(PYR_ENTRY_CTX, x, y);
}
