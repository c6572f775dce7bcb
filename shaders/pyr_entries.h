/* Every GPU entry point, written once for OpenCL C, CUDA and GLSL: thin wrappers over the shared pass functions
 * (shaders/pyr_*.h), one per line of the kernel table (shaders/pyr_kernels.h). Each dialect's file
 * (pyr_opencl.cl, pyr_cuda.cuh, pyr_vulkan.comp) defines, before including this one:
 *  - PYR_KERNEL_1D(name) / PYR_KERNEL_2D(name) / PYR_KERNEL_GROUPS(name): the entry point's head;
 *  - PYR_I (1D: the invocation's index), PYR_X and PYR_Y (2D: its texel), PYR_GID, PYR_LID and PYR_LSIZE (one
 *    workgroup per index: the workgroup's index, the invocation's within it, and how many there are);
 *  - PYR_GROUP_SHARED(type, name, count) before an entry point and PYR_LOCAL_SHARED(type, name, count) at the top
 *    of its body (a workgroup's shared array is declared in one or the other, by dialect), PYR_BARRIER();
 *  - PYR_ARG(k), PYR_ARG_I32(k), PYR_ARG_F32(k): word k of the dispatch's PyrArgs;
 *  - PYR_W (the image width) and PYR_ENTRY_CTX (the context an entry point passes to shared functions);
 *  - PYR_BUF(name): a buffer of the buffer table (shaders/pyr_buffers.h) as an array; PYR_POINT(k) and
 *    PYR_NORMAL(k) (float k of the xyz arrays), PYR_STORE_POINT(k, v), PYR_STORE_NORMAL(k, v), PYR_STORE_MASK(i, v)
 *    and PYR_MASK_INPUT(i) (bind_mask's packed word per pixel, in the points buffer); PYR_UF_LOAD, PYR_UF_STORE
 *    and PYR_UF_MIN over the fill scratch buffer (shaders/pyr_uf.h), and PYR_UF_CAS and PYR_UF_ADD there for the
 *    merge (shaders/pyr_merge_table.h) and the segment graph (shaders/pyr_graph.h);
 *  - PYR_ENTRY_ALL to compile every entry point, or PYR_ENTRY_<NAME> for one (GLSL: one module per kernel).
 * The host side of every dispatch is core/gpu/gpu_executor.cpp; the argument words of each kernel are listed
 * above it. */
#ifndef PYR_ENTRIES_H
#define PYR_ENTRIES_H
#include "pyr_graph.h"
#include "pyr_kernels.h"
#include "pyr_merge_table.h"
#include "pyr_track.h"
#include "pyr_uf.h"

#define PYR_SCAN_NONE 0xffffffffu /* no event yet (a barrier is an event of value 0) */

/* normals (2D, w x h): h, radius */
#if defined(PYR_ENTRY_ALL) || defined(PYR_ENTRY_NORMALS)
PYR_KERNEL_2D(normals) {
    pyr_u32 h = PYR_ARG(0);
    pyr_u32 x = PYR_X;
    pyr_u32 y = PYR_Y;
    if (x >= PYR_W || y >= h) return;
    PyrIVec3 q = pyr_normal_q(PYR_ENTRY_CTX, PYR_W, h, x, y, PYR_ARG(1));
    pyr_u32 i = y * PYR_W + x;
    PYR_STORE_NORMAL(i * 3u + 0u, PYR_F32(q.x) * PYR_NORMAL_UNIT);
    PYR_STORE_NORMAL(i * 3u + 1u, PYR_F32(q.y) * PYR_NORMAL_UNIT);
    PYR_STORE_NORMAL(i * 3u + 2u, PYR_F32(q.z) * PYR_NORMAL_UNIT);
}
#endif

/* depth_points (2D, w x h): h, format (PYR_DEPTH_U16 or _F32), scale (float), rays (a word index). The samples
 * arrive in the quant buffer (u16 two to a word, lower half first; f32 one to a word); ku then kv (float bits) lie in
 * the sums buffer from word `rays` on, after the scan's sums, where they stay from one frame to the next. */
#if defined(PYR_ENTRY_ALL) || defined(PYR_ENTRY_DEPTH_POINTS)
PYR_KERNEL_2D(depth_points) {
    pyr_u32 h = PYR_ARG(0);
    pyr_u32 x = PYR_X;
    pyr_u32 y = PYR_Y;
    if (x >= PYR_W || y >= h) return;
    pyr_u32 i = y * PYR_W + x;
    pyr_u32 format = PYR_ARG(1);
    pyr_u32 word =
        format == PYR_DEPTH_U16 ? (PYR_BUF(quant)[i >> 1u] >> ((i & 1u) * 16u)) & 0xffffu : PYR_BUF(quant)[i];
    pyr_u32 rays = PYR_ARG(3);
    PyrFVec3 p = pyr_depth_point(word, format, PYR_ARG_F32(2), PYR_BITS_FLOAT(PYR_BUF(sums)[rays + x]),
                                 PYR_BITS_FLOAT(PYR_BUF(sums)[rays + PYR_W + y]));
    PYR_STORE_POINT(i * 3u + 0u, p.x);
    PYR_STORE_POINT(i * 3u + 1u, p.y);
    PYR_STORE_POINT(i * 3u + 2u, p.z);
}
#endif

