#pragma once
// pyrseg inside a Vulkan application: a Segmenter on the application's own instance, physical device, device and
// queue, and frames read from and written to the application's VkBuffers on the device, either recorded into the
// application's command buffer or submitted by pyrseg with the application's semaphores, with no host transfer and
// no host wait. Needs pyrseg built with its Vulkan backend (`pyrseg backends`); examples/vulkan_app.cpp is a whole
// application.
//
// Host frames (Segmenter::segment with a CloudView or DepthView) keep working on such a Segmenter: pyrseg records
// them into a command buffer of its own, submits it on the Segmenter's queue and waits for its fence.
//
// pyrseg calls Vulkan through the loader it links (libvulkan), so the application's objects must come from the same
// loader (the usual case: the application links libvulkan too, or uses volk on top of it).
#include <vulkan/vulkan.h>

#include <cstdint>
#include <span>

#include "pyrseg/depth.hpp"
#include "pyrseg/export.hpp"
#include "pyrseg/params.hpp"
#include "pyrseg/result.hpp"
#include "pyrseg/segmenter.hpp"

namespace pyrseg::vulkan {

// The application's objects; pyrseg never destroys them, and the application keeps them alive longer than every
// Segmenter made on them. The instance must have been created with apiVersion 1.1 or later (pyrseg's shaders are
// SPIR-V 1.3); the device needs no extension and no feature. `queue` is queue 0..n of `queue_family` on `device`,
// and the family must support compute.
//
// The queue: pyrseg calls vkQueueSubmit on it in `submit` below and in every host frame. Vulkan requires a queue's
// submissions to be externally synchronised, so the application must not submit to the same queue from another
// thread while one of those calls runs (one thread for both, or a mutex around both).
struct Device {
    VkInstance instance = VK_NULL_HANDLE;
    VkPhysicalDevice physical = VK_NULL_HANDLE;
    VkDevice device = VK_NULL_HANDLE;
    std::uint32_t queue_family = 0;
    VkQueue queue = VK_NULL_HANDLE;
};

// Builds pyrseg's descriptor set layout, pipeline layout and compute pipelines on the device (once per device and
// queue while any Segmenter uses them), and the Segmenter's own buffers, descriptor set, command pool and fences.
// Throws pyrseg::Error naming the problem when a handle is null, the physical device is not one of the instance's,
// the queue family does not exist or has no compute, the device lacks what pyrseg needs (the list `pyrseg backends`
// prints), or the frame does not fit the device's limits.
//
// Destroying the Segmenter waits for the frames pyrseg itself submitted (its own fences) but not for command
// buffers the application recorded with `record`: those must have completed (or been freed) first, since they use
// the Segmenter's pipelines, descriptor set and buffers.
[[nodiscard]] PYRSEG_EXPORT Segmenter make_segmenter(int width, int height, const Device& device,
                                                     const Params& params = {}, const Outputs& outputs = {});

// Vulkan cannot tell a VkBuffer's size, so each buffer below comes with the size the application created it with
// (`*_bytes`: the whole buffer, not what is left after the offset); the frame must fit from the offset on. The
// buffers belong to the Segmenter's device. pyrseg copies the input out of them and the results into them with
// vkCmdCopyBuffer, so input buffers need VK_BUFFER_USAGE_TRANSFER_SRC_BIT and output buffers
// VK_BUFFER_USAGE_TRANSFER_DST_BIT; any memory type will do.

// A cloud: float32 x, y, z packed within each row (12 bytes a point), rows row_step_bytes apart (0: 12 * width),
// from byte `points_offset` on; normals (optional) in the same layout. Offsets and row steps are multiples of 4.
struct CloudBuffers {
    VkBuffer points = VK_NULL_HANDLE;
    VkDeviceSize points_offset = 0;
    VkDeviceSize points_bytes = 0;
    VkBuffer normals = VK_NULL_HANDLE;  // VK_NULL_HANDLE: normals are estimated
    VkDeviceSize normals_offset = 0;
    VkDeviceSize normals_bytes = 0;
    VkDeviceSize row_step_bytes = 0;
    // Optional: the colour image registered to the frame, R, G, B bytes packed within each row, rows
    // color_row_step_bytes apart (0: 3 * width), from byte color_offset on, in a buffer of color_bytes (the colour
    // edge term, Params::color_edge_threshold). Any offset and row step.
    VkBuffer color = VK_NULL_HANDLE;
    VkDeviceSize color_offset = 0;
    VkDeviceSize color_bytes = 0;
    VkDeviceSize color_row_step_bytes = 0;
};

// A depth image: samples packed within each row from byte `offset` on; `view` gives everything else (format, size,
// row step, metres per unit, intrinsics) and its `depth` pointer must be null. The offset and row step are
// multiples of the sample's size (2 for u16, 4 for f32).
struct DepthBuffer {
    VkBuffer samples = VK_NULL_HANDLE;
    VkDeviceSize offset = 0;
    VkDeviceSize bytes = 0;
    DepthView view;                   // its color pointer must be null too: a colour image goes in `color`
    VkBuffer color = VK_NULL_HANDLE;  // optional, as CloudBuffers::color
    VkDeviceSize color_offset = 0;
    VkDeviceSize color_bytes = 0;
    VkDeviceSize color_row_step_bytes = 0;
};

// Where the results go: uint32 labels packed within each row (rows row_step_bytes apart; 0: 4 * width) from byte
// `labels_offset` on, and, when `count` is set, the segment count K as one uint32 at `count_offset`. Offsets and
// the row step are multiples of 4.
struct LabelBuffers {
    VkBuffer labels = VK_NULL_HANDLE;
    VkDeviceSize labels_offset = 0;
    VkDeviceSize labels_bytes = 0;
    VkDeviceSize row_step_bytes = 0;
    VkBuffer count = VK_NULL_HANDLE;  // VK_NULL_HANDLE: K is not written
    VkDeviceSize count_offset = 0;
    VkDeviceSize count_bytes = 0;
    // A Segmenter made with Outputs::segment_stats: the statistics' words (Segmenter::device_statistics_bytes()),
    // which Segmenter::decode_device_statistics turns into segments; VK_NULL_HANDLE: not written.
    VkBuffer statistics = VK_NULL_HANDLE;
    VkDeviceSize statistics_offset = 0;
    VkDeviceSize statistics_bytes = 0;
    // A Segmenter made with Outputs::segment_graph: the segment graph's words
    // (Segmenter::device_segment_graph_bytes()), which Segmenter::decode_device_segment_graph turns into Result::graph;
    // VK_NULL_HANDLE: not written.
    VkBuffer graph = VK_NULL_HANDLE;
    VkDeviceSize graph_offset = 0;
    VkDeviceSize graph_bytes = 0;
    // A Segmenter made with Outputs::segment_tracks or track_ids: required, the tracks' overlaps
    // (Segmenter::device_tracks_bytes()), which Segmenter::decode_device_tracks turns into Result::tracks.
    VkBuffer tracks = VK_NULL_HANDLE;
    VkDeviceSize tracks_offset = 0;
    VkDeviceSize tracks_bytes = 0;
};

// Records one frame into the application's command buffer, which must be in the recording state, outside a render
// pass, and allocated from a pool of the Segmenter's queue family; nothing is submitted. The frame starts with a
// pipeline barrier that makes every earlier write on the device (ALL_COMMANDS, MEMORY_WRITE) visible to pyrseg's
// copies and shaders, and ends with one that makes pyrseg's writes available and visible to every later command and
// to the host (ALL_COMMANDS | HOST; MEMORY_READ, MEMORY_WRITE, HOST_READ): after a fence or semaphore wait on the
// submission, the labels and K can be read. The frame binds pyrseg's compute pipelines, descriptor set and push
// constants, so the command buffer's compute state is pyrseg's afterwards: bind yours again before dispatching.
// The constant tables a depth frame needs are recorded into the command buffer (vkCmdUpdateBuffer), so it may be
// submitted any time later.
//
// Frames of one Segmenter share its buffers: they must execute in the order they were recorded or submitted (one
// after the other in one command buffer, or command buffers submitted in that order to the Segmenter's queue), and
// a command buffer recorded here must be submitted before the Segmenter's next host frame. Nothing is recorded when
// a check fails (a pyrseg::Error names the problem). Outputs other than the labels, the statistics and the segment
// graph (mask, normals, raw labels) are host results and are not produced; tracks are decoded on the host;
// Segmenter::last_timings() is empty after it.
PYRSEG_EXPORT void record(Segmenter& segmenter, VkCommandBuffer commands, const CloudBuffers& cloud,
                          const LabelBuffers& out);
PYRSEG_EXPORT void record(Segmenter& segmenter, VkCommandBuffer commands, const DepthBuffer& depth,
                          const LabelBuffers& out);

// Records one frame, as `record` does, into a command buffer of pyrseg's own and submits it on the Segmenter's
// queue (vkQueueSubmit: see Device on synchronising the queue), after the semaphores in `wait` (each at the stages
// of the same index in `wait_stages`: the two spans have the same size) and signalling those in `signal` when the
// labels and K are written. No host wait: pyrseg keeps a ring of 3 command buffers with fences of its own, and waits
// for the oldest only when a fourth frame is submitted before it completed (so semaphores waited for must have their
// signal already submitted, as binary semaphores require anyway).
//
// `fence`, when given, must be unsignalled; pyrseg submits an empty batch with it right after the frame's batch, so
// it signals once the frame and everything submitted to the queue before it have completed. Nothing is submitted
// when a check fails (a pyrseg::Error names the problem).
PYRSEG_EXPORT void submit(Segmenter& segmenter, const CloudBuffers& cloud, const LabelBuffers& out,
                          std::span<const VkSemaphore> wait = {},
                          std::span<const VkPipelineStageFlags> wait_stages = {},
                          std::span<const VkSemaphore> signal = {}, VkFence fence = VK_NULL_HANDLE);
PYRSEG_EXPORT void submit(Segmenter& segmenter, const DepthBuffer& depth, const LabelBuffers& out,
                          std::span<const VkSemaphore> wait = {},
                          std::span<const VkPipelineStageFlags> wait_stages = {},
                          std::span<const VkSemaphore> signal = {}, VkFence fence = VK_NULL_HANDLE);

}  // namespace pyrseg::vulkan
