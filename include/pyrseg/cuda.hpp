#pragma once
// pyrseg inside a CUDA application: a Segmenter whose work all goes on the application's own cudaStream_t, and
// frames read from and written to the application's device memory, ordered by that stream, with no host transfer
// and no host wait (no cudaStreamSynchronize), so that a frame can be captured into the application's CUDA graph.
// Needs pyrseg built with its CUDA backend (`pyrseg backends`); examples/cuda_app.cpp is a whole application.
//
// Host frames (Segmenter::segment with a CloudView or DepthView) keep working on such a Segmenter, on the same
// stream: they wait for it (cudaStreamSynchronize) as they do on pyrseg's own stream.
//
// pyrseg calls the CUDA runtime API (linked statically into it). Streams and device pointers are the driver's, so
// the application's own runtime, shared or static, passes them in; the stream must be a runtime API stream (on its
// device's primary context).
#include <cuda_runtime_api.h>

#include <cstddef>
#include <cstdint>

#include "pyrseg/depth.hpp"
#include "pyrseg/export.hpp"
#include "pyrseg/params.hpp"
#include "pyrseg/result.hpp"
#include "pyrseg/segmenter.hpp"

namespace pyrseg::cuda {

// A Segmenter whose buffers are on `stream`'s device (cudaStreamGetDevice; the calling thread's current device when
// pyrseg was built with a CUDA older than 12.8) and whose every command goes on `stream`. pyrseg never destroys the
// stream; the application keeps it alive longer than the Segmenter. Allocates the Segmenter's device buffers and
// pinned staging (cudaMalloc, cudaMallocHost), so the stream must not be being captured. Throws pyrseg::Error when
// there is no CUDA device, the stream is not a usable one, it is being captured, or the frame does not fit.
//
// Any stream will do: one of cudaStreamCreate(WithFlags), cudaStreamPerThread, or the legacy default stream (0 or
// cudaStreamLegacy; 0 always means the legacy stream here, even in code compiled with --default-stream per-thread,
// so pass cudaStreamPerThread for that one). The legacy stream also waits for, and makes wait, every other blocking
// stream of its device, and cannot be captured into a graph; PYRSEG_CUDA_GRAPHS has no effect there.
//
// Every pyrseg call on such a Segmenter makes the stream's device current on the calling thread while it runs
// (cudaSetDevice, only when another one is current); make_segmenter and segment below make the previous one
// current again before they return; host frames leave it current, as every CUDA Segmenter does.
//
// Destroying the Segmenter waits for the stream (its queued frames read pyrseg's buffers), unless the stream is
// being captured then, and frees the buffers: do it outside any capture, once no graph that captured one of its
// frames will run again.
[[nodiscard]] PYRSEG_EXPORT Segmenter make_segmenter(int width, int height, cudaStream_t stream,
                                                     const Params& params = {}, const Outputs& outputs = {});

// The application's memory: device memory of the Segmenter's device (cudaMalloc, cudaMallocAsync, cudaMallocPitch,
// a pool, the virtual memory API) or managed memory (cudaMallocManaged, from any device). Host memory, pinned or
// not, is refused: give host frames to Segmenter::segment. Each pointer is where the frame's data starts, with any
// alignment; its `*_bytes` are how many bytes the application has from that pointer on (the caller's word: where
// the driver can tell the allocation's end, cuMemGetAddressRange, pyrseg uses the smaller of the two). A frame must
// fit within them.

// A cloud: float32 x, y, z packed within each row (12 bytes a point), rows row_step_bytes apart (0: 12 * width, else
// a multiple of 4 no smaller than a row); normals (optional) in the same layout and row step.
struct CloudPointers {
    const float* points = nullptr;
    std::size_t points_bytes = 0;
    const float* normals = nullptr;  // nullptr: normals are estimated
    std::size_t normals_bytes = 0;
    std::size_t row_step_bytes = 0;
    // Optional: the colour image registered to the frame, R, G, B bytes packed within each row, rows
    // color_row_step_bytes apart (0: 3 * width) (the colour edge term, Params::color_edge_threshold).
    const std::uint8_t* color = nullptr;
    std::size_t color_bytes = 0;
    std::size_t color_row_step_bytes = 0;
};

// A depth image: samples packed within each row from `samples` on; `view` gives everything else (format, size, row
// step, a multiple of the sample's size: 2 for u16, 4 for f32; metres per unit; intrinsics), and its `depth`
// pointer must be null.
struct DepthPointers {
    const void* samples = nullptr;
    std::size_t bytes = 0;
    DepthView view;                       // its color pointer must be null too: a colour image goes in `color`
    const std::uint8_t* color = nullptr;  // optional, as CloudPointers::color
    std::size_t color_bytes = 0;
    std::size_t color_row_step_bytes = 0;
};

// Where the results go: uint32 labels packed within each row, rows row_step_bytes apart (0: 4 * width, else a
// multiple of 4 no smaller than a row); and, when `count` is set, the segment count K as one uint32 (4 bytes); and,
// when `statistics` is set (a Segmenter made with Outputs::segment_stats), the statistics' words,
// Segmenter::device_statistics_bytes() of them, which Segmenter::decode_device_statistics turns into segments; and,
// when `graph` is set (a Segmenter made with Outputs::segment_graph), the segment graph's words,
// Segmenter::device_segment_graph_bytes() of them, which Segmenter::decode_device_segment_graph turns into
// Result::graph; and `tracks` (required for a Segmenter made with Outputs::segment_tracks or track_ids), the tracks'
// overlaps, Segmenter::device_tracks_bytes() of them, which Segmenter::decode_device_tracks turns into Result::tracks.
struct LabelPointers {
    std::uint32_t* labels = nullptr;
    std::size_t labels_bytes = 0;
    std::size_t row_step_bytes = 0;
    std::uint32_t* count = nullptr;
    std::uint32_t* statistics = nullptr;
    std::size_t statistics_bytes = 0;
    std::uint32_t* graph = nullptr;
    std::size_t graph_bytes = 0;
    std::uint32_t* tracks = nullptr;
    std::size_t tracks_bytes = 0;
};

// Queues one frame on the Segmenter's stream and returns without waiting: the input copied device to device into
// pyrseg's buffers (cudaMemcpy2DAsync), every pass's kernels, the labels copied into `out.labels`
// (cudaMemcpy2DAsync) and K into `out.count` (cudaMemcpyAsync). Stream-ordered: what the application queued on the
// stream before runs first (make the stream wait for another stream's work with cudaStreamWaitEvent), and the
// application learns of the frame's end from the stream (cudaEventRecord after the call, cudaStreamSynchronize,
// or its next commands on the stream). The memory must stay valid until then.
//
// Checks first, and queues nothing when one fails (a pyrseg::Error names the problem): a null pointer where one is
// needed, host memory or memory of another device, sizes too small for the frame, row steps smaller than a row or
// not a multiple of 4 (of 2 for u16 depth), a frame of another size than the Segmenter's, metres_per_unit or
// intrinsics not finite and positive, a non-null view.depth, a Segmenter not made by make_segmenter above.
//
// Frames of one Segmenter run in stream order; its buffers serve one frame at a time, so two frames at once (on two
// streams) need two Segmenters. Outputs other than the labels, the statistics and the segment graph (mask, normals,
// raw labels) are host results and are not produced; tracks are decoded on the host; Segmenter::last_timings() is empty
// after it (time the frame with cudaEvents).
//
// CUDA graphs: the call may come between cudaStreamBeginCapture(stream, any mode) and cudaStreamEndCapture; it then
// adds the frame's copies, memsets and kernels to the graph and calls nothing a capture forbids (no
// synchronisation, no allocation, no host copy, no event query). The graph then holds the addresses of the
// application's memory and of the Segmenter's buffers: each launch reads the input there as it is then and writes
// the labels there; launch it on the Segmenter's stream (or keep it ordered with the Segmenter's other frames),
// while the Segmenter lives. A depth frame carries its own ray table (W + H floats, as the parameters of small
// kernels among its commands), so its graph gives that calibration's points whatever frames ran in between.
PYRSEG_EXPORT void segment(Segmenter& segmenter, const CloudPointers& cloud, const LabelPointers& out);
PYRSEG_EXPORT void segment(Segmenter& segmenter, const DepthPointers& depth, const LabelPointers& out);

}  // namespace pyrseg::cuda