/* robust_texels (2D, w x h): h, radius, point scale (float 2^e). Each pixel's tangents and fixed-point depth, once,
 * for the windows of normals_robust. */
#if defined(PYR_ENTRY_ALL) || defined(PYR_ENTRY_ROBUST_TEXELS)
PYR_KERNEL_2D(robust_texels) {
    pyr_u32 h = PYR_ARG(0);
    pyr_u32 x = PYR_X;
    pyr_u32 y = PYR_Y;
    if (x >= PYR_W || y >= h) return;
    pyr_robust_texel_store(PYR_ENTRY_CTX, y * PYR_W + x,
                           pyr_robust_texel(PYR_ENTRY_CTX, PYR_W, h, x, y, PYR_ARG(1), PYR_ARG_F32(2)));
}
#endif

/* normals_robust (2D, w x h): h, window, point scale (float 2^e) */
#if defined(PYR_ENTRY_ALL) || defined(PYR_ENTRY_NORMALS_ROBUST)
PYR_KERNEL_2D(normals_robust) {
    pyr_u32 h = PYR_ARG(0);
    pyr_u32 x = PYR_X;
    pyr_u32 y = PYR_Y;
    if (x >= PYR_W || y >= h) return;
    PyrIVec3 q = pyr_robust_normal_q(PYR_ENTRY_CTX, PYR_W, h, x, y, PYR_ARG(1), PYR_ARG_F32(2));
    pyr_u32 i = y * PYR_W + x;
    PYR_STORE_NORMAL(i * 3u + 0u, PYR_F32(q.x) * PYR_NORMAL_UNIT);
    PYR_STORE_NORMAL(i * 3u + 1u, PYR_F32(q.y) * PYR_NORMAL_UNIT);
    PYR_STORE_NORMAL(i * 3u + 2u, PYR_F32(q.z) * PYR_NORMAL_UNIT);
}
#endif

/* quantize (1D, pixels): pixels */
#if defined(PYR_ENTRY_ALL) || defined(PYR_ENTRY_QUANTIZE)
PYR_KERNEL_1D(quantize) {
    pyr_u32 i = PYR_I;
    if (i >= PYR_ARG(0)) return;
    PyrQuant q = pyr_quantize(PYR_POINT(i * 3u), PYR_POINT(i * 3u + 1u), PYR_POINT(i * 3u + 2u), PYR_NORMAL(i * 3u),
                              PYR_NORMAL(i * 3u + 1u), PYR_NORMAL(i * 3u + 2u));
    PYR_BUF(quant)[i * 2u + 0u] = pyr_pack_q16(q.qx, q.qy);
    PYR_BUF(quant)[i * 2u + 1u] = pyr_pack_q16(q.qz, PYR_I32(q.valid));
}
#endif

/* metric (2D, w x h): h, offset of level N, Tc (int), dt (float) */
#if defined(PYR_ENTRY_ALL) || defined(PYR_ENTRY_METRIC)
PYR_KERNEL_2D(metric) {
    pyr_u32 h = PYR_ARG(0);
    pyr_u32 x = PYR_X;
    pyr_u32 y = PYR_Y;
    if (x >= PYR_W || y >= h) return;
    PYR_STORE_MASK(PYR_ARG(1) + y * PYR_W + x,
                   pyr_metric_fillable(PYR_ENTRY_CTX, PYR_W, h, x, y, PYR_ARG_I32(2), PYR_ARG_F32(3)));
}
#endif

/* metric_robust (2D, w x h): h, offset of level N, stride, curvature base A, curvature growth Bc, dt, depth growth
 * Bd (the last four float) */
#if defined(PYR_ENTRY_ALL) || defined(PYR_ENTRY_METRIC_ROBUST)
PYR_KERNEL_2D(metric_robust) {
    pyr_u32 h = PYR_ARG(0);
    pyr_u32 x = PYR_X;
    pyr_u32 y = PYR_Y;
    if (x >= PYR_W || y >= h) return;
    PYR_STORE_MASK(PYR_ARG(1) + y * PYR_W + x,
                   pyr_metric_robust_fillable(PYR_ENTRY_CTX, PYR_W, h, x, y, PYR_ARG(2), PYR_ARG_F32(3), PYR_ARG_F32(4),
                                              PYR_ARG_F32(5), PYR_ARG_F32(6)));
}
#endif

/* color_edges (2D, w x h): h, offset of level N, stride, threshold, curvature gate G, curvature stride, curvature
 * base A, curvature growth Bc (the last two float). Step 0c: the fillable pixels on a colour edge that counts
 * cleared. */
#if defined(PYR_ENTRY_ALL) || defined(PYR_ENTRY_COLOR_EDGES)
PYR_KERNEL_2D(color_edges) {
    pyr_u32 h = PYR_ARG(0);
    pyr_u32 x = PYR_X;
    pyr_u32 y = PYR_Y;
    if (x >= PYR_W || y >= h) return;
    pyr_u32 i = PYR_ARG(1) + y * PYR_W + x;
    if ((PYR_MASK(i) & PYR_MASK_FILLABLE) != 0u &&
        pyr_color_edge(PYR_ENTRY_CTX, PYR_W, h, x, y, PYR_ARG(2), PYR_ARG(3)) != 0u &&
        pyr_color_edge_counts(PYR_ENTRY_CTX, PYR_W, h, x, y, PYR_ARG(4), PYR_ARG(5), PYR_ARG_F32(6), PYR_ARG_F32(7)) !=
            0u) {
        PYR_STORE_MASK(i, 0u);
    }
}
#endif

