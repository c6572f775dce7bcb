// pyrseg/opencl.hpp: Segmenters on the caller's context and queue, and frames on the caller's cl_mem buffers. The
// checks here are the OpenCL ones (which context a buffer or queue belongs to, how large a buffer is); the frame
// itself is core/device_frame.cpp's, as for every API.
#include "pyrseg/opencl.hpp"

#include <algorithm>
#include <bit>
#include <cstdint>
#include <string>
#include <vector>

#include "backends/opencl/opencl_device.hpp"
#include "backends/opencl/opencl_runtime.hpp"
#include "core/device_frame.hpp"
#include "core/executor.hpp"
#include "core/gpu/gpu_executor.hpp"
#include "pyrseg/error.hpp"

namespace pyrseg::opencl {
namespace {

// OpenCL's objects are pointers to opaque structs; their queries return the pointer itself.
constexpr std::size_t kHandleBytes = sizeof(void*);
static_assert(sizeof(cl_context) == kHandleBytes && sizeof(cl_mem) == kHandleBytes);

[[noreturn]] void bad(const std::string& what) {
    throw Error(ErrorCode::invalid_argument, what);
}

template <class T>
T queue_info(cl_command_queue queue, cl_command_queue_info what, const char* name) {
    T value{};
    // T is a handle (a pointer to an opaque struct) or a bitfield: the query returns the value itself.
    const cl_int err =
        clGetCommandQueueInfo(queue, what, sizeof(T), &value, nullptr);  // NOLINT(bugprone-sizeof-expression)
    if (err != CL_SUCCESS)
        bad(std::string("the queue is not a valid command queue (") + name + ": " + error_name(err) + ")");
    return value;
}

void check_queue(const Queue& q) {
    if (q.context == nullptr || q.device == nullptr || q.queue == nullptr) {
        bad("opencl::Queue needs a context, a device and a command queue (one is null)");
    }
    cl_uint count = 0;
    if (clGetContextInfo(q.context, CL_CONTEXT_NUM_DEVICES, sizeof(count), &count, nullptr) != CL_SUCCESS) {
        bad("the context is not a valid OpenCL context");
    }
    std::vector<cl_device_id> devices(count);
    clGetContextInfo(q.context, CL_CONTEXT_DEVICES, kHandleBytes * count, devices.data(), nullptr);
    if (std::find(devices.begin(), devices.end(), q.device) == devices.end()) bad("the device is not in the context");
    if (queue_info<cl_context>(q.queue, CL_QUEUE_CONTEXT, "CL_QUEUE_CONTEXT") != q.context) {
        bad("the command queue belongs to another context");
    }
    if (queue_info<cl_device_id>(q.queue, CL_QUEUE_DEVICE, "CL_QUEUE_DEVICE") != q.device) {
        bad("the command queue belongs to another device");
    }
    const auto properties =
        queue_info<cl_command_queue_properties>(q.queue, CL_QUEUE_PROPERTIES, "CL_QUEUE_PROPERTIES");
    if ((properties & CL_QUEUE_OUT_OF_ORDER_EXEC_MODE_ENABLE) != 0) {
        bad("the command queue executes out of order; pyrseg needs an in-order queue (its passes follow each other)");
    }
}

OpenclDevice& device_of(Segmenter& segmenter) {
    auto* device = dynamic_cast<OpenclDevice*>(core::executor_of(segmenter).gpu_device());
    if (device == nullptr) {
        bad("this Segmenter does not run on OpenCL; make it with pyrseg::opencl::make_segmenter on your queue");
    }
    return *device;
}

// The buffer in the Segmenter's context, and its size from the offset on.
core::ExternalBuffer external(const OpenclDevice& device, cl_mem mem, std::size_t offset, const char* what) {
    core::ExternalBuffer b;
    if (mem == nullptr) return b;
    cl_context context = nullptr;
    std::size_t size = 0;
    if (clGetMemObjectInfo(mem, CL_MEM_CONTEXT, kHandleBytes, &context, nullptr) != CL_SUCCESS ||
        clGetMemObjectInfo(mem, CL_MEM_SIZE, sizeof(size), &size, nullptr) != CL_SUCCESS) {
        bad(std::string("the ") + what + " buffer is not a valid cl_mem");
    }
    if (context != device.context()) {
        bad(std::string("the ") + what + " buffer belongs to another context than the Segmenter's queue");
    }
    b.handle = static_cast<std::uint64_t>(std::bit_cast<std::uintptr_t>(mem));
    b.offset = offset;
    b.bytes = offset <= size ? size - offset : 0;
    return b;
}

void check_events(std::span<const cl_event> wait) {
    for (const cl_event e : wait) {
        if (e == nullptr) bad("an event to wait for is null");
    }
}

core::DeviceLabels labels_of(const OpenclDevice& device, const LabelBuffers& out) {
    core::DeviceLabels l;
    l.labels = external(device, out.labels, out.labels_offset, "labels");
    l.row_step_bytes = out.row_step_bytes;
    l.count = external(device, out.count, out.count_offset, "segment count");
    l.statistics = external(device, out.statistics, out.statistics_offset, "statistics");
    l.graph = external(device, out.graph, out.graph_offset, "segment graph");
    l.tracks = external(device, out.tracks, out.tracks_offset, "tracks");
    return l;
}

}  // namespace

Segmenter make_segmenter(int width, int height, const Queue& queue, const Params& params, const Outputs& outputs) {
    check_queue(queue);
    return core::make_segmenter(width, height, params, outputs, "opencl", [&](const core::Plan& plan) {
        return gpu::make_gpu_executor(
            plan, std::make_unique<OpenclDevice>(runtime_for(queue.context, queue.device), queue.queue));
    });
}

cl_event segment(Segmenter& segmenter, const CloudBuffers& cloud, const LabelBuffers& out,
                 std::span<const cl_event> wait) {
    OpenclDevice& device = device_of(segmenter);
    core::DeviceCloud c;
    c.points = external(device, cloud.points, cloud.points_offset, "points");
    c.normals = external(device, cloud.normals, cloud.normals_offset, "normals");
    c.row_step_bytes = cloud.row_step_bytes;
    c.color.rgb = external(device, cloud.color, cloud.color_offset, "colour image");
    c.color.row_step_bytes = cloud.color_row_step_bytes;
    const core::DeviceLabels l = labels_of(device, out);
    check_events(wait);
    core::run_device_frame(segmenter, c, l, [&] { device.wait_for(wait); });
    return device.take_done_event();
}

cl_event segment(Segmenter& segmenter, const DepthBuffer& depth, const LabelBuffers& out,
                 std::span<const cl_event> wait) {
    OpenclDevice& device = device_of(segmenter);
    core::DeviceDepth d;
    d.samples = external(device, depth.samples, depth.offset, "depth samples");
    d.view = depth.view;
    d.color.rgb = external(device, depth.color, depth.color_offset, "colour image");
    d.color.row_step_bytes = depth.color_row_step_bytes;
    const core::DeviceLabels l = labels_of(device, out);
    check_events(wait);
    core::run_device_frame(segmenter, d, l, [&] { device.wait_for(wait); });
    return device.take_done_event();
}

}  // namespace pyrseg::opencl
