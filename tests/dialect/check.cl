/* Every shared pass function as OpenCL C 1.2 (clang -fsyntax-only), over the backend's own dialect and buffers
 * (shaders/pyr_opencl.cl, whose entry points this compiles too), to keep shaders/ within the dialect. */
#include "pyr_opencl.cl"

#include "check_calls.h"

__kernel void pyr_check(PYR_CTX_PARAM, __global int* out) {
    uint x = (uint)get_global_id(0);
    uint y = (uint)get_global_id(1);
    out[y * 64u + x] = pyr_check_all(PYR_ENTRY_CTX, x, y);
}