/* bind_mask (1D, pixels): pixels, offset of level N. The caller's mask arrives in the points buffer, one word per
 * pixel: bit 0 fillable, bit 1 valid. */
#if defined(PYR_ENTRY_ALL) || defined(PYR_ENTRY_BIND_MASK)
PYR_KERNEL_1D(bind_mask) {
    pyr_u32 i = PYR_I;
    if (i >= PYR_ARG(0)) return;
    pyr_u32 packed = PYR_MASK_INPUT(i);
    PYR_STORE_MASK(PYR_ARG(1) + i, packed & 1u);
    PYR_BUF(quant)[i * 2u + 1u] = pyr_pack_q16(0, PYR_I32((packed >> 1u) & 1u));
}
#endif

/* mip (2D, parent level): parent width, height, offset; child width, height, offset */
#if defined(PYR_ENTRY_ALL) || defined(PYR_ENTRY_MIP)
PYR_KERNEL_2D(mip) {
    pyr_u32 x = PYR_X;
    pyr_u32 y = PYR_Y;
    if (x >= PYR_ARG(0) || y >= PYR_ARG(1)) return;
    PYR_STORE_MASK(PYR_ARG(2) + y * PYR_ARG(0) + x,
                   pyr_mip_texel(PYR_ENTRY_CTX, pyr_level(PYR_ARG(3), PYR_ARG(4), PYR_ARG(5)), x, y));
}
#endif

/* init_labels (2D, the level): level width, height, offset; parent width, height, offset; mode (PYR_INIT_*) */
#if defined(PYR_ENTRY_ALL) || defined(PYR_ENTRY_INIT_LABELS)
PYR_KERNEL_2D(init_labels) {
    pyr_u32 x = PYR_X;
    pyr_u32 y = PYR_Y;
    if (x >= PYR_ARG(0) || y >= PYR_ARG(1)) return;
    PYR_BUF(labels)
    [PYR_ARG(2) + y * PYR_ARG(0) + x] =
        pyr_label_init_texel(PYR_ENTRY_CTX, pyr_level(PYR_ARG(0), PYR_ARG(1), PYR_ARG(2)),
                             pyr_level(PYR_ARG(3), PYR_ARG(4), PYR_ARG(5)), x, y, PYR_ARG(6));
}
#endif

/* anchor (1D, texels of the level): offset, count, anchor_max */
#if defined(PYR_ENTRY_ALL) || defined(PYR_ENTRY_ANCHOR)
PYR_KERNEL_1D(anchor) {
    pyr_u32 i = PYR_I;
    if (i >= PYR_ARG(1)) return;
    i += PYR_ARG(0);
    PYR_STORE_MASK(i, pyr_anchor_mask(PYR_U32(PYR_BUF(mask)[i]), PYR_BUF(labels)[i], PYR_ARG(2)));
}
#endif

/* Steps 2 and 4 (shaders/pyr_uf.h), five dispatches per fill over a level of n texels:
 * uf_init (one workgroup per row of the level): level width, height, offset; n. Every eligible texel's parent is
 * the first texel of its run of eligible texels in the row (a scan of the row's last non-eligible position, as in
 * final_lines below), so a row's runs are joined from the start and trees stay one level deep along rows; every
 * other texel is its own parent; every minimum is none. */
#if defined(PYR_ENTRY_ALL) || defined(PYR_ENTRY_UF_INIT)
PYR_GROUP_SHARED(pyr_u32, pyr_run_start, PYR_SCAN_GROUP_MAX)
PYR_KERNEL_GROUPS(uf_init) {
    PYR_LOCAL_SHARED(pyr_u32, pyr_run_start, PYR_SCAN_GROUP_MAX)
    PyrLevel lv = pyr_level(PYR_ARG(0), PYR_ARG(1), PYR_ARG(2));
    pyr_u32 n = PYR_ARG(3);
    pyr_u32 y = PYR_GID; /* the same for the whole workgroup: its early return skips no barrier of another */
    if (y >= lv.height) return;
    pyr_u32 t = PYR_LID;
    pyr_u32 g = PYR_LSIZE;
    pyr_u32 chunk = (lv.width + g - 1u) / g;
    pyr_u32 x0 = min(lv.width, t * chunk);
    pyr_u32 x1 = min(lv.width, x0 + chunk);
    pyr_u32 row = y * lv.width;
    /* Where a run starting in this chunk would start: one past its last non-eligible texel (0: none). */
    pyr_u32 start = 0u;
    for (pyr_u32 x = x0; x < x1; ++x) {
        if (pyr_uf_eligible(PYR_U32(PYR_BUF(mask)[lv.offset + row + x])) == 0u) start = x + 1u;
    }
    pyr_run_start[t] = start;
    PYR_BARRIER();
    for (pyr_u32 d = 1u; d < g; d <<= 1u) { /* inclusive max-scan over the chunks */
        pyr_u32 before = t >= d ? pyr_run_start[t - d] : 0u;
        PYR_BARRIER();
        pyr_run_start[t] = max(pyr_run_start[t], before);
        PYR_BARRIER();
    }
    start = t > 0u ? pyr_run_start[t - 1u] : 0u;
    for (pyr_u32 x = x0; x < x1; ++x) {
        pyr_u32 k = row + x;
        if (pyr_uf_eligible(PYR_U32(PYR_BUF(mask)[lv.offset + k])) == 0u) {
            start = x + 1u;
            PYR_UF_STORE(k, k);
        } else {
            PYR_UF_STORE(k, row + start);
        }
        PYR_UF_STORE(n + k, PYR_UF_NONE);
    }
}
#endif

