#pragma once
// The CPU backend's per-pixel passes over whole rows with Google Highway vectors (VectorRows below: depth images,
// normals, quantize and both metrics, the fused front end's rows, mip, label init, step 6's fill and edges, and
// compaction's lookup; each family in its *-inl.h file next to this one). Each row function computes, lane by
// lane, exactly the integer and float operations of the shared scalar function (contraction off, no fused
// multiply-add, integer divisions and square roots exact: see cpu_simd.cpp), and calls the shared function itself
// for the pixels where the neighbour tests differ (image borders), so the bytes are those of the scalar path on
// every target.
//
// One binary holds every target Highway can build for the architecture (x86: SSSE3, SSE4, AVX2, AVX3 (AVX-512)
// and Highway's one-lane scalar; Arm: NEON, SVE, SVE2) and picks the best one the CPU runs. The environment
// variable PYRSEG_CPU_SIMD, read when a Segmenter is made, overrides that choice:
//   PYRSEG_CPU_SIMD=scalar       the shared scalar functions one pixel at a time (no Highway at all);
//   PYRSEG_CPU_SIMD=<target>     that Highway target, by its lower-case name ("avx2", "sse4", "neon", ...; Highway's
//                                own one-lane target is "hwy_scalar"), if this build has it and this CPU runs it;
//   unset, empty or "auto"       the best target this CPU runs.
// Any other value makes the Segmenter's constructor throw pyrseg::Error (invalid_argument) listing the names
// that would work here. The tests force each target in turn this way (tests/unit/test_cpu_simd.cpp).
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace pyrseg::cpu {
struct PassContext;
}  // namespace pyrseg::cpu

namespace pyrseg::cpu::simd {

// The fused front end's rows (backends/cpu/points_to_mask.cpp), which only a thread's own window holds, as
// structures of arrays of w elements each (vector loads at any offset, no deinterleaving).
//
// A row of points: the components and pyr_point_valid (-1 where valid, else 0).
struct PointRow {
    float* x = nullptr;
    float* y = nullptr;
    float* z = nullptr;
    std::int32_t* valid = nullptr;
};

// A row of quantized pixels unpacked (the values of store_quant's words, as the paper metric reads them): qn (0
// where not valid), validity (1 or 0), depth (z where valid, +infinity where not), and, for pixels 1 .. w - 2, the
// sums of qx, qy, qz and validity over the pixel and its horizontal neighbours.
struct QuantRow {
    std::int32_t* q[3] = {nullptr, nullptr, nullptr};
    std::int32_t* valid = nullptr;
    float* z = nullptr;
    std::int32_t* sum[4] = {nullptr, nullptr, nullptr, nullptr};
};

// Step 6c's depth test in rounds >= 2 (shaders/pyr_edges.h): the share s (0: no test) and the row's first pixel in
// the quant buffer (kQuantWords words a pixel, its z in word 2; the rows above and below at -/+ w pixels), null
// when s is 0.
struct EdgeDepths {
    float step = 0.0f;
    const std::uint32_t* quant = nullptr;
};

// Memory that the next row function will read and this one reads ahead into the L2 cache, a few lines with each of
// its vectors (its arithmetic then hides the wait): the spans at[i] of `bytes` bytes each, null for none.
struct ReadAhead {
    const void* at[2] = {nullptr, nullptr};
    std::size_t bytes = 0;
};

// What the robust normals' vector rows read of the windows of one row y (backends/cpu/robust_windows.hpp): per
// tangent component k (t_h x y z, t_v x y z) the rows y0 (top) and y1 + 1 (bottom) of its summed-area table (W + 1
// entries each), y0 .. y1 being the window's rows clipped to the image; and the range of G(z) over each pixel's
// window (W entries each).
struct RobustWindowRow {
    const std::uint32_t* top[6] = {};
    const std::uint32_t* bottom[6] = {};
    const std::int32_t* min = nullptr;
    const std::int32_t* max = nullptr;
};

// A stretch of pixels' sums for the statistics (shaders/pyr_stats.h, backends/cpu/cpu_stats.cpp), exact, over its
// fillable pixels: how many, the fixed-point coordinates q, the quantized normals, the least and greatest q_z, and
// the six products of q's components (xx, xy, xz, yy, yz, zz).
__extension__ typedef __int128 StatsInt128;
struct StatsSums {
    std::uint64_t fillable = 0;
    std::int64_t point[3] = {0, 0, 0};
    std::int64_t normal[3] = {0, 0, 0};
    std::int32_t z_min = 2147483647;
    std::int32_t z_max = -2147483647 - 1;
    StatsInt128 product[6] = {0, 0, 0, 0, 0, 0};
};

// The row functions of one Highway target. Rows are independent: the passes call these from many threads.
struct VectorRows {
    const char* name = "";    // the PYRSEG_CPU_SIMD name
    std::int64_t target = 0;  // Highway's HWY_* bit

