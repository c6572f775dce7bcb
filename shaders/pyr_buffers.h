/* The buffer table: every buffer the GPU backends bind, once, in binding order (OpenCL's kernel arguments, Vulkan's
 * bindings, CUDA's context). B(name, index, TYPE, QUAL) per buffer:
 *  - name: PYR_BUF(name) in the kernels (shaders/pyr_entries.h), gpu::Buffer::name on the host;
 *  - index: its place in the table, which the host checks (core/gpu/device.hpp) and GLSL takes as the binding;
 *  - TYPE: the element type, F32 or U32, or MASK: a byte where the dialect has byte access (OpenCL C, CUDA), a
 *    uint in GLSL (gpu::DeviceLimits::mask_texel_bytes);
 *  - QUAL: PLAIN, or COHERENT where invocations of one dispatch read what others wrote (GLSL's `coherent`; the
 *    other dialects read those words through volatile accessors).
 * Each dialect (pyr_opencl.cl, pyr_vulkan.comp, pyr_cuda.cuh) declares its buffers from this table, and the host
 * takes the ids and names from it; sizes are gpu::buffer_sizes (core/gpu/gpu_executor.cpp). Adding a buffer: one
 * line here, its size there. */
#ifndef PYR_BUFFERS_H
#define PYR_BUFFERS_H

#define PYR_BUFFER_TABLE(B)                                                                                    \
    B(points, 0, F32, PLAIN)    /* xyz per pixel (depth frames write them); a mask frame's input words */      \
    B(normals, 1, F32, PLAIN)   /* xyz per pixel */                                                            \
    B(quant, 2, U32, PLAIN)     /* two words per pixel: pyr_pack_q16(qx, qy), pyr_pack_q16(qz, valid) */       \
    B(mask, 3, MASK, PLAIN)     /* the fillable mask, all levels */                                            \
    B(labels, 4, U32, PLAIN)    /* all levels */                                                               \
    B(lut, 5, U32, PLAIN)       /* the compaction table, then the statistics words (PYR_STATS_WORDS a slot) */ \
    B(sums, 6, U32, PLAIN)      /* the compaction scan, K last; the depth frames' ray tables */                \
    B(fill, 7, U32, COHERENT)   /* the fills' union-find: parents, then minima */                              \
    B(out, 8, U32, PLAIN)       /* the compacted labels */                                                     \
    B(texels, 9, U32, PLAIN)    /* the robust normals' texels, PYR_TEXEL_WORDS per pixel */                    \
    B(color, 10, U32, PLAIN)    /* a frame's colour image: R, G, B bytes per pixel, packed row by row */       \
    B(previous, 11, U32, PLAIN) /* tracks: the previous frame's compacted labels */

#define PYR_BUFFER_COUNT 12

#endif /* PYR_BUFFERS_H */