/* uf_merge, uf_flatten and uf_resolve (2D, the level): level width, height, offset; n */
#if defined(PYR_ENTRY_ALL) || defined(PYR_ENTRY_UF_MERGE)
PYR_KERNEL_2D(uf_merge) {
    pyr_u32 x = PYR_X;
    pyr_u32 y = PYR_Y;
    if (x >= PYR_ARG(0) || y >= PYR_ARG(1)) return;
    pyr_uf_merge(PYR_ENTRY_CTX, pyr_level(PYR_ARG(0), PYR_ARG(1), PYR_ARG(2)), x, y);
}
#endif

#if defined(PYR_ENTRY_ALL) || defined(PYR_ENTRY_UF_FLATTEN)
PYR_KERNEL_2D(uf_flatten) {
    pyr_u32 x = PYR_X;
    pyr_u32 y = PYR_Y;
    if (x >= PYR_ARG(0) || y >= PYR_ARG(1)) return;
    pyr_uf_flatten(PYR_ENTRY_CTX, pyr_level(PYR_ARG(0), PYR_ARG(1), PYR_ARG(2)), x, y);
}
#endif

#if defined(PYR_ENTRY_ALL) || defined(PYR_ENTRY_UF_RESOLVE)
PYR_KERNEL_2D(uf_resolve) {
    pyr_u32 x = PYR_X;
    pyr_u32 y = PYR_Y;
    if (x >= PYR_ARG(0) || y >= PYR_ARG(1)) return;
    pyr_uf_resolve(PYR_ENTRY_CTX, pyr_level(PYR_ARG(0), PYR_ARG(1), PYR_ARG(2)), PYR_ARG(3), x, y);
}
#endif

/* uf_gather (1D, n): offset, n. Every eligible texel takes its component's minimum, 0 when it has none. */
#if defined(PYR_ENTRY_ALL) || defined(PYR_ENTRY_UF_GATHER)
PYR_KERNEL_1D(uf_gather) {
    pyr_u32 k = PYR_I;
    if (k >= PYR_ARG(1)) return;
    pyr_u32 i = PYR_ARG(0) + k;
    if (pyr_uf_eligible(PYR_U32(PYR_BUF(mask)[i])) == 0u) return;
    pyr_u32 m = PYR_UF_LOAD(PYR_ARG(1) + PYR_UF_LOAD(k));
    PYR_BUF(labels)[i] = m == PYR_UF_NONE ? 0u : m;
}
#endif

/* Step 6 a and b (and step 5, fused into the row pass): final_lines, one workgroup per PYR_SCAN_STRIP lines.
 * Arguments: level N's width, height, offset; level N - 1's width, height, offset; rows (1: the rows, each after
 * step 5's labels, one row per workgroup; 0: the columns, PYR_SCAN_STRIP adjacent ones per workgroup, so that
 * neighbouring invocations read neighbouring texels).
 * Each line's pass is the closed form of the contract's sequential one (docs/algorithm.md section 9): call a pixel an
 * event when it is labelled or not fillable (a barrier, value 0); F(x) is the label of the last event at or before
 * x, B(x) that of the first event at or after x (0 when there is none); an unlabelled fillable pixel takes F(x) when
 * non-zero, else B(x). That is exactly the pass there and back. Each invocation takes a chunk of a line; the
 * chunks' last and first events are scanned across the line's invocations in shared memory (the operator "the later
 * event wins" is associative, so how a line is cut into chunks cannot change a result). */
