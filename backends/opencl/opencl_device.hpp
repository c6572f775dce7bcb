#pragma once
// gpu::Device over one in-order OpenCL command queue: pyrseg's own, or the caller's (pyrseg/opencl.hpp).
#include <array>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "backends/opencl/opencl_runtime.hpp"
#include "core/gpu/device.hpp"

namespace pyrseg::opencl {

class OpenclDevice final : public gpu::Device {
public:
    // A queue of pyrseg's own on the runtime's context.
    explicit OpenclDevice(std::shared_ptr<const Runtime> runtime);
    // The caller's queue (retained until the device is destroyed); it must be in order.
    OpenclDevice(std::shared_ptr<const Runtime> runtime, cl_command_queue queue);
    ~OpenclDevice() override;
    OpenclDevice(const OpenclDevice&) = delete;
    OpenclDevice& operator=(const OpenclDevice&) = delete;

    [[nodiscard]] std::string description() const override { return rt_->description; }
    [[nodiscard]] gpu::DeviceLimits limits() const override;
    void allocate(const gpu::BufferSizes& sizes, std::uint32_t image_width) override;
    void upload(gpu::Buffer b, std::size_t offset, const void* src, std::size_t bytes) override;
    void download(gpu::Buffer b, std::size_t offset, void* dst, std::size_t bytes) override;
    void zero(gpu::Buffer b, std::size_t offset, std::size_t bytes) override;
    void dispatch(gpu::Kernel k, std::uint32_t nx, std::uint32_t ny, const gpu::Args& args) override;
    void mark(const char* pass) override;
    void finish() override;
    bool pass_times(std::vector<PassTiming>& timings) override;
    void begin_frame() override;

    void copy_in(gpu::Buffer dst, std::size_t offset, const core::ExternalBuffer& src, std::size_t pitch,
                 std::size_t row_bytes, std::size_t rows) override;
    void copy_out(const core::ExternalBuffer& dst, std::size_t pitch, gpu::Buffer src, std::size_t offset,
                  std::size_t row_bytes, std::size_t rows) override;
    void upload_inline(gpu::Buffer b, std::size_t offset, const void* src, std::size_t bytes) override;
    void submit() override;
    [[noreturn]] void fail_like(gpu::Fault fault, const char* what) const override;

    // For the interop functions: the queue and context, what the next device frame waits for, and the event that
    // completes with the last submitted one (the caller owns it once taken).
    [[nodiscard]] cl_command_queue queue() const { return queue_; }
    [[nodiscard]] cl_context context() const { return rt_->context; }
    void wait_for(std::span<const cl_event> events);
    [[nodiscard]] cl_event take_done_event();

private:
    // Every cl_int of the device goes through here: a faulted context is marked on the shared runtime.
    void check(cl_int code, const char* what) const;
    // Waits for the queued transfers to or from host memory, if any; errors are the caller's to report.
    void drain() const;
    struct Mark {
        const char* pass;
        cl_event event;
        cl_ulong end;  // CL_PROFILING_COMMAND_END, read by pass_times
    };

    [[nodiscard]] cl_mem buffer(gpu::Buffer b) const { return buffers_[std::size_t(b)]; }
    std::size_t max_group(gpu::Kernel k);
    void release_marks();
    void create_kernels();
    void copy_rect(cl_mem src, std::size_t src_offset, std::size_t src_pitch, cl_mem dst, std::size_t dst_offset,
                   std::size_t dst_pitch, std::size_t row_bytes, std::size_t rows);

    std::shared_ptr<const Runtime> rt_;
    cl_command_queue queue_ = nullptr;
    std::array<cl_kernel, gpu::kKernelCount> kernels_{};
    std::array<std::size_t, gpu::kKernelCount> group_limits_{};
    std::array<cl_mem, gpu::kBufferCount> buffers_{};
    std::vector<Mark> marks_;
    cl_event done_ = nullptr;
    bool host_pending_ = false;  // transfers to or from host memory queued and not yet finished
};

}  // namespace pyrseg::opencl
