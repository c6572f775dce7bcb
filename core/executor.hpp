#pragma once
// What a backend implements: one method per pass of the contract. core/pipeline.cpp calls them in the contract's
// order, and is the only place that does; a backend holds only the code that runs a pass on its device (the
// per-pixel logic is in shaders/). Where a backend runs several passes as one, it says so in a query
// (fuses_points_to_mask, fuses_edges_into_final_fill, marks_labels_before_compact) and the pipeline calls the
// fused pass instead: no pass depends on what an earlier call of the frame chose.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include "pyrseg/cloud.hpp"
#include "pyrseg/result.hpp"
#include "pyrseg/segmenter.hpp"

namespace pyrseg::gpu {
class Device;
}

namespace pyrseg::core {

struct Plan;
struct DepthTables;
struct DeviceCloud;
struct DeviceDepth;
struct DeviceColor;
struct DeviceLabels;

class PassExecutor {
public:
    virtual ~PassExecutor() = default;
    PassExecutor() = default;
    PassExecutor(const PassExecutor&) = delete;
    PassExecutor& operator=(const PassExecutor&) = delete;

    // Input: a cloud (passes from normals on), or a caller's mask (passes from the pyramid on).
    virtual void bind_cloud(const CloudView& cloud) = 0;
    virtual void bind_mask(const MaskView& mask) = 0;
    // A depth image and its per-frame constants (docs/algorithm.md section 1b); depth_to_points back-projects it
    // into the points the passes from normals on read.
    virtual void bind_depth(const DepthView& depth, const DepthTables& tables) = 0;
    virtual void depth_to_points() = 0;
    // A frame's colour image (RGB8, rows row_step_bytes apart), bound after its cloud or depth; color_edges (step
    // 0c, docs/algorithm.md section 2c) then clears B where it finds a colour edge, after the metric.
    virtual void bind_color(const std::uint8_t* rgb, std::size_t row_step_bytes) = 0;
    virtual void color_edges() = 0;
    virtual void estimate_normals() = 0;  // when the cloud has no normals
    virtual void quantize() = 0;          // validity and qn per pixel
    virtual void metric() = 0;            // fillable mask B into level N
    // A backend that returns true runs normals (when estimate_normals), quantize and metric as the one pass
    // points_to_mask, over bands of rows that stay in cache, instead of the three; the results are the same.
    [[nodiscard]] virtual bool fuses_points_to_mask() const { return false; }
    virtual void points_to_mask(bool /*estimate_normals*/) {}
    virtual void mip(int parent_level) = 0;                       // level parent_level from level parent_level + 1
    virtual void init_labels(int level, std::uint32_t mode) = 0;  // PYR_INIT_* (shaders/pyr_types.h)
    virtual void fill_to_fixed_point(int level, std::uint32_t anchor_max) = 0;  // steps 2 and 4
    virtual void final_fill(int level) = 0;  // steps 5 and 6 a, b (level N): one call, so a backend may fuse them
    // A backend that returns true runs step 6c with steps 5 and 6 a, b, while each row is in cache: the pipeline
    // then calls final_fill_with_edges instead of final_fill and label_edges.
    [[nodiscard]] virtual bool fuses_edges_into_final_fill() const { return false; }
    virtual void final_fill_with_edges(int /*level*/) {}
    virtual void label_edges() = 0;  // step 6c
    // Step 6d (Params::merge; docs/algorithm.md section 5b): level N's segments that meet along a convex or flat
    // boundary take the smallest label of the group they join. Runs on a cloud or depth frame, never on a mask.
    virtual void merge_segments() = 0;
    // A backend that marks labels before compact (marks_labels_before_compact) and returns true here marks them in
    // merge_segments, as it relabels each row: the pipeline then makes no marks after the merge.
    [[nodiscard]] virtual bool marks_labels_in_merge() const { return false; }
    // Step 7 marks the labels present at level N, counts them (the segment count K, reported by read_back) and,
    // when apply, renumbers them. compact does all of it, unless the backend returns true here: its label_edges
    // then marks them as well (each row while it is in cache), the pipeline calls mark_labels where label_edges does
    // not run (with the level that holds level N's labels), and compact only counts and renumbers.
    [[nodiscard]] virtual bool marks_labels_before_compact() const { return false; }
    virtual void mark_labels(int /*level*/) {}
    virtual void compact(bool apply) = 0;
    // Per-segment statistics into plan.stats_slots slots (docs/algorithm.md section 10), after compact; read_back
    // returns them (core/segment_stats.hpp decodes the words).
    virtual void segment_stats() = 0;
    // The segment graph into plan.graph_slots slots (docs/algorithm.md section 10d), after compact; read_back
    // returns it (core/segment_graph.hpp sorts the pairs).
    virtual void segment_graph() = 0;
    // Tracks (Outputs::segment_tracks; docs/algorithm.md section 11), after compact and the statistics: the pixels
    // each pair of (previous frame's label, this frame's label) shares, counted when the executor holds a previous
    // frame's labels (shaders/pyr_track.h), then this frame's labels kept as the previous ones. track_pairs gives
    // the pairs after read_back.
    virtual void track_overlaps();
    virtual void forget_previous_labels() {}
    // After read_back: the last frame's table slots, PYR_TRACK_SLOT_WORDS words each (previous label, label, pixels;
    // a free slot's first word is 0), in no order; `count` of them (0 on a stream's first frame).
    [[nodiscard]] virtual const std::uint32_t* track_pairs(std::uint32_t& count) const {
        count = 0;
        return nullptr;
    }
    // After read_back: the last frame's number in its stream as the device counted it, where device frames may have
    // come between (GPUs); nullopt where only host frames run.
    [[nodiscard]] virtual std::optional<std::uint32_t> track_frame() const { return std::nullopt; }
    // Results to the host. A backend that queues the passes may run them only here.
    virtual void read_back(Result& out, const Outputs& outputs) = 0;
    // Device-resident frames (core/device_frame.hpp), on a GPU backend made on the caller's context: the input
    // copied from the caller's buffers on the device, then the passes as for a host frame, then, instead of
    // read_back, the labels and K copied into the caller's buffers and the frame submitted without a host wait.
    // The CPU backend (and any executor without a device) throws pyrseg::Error.
    virtual void bind_device_cloud(const DeviceCloud& cloud);
    virtual void bind_device_depth(const DeviceDepth& depth, const DepthTables& tables);
    virtual void bind_device_color(const DeviceColor& color);  // after bind_device_cloud or bind_device_depth
    virtual void write_device_labels(const DeviceLabels& labels);
    // The GPU device the executor runs on (for the interop functions); nullptr on the CPU.
    [[nodiscard]] virtual gpu::Device* gpu_device() { return nullptr; }

    // Called before each pass the pipeline times, with the pass's name ("normals", ..., "compact").
    virtual void begin_pass(const char* /*pass*/) {}
    // A backend whose passes run asynchronously overwrites the host's times in `timings` (same names) with the
    // times its device measured, and returns true. Called after read_back.
    virtual bool device_timings(std::vector<PassTiming>& /*timings*/) { return false; }
    // Rounds of row and column sweeps the fixed-point fills (steps 2 and 4) of the last frame took, each fill
    // counted up to and including its first round that changed nothing; 0 for the union-find fills every backend
    // uses by default (only the CPU's PYRSEG_CPU_FILL=sweeps sweeps). Read after read_back.
    [[nodiscard]] virtual std::uint32_t fill_rounds() const { return 0; }
    // A device's dispatches and host waits in the last frame (Segmenter::last_dispatches, last_host_syncs).
    [[nodiscard]] virtual std::uint32_t dispatches() const { return 0; }
    [[nodiscard]] virtual std::uint32_t host_syncs() const { return 0; }
};

}  // namespace pyrseg::core