#if defined(PYR_ENTRY_ALL) || defined(PYR_ENTRY_FINAL_LINES)
PYR_GROUP_SHARED(pyr_u32, pyr_scan_last, PYR_SCAN_GROUP_MAX)
PYR_GROUP_SHARED(pyr_u32, pyr_scan_first, PYR_SCAN_GROUP_MAX)
PYR_KERNEL_GROUPS(final_lines) {
    PYR_LOCAL_SHARED(pyr_u32, pyr_scan_last, PYR_SCAN_GROUP_MAX)
    PYR_LOCAL_SHARED(pyr_u32, pyr_scan_first, PYR_SCAN_GROUP_MAX)
    PyrLevel lv = pyr_level(PYR_ARG(0), PYR_ARG(1), PYR_ARG(2));
    PyrLevel parent = pyr_level(PYR_ARG(3), PYR_ARG(4), PYR_ARG(5));
    pyr_u32 rows = PYR_ARG(6);
    pyr_u32 strip = rows != 0u ? 1u : PYR_SCAN_STRIP; /* lines per workgroup */
    pyr_u32 parts = PYR_LSIZE / strip;                /* invocations per line */
    pyr_u32 lane = PYR_LID % strip;                   /* the invocation's line within the strip */
    pyr_u32 part = PYR_LID / strip;                   /* and its chunk of that line */
    pyr_u32 line = PYR_GID * strip + lane;            /* a row, or a column */
    pyr_u32 lines = rows != 0u ? lv.height : lv.width;
    pyr_u32 length = rows != 0u ? lv.width : lv.height;
    pyr_u32 step = rows != 0u ? 1u : lv.width;
    pyr_u32 start = lv.offset + (rows != 0u ? line * lv.width : line);
    pyr_u32 chunk = (length + parts - 1u) / parts;
    pyr_u32 k0 = min(length, part * chunk);
    pyr_u32 k1 = line < lines ? min(length, k0 + chunk) : k0; /* past the last line: no work, but every barrier */
    /* The chunk's last and first events; on rows, step 5's labels first. */
    pyr_u32 last = PYR_SCAN_NONE;
    pyr_u32 first = PYR_SCAN_NONE;
    for (pyr_u32 k = k0; k < k1; ++k) {
        pyr_u32 i = start + k * step;
        pyr_u32 l = PYR_BUF(labels)[i];
        if (rows != 0u) {
            l = pyr_label_init_texel(PYR_ENTRY_CTX, lv, parent, k, line, PYR_INIT_INHERIT);
            PYR_BUF(labels)[i] = l;
        }
        if (l != 0u || (PYR_U32(PYR_BUF(mask)[i]) & PYR_MASK_FILLABLE) == 0u) {
            last = l;
            if (first == PYR_SCAN_NONE) first = l;
        }
    }
    pyr_u32 slot = part * strip + lane;
    pyr_scan_last[slot] = last;
    pyr_scan_first[slot] = first;
    PYR_BARRIER();
    /* Inclusive scans over a line's invocations: the last event up to each chunk, the first one from each on. */
    for (pyr_u32 d = 1u; d < parts; d <<= 1u) {
        pyr_u32 before = part >= d ? pyr_scan_last[slot - d * strip] : PYR_SCAN_NONE;
        pyr_u32 after = part + d < parts ? pyr_scan_first[slot + d * strip] : PYR_SCAN_NONE;
        PYR_BARRIER();
        if (pyr_scan_last[slot] == PYR_SCAN_NONE) pyr_scan_last[slot] = before;
        if (pyr_scan_first[slot] == PYR_SCAN_NONE) pyr_scan_first[slot] = after;
        PYR_BARRIER();
    }
    pyr_u32 f = part > 0u ? pyr_scan_last[slot - strip] : PYR_SCAN_NONE;
    pyr_u32 b = part + 1u < parts ? pyr_scan_first[slot + strip] : PYR_SCAN_NONE;
    /* There: an unlabelled fillable pixel takes F when non-zero. */
    f = f == PYR_SCAN_NONE ? 0u : f;
    for (pyr_u32 k = k0; k < k1; ++k) {
        pyr_u32 i = start + k * step;
        pyr_u32 l = PYR_BUF(labels)[i];
        if (l != 0u || (PYR_U32(PYR_BUF(mask)[i]) & PYR_MASK_FILLABLE) == 0u) {
            f = l;
        } else if (f != 0u) {
            PYR_BUF(labels)[i] = f;
        }
    }
    /* Back: what is still 0 takes B. Pixels filled just now count as events: they lie after the run's first
     * labelled pixel, so no pixel still 0 can see past them to a different one. */
    b = b == PYR_SCAN_NONE ? 0u : b;
    for (pyr_u32 k = k1; k > k0; --k) {
        pyr_u32 i = start + (k - 1u) * step;
        pyr_u32 l = PYR_BUF(labels)[i];
        if (l != 0u || (PYR_U32(PYR_BUF(mask)[i]) & PYR_MASK_FILLABLE) == 0u) {
            b = l;
        } else if (b != 0u) {
            PYR_BUF(labels)[i] = b;
        }
    }
}
#endif

/* edges (2D, w x h): h, offset of level N, round (1..63), rounds (E), the depth step share s (float; 0: none). In
 * place: only valid, non-fillable, unlabelled pixels change, and no pixel of this round reads those. With more than
 * one round, a pixel labelled here records the round in its mask, for the rounds after it. */
#if defined(PYR_ENTRY_ALL) || defined(PYR_ENTRY_EDGES)
PYR_KERNEL_2D(edges) {
    pyr_u32 x = PYR_X;
    pyr_u32 y = PYR_Y;
    if (x >= PYR_W || y >= PYR_ARG(0)) return;
    pyr_u32 i = PYR_ARG(1) + y * PYR_W + x;
    pyr_u32 round = PYR_ARG(2);
    pyr_u32 l = pyr_edge_label(PYR_ENTRY_CTX, pyr_level(PYR_W, PYR_ARG(0), PYR_ARG(1)), x, y, round, PYR_ARG_F32(4));
    if (l != PYR_BUF(labels)[i]) {
        PYR_BUF(labels)[i] = l;
        if (round < PYR_ARG(3)) PYR_STORE_MASK(i, PYR_MASK(i) | (round << PYR_MASK_EDGE_SHIFT));
    }
}
#endif