    // Row y of the paper metric's normals with radius r (pyr_normal_q): 3 * w floats, q * 2^-13, packed.
    void (*normals_row)(const PassContext& c, std::uint32_t w, std::uint32_t h, std::uint32_t y, std::uint32_t r,
                        float* out) = nullptr;
    // One row of quantize (pyr_quantize): w pixels; points and normals each point_floats / normal_floats apart; out
    // gets kQuantWords words a pixel (cpu_dialect.hpp).
    void (*quantize_row)(const float* points, std::size_t point_floats, const float* normals, std::size_t normal_floats,
                         std::uint32_t w, std::uint32_t* out) = nullptr;
    // Row y of the paper metric (pyr_metric_fillable) over c.quant: w mask bytes, 1 where fillable.
    void (*metric_row)(const PassContext& c, std::uint32_t w, std::uint32_t h, std::uint32_t y, std::int32_t tc,
                       float dt, std::uint8_t* out) = nullptr;
    // Row y of the level above a child level (pyr_mip_texel): parent_width bytes. child_top is the child's row 2y
    // (nullptr when 2y + 1 is not a row of the child: the whole row is then 0).
    void (*mip_row)(const std::uint8_t* child_top, std::uint32_t child_width, std::uint32_t parent_width,
                    std::uint8_t* out) = nullptr;
    // One row of step 3's or 5's label init (pyr_label_init_texel, PYR_INIT_INHERIT): out[x] is parent[x / 2]
    // where mask[x] is fillable, else 0, for x < w (parent: the parent level's row, (w + 1) / 2 labels). Unless
    // unlabelled is null, it gets (w + 63) / 64 words with bit x % 64 of word x / 64 set where x is fillable and
    // out[x] is 0 (the pixels step 6 can change), bits past w clear. Returns whether a bit is set.
    bool (*inherit_row)(const std::uint8_t* mask, const std::uint32_t* parent, std::uint32_t w, std::uint32_t* out,
                        std::uint64_t* unlabelled) = nullptr;
    // Step 6c with one round (pyr_edge_label, round 1) on one row of the full level, in place: each valid
    // (valid[x] != 0), non-fillable pixel gets the smallest non-zero label among its own and those of its fillable
    // 4-neighbours, 0 when there is none; other pixels keep theirs. With its own label 0 that is pyr_edge_label's;
    // with a non-zero one it is the same minimum taken again, so neighbours labelled later can be folded in. The
    // rows above and below (labels and masks) are null at the image's top and bottom.
    void (*edge_row)(const std::uint8_t* mask_above, const std::uint8_t* mask, const std::uint8_t* mask_below,
                     const std::uint32_t* above, std::uint32_t* labels, const std::uint32_t* below,
                     const std::uint8_t* valid, std::uint32_t w) = nullptr;
    // Row y of the paper metric's normals (as normals_row, unless normals is null) and their quantize words (as
    // quantize_row of the row's points and those normals, unless quant is null), from one pass over the points.
    void (*normals_to_row)(const PassContext& c, std::uint32_t w, std::uint32_t h, std::uint32_t y, std::uint32_t r,
                           float* normals, std::uint32_t* quant) = nullptr;
    // One row of a depth image to points (pyr_depth_point): w samples (u16 or f32 as `format` says: PYR_DEPTH_*)
    // from `samples`, with the row's ku[0..w-1] and kv; 3 * w floats out, packed.
    void (*depth_row)(const void* samples, std::uint32_t format, std::uint32_t w, float scale, const float* ku,
                      float kv, float* out) = nullptr;
    // One step of step 6b's column sweeps on a row of the full level: each pixel marked in `marked` ((w + 63) / 64
    // words, bit x % 64 of word x / 64; the pixels step 6 can still change) takes the label of pixel x of the row
    // the sweep comes from (`from`, its mask `from_mask`) when that pixel is fillable and labelled, and its mark is
    // cleared; other pixels keep theirs. Returns whether a pixel took a label.
    bool (*column_step)(const std::uint8_t* from_mask, const std::uint32_t* from, std::uint32_t* row,
                        std::uint64_t* marked, std::uint32_t w) = nullptr;
    // Compaction's lookup over a row: out[x] = lut[raw[x]] for x < w. lut[0] must be 0, and every raw label below
    // 2^31 (the vector targets index the table with signed 32-bit lanes).
    void (*compact_row)(const std::uint32_t* raw, const std::uint32_t* lut, std::uint32_t w,
                        std::uint32_t* out) = nullptr;
    // Step 6a on a row of the full level whose pixels step 6 can change are marked (as inherit_row leaves them; bits
    // past w clear): each run of marked pixels takes the label of the pixel left of it when that one is fillable
    // (so labelled), else of the one right of it, and its marks are cleared; else it stays as it is. That is the
    // contract's sweep there and back along the row. Returns whether marks remain.
    bool (*row_runs)(const std::uint8_t* mask, std::uint32_t* row, std::uint64_t* marked, std::uint32_t w) = nullptr;

