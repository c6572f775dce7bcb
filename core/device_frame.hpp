#pragma once
// Device-resident frames: input read from, and labels written to, buffers the caller owns on its own GPU context
// (a cl_mem, a VkBuffer, a CUDA device pointer), with no host transfer and no host wait. The API-neutral part, once
// for every GPU backend: the buffer descriptions, their checks, and the frame's run over the pass executor. Each
// backend's interop functions (pyrseg/opencl.hpp, pyrseg/vulkan.hpp, pyrseg/cuda.hpp) fill these in from the API's
// own types and add the API's ordering (events, semaphores, command buffers, streams).
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include "pyrseg/depth.hpp"
#include "pyrseg/params.hpp"
#include "pyrseg/result.hpp"
#include "pyrseg/segmenter.hpp"

namespace pyrseg::core {

class PassExecutor;
struct Plan;

// One of the caller's buffers: the API's handle as an integer (cl_mem and CUDA pointers cast, VkBuffer as it is),
// where the frame's data starts in it, and how many bytes it has from there (the API's own size where the API can
// tell, else the caller's word).
struct ExternalBuffer {
    std::uint64_t handle = 0;  // 0: none
    std::size_t offset = 0;
    std::size_t bytes = 0;
};

// A colour image registered to the frame (optional): R, G, B bytes packed within each row, rows row_step_bytes apart
// (0: 3 * width). No handle: the frame has none.
struct DeviceColor {
    ExternalBuffer rgb;
    std::size_t row_step_bytes = 0;
};

// A cloud: float32 xyz packed within each row (12 bytes a point), rows row_step_bytes apart (0: 12 * width).
// Normals, when given, have the same layout.
struct DeviceCloud {
    ExternalBuffer points;
    ExternalBuffer normals;
    std::size_t row_step_bytes = 0;
    DeviceColor color;
};

// A depth image: the samples in `samples` (packed within each row), everything else as in DepthView (its `depth`
// pointer is not used and must be null).
struct DeviceDepth {
    ExternalBuffer samples;
    DepthView view;  // its color pointer is not used either and must be null
    DeviceColor color;
};

// Where the labels go: uint32 per pixel, packed within each row, rows row_step_bytes apart (0: 4 * width); the
// segment count K as one uint32 into `count` when it has a handle.
struct DeviceLabels {
    ExternalBuffer labels;
    std::size_t row_step_bytes = 0;
    ExternalBuffer count;
    // The statistics' words (Segmenter::device_statistics_bytes), for a Segmenter made with Outputs::segment_stats.
    ExternalBuffer statistics;
    // The segment graph's words (Segmenter::device_segment_graph_bytes), for a Segmenter made with
    // Outputs::segment_graph.
    ExternalBuffer graph;
    // The tracks' overlaps (Segmenter::device_tracks_bytes), which a Segmenter made with Outputs::segment_tracks or
    // track_ids needs on every device frame.
    ExternalBuffer tracks;
};

// A Segmenter over an executor a backend made on the caller's context (the interop functions' constructors).
[[nodiscard]] Segmenter make_segmenter(int width, int height, const Params& params, const Outputs& outputs,
                                       const std::string& backend,
                                       const std::function<std::unique_ptr<PassExecutor>(const Plan&)>& make_executor);

// The Segmenter's executor, for a backend's interop functions to reach their device.
[[nodiscard]] PassExecutor& executor_of(Segmenter& segmenter);

// One device-resident frame: the checks every API shares (a frame of the Segmenter's size fits each buffer at its
// offset, the steps fit the rows and are multiples of 4 (of 2 for u16 depth), depth's units and intrinsics are
// positive and finite; a pyrseg::Error names the problem), then `checked` (where an API queues what the frame waits
// for: nothing is queued before every check passed), the input bound, every pass, the labels (and K) written to the
// caller's buffers; then the executor submits without waiting. The results of Outputs other than the labels, K, the
// statistics and the graph are not produced (they are host results); Segmenter::last_timings() is empty after such a
// frame.
void run_device_frame(Segmenter& segmenter, const DeviceCloud& cloud, const DeviceLabels& labels,
                      const std::function<void()>& checked = {});
void run_device_frame(Segmenter& segmenter, const DeviceDepth& depth, const DeviceLabels& labels,
                      const std::function<void()>& checked = {});

}  // namespace pyrseg::core