/* Step 6d, the merge (shaders/pyr_merge_table.h), five dispatches over the fill scratch buffer. merge_clear (1D,
 * words): words, lut_size. Label l's parent is l, every slot free. */
#if defined(PYR_ENTRY_ALL) || defined(PYR_ENTRY_MERGE_CLEAR)
PYR_KERNEL_1D(merge_clear) {
    pyr_u32 k = PYR_I;
    if (k >= PYR_ARG(0)) return;
    PYR_UF_STORE(k, k < PYR_ARG(1) ? k : 0u);
}
#endif

/* merge_count (2D, w x h): h, offset of level N, reach, point scale (float), tolerance base and growth (floats),
 * the table's first word, slots - 1. */
#if defined(PYR_ENTRY_ALL) || defined(PYR_ENTRY_MERGE_COUNT)
PYR_KERNEL_2D(merge_count) {
    pyr_u32 x = PYR_X;
    pyr_u32 y = PYR_Y;
    if (x >= PYR_W || y >= PYR_ARG(0)) return;
    pyr_merge_count(PYR_ENTRY_CTX, pyr_level(PYR_W, PYR_ARG(0), PYR_ARG(1)), x, y, PYR_ARG(2), PYR_ARG_F32(3),
                    PYR_ARG_F32(4), PYR_ARG_F32(5), PYR_ARG(6), PYR_ARG(7));
}
#endif

/* merge_link (1D, slots): the table's first word, slots, minimum crossings, bad share (256ths). */
#if defined(PYR_ENTRY_ALL) || defined(PYR_ENTRY_MERGE_LINK)
PYR_KERNEL_1D(merge_link) {
    pyr_u32 s = PYR_I;
    if (s >= PYR_ARG(1)) return;
    pyr_merge_link(PYR_ENTRY_CTX, PYR_ARG(0), s, PYR_ARG(2), PYR_ARG(3));
}
#endif

/* merge_flatten (1D, lut_size): lut_size. Every label points at its root, the smallest label of its group (the
 * forest no longer changes: a concurrent reader sees the old parent or the root, both ancestors). */
#if defined(PYR_ENTRY_ALL) || defined(PYR_ENTRY_MERGE_FLATTEN)
PYR_KERNEL_1D(merge_flatten) {
    pyr_u32 l = PYR_I;
    if (l >= PYR_ARG(0)) return;
    PYR_UF_STORE(l, pyr_uf_root(PYR_ENTRY_CTX, l));
}
#endif

/* merge_apply (1D, pixels): pixels, offset of level N. Each label becomes its group's. */
#if defined(PYR_ENTRY_ALL) || defined(PYR_ENTRY_MERGE_APPLY)
PYR_KERNEL_1D(merge_apply) {
    pyr_u32 k = PYR_I;
    if (k >= PYR_ARG(0)) return;
    pyr_u32 i = PYR_ARG(1) + k;
    PYR_BUF(labels)[i] = PYR_UF_LOAD(PYR_BUF(labels)[i]);
}
#endif

/* lut_mark (1D, pixels): pixels, offset of level N. Every invocation that marks a label writes the same value: the
 * race is benign. */
#if defined(PYR_ENTRY_ALL) || defined(PYR_ENTRY_LUT_MARK)
PYR_KERNEL_1D(lut_mark) {
    pyr_u32 i = PYR_I;
    if (i >= PYR_ARG(0)) return;
    pyr_u32 l = PYR_BUF(labels)[PYR_ARG(1) + i];
    if (l != 0u) PYR_BUF(lut)[l] = 1u;
}
#endif

/* Marks to new ids 1..K in three steps: count marks per chunk, scan the chunk counts (K last), number within chunks.
 * scan_count and scan_number (1D, chunks): count, chunk, chunks. scan_sums (1D, one invocation): chunks. */
#if defined(PYR_ENTRY_ALL) || defined(PYR_ENTRY_SCAN_COUNT)
PYR_KERNEL_1D(scan_count) {
    pyr_u32 c = PYR_I;
    if (c >= PYR_ARG(2)) return;
    pyr_u32 begin = c * PYR_ARG(1);
    PYR_BUF(sums)[c] = pyr_count_marks(PYR_ENTRY_CTX, begin, min(PYR_ARG(0), begin + PYR_ARG(1)));
}
#endif

#if defined(PYR_ENTRY_ALL) || defined(PYR_ENTRY_SCAN_SUMS)
PYR_KERNEL_1D(scan_sums) {
    if (PYR_I != 0u) return;
    pyr_u32 running = 0u;
    for (pyr_u32 c = 0u; c < PYR_ARG(0); ++c) {
        pyr_u32 n = PYR_BUF(sums)[c];
        PYR_BUF(sums)[c] = running;
        running += n;
    }
    PYR_BUF(sums)[PYR_ARG(0)] = running;
}
#endif

#if defined(PYR_ENTRY_ALL) || defined(PYR_ENTRY_SCAN_NUMBER)
PYR_KERNEL_1D(scan_number) {
    pyr_u32 c = PYR_I;
    if (c >= PYR_ARG(2)) return;
    pyr_u32 begin = c * PYR_ARG(1);
    pyr_number_marks(PYR_ENTRY_CTX, begin, min(PYR_ARG(0), begin + PYR_ARG(1)), PYR_BUF(sums)[c]);
}
#endif

