#pragma once
// The independent oracle for pyrseg: a plain, slow-but-linear implementation of the algorithm contract
// (shared/spec/algorithm-contract.md) and of docs/algorithm.md section 8 (the normals pass), written from that text
// only. The conformance suite compares every backend with it bit for bit.
#include <cstdint>
#include <string>
#include <vector>

namespace pyrseg_ref {

struct Params {
    double ct = 0.25;  // radians
    double dt = 10.0;  // millimetres
    double unit_mm = 1.0;
    int bridge_levels = 2;     // b
    int unjoinable_gap = 2;    // g
    bool bg_explicit = false;  // true: b/g that do not fit the image are an error (ok=false) instead of the fallback
    bool label_edges = true;
    bool compact = true;
    int normal_radius = 1;
};

// One segment's statistics (docs/algorithm.md section 10), in compacted order: exact integer sums.
struct Segment {
    std::uint32_t label = 0;  // as in Output::labels
    std::uint32_t pixel_count = 0;
    int x_min = 0, y_min = 0, x_max = 0, y_max = 0;
    std::int64_t point_sum[3] = {0, 0, 0};   // sum of rint(clamp(p * 2^point_shift)), zero for a mask
    std::int64_t normal_sum[3] = {0, 0, 0};  // sum of qn, zero for a mask
    int point_shift = 0;
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
};

// points: packed xyz float32, 3*W*H, row-major. normals: packed, or nullptr to estimate them (docs section 8).
Output segment(const float* points, const float* normals, int width, int height, const Params& params);

// Steps 3..7 only, from a given mask: fillable[i] is B; valid[i] (nullptr = every pixel valid) is used by edge
// labelling (step 6c). Output::fillable echoes the mask, Output::normals stays empty.
Output segment_mask(const std::uint8_t* fillable, const std::uint8_t* valid, int width, int height,
                    const Params& params);

// The normals pass alone (docs/algorithm.md section 8): 3*W*H floats, (0,0,0) where undefined.
// Returns an empty vector when width, height or radius is < 1.
std::vector<float> estimate_normals(const float* points, int width, int height, int radius);

}  // namespace pyrseg_ref
