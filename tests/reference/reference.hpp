#pragma once
// The independent oracle for pyrseg: a plain, slow-but-linear implementation of the algorithm contract
// (shared/spec/algorithm-contract.md) and of docs/algorithm.md sections 2b and 8b (the robust metric and its normals),
// 8 (the normals pass), 1b (depth images), 2c (the colour edge term), 5b (the merge) and 10d (the segment graph),
// written from that text only.
// The conformance suite compares every backend with it bit for bit.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace pyrseg_ref {

// Which metric builds the fillable mask B: `paper` is the contract's (docs/algorithm.md section 2, normals of section
// 8), `robust` is section 2b (normals of section 8b when the caller gives none).
enum class Metric { paper, robust };

struct Params {
    using Metric = pyrseg_ref::Metric;  // so Params::Metric::robust reads too

    double ct = 0.25;  // radians
    double dt = 10.0;  // millimetres
    double unit_mm = 1.0;
    int bridge_levels = 2;     // b
    int unjoinable_gap = 2;    // g
    bool bg_explicit = false;  // true: b/g that do not fit the image are an error (ok=false) instead of the fallback
    bool label_edges = true;
    int edge_rounds = 1;  // rounds of step 6c, 1..63 (docs/algorithm.md section 5)
    // c of step 6c (docs/algorithm.md section 5): 0 (no test) or finite in [1e-6, 1]. In rounds k >= 2 a neighbour q
    // counts for pixel p only when |z_p - z_q| <= (float)c * z_p. segment_mask refuses c > 0 when the test would be
    // used (label_edges on, edge_rounds >= 2): a mask has no depths.
    double edge_max_depth_step = 0.0;
    bool compact = true;
    int normal_radius = 1;
    // Section 2b. With Metric::paper the four numbers below must keep their defaults (else ok = false); with
    // Metric::robust they are checked against their ranges whether or not normals are given.
    Metric metric = Metric::paper;
    int normal_window = 3;          // R, 1..7: the (2R+1) x (2R+1) window of section 8b
    int curvature_stride = 4;       // s, 1..64: the curvature term compares the pairs of pixels s before and after
    double dt_per_m2 = 0.0;         // millimetres added to dt per square metre of depth; finite, >= 0
    double ct_growth_per_m2 = 0.0;  // growth of the curvature limit per square metre of depth; finite, >= 0
    // Section 5b: the merge (step 6d) of segments whose shared boundary is convex or flat. Needs points and normals
    // (segment_mask with merge on gives ok = false); not run in the small-image fallback. The five numbers below are
    // checked against their ranges whether or not merge is on.
    bool merge = false;
    int merge_reach = 2;                  // r, 1..16: each side looks up to r - 1 pixels back from the boundary
    double merge_tolerance_mm = 1.0;      // t0, finite, >= 0: how far a side may lie above the other's tangent plane
    double merge_tolerance_per_m2 = 0.0;  // t2, finite, >= 0: millimetres added to t0 per square metre of depth
    int merge_min_crossings = 16;         // C >= 1: crossings a pair needs to join
    double merge_max_bad_share = 0.05;    // f in [0, 1]: the largest share of bad crossings a joining pair may have
    // Section 2c: the colour edge term, on frames given a colour image. Checked against their ranges always; the
    // curvature gate g must also keep its default (0) with Metric::paper.
    int color_edge_threshold = 765;           // T, 0..765; 765: no pixel is a colour edge
    int color_edge_stride = 1;                // s, 1..16
    double color_edge_curvature_share = 0.0;  // g, finite, in [0, 1]; 0: every colour edge counts; robust only
};

// Exact sums of products (a product of two fixed-point coordinates is below 2^62 in magnitude).
__extension__ typedef __int128 Int128;

// One segment's statistics (docs/algorithm.md section 10), in compacted order: exact integer sums.
struct Segment {
    std::uint32_t label = 0;  // as in Output::labels
    std::uint32_t pixel_count = 0;
    int x_min = 0, y_min = 0, x_max = 0, y_max = 0;
    // Over the segment's fillable pixels:
    std::int64_t point_sum[3] = {0, 0, 0};   // sum of rint(clamp(p * 2^point_shift)), zero for a mask
    std::int64_t normal_sum[3] = {0, 0, 0};  // sum of qn, zero for a mask
    int point_shift = 0;
    // Sums of the products of the fixed-point coordinates (xx, xy, xz, yy, yz, zz), exact; zero for a mask.
    Int128 product_sum[6] = {0, 0, 0, 0, 0, 0};
    std::int64_t z_fixed_min = 0, z_fixed_max = 0;  // the fixed-point z's range; zero for a mask
    std::uint32_t fillable_count = 0;               // the fillable pixels the sums run over; zero for a mask
};

