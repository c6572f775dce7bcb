#pragma once
// What a segmentation returns. A Result is reused frame after frame: its buffers are sized once.
#include <cstdint>
#include <vector>

namespace pyrseg {

// Intermediate images a caller may ask for, for inspection and conformance tests.
struct Outputs {
    bool raw_labels = false;     // labels before compaction (step 7)
    bool fillable_mask = false;  // the metric pass's mask B: 1 fillable, 0 edge/invalid/isolated
    bool normals = false;        // the normals the metric used (given, or estimated), 3 floats per pixel
};

struct Result {
    int width = 0;
    int height = 0;
    std::vector<std::uint32_t> labels;        // width*height, row-major; compacted 1..K unless Params::compact is false
    std::uint32_t segment_count = 0;          // K, the number of distinct non-zero labels
    std::vector<std::uint32_t> raw_labels;    // filled when Outputs::raw_labels
    std::vector<std::uint8_t> fillable_mask;  // filled when Outputs::fillable_mask
    std::vector<float> normals;               // filled when Outputs::normals
};

}  // namespace pyrseg
