/* Calls every shared pass function once, in the shared dialect (shaders/pyr_shim.h), over the includer's dialect:
 * so that a function only the CPU backend calls (the sweeps) still compiles as OpenCL C, GLSL and CUDA. The
 * arguments are arbitrary; nothing runs. Adding a pass function: a call here. */
#ifndef PYR_CHECK_CALLS_H
#define PYR_CHECK_CALLS_H

PYR_FN pyr_i32 pyr_check_all(PYR_CTX_PARAM, pyr_u32 x, pyr_u32 y) {
    PyrLevel lv = pyr_level(64u, 64u, 0u);
    PyrIVec3 q = pyr_normal_q(PYR_CTX_ARG, 64u, 64u, x, y, 1u);
    PyrQuant qu = pyr_quantize(1.0f, 2.0f, 3.0f, 0.0f, 0.0f, -1.0f);
    pyr_u32 r = pyr_metric_fillable(PYR_CTX_ARG, 64u, 64u, x, y, 100, 1.0f);
    r += pyr_metric_robust_fillable(PYR_CTX_ARG, 64u, 64u, x, y, 4u, 100.0f, 0.5f, 1.0f, 0.25f);
    r += PYR_U32(pyr_robust_normal_q(PYR_CTX_ARG, 64u, 64u, x, y, 3u, 16.0f).z);
    pyr_robust_texel_store(PYR_CTX_ARG, y * 64u + x, pyr_robust_texel(PYR_CTX_ARG, 64u, 64u, x, y, 1u, 16.0f));
    r += pyr_mip_texel(PYR_CTX_ARG, lv, x, y);
    r += pyr_color_edge(PYR_CTX_ARG, 64u, 64u, x, y, 1u, 48u);
    r += pyr_label_init_texel(PYR_CTX_ARG, lv, lv, x, y, PYR_INIT_NEW);
    r += pyr_sweep_line(PYR_CTX_ARG, y * 64u, 1u, 64u, 0u);
    r += pyr_anchor_mask(1u, 2u, 3u) + pyr_fill_relax(1u, 1u, 2u, 1u) + pyr_fill_once(0u, 1u, 1u);
    r += pyr_edge_label(PYR_CTX_ARG, lv, x, y, 2u, 0.02f);
    r += PYR_U32(PYR_FLOAT_BITS(pyr_depth_point(x, PYR_DEPTH_F32, 0.5f, 0.25f, -0.25f).x));
    r += pyr_compact_label(PYR_CTX_ARG, 3u);
    r += pyr_sweep_row(PYR_CTX_ARG, lv, y, 0u) + pyr_sweep_column(PYR_CTX_ARG, lv, x, 1u);
    r += pyr_count_marks(PYR_CTX_ARG, 0u, 64u);
    pyr_number_marks(PYR_CTX_ARG, 0u, 64u, r);
    pyr_stats_row_run(PYR_CTX_ARG, lv, y, 0u, 64u, 1u, 16.0f, 128u, 64u);
    pyr_stats_run(PYR_CTX_ARG, lv, x, 0u, 16.0f, 128u, 64u);
    return q.x + qu.qz + PYR_I32(r);
}

#endif /* PYR_CHECK_CALLS_H */
