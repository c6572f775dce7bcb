/* The shared dialect. The per-pixel code of every pass (shaders/pyr_*.h) compiles as C++, CUDA, OpenCL C and
 * GLSL through this header. Rules for shared code, so that it stays within what all four accept:
 *  - no pointers or references: memory goes through accessor macros the including entry point defines
 *    (PYR_PT, PYR_Q_VALID, PYR_QN, PYR_QZ, PYR_MASK, PYR_LABEL, PYR_STORE_LABEL, PYR_VALID) and the context
 *    parameter PYR_CTX_PARAM / argument PYR_CTX_ARG that carries whatever those macros need;
 *  - casts only through PYR_I32 / PYR_U32 / PYR_F32; a struct is declared PYR_TYPEDEF(Name) struct Name {...};
 *    (OpenCL C needs the typedef to use the bare name);
 *  - entry points name their buffers pyr_buf_* (a prefix shared code never uses), so that no local variable of
 *    shared code can shadow a buffer an accessor macro refers to; shared code avoids the keywords of all four
 *    languages (OpenCL C: local, global, constant, private, kernel; GLSL: input, output, sample, filter, ...);
 *  - no bool in structs, no recursion, no overloading, integer literals with a u suffix where unsigned;
 *  - float expressions that decide a result are PYR_PRECISE (GLSL `precise`; contraction is off elsewhere);
 *  - no 64-bit integer types (GLSL has none without an extension): a wide product is PYR_U32(a) * PYR_U32(b) for
 *    its low word and PYR_MUL_HI_I32(a, b) for the high word of the signed product.
 */
#ifndef PYR_SHIM_H
#define PYR_SHIM_H

#if defined(PYR_GLSL)
#define PYR_FN
#define pyr_i32 int
#define pyr_u32 uint
#define pyr_f32 float
#define PYR_I32(x) int(x)
#define PYR_U32(x) uint(x)
#define PYR_F32(x) float(x)
#define PYR_FLOAT_BITS(f) floatBitsToInt(f)
#define PYR_BITS_FLOAT(u) uintBitsToFloat(u)
#define PYR_RINT(f) roundEven(f)
#define PYR_FABS(f) abs(f)
#define PYR_SQRT(f) sqrt(f)
#define PYR_MSB(u) findMSB(u)
#define PYR_PRECISE precise
#define PYR_TYPEDEF(name)
#define PYR_MUL_HI_I32(a, b) pyr_glsl_mul_hi(a, b)
int pyr_glsl_mul_hi(int a, int b) {
    int hi;
    int lo;
    imulExtended(a, b, hi, lo);
    return hi;
}

#elif defined(__OPENCL_VERSION__) || defined(__OPENCL_C_VERSION__)
#pragma OPENCL FP_CONTRACT OFF
#define PYR_FN static inline
#define pyr_i32 int
#define pyr_u32 uint
#define pyr_f32 float
#define PYR_I32(x) ((int)(x))
#define PYR_U32(x) ((uint)(x))
#define PYR_F32(x) ((float)(x))
#define PYR_FLOAT_BITS(f) as_int(f)
#define PYR_BITS_FLOAT(u) as_float(u)
#define PYR_RINT(f) rint(f)
#define PYR_FABS(f) fabs(f)
#define PYR_SQRT(f) sqrt(f)
#define PYR_MSB(u) (31 - (int)clz((uint)(u)))
#define PYR_PRECISE
#define PYR_TYPEDEF(name) typedef struct name name;
#define PYR_MUL_HI_I32(a, b) mul_hi((int)(a), (int)(b))

