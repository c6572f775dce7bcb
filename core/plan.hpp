#pragma once
// The plan of one Segmenter: validated parameters, thresholds, pyramid geometry and label ranges. Computed once
// on the host for every backend, so that all of them run exactly the same passes on the same numbers.
#include <cstdint>
#include <vector>

#include "pyrseg/params.hpp"
#include "shaders/pyr_types.h"

namespace pyrseg::core {

struct Thresholds {
    std::int32_t curvature;  // Tc
    float depth;             // dt in input units
};

// Throws pyrseg::Error(invalid_parameter) naming the parameter.
[[nodiscard]] Thresholds compute_thresholds(const Params& params);

struct Plan {
    int width = 0;
    int height = 0;
    Params params;
    Thresholds thresholds{};
    int level_count = 0;              // N
    int bridge_level = 0;             // M = N - b
    int unjoinable_level = 0;         // U = M - g
    bool small_image = false;         // the contract's fallback: plain 4-connected components
    std::vector<PyrLevel> levels;     // levels[k - 1] is level k; level N is the full image
    std::uint32_t old_label_max = 0;  // offset_{U+1}: labels 1..this are old
    std::uint32_t max_label = 0;      // the largest label any pass can create
    std::uint64_t total_texels = 0;   // offset_{N+1}, the size of the all-levels buffers

    [[nodiscard]] const PyrLevel& level(int k) const { return levels[static_cast<std::size_t>(k - 1)]; }
    [[nodiscard]] const PyrLevel& full() const { return levels.back(); }
    [[nodiscard]] std::size_t pixel_count() const {
        return static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
    }
    // Compaction's label table (indexed by raw label, 0..max_label) and its scan's chunks (PYR_SCAN_CHUNK each).
    [[nodiscard]] std::uint32_t lut_size() const { return max_label + 1; }
    [[nodiscard]] std::uint32_t scan_chunks() const { return (lut_size() + PYR_SCAN_CHUNK - 1) / PYR_SCAN_CHUNK; }
};

// Validates everything before anything is allocated. Throws pyrseg::Error.
[[nodiscard]] Plan make_plan(int width, int height, const Params& params);

}  // namespace pyrseg::core