// One pair of touching segments (docs/algorithm.md section 10d): the crossings of their shared boundary, by kind.
struct Edge {
    std::uint32_t a = 0, b = 0;                                 // their labels as in Output::labels, a < b
    std::uint32_t length = 0;                                   // crossings
    std::uint32_t flat = 0, convex = 0, concave = 0, step = 0;  // zero for a mask
};

struct Output {
    bool ok = true;
    std::string error;                      // why, when !ok (bad parameters, sizes, too large for 32-bit labels)
    std::vector<std::uint32_t> labels;      // W*H final labels (compacted if compact, else raw)
    std::vector<std::uint32_t> raw_labels;  // W*H labels before compaction
    std::vector<std::uint8_t> fillable;     // W*H mask B (1/0)
    std::vector<float> normals;             // 3*W*H: the normals the metric used (given ones copied, or estimated)
    std::uint32_t segment_count = 0;        // distinct non-zero labels
    std::vector<Segment> segments;          // segment_count entries, by increasing raw label
    std::vector<Edge> graph;                // every pair of touching segments, by increasing (a, b)
};

// points: packed xyz float32, 3*W*H, row-major. normals: packed, or nullptr to estimate them (docs section 8, or
// section 8b with Metric::robust). Output::normals holds the normals the metric used. color: packed R, G, B bytes,
// 3*W*H, row-major, or nullptr for none (section 2c).
Output segment(const float* points, const float* normals, int width, int height, const Params& params,
               const std::uint8_t* color = nullptr);

// Steps 3..7 only, from a given mask: fillable[i] is B; valid[i] (nullptr = every pixel valid) is used by edge
// labelling (step 6c). Output::fillable echoes the mask, Output::normals stays empty. Refused (ok = false) with merge
// on, and with edge_max_depth_step > 0 while label_edges is on and edge_rounds >= 2 (no points, so no depths).
Output segment_mask(const std::uint8_t* fillable, const std::uint8_t* valid, int width, int height,
                    const Params& params);

// The normals pass alone (docs/algorithm.md section 8): 3*W*H floats, (0,0,0) where undefined.
// Returns an empty vector when width, height or radius is < 1.
std::vector<float> estimate_normals(const float* points, int width, int height, int radius);

// The robust normals alone (docs/algorithm.md section 8b): 3*W*H floats, (0,0,0) where undefined. radius is r,
// window is R, unit_mm fixes the exponent e of the fixed-point points. Returns an empty vector when width, height or
// radius is < 1, window is outside 1..7, or unit_mm is not finite and > 0.
std::vector<float> estimate_robust_normals(const float* points, int width, int height, int radius, int window,
                                           double unit_mm);

// Depth images (docs/algorithm.md section 1b).
enum class DepthFormat { u16, f32 };

struct DepthInput {
    const void* samples = nullptr;  // row-major, rows row_step_bytes apart (any alignment: read with memcpy)
    DepthFormat format = DepthFormat::u16;
    int width = 0, height = 0;
    std::size_t row_step_bytes = 0;  // 0: width * sample size; otherwise at least that
    double metres_per_unit = 0.001;  // m
    double fx = 0, fy = 0, cx = 0, cy = 0;
};

// Section 1b: the points (3*W*H floats, the quiet NaN 0x7fc00000 where no data), or ok = false with the reason in
// `error` (naming the parameter). unit_mm is the Segmenter's, the unit the points are in.
struct DepthPoints {
    bool ok = true;
    std::string error;
    std::vector<float> points;
};
DepthPoints depth_to_points(const DepthInput& depth, double unit_mm);

// The whole algorithm from a depth image: section 1b with params.unit_mm, then segment() with normals estimated.
// ok = false when depth.width / depth.height differ from width / height, or for any error of either step.
Output segment_depth(const DepthInput& depth, int width, int height, const Params& params,
                     const std::uint8_t* color = nullptr);

}  // namespace pyrseg_ref