/* compact (1D, pixels): pixels, offset of level N, apply */
#if defined(PYR_ENTRY_ALL) || defined(PYR_ENTRY_COMPACT)
PYR_KERNEL_1D(compact) {
    pyr_u32 i = PYR_I;
    if (i >= PYR_ARG(0)) return;
    pyr_u32 raw = PYR_BUF(labels)[PYR_ARG(1) + i];
    PYR_BUF(out)[i] = PYR_ARG(2) != 0u ? pyr_compact_label(PYR_ENTRY_CTX, raw) : raw;
}
#endif

/* stats (1D, runs): h, offset of level N, runs, with_points, point_scale (float), base (the first statistics word,
 * after the label table in the lut buffer), slots */
#if defined(PYR_ENTRY_ALL) || defined(PYR_ENTRY_STATS)
PYR_KERNEL_1D(stats) {
    pyr_u32 run = PYR_I;
    if (run >= PYR_ARG(2)) return;
    pyr_stats_run(PYR_ENTRY_CTX, pyr_level(PYR_W, PYR_ARG(0), PYR_ARG(1)), run, PYR_ARG(3), PYR_ARG_F32(4), PYR_ARG(5),
                  PYR_ARG(6));
}
#endif

/* The segment graph (shaders/pyr_graph.h), after compact, in three dispatches over the plan's largest table; each
 * uses the slots K needs (pyr_graph_slots, K read where the scan left it) and leaves the rest. graph_clear (1D,
 * 1 + PYR_GRAPH_SLOT_WORDS * max slots): the word of K in the sums buffer, max slots. The counter (word 0) and the
 * table (from word 1) zeroed. */
#if defined(PYR_ENTRY_ALL) || defined(PYR_ENTRY_GRAPH_CLEAR)
PYR_KERNEL_1D(graph_clear) {
    pyr_u32 k = PYR_I;
    pyr_u32 slots = pyr_graph_slots(PYR_BUF(sums)[PYR_ARG(0)], PYR_ARG(1));
    if (k >= 1u + PYR_GRAPH_SLOT_WORDS * slots) return;
    PYR_UF_STORE(k, 0u);
}
#endif

/* graph_count (2D, w x h): h, offset of level N, flags (bit 0: with points, bit 1: the labels compacted) | reach << 8,
 * the word of K, point scale (float), tolerance base and growth (floats), max slots. */
#if defined(PYR_ENTRY_ALL) || defined(PYR_ENTRY_GRAPH_COUNT)
PYR_KERNEL_2D(graph_count) {
    pyr_u32 x = PYR_X;
    pyr_u32 y = PYR_Y;
    if (x >= PYR_W || y >= PYR_ARG(0)) return;
    pyr_u32 slots = pyr_graph_slots(PYR_BUF(sums)[PYR_ARG(3)], PYR_ARG(7));
    pyr_graph_count(PYR_ENTRY_CTX, pyr_level(PYR_W, PYR_ARG(0), PYR_ARG(1)), x, y, PYR_ARG(2) & 1u,
                    (PYR_ARG(2) >> 1u) & 1u, PYR_ARG(2) >> 8u, PYR_ARG_F32(4), PYR_ARG_F32(5), PYR_ARG_F32(6), 1u,
                    slots - 1u);
}
#endif

/* graph_gather (1D, max slots): the word of K, max slots. The list follows the table K needs. */
#if defined(PYR_ENTRY_ALL) || defined(PYR_ENTRY_GRAPH_GATHER)
PYR_KERNEL_1D(graph_gather) {
    pyr_u32 s = PYR_I;
    pyr_u32 slots = pyr_graph_slots(PYR_BUF(sums)[PYR_ARG(0)], PYR_ARG(1));
    if (s >= slots) return;
    pyr_graph_gather(PYR_ENTRY_CTX, 1u, s, 1u + PYR_GRAPH_SLOT_WORDS * slots, 0u);
}
#endif

/* Tracks' overlaps (shaders/pyr_track.h), after compact, in four dispatches. Each uses the slots K' and K need
 * (pyr_track_slots): K read where the scan left it, K' where the previous frame's track_advance left it (the word
 * after the previous buffer's pixels, then the previous frame's number in its stream), or 0 when the frame starts a
 * stream, so that frames queued on the device, or recorded once and run many times, follow one another without the
 * host. The table starts at a word of the fill buffer after the segment graph's; the
 * header and the gathered pairs follow the table at its largest (PYR_TRACK_HEADER_WORDS, pyr_types.h).
 * track_clear, track_gather and track_advance take: the word of K, whether a previous frame is counted against (0
 * at a stream's start), max slots, the table's first word, the word of K' in the previous buffer (the pixel count).
 * track_clear (1D, PYR_TRACK_SLOT_WORDS * at least the slots K' and K need) also zeroes the gathered pairs' counter. */
#define PYR_TRACK_PREVIOUS(has_previous, word) ((has_previous) != 0u ? PYR_BUF(previous)[word] : 0u)
#define PYR_TRACK_HEADER(table, max_slots) ((table) + PYR_TRACK_SLOT_WORDS * (max_slots))

