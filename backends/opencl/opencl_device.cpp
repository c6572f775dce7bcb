// The OpenCL backend's gpu::Device: one in-order command queue per Segmenter. The passes are
// core/gpu/gpu_executor.cpp; the kernels are shaders/pyr_opencl.cl, built once per context (opencl_runtime.cpp).
// Nothing waits between passes: per-pass times come from the queue's profiling of a marker at each pass boundary.
#include "backends/opencl/opencl_device.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cstring>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "pyrseg/error.hpp"

namespace pyrseg::opencl {
namespace {

using std::size_t;
using std::uint32_t;

// PYR_CTX_PARAM in shaders/pyr_opencl.cl: the buffer table's buffers, then the width; the PyrArgs follow.
constexpr cl_uint kContextArgs = gpu::kBufferCount + 1;

size_t round_up(size_t v, size_t m) {
    return (v + m - 1) / m * m;
}

cl_mem as_mem(std::uint64_t handle) {
    return std::bit_cast<cl_mem>(static_cast<std::uintptr_t>(handle));
}

// An inline upload's bytes, freed by the runtime once the write has read them.
void CL_CALLBACK free_upload(cl_event /*event*/, cl_int /*status*/, void* bytes) {
    delete static_cast<std::vector<unsigned char>*>(bytes);
}

}  // namespace

OpenclDevice::OpenclDevice(std::shared_ptr<const Runtime> runtime) : rt_(std::move(runtime)) {
    cl_int err = CL_SUCCESS;
    queue_ = clCreateCommandQueue(rt_->context, rt_->device, CL_QUEUE_PROFILING_ENABLE, &err);
    check(err, "clCreateCommandQueue");
    create_kernels();
}

OpenclDevice::OpenclDevice(std::shared_ptr<const Runtime> runtime, cl_command_queue queue) : rt_(std::move(runtime)) {
    check(clRetainCommandQueue(queue), "clRetainCommandQueue");
    queue_ = queue;
    create_kernels();
}

void OpenclDevice::create_kernels() {
    cl_int err = CL_SUCCESS;
    for (size_t k = 0; k < gpu::kKernelCount; ++k) {
        const char* name = gpu::kernel_entry_name(gpu::Kernel(k));
        kernels_[k] = clCreateKernel(rt_->program, name, &err);
        check(err, name);
    }
}

OpenclDevice::~OpenclDevice() {
    // A frame an error abandoned may still have reads into the executor's host memory queued, which dies with it;
    // the queue's own error, if any, was reported already.
    drain();
    release_marks();
    if (done_ != nullptr) clReleaseEvent(done_);
    for (cl_mem m : buffers_) {
        if (m != nullptr) clReleaseMemObject(m);
    }
    for (cl_kernel k : kernels_) {
        if (k != nullptr) clReleaseKernel(k);
    }
    if (queue_ != nullptr) clReleaseCommandQueue(queue_);
}

gpu::DeviceLimits OpenclDevice::limits() const {
    gpu::DeviceLimits l;
    l.max_buffer_bytes.fill(size_t(rt_->max_alloc));
    l.max_buffer_what = "CL_DEVICE_MAX_MEM_ALLOC_SIZE";
    l.memory_bytes = size_t(rt_->global_mem);
    l.memory_what = "CL_DEVICE_GLOBAL_MEM_SIZE";
    return l;
}

void OpenclDevice::allocate(const gpu::BufferSizes& sizes, uint32_t image_width) {
    for (size_t b = 0; b < gpu::kBufferCount; ++b) {
        cl_int err = CL_SUCCESS;
        buffers_[b] = clCreateBuffer(rt_->context, CL_MEM_READ_WRITE, sizes[b], nullptr, &err);
        check(err, (std::string("clCreateBuffer(") + gpu::buffer_name(gpu::Buffer(b)) + ")").c_str());
    }
    // The context arguments of every kernel, once.
    for (cl_kernel k : kernels_) {
        for (cl_uint a = 0; a < gpu::kBufferCount; ++a)
            check(clSetKernelArg(k, a, sizeof(cl_mem), &buffers_[a]), "clSetKernelArg(buffer)");
        check(clSetKernelArg(k, gpu::kBufferCount, sizeof(image_width), &image_width), "clSetKernelArg(width)");
    }
}

void OpenclDevice::upload(gpu::Buffer b, size_t offset, const void* src, size_t bytes) {
    host_pending_ = true;
    check(clEnqueueWriteBuffer(queue_, buffer(b), CL_FALSE, offset, bytes, src, 0, nullptr, nullptr),
          "clEnqueueWriteBuffer");
}

void OpenclDevice::download(gpu::Buffer b, size_t offset, void* dst, size_t bytes) {
    host_pending_ = true;
    check(clEnqueueReadBuffer(queue_, buffer(b), CL_FALSE, offset, bytes, dst, 0, nullptr, nullptr),
          "clEnqueueReadBuffer");
}

void OpenclDevice::zero(gpu::Buffer b, size_t offset, size_t bytes) {
    const cl_uint zero = 0;
    check(clEnqueueFillBuffer(queue_, buffer(b), &zero, sizeof(zero), offset, bytes, 0, nullptr, nullptr),
          "clEnqueueFillBuffer");
}

void OpenclDevice::dispatch(gpu::Kernel k, uint32_t nx, uint32_t ny, const gpu::Args& args) {
    if (nx == 0 || ny == 0) return;
    cl_kernel kernel = kernels_[size_t(k)];
    check(clSetKernelArg(kernel, kContextArgs, sizeof(args.words), args.words.data()), gpu::kernel_entry_name(k));
    std::array<size_t, 2> local = {64, 1};
    if (gpu::kernel_dims(k) == 2) local = {8, 8};
    std::array<size_t, 2> global = {round_up(nx, local[0]), round_up(ny, local[1])};
    if (gpu::kernel_dims(k) == 3) global = {size_t(nx) * local[0], 1};  // one workgroup per index
    // A device may allow fewer work-items per group than the fixed sizes ask: then the runtime chooses.
    const size_t* local_size = local[0] * local[1] <= max_group(k) ? local.data() : nullptr;
    if (local_size == nullptr && gpu::kernel_dims(k) == 3) {
        throw Error(ErrorCode::backend_unavailable, std::string(gpu::kernel_entry_name(k)) + " needs workgroups of " +
                                                        std::to_string(local[0]) + " on " + rt_->description);
    }
    check(clEnqueueNDRangeKernel(queue_, kernel, 2, nullptr, global.data(), local_size, 0, nullptr, nullptr),
          gpu::kernel_entry_name(k));
}

void OpenclDevice::mark(const char* pass) {
    cl_event event = nullptr;
    check(clEnqueueMarkerWithWaitList(queue_, 0, nullptr, &event), "clEnqueueMarkerWithWaitList");
    marks_.push_back({pass, event, 0});
}

void OpenclDevice::finish() {
    check(clFinish(queue_), "clFinish");
    host_pending_ = false;
}

void OpenclDevice::fail_like(gpu::Fault fault, const char* what) const {
    if (fault == gpu::Fault::device_lost) rt_->faulted = true;
    drain();
    fail(fault == gpu::Fault::out_of_memory ? CL_MEM_OBJECT_ALLOCATION_FAILURE : CL_OUT_OF_RESOURCES, what);
}

void OpenclDevice::check(cl_int code, const char* what) const {
    if (code == CL_SUCCESS) return;
    if (code == CL_OUT_OF_RESOURCES) rt_->faulted = true;
    drain();
    fail(code, what);
}

// Before an error leaves the device: the frame's queued transfers may read the caller's frame (uploads go straight
// from it), which the caller may free as soon as segment() throws. Only on the error path: frames pay nothing.
void OpenclDevice::drain() const {
    if (host_pending_) clFinish(queue_);
}

// Each pass runs from its marker to the next one. A caller's queue without profiling keeps no times.
bool OpenclDevice::pass_times(std::vector<PassTiming>& timings) {
    if (marks_.size() < 2) return false;
    for (Mark& m : marks_) {
        if (clGetEventProfilingInfo(m.event, CL_PROFILING_COMMAND_END, sizeof(cl_ulong), &m.end, nullptr) != CL_SUCCESS)
            return false;
    }
    for (PassTiming& t : timings) t.milliseconds = 0.0;
    for (size_t k = 0; k + 1 < marks_.size(); ++k) {
        const double ms = double(marks_[k + 1].end - marks_[k].end) * 1e-6;
        for (PassTiming& t : timings) {
            if (marks_[k].pass != nullptr && std::string_view(t.pass) == marks_[k].pass) t.milliseconds += ms;
        }
    }
    return true;
}

void OpenclDevice::begin_frame() {
    release_marks();
}

void OpenclDevice::copy_rect(cl_mem src, size_t src_offset, size_t src_pitch, cl_mem dst, size_t dst_offset,
                             size_t dst_pitch, size_t row_bytes, size_t rows) {
    if (src_pitch == row_bytes && dst_pitch == row_bytes) {
        check(clEnqueueCopyBuffer(queue_, src, dst, src_offset, dst_offset, row_bytes * rows, 0, nullptr, nullptr),
              "clEnqueueCopyBuffer");
        return;
    }
    const std::array<size_t, 3> src_origin = {src_offset, 0, 0};
    const std::array<size_t, 3> dst_origin = {dst_offset, 0, 0};
    const std::array<size_t, 3> region = {row_bytes, rows, 1};
    check(clEnqueueCopyBufferRect(queue_, src, dst, src_origin.data(), dst_origin.data(), region.data(), src_pitch, 0,
                                  dst_pitch, 0, 0, nullptr, nullptr),
          "clEnqueueCopyBufferRect");
}

void OpenclDevice::copy_in(gpu::Buffer dst, size_t offset, const core::ExternalBuffer& src, size_t pitch,
                           size_t row_bytes, size_t rows) {
    copy_rect(as_mem(src.handle), src.offset, pitch, buffer(dst), offset, row_bytes, row_bytes, rows);
}

void OpenclDevice::copy_out(const core::ExternalBuffer& dst, size_t pitch, gpu::Buffer src, size_t offset,
                            size_t row_bytes, size_t rows) {
    copy_rect(buffer(src), offset, row_bytes, as_mem(dst.handle), dst.offset, pitch, row_bytes, rows);
}

// Non-blocking from a copy the runtime frees once the write has read it: no host wait, and the caller's next
// frame may change the source at once.
void OpenclDevice::upload_inline(gpu::Buffer b, size_t offset, const void* src, size_t bytes) {
    auto copy = std::make_unique<std::vector<unsigned char>>(static_cast<const unsigned char*>(src),
                                                             static_cast<const unsigned char*>(src) + bytes);
    cl_event written = nullptr;
    check(clEnqueueWriteBuffer(queue_, buffer(b), CL_FALSE, offset, bytes, copy->data(), 0, nullptr, &written),
          "clEnqueueWriteBuffer");
    const cl_int err = clSetEventCallback(written, CL_COMPLETE, free_upload, copy.get());
    if (err != CL_SUCCESS) {
        clWaitForEvents(1, &written);  // the copy must outlive the write
        clReleaseEvent(written);
        fail(err, "clSetEventCallback");
    }
    (void)copy.release();  // the callback owns it now
    clReleaseEvent(written);
}

void OpenclDevice::submit() {
    if (done_ != nullptr) clReleaseEvent(done_);
    done_ = nullptr;
    check(clEnqueueMarkerWithWaitList(queue_, 0, nullptr, &done_), "clEnqueueMarkerWithWaitList");
    check(clFlush(queue_), "clFlush");
}

void OpenclDevice::wait_for(std::span<const cl_event> events) {
    if (events.empty()) return;
    check(clEnqueueBarrierWithWaitList(queue_, cl_uint(events.size()), events.data(), nullptr),
          "clEnqueueBarrierWithWaitList");
}

cl_event OpenclDevice::take_done_event() {
    return std::exchange(done_, nullptr);
}

size_t OpenclDevice::max_group(gpu::Kernel k) {
    size_t& limit = group_limits_[size_t(k)];
    if (limit == 0) {
        limit = 1;
        clGetKernelWorkGroupInfo(kernels_[size_t(k)], rt_->device, CL_KERNEL_WORK_GROUP_SIZE, sizeof(limit), &limit,
                                 nullptr);
    }
    return limit;
}

void OpenclDevice::release_marks() {
    for (const Mark& m : marks_) clReleaseEvent(m.event);
    marks_.clear();
}

}  // namespace pyrseg::opencl
