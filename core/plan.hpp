#pragma once
// The plan of one Segmenter: validated parameters, thresholds, pyramid geometry and label ranges. Computed once
// on the host for every backend, so that all of them run exactly the same passes on the same numbers.
#include <cstdint>
#include <vector>

#include "pyrseg/params.hpp"
#include "pyrseg/result.hpp"
#include "shaders/pyr_types.h"

namespace pyrseg::core {

struct Thresholds {
    std::int32_t curvature;  // Tc
    float depth;             // dt in input units
    // The robust metric (section 2b): the curvature limit A + Bc * z^2 (units of 2^-26), the depth growth Bd (dt in
    // units + Bd * z^2) and the fixed-point scale 2^e of its normals (section 8b).
    float curvature_base = 0;
    float curvature_growth = 0;
    float depth_growth = 0;
    float point_scale = 1;
    // The merge (section 5b): its points' fixed point 2^e, its tolerance base + growth * z^2 (units of 2^-(e + 13)
    // input units) and the bad share it allows, in 256ths.
    float merge_point_scale = 1;
    float merge_tolerance_base = 0;
    float merge_tolerance_growth = 0;
    std::uint32_t merge_share = 0;
    // The colour edge's curvature gate G = rint(color_edge_curvature_share * 256), 0..256 (section 2c).
    std::uint32_t color_curvature_gate = 0;
    // Step 6c's depth test in rounds >= 2: s = (float)edge_max_depth_step, 0 for none (section 5).
    float edge_depth_step = 0;
};

// Throws pyrseg::Error(invalid_parameter) naming the parameter.
[[nodiscard]] Thresholds compute_thresholds(const Params& params);

// unit_mm (Params, sensor_preset, measure_frame_noise): a finite number of millimetres > 0, else
// pyrseg::Error(invalid_parameter) naming it.
void check_unit_mm(double unit_mm);

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
    // Per-segment statistics (Outputs::segment_stats; docs/algorithm.md section 10): slots, 0 when not asked for;
    // and the fixed point of the point sums, 2^stats_point_shift steps per input unit.
    std::uint32_t stats_slots = 0;
    int stats_point_shift = 0;
    // The merge's pair table (shaders/pyr_merge_table.h, every backend): a power of two above twice the pairs a
    // frame can have; 0 without the merge.
    std::uint32_t merge_slots = 0;
    // The segment graph's pair table (Outputs::segment_graph; shaders/pyr_graph.h): a power of two above twice the
    // pairs a frame can have; 0 when not asked for.
    std::uint32_t graph_slots = 0;
    // The tracks' pair table at most (Outputs::segment_tracks; shaders/pyr_track.h): a power of two above twice
    // the pairs of (previous label, label) a frame can have; 0 without tracks (which also run the statistics).
    std::uint32_t track_slots = 0;
    // Outputs::normals: the frame returns the normals the metric used, so a backend must keep them per pixel.
    bool keep_normals = false;

    [[nodiscard]] const PyrLevel& level(int k) const { return levels[static_cast<std::size_t>(k - 1)]; }
    [[nodiscard]] const PyrLevel& full() const { return levels.back(); }
    [[nodiscard]] std::size_t pixel_count() const {
        return static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
    }
    // Compaction's label table (indexed by raw label, 0..max_label) and its scan's chunks (PYR_SCAN_CHUNK each).
    [[nodiscard]] std::uint32_t lut_size() const { return max_label + 1; }
    [[nodiscard]] std::uint32_t scan_chunks() const { return (lut_size() + PYR_SCAN_CHUNK - 1) / PYR_SCAN_CHUNK; }
    // The statistics pass: its words (PYR_STATS_WORDS per slot), its invocations (runs of PYR_STATS_RUN pixels of
    // a row) and the float it scales points by (2^stats_point_shift, exact).
    [[nodiscard]] std::size_t stats_words() const { return std::size_t(stats_slots) * PYR_STATS_WORDS; }
    [[nodiscard]] std::uint32_t stats_runs_per_row() const {
        return (std::uint32_t(width) + PYR_STATS_RUN - 1) / PYR_STATS_RUN;
    }
    [[nodiscard]] float stats_point_scale() const;
    // The segment graph's words at most: the pairs' counter, the table, and the dense list of at most half as many
    // pairs (shaders/pyr_graph.h); a frame uses those of pyr_graph_slots(K, graph_slots).
    [[nodiscard]] std::size_t graph_words() const {
        return graph_slots == 0 ? 0 : 1 + std::size_t(PYR_GRAPH_SLOT_WORDS) * (graph_slots + graph_slots / 2);
    }
    // The tracks' words on GPUs: the table at its largest, then the header and the gathered pairs, at most one per
    // pixel (shaders/pyr_types.h: PYR_TRACK_HEADER_WORDS), which device frames copy to the caller.
    [[nodiscard]] std::uint32_t track_pair_capacity() const {
        return track_slots == 0 ? 0 : std::uint32_t(pixel_count());
    }
    [[nodiscard]] std::size_t track_list_words() const {
        return track_slots == 0 ? 0
                                : PYR_TRACK_HEADER_WORDS + std::size_t(PYR_TRACK_SLOT_WORDS) * track_pair_capacity();
    }
    [[nodiscard]] std::size_t track_words() const {
        return std::size_t(PYR_TRACK_SLOT_WORDS) * track_slots + track_list_words();
    }
};

// Validates everything before anything is allocated. Throws pyrseg::Error.
[[nodiscard]] Plan make_plan(int width, int height, const Params& params, const Outputs& outputs = {});

}  // namespace pyrseg::core
