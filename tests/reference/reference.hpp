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

struct Output {
    bool ok = true;
    std::string error;                      // why, when !ok (bad parameters, sizes, too large for 32-bit labels)
    std::vector<std::uint32_t> labels;      // W*H final labels (compacted if compact, else raw)
    std::vector<std::uint32_t> raw_labels;  // W*H labels before compaction
    std::vector<std::uint8_t> fillable;     // W*H mask B (1/0)
    std::vector<float> normals;             // 3*W*H: the normals the metric used (given ones copied, or estimated)
    std::uint32_t segment_count = 0;        // distinct non-zero labels
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