#elif defined(__CUDACC__)
#define PYR_FN static __host__ __device__ __forceinline__
#define pyr_i32 int
#define pyr_u32 unsigned int
#define pyr_f32 float
#define PYR_I32(x) static_cast<int>(x)
#define PYR_U32(x) static_cast<unsigned int>(x)
#define PYR_F32(x) static_cast<float>(x)
#ifdef __CUDA_ARCH__
#define PYR_FLOAT_BITS(f) __float_as_int(f)
#define PYR_BITS_FLOAT(u) __uint_as_float(u)
#define PYR_MSB(u) (31 - __clz(static_cast<int>(u)))
#else
#include <bit>
#define PYR_FLOAT_BITS(f) std::bit_cast<int>(f)
#define PYR_BITS_FLOAT(u) std::bit_cast<float>(static_cast<unsigned int>(u))
#define PYR_MSB(u) (static_cast<int>(std::bit_width(static_cast<unsigned int>(u))) - 1)
#endif
#define PYR_RINT(f) rintf(f)
#define PYR_FABS(f) fabsf(f)
#define PYR_SQRT(f) sqrtf(f)
#define PYR_PRECISE
#define PYR_TYPEDEF(name)
#define PYR_MUL_HI_I32(a, b) static_cast<int>((static_cast<long long>(a) * static_cast<long long>(b)) >> 32)
/* Atomics for accessor macros: shared functions are __host__ __device__, and CUDA's atomics are device-only. */
#ifdef __CUDA_ARCH__
#define pyr_cuda_atomic_add(p, v) atomicAdd((p), (v))
#define pyr_cuda_atomic_max(p, v) atomicMax((p), (v))
#define pyr_cuda_atomic_min(p, v) atomicMin((p), (v))
#define pyr_cuda_atomic_cas(p, e, v) atomicCAS((p), (e), (v))
#else
#include <atomic>
#define pyr_cuda_atomic_add(p, v) std::atomic_ref<unsigned int>(*(p)).fetch_add((v))
#define pyr_cuda_atomic_max(p, v) pyr_cuda_host_atomic_max((p), (v))
#define pyr_cuda_atomic_min(p, v) pyr_cuda_host_atomic_min((p), (v))
#define pyr_cuda_atomic_cas(p, e, v) pyr_cuda_host_atomic_cas((p), (e), (v))
static inline unsigned int pyr_cuda_host_atomic_max(unsigned int* p, unsigned int v) {
    std::atomic_ref<unsigned int> a(*p);
    unsigned int old = a.load();
    while (old < v && !a.compare_exchange_weak(old, v)) {
    }
    return old;
}
static inline unsigned int pyr_cuda_host_atomic_cas(unsigned int* p, unsigned int expected, unsigned int v) {
    std::atomic_ref<unsigned int>(*p).compare_exchange_strong(expected, v);
    return expected;
}
static inline unsigned int pyr_cuda_host_atomic_min(unsigned int* p, unsigned int v) {
    std::atomic_ref<unsigned int> a(*p);
    unsigned int old = a.load();
    while (old > v && !a.compare_exchange_weak(old, v)) {
    }
    return old;
}
#endif

#else /* C++ (CPU backend, host code) */
#define PYR_CPP 1
#include <bit>
#include <cmath>
#include <cstdint>
#define PYR_FN inline
#define pyr_i32 std::int32_t
#define pyr_u32 std::uint32_t
#define pyr_f32 float
#define PYR_I32(x) static_cast<std::int32_t>(x)
#define PYR_U32(x) static_cast<std::uint32_t>(x)
#define PYR_F32(x) static_cast<float>(x)
#define PYR_FLOAT_BITS(f) std::bit_cast<std::int32_t>(static_cast<float>(f))
#define PYR_BITS_FLOAT(u) std::bit_cast<float>(static_cast<std::uint32_t>(u))
#define PYR_RINT(f) std::nearbyint(f)
#define PYR_FABS(f) std::fabs(f)
#define PYR_SQRT(f) std::sqrt(f)
#define PYR_MSB(u) (static_cast<std::int32_t>(std::bit_width(static_cast<std::uint32_t>(u))) - 1)
#define PYR_PRECISE
#define PYR_TYPEDEF(name)
#define PYR_MUL_HI_I32(a, b) \
    static_cast<std::int32_t>((static_cast<std::int64_t>(a) * static_cast<std::int64_t>(b)) >> 32)
#endif

#endif /* PYR_SHIM_H */
