#pragma once
// What a segmentation returns. A Result is reused frame after frame: its buffers are sized once.
#include <array>
#include <cstdint>
#include <vector>

namespace pyrseg {

// Intermediate images a caller may ask for, for inspection and conformance tests.
struct Outputs {
    bool raw_labels = false;     // labels before compaction (step 7)
    bool fillable_mask = false;  // the metric pass's mask B: 1 fillable, 0 edge/invalid/isolated
    bool normals = false;        // the normals the metric used (given, or estimated), 3 floats per pixel
    bool segment_stats = false;  // per-segment statistics (Result::segments), a pass of every backend
};

// One segment's statistics (docs/algorithm.md section 10). Every backend computes the integer fields with the same
// exact arithmetic, so they agree bit for bit; the double fields are derived from them on the host.
struct SegmentStats {
    std::uint32_t label = 0;                         // its value in Result::labels (the compacted id, or the raw label)
    std::uint32_t pixel_count = 0;                   // labelled pixels, edge pixels of step 6c included
    int x_min = 0, y_min = 0, x_max = 0, y_max = 0;  // bounding box in pixels, inclusive
    // Sums over the segment's pixels, exact: points in fixed point (rint(p * 2^point_shift), the caller's units,
    // each coordinate clamped to +-(2^31 - 128)) and the quantized normals qn (units of 2^-13). Zero for a mask.
    std::array<std::int64_t, 3> point_sum{};
    std::array<std::int64_t, 3> normal_sum{};
    int point_shift = 0;  // the fixed point's binary exponent, from Params::unit_mm (steps of 1/16 mm or finer)
    // Derived: the 3D centroid (mean point, the caller's units) and the unit mean normal (normal_sum normalised;
    // zero when it is zero). NaN when the frame was a caller's mask, which has no points.
    std::array<double, 3> centroid{};
    std::array<double, 3> mean_normal{};
};

struct Result {
    int width = 0;
    int height = 0;
    std::vector<std::uint32_t> labels;        // width*height, row-major; compacted 1..K unless Params::compact is false
    std::uint32_t segment_count = 0;          // K, the number of distinct non-zero labels
    std::vector<std::uint32_t> raw_labels;    // filled when Outputs::raw_labels
    std::vector<std::uint8_t> fillable_mask;  // filled when Outputs::fillable_mask
    std::vector<float> normals;               // filled when Outputs::normals
    // Filled when Outputs::segment_stats: K entries, segment k at k - 1. It keeps its capacity, so it allocates
    // only when a frame has more segments than every frame before.
    std::vector<SegmentStats> segments;
};

}  // namespace pyrseg
