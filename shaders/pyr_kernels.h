/* The kernel table: every GPU entry point, once. K(name, NAME, dims) per kernel:
 *  - name: the entry point is pyr_k_<name> (OpenCL, CUDA) and the host's gpu::Kernel::<name>;
 *  - NAME: the GLSL build compiles shaders/pyr_entries.h once per kernel with -DPYR_ENTRY_<NAME>
 *    (backends/CMakeLists.txt reads the names from this table);
 *  - dims: 1, invocations over a count (PYR_I); 2, over a width x height grid (PYR_X, PYR_Y); or 3, one workgroup
 *    per index of a count (PYR_GID; PYR_LID of PYR_LSIZE invocations, at most PYR_SCAN_GROUP_MAX).
 * Every kernel takes the Segmenter's buffers (the buffer table, pyr_buffers.h; bound once) and one PyrArgs of
 * PYR_ARG_WORDS words per dispatch; the words of each are listed where it is defined, in shaders/pyr_entries.h. Adding
 * a kernel: one line here, its body there, and its dispatch in core/gpu/gpu_executor.cpp. */
#ifndef PYR_KERNELS_H
#define PYR_KERNELS_H

#include "pyr_buffers.h"

#define PYR_KERNEL_TABLE(K)              \
    K(depth_points, DEPTH_POINTS, 2)     \
    K(normals, NORMALS, 2)               \
    K(robust_texels, ROBUST_TEXELS, 2)   \
    K(normals_robust, NORMALS_ROBUST, 2) \
    K(quantize, QUANTIZE, 1)             \
    K(metric, METRIC, 2)                 \
    K(metric_robust, METRIC_ROBUST, 2)   \
    K(color_edges, COLOR_EDGES, 2)       \
    K(bind_mask, BIND_MASK, 1)           \
    K(mip, MIP, 2)                       \
    K(init_labels, INIT_LABELS, 2)       \
    K(anchor, ANCHOR, 1)                 \
    K(uf_init, UF_INIT, 3)               \
    K(uf_merge, UF_MERGE, 2)             \
    K(uf_flatten, UF_FLATTEN, 2)         \
    K(uf_resolve, UF_RESOLVE, 2)         \
    K(uf_gather, UF_GATHER, 1)           \
    K(final_lines, FINAL_LINES, 3)       \
    K(edges, EDGES, 2)                   \
    K(merge_clear, MERGE_CLEAR, 1)       \
    K(merge_count, MERGE_COUNT, 2)       \
    K(merge_link, MERGE_LINK, 1)         \
    K(merge_flatten, MERGE_FLATTEN, 1)   \
    K(merge_apply, MERGE_APPLY, 1)       \
    K(lut_mark, LUT_MARK, 1)             \
    K(scan_count, SCAN_COUNT, 1)         \
    K(scan_sums, SCAN_SUMS, 1)           \
    K(scan_number, SCAN_NUMBER, 1)       \
    K(compact, COMPACT, 1)               \
    K(stats, STATS, 1)                   \
    K(graph_clear, GRAPH_CLEAR, 1)       \
    K(graph_count, GRAPH_COUNT, 2)       \
    K(graph_gather, GRAPH_GATHER, 1)     \
    K(track_clear, TRACK_CLEAR, 1)       \
    K(track_count, TRACK_COUNT, 1)       \
    K(track_gather, TRACK_GATHER, 1)     \
    K(track_advance, TRACK_ADVANCE, 1)

/* Per-dispatch argument words (uint32; ints and floats by their bits). */
#define PYR_ARG_WORDS 8

/* Workgroup sizes of the GLSL entry points (compile-time there); other dialects choose their own, up to
 * PYR_SCAN_GROUP_MAX for the workgroup kernels (dims 3), whose shared arrays have that many slots. */
#define PYR_GROUP_1D 64u
#define PYR_GROUP_2D 8u
#define PYR_SCAN_GROUP_MAX 256u
/* Columns per workgroup of step 6b's scan (shaders/pyr_entries.h: final_lines); every dialect's workgroup kernels
 * have a multiple of it invocations. */
#define PYR_SCAN_STRIP 32u

#endif /* PYR_KERNELS_H */