    // The fused front end's row functions (PointRow, QuantRow above).
    // One row of points (point_floats apart) split into `out`: w points.
    void (*split_points_row)(const float* points, std::size_t point_floats, std::uint32_t w,
                             const PointRow& out) = nullptr;
    // Row y of the paper metric's normals with radius r and their quantized pixels (what normals_to_row writes),
    // from the rows y - r (up), y (row) and y + r (down) split (`row` again for up / down outside the image; the
    // image's columns x < r and x >= w - r read c's points). Into `out`, and into normals (3 floats a pixel),
    // quant (kQuantWords words a pixel) and valid (a byte a pixel, 1 or 0) unless null.
    void (*normals_quant_row)(const PassContext& c, const PointRow& up, const PointRow& row, const PointRow& down,
                              std::uint32_t w, std::uint32_t h, std::uint32_t y, std::uint32_t r, float* normals,
                              std::uint32_t* quant, std::uint8_t* valid, const QuantRow& out,
                              const ReadAhead& ahead) = nullptr;
    // One row of quantize (what quantize_row writes) into `out`, and into quant and valid unless null.
    void (*quantize_quant_row)(const float* points, std::size_t point_floats, const float* normals,
                               std::size_t normal_floats, std::uint32_t w, std::uint32_t* quant, std::uint8_t* valid,
                               const QuantRow& out) = nullptr;
    // The paper metric of a row (what metric_row writes) from it, the row above and the row below (null outside the
    // image).
    void (*metric_quant_row)(const QuantRow* above, const QuantRow& row, const QuantRow* below, std::uint32_t w,
                             std::int32_t tc, float dt, std::uint8_t* out, const ReadAhead& ahead) = nullptr;
    // Round `round` >= 1 of step 6c with several rounds (pyr_edge_label) on one row of the full level: marks in
    // `changed` ((w + 63) / 64 words, bit x % 64 of word x / 64; bits past w clear) the pixels that take a label in
    // that round, with the label in out[x] (out is not written elsewhere); returns whether one does. The masks hold
    // the rounds before (bits PYR_MASK_EDGE_SHIFT and up); the rows above and below are null at the image's top and
    // bottom.
    bool (*edge_round_row)(const std::uint8_t* mask_above, const std::uint8_t* mask, const std::uint8_t* mask_below,
                           const std::uint32_t* above, const std::uint32_t* labels, const std::uint32_t* below,
                           const std::uint8_t* valid, std::uint32_t w, std::uint32_t round, const EdgeDepths& depths,
                           std::uint32_t* out, std::uint64_t* changed) = nullptr;
    // The robust metric's rows (docs/algorithm.md sections 2b and 8b).
    // Row y of the robust normals' texels with radius r (pyr_robust_texel): into c.robust_texels.
    void (*robust_texels_row)(const PassContext& c, std::uint32_t w, std::uint32_t h, std::uint32_t y, std::uint32_t r,
                              float scale) = nullptr;
    // The smallest (lo) and largest (hi) of in[x - r .. x + r], clipped to 0 .. w - 1, for x < w: the robust windows'
    // depth range along a row.
    void (*robust_range_row)(const std::int32_t* in, std::uint32_t w, std::uint32_t r, std::int32_t* lo,
                             std::int32_t* hi) = nullptr;
    // Row y of the robust normals (pyr_robust_normal_q) with windows of radius `window`, as normals_row writes them,
    // for each pixel whose window's columns lie inside the image: from the box sums (`sums`: RobustWindowRow) where
    // the window's pixels are all members, else from the members pixel by pixel. The other pixels (the first and
    // last `window` columns, or all of a row too narrow for a vector) are left to the caller, marked in `rest`
    // ((w + 63) / 64 words, bit x % 64 of word x / 64; bits past w clear).
    void (*robust_normals_row)(const PassContext& c, const RobustWindowRow& sums, std::uint32_t w, std::uint32_t h,
                               std::uint32_t y, std::uint32_t window, float* out, std::uint64_t* rest) = nullptr;
    // Row y of the robust metric (pyr_metric_robust_fillable) over c.quant with curvature stride `stride` and the
    // thresholds' constants: w mask bytes, 1 where fillable.
    void (*metric_robust_row)(const PassContext& c, std::uint32_t w, std::uint32_t h, std::uint32_t y,
                              std::uint32_t stride, float curvature_base, float curvature_growth, float dt,
                              float depth_growth, std::uint8_t* out) = nullptr;
    // Step 6c's candidates of a row of the full level: out[x] = labels[x] - 1 (wrapping) where mask[x] is fillable,
    // else the largest value; edge_row_from_candidates reads them in place of the labels and masks of the rows.
    void (*edge_candidates)(const std::uint8_t* mask, const std::uint32_t* labels, std::uint32_t w,
                            std::uint32_t* out) = nullptr;
    // edge_row (the same labels) from the candidates of the rows above and below (null at the image's top and
    // bottom) and of the row itself, with the row's mask, validity and labels.
    void (*edge_row_from_candidates)(const std::uint32_t* above, const std::uint32_t* row, const std::uint32_t* below,
                                     const std::uint8_t* mask, const std::uint8_t* valid, std::uint32_t* labels,
                                     std::uint32_t w) = nullptr;
    // The statistics' sums (StatsSums) over the fillable pixels (PYR_MASK_FILLABLE in their `mask` byte) of `count`
    // pixels from the point at `points` (each `stride` floats after the one before; only its three floats are read)
    // and their quant words (kQuantWords a pixel), added to `sums` a vector at a time (the last one partial) while
    // every fixed-point coordinate of a fillable pixel stays below 2^26 in magnitude (then no 64-bit lane can
    // overflow). Returns the pixels summed: fewer than `count` at a vector with a larger coordinate, from which the
    // caller sums another way.
    std::uint32_t (*stats_sums)(const float* points, std::size_t stride, const std::uint32_t* quant,
                                const std::uint8_t* mask, std::uint32_t count, float scale, StatsSums& sums) = nullptr;
};

// The targets of this build that this CPU runs, best first.
[[nodiscard]] std::vector<const VectorRows*> available_targets();

// What PYRSEG_CPU_SIMD asks for (see above): nullptr for "scalar", else the vector rows to use. Throws pyrseg::Error
// (invalid_argument) for a value that names nothing available here.
[[nodiscard]] const VectorRows* rows_from_environment();

// The names PYRSEG_CPU_SIMD accepts here: "scalar", then the available targets, best first.
[[nodiscard]] std::vector<std::string> accepted_names();

}  // namespace pyrseg::cpu::simd
