#pragma once
// What a backend implements: one method per pass of the contract. core/pipeline.cpp calls them in the contract's
// order; a backend holds only the code that runs a pass on its device (the per-pixel logic is in shaders/).
#include <cstdint>
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
    // Step 6 c. A backend may also mark the labels present for compaction here, while each row is in cache.
    virtual void label_edges() = 0;
    // Step 7: counts the distinct labels of level N (the segment count K, reported by read_back) and, when apply,
    // renumbers them. after_edges: label_edges ran just before (so a backend that marks there need not again).
    virtual void compact(bool apply, bool after_edges) = 0;
    // Per-segment statistics into plan.stats_slots slots (docs/algorithm.md section 10), after compact; read_back
    // returns them (core/segment_stats.hpp decodes the words).
    virtual void segment_stats() = 0;
    // Results to the host. A backend that queues the passes may run them only here.
    virtual void read_back(Result& out, const Outputs& outputs) = 0;
    // Device-resident frames (core/device_frame.hpp), on a GPU backend made on the caller's context: the input
    // copied from the caller's buffers on the device, then the passes as for a host frame, then, instead of
    // read_back, the labels and K copied into the caller's buffers and the frame submitted without a host wait.
    // The CPU backend (and any executor without a device) throws pyrseg::Error.
    virtual void bind_device_cloud(const DeviceCloud& cloud);
    virtual void bind_device_depth(const DeviceDepth& depth, const DepthTables& tables);
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