#if defined(PYR_ENTRY_ALL) || defined(PYR_ENTRY_TRACK_CLEAR)
PYR_KERNEL_1D(track_clear) {
    pyr_u32 i = PYR_I;
    pyr_u32 slots = pyr_track_slots(PYR_TRACK_PREVIOUS(PYR_ARG(1), PYR_ARG(4)), PYR_BUF(sums)[PYR_ARG(0)], PYR_ARG(2));
    if (i == 0u) PYR_UF_STORE(PYR_TRACK_HEADER(PYR_ARG(3), PYR_ARG(2)) + PYR_TRACK_PAIRS, 0u);
    if (i >= PYR_TRACK_SLOT_WORDS * slots) return;
    PYR_UF_STORE(PYR_ARG(3) + i, 0u);
}
#endif

/* track_count (1D, runs of PYR_STATS_RUN pixels of each row): h, runs, the word of K, whether a previous frame is
 * counted against, max slots, the table's first word, the word of K'. Each run's stretches of one (previous label,
 * label) pair counted at once, and the frame's labels kept as the previous ones. */
#if defined(PYR_ENTRY_ALL) || defined(PYR_ENTRY_TRACK_COUNT)
PYR_KERNEL_1D(track_count) {
    pyr_u32 run = PYR_I;
    if (run >= PYR_ARG(1)) return;
    pyr_u32 per_row = (PYR_W + PYR_STATS_RUN - 1u) / PYR_STATS_RUN;
    pyr_u32 y = run / per_row;
    pyr_u32 x0 = (run - y * per_row) * PYR_STATS_RUN;
    pyr_u32 x1 = min(x0 + PYR_STATS_RUN, PYR_W);
    pyr_u32 previous_count = PYR_TRACK_PREVIOUS(PYR_ARG(3), PYR_ARG(6));
    pyr_u32 slot_mask = pyr_track_slots(previous_count, PYR_BUF(sums)[PYR_ARG(2)], PYR_ARG(4)) - 1u;
    pyr_u32 run_previous = 0u;
    pyr_u32 run_label = 0u;
    pyr_u32 count = 0u;
    for (pyr_u32 x = x0; x < x1; ++x) {
        pyr_u32 i = y * PYR_W + x;
        pyr_u32 k = PYR_BUF(out)[i];
        pyr_u32 j = previous_count != 0u ? PYR_BUF(previous)[i] : 0u; /* a first frame's buffer is unwritten */
        PYR_BUF(previous)[i] = k;
        if (j == run_previous && k == run_label) {
            count += 1u;
            continue;
        }
        if (previous_count != 0u) pyr_track_count(PYR_ENTRY_CTX, run_previous, run_label, count, PYR_ARG(5), slot_mask);
        run_previous = j;
        run_label = k;
        count = 1u;
    }
    if (previous_count != 0u) pyr_track_count(PYR_ENTRY_CTX, run_previous, run_label, count, PYR_ARG(5), slot_mask);
}
#endif

/* track_gather (1D, at least the slots K' and K need): the pairs counted, appended after the header. */
#if defined(PYR_ENTRY_ALL) || defined(PYR_ENTRY_TRACK_GATHER)
PYR_KERNEL_1D(track_gather) {
    pyr_u32 s = PYR_I;
    pyr_u32 slots = pyr_track_slots(PYR_TRACK_PREVIOUS(PYR_ARG(1), PYR_ARG(4)), PYR_BUF(sums)[PYR_ARG(0)], PYR_ARG(2));
    if (s >= slots) return;
    pyr_u32 header = PYR_TRACK_HEADER(PYR_ARG(3), PYR_ARG(2));
    pyr_slot_gather(PYR_ENTRY_CTX, PYR_ARG(3), PYR_TRACK_SLOT_WORDS, s, header + PYR_TRACK_HEADER_WORDS,
                    header + PYR_TRACK_PAIRS);
}
#endif

/* track_advance (1D, one invocation, last): the header (the frame's number: the previous frame's + 1, or 0 when the
 * frame starts a stream; K'; K), and K and the number kept for the next frame. */
#if defined(PYR_ENTRY_ALL) || defined(PYR_ENTRY_TRACK_ADVANCE)
PYR_KERNEL_1D(track_advance) {
    if (PYR_I != 0u) return;
    pyr_u32 header = PYR_TRACK_HEADER(PYR_ARG(3), PYR_ARG(2));
    pyr_u32 count = PYR_BUF(sums)[PYR_ARG(0)];
    pyr_u32 frame = PYR_ARG(1) != 0u ? PYR_BUF(previous)[PYR_ARG(4) + 1u] + 1u : 0u;
    PYR_UF_STORE(header + PYR_TRACK_FRAME, frame);
    PYR_UF_STORE(header + PYR_TRACK_PREVIOUS_COUNT, PYR_TRACK_PREVIOUS(PYR_ARG(1), PYR_ARG(4)));
    PYR_UF_STORE(header + PYR_TRACK_COUNT, count);
    PYR_BUF(previous)[PYR_ARG(4)] = count;
    PYR_BUF(previous)[PYR_ARG(4) + 1u] = frame;
}
#endif

#endif /* PYR_ENTRIES_H */
