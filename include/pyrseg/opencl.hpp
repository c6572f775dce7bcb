#pragma once
// pyrseg inside an OpenCL application: a Segmenter on the application's own context, device and command queue, and
// frames read from and written to the application's cl_mem buffers on the device, ordered through the queue and
// events, with no host transfer and no host wait (no clFinish). Needs pyrseg built with its OpenCL backend
// (`pyrseg backends`); docs/embedding.md shows a whole application, examples/opencl_app.cpp is one.
//
// Host frames (Segmenter::segment with a CloudView or DepthView) keep working on such a Segmenter, through the same
// queue; they wait for it as they do on pyrseg's own.
#ifndef CL_TARGET_OPENCL_VERSION
#define CL_TARGET_OPENCL_VERSION 120
#endif
#include <CL/cl.h>

#include <cstddef>
#include <span>

#include "pyrseg/depth.hpp"
#include "pyrseg/export.hpp"
#include "pyrseg/params.hpp"
#include "pyrseg/result.hpp"
#include "pyrseg/segmenter.hpp"

namespace pyrseg::opencl {

// The application's objects. pyrseg retains them for the Segmenter's life (clRetain*) and releases them after. The
// queue must be an in-order queue of `device` in `context`; its profiling need not be on.
struct Queue {
    cl_context context = nullptr;
    cl_device_id device = nullptr;
    cl_command_queue queue = nullptr;
};

// Builds pyrseg's kernels for the device (once per context and process) and its buffers in the context. Throws
// pyrseg::Error when the queue is not of that device and context, is out of order, or the frame does not fit.
[[nodiscard]] PYRSEG_EXPORT Segmenter make_segmenter(int width, int height, const Queue& queue,
                                                     const Params& params = {}, const Outputs& outputs = {});

// A cloud in the application's buffers: float32 x, y, z packed within each row (12 bytes a point), rows
// row_step_bytes apart (0: 12 * width), from byte `offset` on; normals (optional) in the same layout.
struct CloudBuffers {
    cl_mem points = nullptr;
    std::size_t points_offset = 0;
    cl_mem normals = nullptr;  // nullptr: normals are estimated
    std::size_t normals_offset = 0;
    std::size_t row_step_bytes = 0;
    // Optional: the colour image registered to the frame, R, G, B bytes packed within each row, rows
    // color_row_step_bytes apart (0: 3 * width), from byte color_offset on (the colour edge term,
    // Params::color_edge_threshold).
    cl_mem color = nullptr;
    std::size_t color_offset = 0;
    std::size_t color_row_step_bytes = 0;
};

// A depth image in the application's buffer: samples packed within each row from byte `offset` on; `view` gives
// everything else (format, size, row step, metres per unit, intrinsics) and its `depth` pointer must be null.
struct DepthBuffer {
    cl_mem samples = nullptr;
    std::size_t offset = 0;
    DepthView view;          // its color pointer must be null too: a colour image goes in `color`
    cl_mem color = nullptr;  // optional, as CloudBuffers::color
    std::size_t color_offset = 0;
    std::size_t color_row_step_bytes = 0;
};

// Where the results go: uint32 labels packed within each row (rows row_step_bytes apart; 0: 4 * width) from byte
// `labels_offset` on, and, when `count` is set, the segment count K as one uint32 at `count_offset`.
struct LabelBuffers {
    cl_mem labels = nullptr;
    std::size_t labels_offset = 0;
    std::size_t row_step_bytes = 0;
    cl_mem count = nullptr;
    std::size_t count_offset = 0;
    // A Segmenter made with Outputs::segment_stats: the statistics' words (Segmenter::device_statistics_bytes()),
    // which Segmenter::decode_device_statistics turns into segments; nullptr: not written.
    cl_mem statistics = nullptr;
    std::size_t statistics_offset = 0;
    // A Segmenter made with Outputs::segment_graph: the segment graph's words
    // (Segmenter::device_segment_graph_bytes()), which Segmenter::decode_device_segment_graph turns into Result::graph;
    // nullptr: not written.
    cl_mem graph = nullptr;
    std::size_t graph_offset = 0;
    // A Segmenter made with Outputs::segment_tracks or track_ids: required, the tracks' overlaps
    // (Segmenter::device_tracks_bytes()), which Segmenter::decode_device_tracks turns into Result::tracks.
    cl_mem tracks = nullptr;
    std::size_t tracks_offset = 0;
};

// Enqueues one frame on the Segmenter's queue, after the events in `wait` (and, the queue being in order, after
// everything enqueued before). Returns an event that completes when the labels and K are written; the caller
// releases it (clReleaseEvent). The buffers must belong to the Segmenter's context, be large enough for the frame
// at their offsets, and stay valid until that event completes; nothing is enqueued when a check fails (a
// pyrseg::Error names the problem). Frames of one Segmenter run in queue order; its buffers serve one frame at a
// time, so two Segmenters are needed for two frames at once. Outputs other than the labels, the statistics and the
// segment graph (mask, normals, raw labels) are host results and are not produced; tracks are decoded on the host;
// Segmenter::last_timings() is empty after it.
[[nodiscard]] PYRSEG_EXPORT cl_event segment(Segmenter& segmenter, const CloudBuffers& cloud, const LabelBuffers& out,
                                             std::span<const cl_event> wait = {});
[[nodiscard]] PYRSEG_EXPORT cl_event segment(Segmenter& segmenter, const DepthBuffer& depth, const LabelBuffers& out,
                                             std::span<const cl_event> wait = {});

}  // namespace pyrseg::opencl
