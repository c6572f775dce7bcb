// The OpenCL backend: gpu::Device over one in-order command queue per Segmenter. The passes are
// core/gpu/gpu_executor.cpp; the kernels are shaders/pyr_opencl.cl, built once per device (opencl_runtime.cpp).
// Nothing waits between passes: per-pass times come from the queue's profiling of a marker at each pass boundary.
#include "backends/opencl/opencl_backend.hpp"

#include <algorithm>
#include <array>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "backends/opencl/opencl_runtime.hpp"
#include "core/gpu/device.hpp"
#include "core/gpu/gpu_executor.hpp"
#include "pyrseg/error.hpp"

namespace pyrseg::opencl {
namespace {

using std::size_t;
using std::uint32_t;

constexpr cl_uint kContextArgs = 11;  // PYR_CTX_PARAM in shaders/pyr_opencl.cl: the buffers, then the width
static_assert(kContextArgs == gpu::kBufferCount + 1);

size_t round_up(size_t v, size_t m) {
    return (v + m - 1) / m * m;
}

class OpenclDevice final : public gpu::Device {
public:
    explicit OpenclDevice(std::shared_ptr<const Runtime> runtime) : rt_(std::move(runtime)) {
        cl_int err = CL_SUCCESS;
        queue_ = clCreateCommandQueue(rt_->context, rt_->device, CL_QUEUE_PROFILING_ENABLE, &err);
        check(err, "clCreateCommandQueue");
        for (size_t k = 0; k < gpu::kKernelCount; ++k) {
            const char* name = gpu::kernel_entry_name(gpu::Kernel(k));
            kernels_[k] = clCreateKernel(rt_->program, name, &err);
            check(err, name);
        }
    }

    ~OpenclDevice() override {
        release_marks();
        for (cl_mem m : buffers_) {
            if (m != nullptr) clReleaseMemObject(m);
        }
        for (cl_kernel k : kernels_) {
            if (k != nullptr) clReleaseKernel(k);
        }
        if (queue_ != nullptr) clReleaseCommandQueue(queue_);
    }
    OpenclDevice(const OpenclDevice&) = delete;
    OpenclDevice& operator=(const OpenclDevice&) = delete;

    [[nodiscard]] std::string description() const override { return rt_->description; }

    [[nodiscard]] gpu::DeviceLimits limits() const override {
        gpu::DeviceLimits l;
        l.max_buffer_bytes.fill(size_t(rt_->max_alloc));
        l.max_buffer_what = "CL_DEVICE_MAX_MEM_ALLOC_SIZE";
        l.memory_bytes = size_t(rt_->global_mem);
        l.memory_what = "CL_DEVICE_GLOBAL_MEM_SIZE";
        return l;
    }

    void allocate(const gpu::BufferSizes& sizes, uint32_t image_width) override {
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

    void upload(gpu::Buffer b, size_t offset, const void* src, size_t bytes) override {
        check(clEnqueueWriteBuffer(queue_, buffer(b), CL_FALSE, offset, bytes, src, 0, nullptr, nullptr),
              "clEnqueueWriteBuffer");
    }

    void download(gpu::Buffer b, size_t offset, void* dst, size_t bytes) override {
        check(clEnqueueReadBuffer(queue_, buffer(b), CL_FALSE, offset, bytes, dst, 0, nullptr, nullptr),
              "clEnqueueReadBuffer");
    }

    void zero(gpu::Buffer b, size_t offset, size_t bytes) override {
        const cl_uint zero = 0;
        check(clEnqueueFillBuffer(queue_, buffer(b), &zero, sizeof(zero), offset, bytes, 0, nullptr, nullptr),
              "clEnqueueFillBuffer");
    }

    void dispatch(gpu::Kernel k, uint32_t nx, uint32_t ny, const gpu::Args& args) override {
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
            throw Error(ErrorCode::backend_unavailable, std::string(gpu::kernel_entry_name(k)) +
                                                            " needs workgroups of " + std::to_string(local[0]) +
                                                            " on " + rt_->description);
        }
        check(clEnqueueNDRangeKernel(queue_, kernel, 2, nullptr, global.data(), local_size, 0, nullptr, nullptr),
              gpu::kernel_entry_name(k));
    }

    void mark(const char* pass) override {
        cl_event event = nullptr;
        check(clEnqueueMarkerWithWaitList(queue_, 0, nullptr, &event), "clEnqueueMarkerWithWaitList");
        marks_.push_back({pass, event, 0});
    }

    void finish() override { check(clFinish(queue_), "clFinish"); }

    // Each pass runs from its marker to the next one.
    bool pass_times(std::vector<PassTiming>& timings) override {
        if (marks_.size() < 2) return false;
        for (Mark& m : marks_) {
            if (clGetEventProfilingInfo(m.event, CL_PROFILING_COMMAND_END, sizeof(cl_ulong), &m.end, nullptr) !=
                CL_SUCCESS)
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

    void begin_frame() override { release_marks(); }

private:
    struct Mark {
        const char* pass;
        cl_event event;
        cl_ulong end;  // CL_PROFILING_COMMAND_END, read by pass_times
    };

    [[nodiscard]] cl_mem buffer(gpu::Buffer b) const { return buffers_[size_t(b)]; }

    size_t max_group(gpu::Kernel k) {
        size_t& limit = group_limits_[size_t(k)];
        if (limit == 0) {
            limit = 1;
            clGetKernelWorkGroupInfo(kernels_[size_t(k)], rt_->device, CL_KERNEL_WORK_GROUP_SIZE, sizeof(limit), &limit,
                                     nullptr);
        }
        return limit;
    }

    void release_marks() {
        for (const Mark& m : marks_) clReleaseEvent(m.event);
        marks_.clear();
    }

    std::shared_ptr<const Runtime> rt_;
    cl_command_queue queue_ = nullptr;
    std::array<cl_kernel, gpu::kKernelCount> kernels_{};
    std::array<size_t, gpu::kKernelCount> group_limits_{};
    std::array<cl_mem, gpu::kBufferCount> buffers_{};
    std::vector<Mark> marks_;
};

}  // namespace

std::unique_ptr<core::PassExecutor> make_executor(const core::Plan& plan) {
    return gpu::make_gpu_executor(plan, std::make_unique<OpenclDevice>(runtime_for(choose_device())));
}

std::vector<std::string> describe_devices(std::string* why_none) {
    std::vector<std::string> out;
    for (const DeviceRef& d : enumerate_devices(why_none)) out.push_back(d.description);
    return out;
}

const core::BackendEntry kBackend = {[](std::string* why_none, bool* available) {
                                         std::vector<std::string> devices = describe_devices(why_none);
                                         *available = !devices.empty();
                                         return devices;
                                     },
                                     make_executor};

}  // namespace pyrseg::opencl
