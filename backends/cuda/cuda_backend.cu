// The CUDA backend: gpu::Device over one stream per Segmenter, a non-blocking one of its own or the application's
// (pyrseg/cuda.hpp, cuda_interop.cpp). The passes are core/gpu/gpu_executor.cpp; the kernels are shaders/pyr_cuda.cuh
// (the entry points of shaders/pyr_entries.h), launched through the kernel table. Host transfers go through pinned
// staging memory; per-pass times come from CUDA events.
#include "backends/cuda/cuda_backend.hpp"
#include "backends/cuda/cuda_device.hpp"

#include <cuda_runtime.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <iterator>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/device_choice.hpp"
#include "core/gpu/api_error.hpp"
#include "core/gpu/device.hpp"
#include "core/gpu/gpu_executor.hpp"
#include "core/gpu/staging.hpp"
#include "pyrseg/error.hpp"
#include "shaders/pyr_cuda.cuh"

namespace pyrseg::cuda {
namespace {

using std::size_t;
using std::uint32_t;

constexpr uint32_t kBlock1D = 256;  // at most PYR_SCAN_GROUP_MAX: also the workgroup kernels' size
static_assert(kBlock1D <= PYR_SCAN_GROUP_MAX);
constexpr uint32_t kBlock2DX = 32;  // a warp along a row: coalesced loads
constexpr uint32_t kBlock2DY = 8;
constexpr uint32_t kMaxEvents = 64;

// The kernel table's entry points, in gpu::Kernel order.
using KernelFn = void (*)(PyrCudaCtx, PyrArgs);
constexpr KernelFn kKernelFns[] = {
#define PYR_CUDA_KERNEL_FN(name, NAME, dims) pyr_k_##name,
    PYR_KERNEL_TABLE(PYR_CUDA_KERNEL_FN)
#undef PYR_CUDA_KERNEL_FN
};
static_assert(std::size(kKernelFns) == gpu::kKernelCount);

// CUDA's codes for the kinds of failure core/gpu/api_error.hpp gives their meaning: a launch failure or an illegal
// address leaves the context unusable (a sticky error), a device that cannot go on.
[[noreturn]] void fail(cudaError_t err, const char* what) {
    std::optional<gpu::Fault> fault;
    if (err == cudaErrorMemoryAllocation) {
        fault = gpu::Fault::out_of_memory;
    } else if (err == cudaErrorLaunchFailure || err == cudaErrorIllegalAddress) {
        fault = gpu::Fault::device_lost;
    }
    gpu::throw_api_failure({"CUDA", what, std::string(cudaGetErrorName(err)) + " (" + cudaGetErrorString(err) + ")",
                            fault, "; the device failed: this Segmenter cannot run it any more"});
}

void check(cudaError_t err, const char* what) {
    if (err != cudaSuccess) fail(err, what);
}

// A device (or pinned host) allocation owned by one Segmenter.
template <bool Host>
class Memory {
public:
    Memory() = default;
    Memory(size_t bytes, const char* what) : bytes_(std::max<size_t>(bytes, 4)) {
        if constexpr (Host) {
            check(cudaMallocHost(&ptr_, bytes_), what);
        } else {
            check(cudaMalloc(&ptr_, bytes_), what);
        }
    }
    ~Memory() {
        if (ptr_ == nullptr) return;
        if constexpr (Host) {
            cudaFreeHost(ptr_);
        } else {
            cudaFree(ptr_);
        }
    }
    Memory(Memory&& o) noexcept : ptr_(std::exchange(o.ptr_, nullptr)), bytes_(o.bytes_) {}
    Memory& operator=(Memory&& o) noexcept {
        std::swap(ptr_, o.ptr_);
        std::swap(bytes_, o.bytes_);
        return *this;
    }
    Memory(const Memory&) = delete;
    Memory& operator=(const Memory&) = delete;
    template <class T>
    [[nodiscard]] T* as() const {
        return static_cast<T*>(ptr_);
    }
    [[nodiscard]] size_t bytes() const { return bytes_; }

private:
    void* ptr_ = nullptr;
    size_t bytes_ = 0;
};

// An upload_inline's bytes travel as a kernel's parameter (at most 4 KiB of them, with the other two): copied when the
// launch is queued, so the frame may run long after the call, and the next frame may change the source at once,
// with no staging memory to keep alive.
constexpr size_t kInlineBytes = 4000;
struct InlineBytes {
    unsigned char b[kInlineBytes];
};

__global__ void pyr_cuda_put_bytes(unsigned char* dst, unsigned n, InlineBytes bytes) {
    const unsigned i = blockIdx.x * blockDim.x + threadIdx.x;
    if (i < n) dst[i] = bytes.b[i];
}

// gpu::Device over one stream: a non-blocking one of pyrseg's own, or the caller's (pyrseg/cuda.hpp).
//
// On pyrseg's own stream, commands are issued as they come (or, with PYRSEG_CUDA_GRAPHS=1, queued and run as a
// CUDA graph at finish()). On the caller's stream, every command of a frame is queued and issued at the frame's
// end: finish() for host frames (which then wait for the stream), submit() for device frames, which are issued
// directly on the caller's stream, never wrapped in a graph of pyrseg's own (the caller may be capturing the
// stream into its graph), and record no events. A frame refused half-way (by a check, or a capture it cannot be
// part of) thus leaves nothing on the stream.
class StreamDevice final : public CudaDevice {
public:
    // pyrseg's own non-blocking stream on `device`.
    explicit StreamDevice(int device) : device_(device) {
        select();
        describe_device();
        check(cudaStreamCreateWithFlags(&stream_, cudaStreamNonBlocking), "cudaStreamCreate");
        create_events();
        const char* graphs = std::getenv("PYRSEG_CUDA_GRAPHS");
        graphs_ = graphs != nullptr && std::strcmp(graphs, "1") == 0;
    }

    // The caller's stream of `device`. The legacy default stream (0, cudaStreamLegacy) cannot be captured, so
    // PYRSEG_CUDA_GRAPHS leaves host frames on it as they are.
    StreamDevice(int device, cudaStream_t stream) : device_(device), stream_(stream), external_(true) {
        select();
        describe_device();
        description_ += " on the application's stream";
        create_events();
        const char* graphs = std::getenv("PYRSEG_CUDA_GRAPHS");
        const bool legacy = stream == nullptr || stream == cudaStreamLegacy;
        graphs_ = graphs != nullptr && std::strcmp(graphs, "1") == 0 && !legacy;
    }

    // Waits for the stream (the caller's too: work queued there reads pyrseg's buffers) unless it is being
    // captured, then frees everything with the device current, and makes the caller's current device current again.
    ~StreamDevice() override {
        int previous = -1;
        if (cudaGetDevice(&previous) == cudaSuccess && previous != device_) cudaSetDevice(device_);
        if (stream_ != nullptr || external_) {
            cudaStreamCaptureStatus status = cudaStreamCaptureStatusNone;
            if (cudaStreamIsCapturing(stream_, &status) == cudaSuccess && status == cudaStreamCaptureStatusNone)
                cudaStreamSynchronize(stream_);
            if (!external_) cudaStreamDestroy(stream_);
        }
        for (const Graph& g : graphs_cache_) cudaGraphExecDestroy(g.exec);
        for (cudaEvent_t e : events_) {
            if (e != nullptr) cudaEventDestroy(e);
        }
        for (Memory<false>& m : buffers_) m = Memory<false>();
        upload_ = Memory<true>();
        download_ = Memory<true>();
        if (previous >= 0 && previous != device_) cudaSetDevice(previous);
    }
    StreamDevice(const StreamDevice&) = delete;
    StreamDevice& operator=(const StreamDevice&) = delete;

    [[nodiscard]] std::string description() const override { return description_; }
    [[nodiscard]] int ordinal() const override { return device_; }
    [[nodiscard]] cudaStream_t stream() const override { return stream_; }
    [[nodiscard]] bool callers_stream() const override { return external_; }

    [[nodiscard]] gpu::DeviceLimits limits() const override {
        select();
        size_t free_bytes = 0;
        size_t total_bytes = 0;
        check(cudaMemGetInfo(&free_bytes, &total_bytes), "cudaMemGetInfo");
        gpu::DeviceLimits l;
        l.max_buffer_bytes.fill(free_bytes);
        l.max_buffer_what = "its free memory";
        l.memory_bytes = free_bytes;
        l.memory_what = "its free memory";
        return l;
    }

    void allocate(const gpu::BufferSizes& sizes, uint32_t image_width) override {
        select();
        for (size_t b = 0; b < gpu::kBufferCount; ++b) {
            const std::string what = std::string("cudaMalloc(") + gpu::buffer_name(gpu::Buffer(b)) + ")";
            buffers_[b] = Memory<false>(sizes[b], what.c_str());
        }
        const gpu::StagingBytes staging = gpu::staging_bytes(sizes);
        upload_ = Memory<true>(staging.upload, "cudaMallocHost(upload staging)");
        download_ = Memory<true>(staging.download, "cudaMallocHost(download staging)");
        staging_.reset(upload_.as<unsigned char>(), upload_.bytes(), download_.as<unsigned char>(), download_.bytes());
        // The ray tables, the only inline uploads, live in the sums buffer: no allocation when they change.
        inline_.reserve(std::max<size_t>(sizes[size_t(gpu::Buffer::sums)], size_t(64) << 10));
#define PYR_CUDA_BUFFER_POINTER(name, index, TYPE, QUAL) ctx_.name = buffer<PYR_CUDA_##TYPE>(gpu::Buffer::name);
        PYR_BUFFER_TABLE(PYR_CUDA_BUFFER_POINTER)
#undef PYR_CUDA_BUFFER_POINTER
        ctx_.w = image_width;
    }

    void upload(gpu::Buffer b, size_t offset, const void* src, size_t bytes) override {
        Op op{Op::h2d};
        op.dst = buffer<unsigned char>(b) + offset;
        op.src = upload_.as<unsigned char>() + staging_.stage_upload(src, bytes);
        op.bytes = bytes;
        enqueue(op);
    }

    void download(gpu::Buffer b, size_t offset, void* dst, size_t bytes) override {
        Op op{Op::d2h};
        op.dst = download_.as<unsigned char>() + staging_.stage_download(dst, bytes);
        op.src = buffer<unsigned char>(b) + offset;
        op.bytes = bytes;
        enqueue(op);
    }

    void zero(gpu::Buffer b, size_t offset, size_t bytes) override {
        Op op{Op::memset};
        op.dst = buffer<unsigned char>(b) + offset;
        op.bytes = bytes;
        enqueue(op);
    }

    // 1D: blocks of 256 threads over a 2D grid (PYR_I); 2D: 32 x 8 blocks, a warp along a row.
    void dispatch(gpu::Kernel k, uint32_t nx, uint32_t ny, const gpu::Args& args) override {
        if (nx == 0 || ny == 0) return;
        dim3 grid;
        dim3 block;
        if (gpu::kernel_dims(k) != 2) {
            // 1D: blocks of 256 threads; 3: one block of 256 threads per index (PYR_GID).
            const uint32_t blocks = gpu::kernel_dims(k) == 3 ? nx : (nx + kBlock1D - 1) / kBlock1D;
            const uint32_t x = std::min<uint32_t>(blocks, 65535u);
            grid = dim3(x, (blocks + x - 1) / x);
            block = dim3(kBlock1D);
        } else {
            grid = dim3((nx + kBlock2DX - 1) / kBlock2DX, (ny + kBlock2DY - 1) / kBlock2DY);
            block = dim3(kBlock2DX, kBlock2DY);
        }
        Op op{Op::launch};
        op.kernel = uint32_t(k);
        op.grid = grid;
        op.block = block;
        std::copy(args.words.begin(), args.words.end(), op.args.a);
        enqueue(op);
    }

    void mark(const char* pass) override {
        if (event_count_ == kMaxEvents) return;
        Op op{Op::record};
        op.event = event_count_;
        event_names_[event_count_++] = pass;
        enqueue(op);
    }

    // With PYRSEG_CUDA_GRAPHS=1 the commands queued since the last finish() run as one CUDA graph: captured from the
    // stream the first time this exact sequence comes (a frame's commands, their arguments and addresses depend only
    // on the plan and the input kind, so a Segmenter sees a handful), then replayed with one launch.
    void finish() override {
        if (external_) {
            refuse_if_capturing(
                "a host frame (Segmenter::segment) waits for the Segmenter's stream, which is being captured into a "
                "CUDA graph: give the graph device frames (pyrseg::cuda::segment), and host frames outside the "
                "capture");
        }
        if (!ops_.empty()) run_queued();
        check(cudaStreamSynchronize(stream_), "cudaStreamSynchronize");
        staging_.complete();
    }

    // Each pass runs from its event to the next one.
    bool pass_times(std::vector<PassTiming>& timings) override {
        if (event_count_ < 2) return false;
        for (PassTiming& t : timings) t.milliseconds = 0.0;
        for (uint32_t k = 0; k + 1 < event_count_; ++k) {
            float ms = 0.0f;
            check(cudaEventElapsedTime(&ms, events_[k], events_[k + 1]), "cudaEventElapsedTime");
            for (PassTiming& t : timings) {
                if (event_names_[k] != nullptr && std::strcmp(t.pass, event_names_[k]) == 0)
                    t.milliseconds += double(ms);
            }
        }
        return true;
    }

    // A frame that an error abandoned leaves nothing behind: no queued commands, no staged transfers.
    void begin_frame() override {
        select();
        event_count_ = 0;
        ops_.clear();
        inline_.clear();
        staging_.restart();
    }

    // Device-resident frames, on the caller's stream only: device-to-device copies between the caller's memory and
    // pyrseg's buffers (cudaMemcpy2DAsync where rows are padded).
    void copy_in(gpu::Buffer dst, size_t offset, const core::ExternalBuffer& src, size_t pitch, size_t row_bytes,
                 size_t rows) override {
        if (!external_) gpu::Device::copy_in(dst, offset, src, pitch, row_bytes, rows);  // throws
        Op op{Op::d2d};
        op.dst = buffer<unsigned char>(dst) + offset;
        op.dst_pitch = row_bytes;
        op.src = callers(src);
        op.src_pitch = pitch;
        op.bytes = row_bytes;
        op.rows = rows;
        enqueue(op);
    }

    void copy_out(const core::ExternalBuffer& dst, size_t pitch, gpu::Buffer src, size_t offset, size_t row_bytes,
                  size_t rows) override {
        if (!external_) gpu::Device::copy_out(dst, pitch, src, offset, row_bytes, rows);  // throws
        Op op{Op::d2d};
        op.dst = const_cast<unsigned char*>(callers(dst));
        op.dst_pitch = pitch;
        op.src = buffer<unsigned char>(src) + offset;
        op.src_pitch = row_bytes;
        op.bytes = row_bytes;
        op.rows = rows;
        enqueue(op);
    }

    // A device depth frame's ray tables, as kernel parameters (kInlineBytes a launch): part of the frame, so a
    // captured graph carries its own.
    void upload_inline(gpu::Buffer b, size_t offset, const void* src, size_t bytes) override {
        if (!external_) gpu::Device::upload_inline(b, offset, src, bytes);  // throws
        const auto* from = static_cast<const unsigned char*>(src);
        for (size_t done = 0; done < bytes; done += kInlineBytes) {
            Op op{Op::put};
            op.dst = buffer<unsigned char>(b) + offset + done;
            op.bytes = std::min(kInlineBytes, bytes - done);
            op.inline_at = inline_.size();
            inline_.insert(inline_.end(), from + done, from + done + op.bytes);
            enqueue(op);
        }
    }

    [[noreturn]] void fail_like(gpu::Fault fault, const char* what) const override {
        fail(fault == gpu::Fault::out_of_memory ? cudaErrorMemoryAllocation : cudaErrorLaunchFailure, what);
    }

    // The device frame's commands, in order, on the caller's stream; nothing waits.
    void submit() override {
        if (!external_) gpu::Device::submit();  // throws
        for (const Op& op : ops_) issue(op, false);
        ops_.clear();
    }

private:
    // A command of the stream, issued at once, or queued for a graph.
    struct Op {
        enum Kind : std::uint8_t { h2d, d2h, memset, launch, record, d2d, put };
        explicit Op(Kind k) : kind(k) {}
        Kind kind;
        void* dst = nullptr;  // copies, memset, put
        const void* src = nullptr;
        size_t bytes = 0;      // d2d: bytes a row
        size_t dst_pitch = 0;  // d2d
        size_t src_pitch = 0;
        size_t rows = 0;
        size_t inline_at = 0;  // put: where its bytes are in inline_
        uint32_t kernel = 0;   // launch
        dim3 grid;
        dim3 block;
        PyrArgs args{};
        uint32_t event = 0;  // record: which of events_

        [[nodiscard]] bool same(const Op& o) const {
            const auto same_dim = [](dim3 a, dim3 b) { return a.x == b.x && a.y == b.y && a.z == b.z; };
            return kind == o.kind && dst == o.dst && src == o.src && bytes == o.bytes && dst_pitch == o.dst_pitch &&
                   src_pitch == o.src_pitch && rows == o.rows && inline_at == o.inline_at && kernel == o.kernel &&
                   same_dim(grid, o.grid) && same_dim(block, o.block) &&
                   std::equal(std::begin(args.a), std::end(args.a), std::begin(o.args.a)) && event == o.event;
        }
    };

    struct Graph {
        std::vector<Op> ops;
        cudaGraphExec_t exec;
    };

    static constexpr size_t kMinGraphLaunches = 4;  // fewer (the statistics' download) run as they are

    void describe_device() {
        cudaDeviceProp p{};
        check(cudaGetDeviceProperties(&p, device_), "cudaGetDeviceProperties");
        description_ = "CUDA device " + std::to_string(device_) + " (" + p.name + ")";
    }

    void create_events() {
        for (cudaEvent_t& e : events_) check(cudaEventCreate(&e), "cudaEventCreate");
        ops_.reserve(256);
    }

    static const unsigned char* callers(const core::ExternalBuffer& b) {
        return reinterpret_cast<const unsigned char*>(static_cast<std::uintptr_t>(b.handle)) + b.offset;
    }

    void refuse_if_capturing(const char* why) const {
        cudaStreamCaptureStatus status = cudaStreamCaptureStatusNone;
        check(cudaStreamIsCapturing(stream_, &status), "cudaStreamIsCapturing");
        if (status != cudaStreamCaptureStatusNone) throw Error(ErrorCode::invalid_argument, why);
    }

    // pyrseg's own stream issues at once unless graphs are on; the caller's queues the whole frame.
    void enqueue(const Op& op) {
        if (graphs_ || external_) {
            ops_.push_back(op);
        } else {
            issue(op, false);
        }
    }

    void issue(const Op& op, bool capturing) {
        switch (op.kind) {
            case Op::h2d:
                check(cudaMemcpyAsync(op.dst, op.src, op.bytes, cudaMemcpyHostToDevice, stream_),
                      "cudaMemcpyAsync(upload)");
                break;
            case Op::d2h:
                check(cudaMemcpyAsync(op.dst, op.src, op.bytes, cudaMemcpyDeviceToHost, stream_),
                      "cudaMemcpyAsync(download)");
                break;
            case Op::d2d:
                if (op.rows == 1 || (op.src_pitch == op.bytes && op.dst_pitch == op.bytes)) {
                    check(cudaMemcpyAsync(op.dst, op.src, op.bytes * op.rows, cudaMemcpyDeviceToDevice, stream_),
                          "cudaMemcpyAsync(device to device)");
                } else {
                    check(cudaMemcpy2DAsync(op.dst, op.dst_pitch, op.src, op.src_pitch, op.bytes, op.rows,
                                            cudaMemcpyDeviceToDevice, stream_),
                          "cudaMemcpy2DAsync(device to device)");
                }
                break;
            case Op::memset:
                check(cudaMemsetAsync(op.dst, 0, op.bytes, stream_), "cudaMemsetAsync");
                break;
            case Op::launch: {
                PyrArgs args = op.args;
                void* params[] = {&ctx_, &args};
                check(cudaLaunchKernel(reinterpret_cast<const void*>(kKernelFns[op.kernel]), op.grid, op.block, params,
                                       0, stream_),
                      gpu::kernel_entry_name(gpu::Kernel(op.kernel)));
                break;
            }
            case Op::put: {
                auto* dst = static_cast<unsigned char*>(op.dst);
                auto n = unsigned(op.bytes);
                InlineBytes bytes{};
                std::memcpy(bytes.b, inline_.data() + op.inline_at, op.bytes);
                void* params[] = {&dst, &n, &bytes};
                check(cudaLaunchKernel(reinterpret_cast<const void*>(&pyr_cuda_put_bytes), dim3((n + 255) / 256),
                                       dim3(256), params, 0, stream_),
                      "pyr_cuda_put_bytes");
                break;
            }
            case Op::record:
                // In a capture, an external record: the graph's replays record the event too (pass times).
                check(capturing ? cudaEventRecordWithFlags(events_[op.event], stream_, cudaEventRecordExternal)
                                : cudaEventRecord(events_[op.event], stream_),
                      "cudaEventRecord");
                break;
        }
    }

    void run_queued() {
        const size_t launches =
            size_t(std::count_if(ops_.begin(), ops_.end(), [](const Op& op) { return op.kind == Op::launch; }));
        if (!graphs_ || launches < kMinGraphLaunches) {
            for (const Op& op : ops_) issue(op, false);
            ops_.clear();
            return;
        }
        const Graph* graph = nullptr;
        for (const Graph& g : graphs_cache_) {
            if (g.ops.size() == ops_.size() &&
                std::equal(ops_.begin(), ops_.end(), g.ops.begin(), [](const Op& a, const Op& b) { return a.same(b); }))
                graph = &g;
        }
        if (graph == nullptr) graph = &capture();
        ops_.clear();
        check(cudaGraphLaunch(graph->exec, stream_), "cudaGraphLaunch");
    }

    const Graph& capture() {
        check(cudaStreamBeginCapture(stream_, cudaStreamCaptureModeThreadLocal), "cudaStreamBeginCapture");
        cudaGraph_t captured = nullptr;
        try {
            for (const Op& op : ops_) issue(op, true);
        } catch (...) {
            cudaStreamEndCapture(stream_, &captured);
            if (captured != nullptr) cudaGraphDestroy(captured);
            throw;
        }
        check(cudaStreamEndCapture(stream_, &captured), "cudaStreamEndCapture");
        cudaGraphExec_t exec = nullptr;
        const cudaError_t err = cudaGraphInstantiate(&exec, captured, 0);
        cudaGraphDestroy(captured);
        check(err, "cudaGraphInstantiate");
        graphs_cache_.push_back(Graph{ops_, exec});
        return graphs_cache_.back();
    }

    // The device current on the calling thread (set only when another one is).
    void select() const {
        int current = -1;
        if (cudaGetDevice(&current) != cudaSuccess || current != device_)
            check(cudaSetDevice(device_), "cudaSetDevice");
    }

    template <class T>
    [[nodiscard]] T* buffer(gpu::Buffer b) const {
        return buffers_[size_t(b)].as<T>();
    }

    int device_;
    std::string description_;
    cudaStream_t stream_ = nullptr;
    bool external_ = false;  // stream_ is the caller's
    std::array<Memory<false>, gpu::kBufferCount> buffers_;
    Memory<true> upload_, download_;
    gpu::StagingArena staging_;
    PyrCudaCtx ctx_{};
    std::array<cudaEvent_t, kMaxEvents> events_{};
    std::array<const char*, kMaxEvents> event_names_{};
    uint32_t event_count_ = 0;
    bool graphs_ = false;                // PYRSEG_CUDA_GRAPHS=1 (host frames only)
    std::vector<Op> ops_;                // queued: in graph mode, and every frame on the caller's stream
    std::vector<unsigned char> inline_;  // the bytes of the queued put commands
    std::vector<Graph> graphs_cache_;
};

std::string describe(int index, const cudaDeviceProp& p) {
    return std::to_string(index) + " " + p.name + " (sm_" + std::to_string(p.major) + std::to_string(p.minor) + ", " +
           std::to_string(p.totalGlobalMem >> 20) + " MiB)";
}

}  // namespace

std::vector<std::string> describe_devices(std::string* why_none) {
    std::vector<std::string> out;
    int count = 0;
    const cudaError_t err = cudaGetDeviceCount(&count);
    if (err != cudaSuccess || count == 0) {
        if (why_none != nullptr) {
            int driver = 0;
            cudaDriverGetVersion(&driver);
            if (driver == 0) {
                *why_none = "no CUDA device: no NVIDIA driver is installed (libcuda not found)";
            } else if (err == cudaErrorInsufficientDriver) {
                *why_none = "no CUDA device: the NVIDIA driver supports CUDA " + std::to_string(driver / 1000) + "." +
                            std::to_string(driver % 1000 / 10) + ", older than the CUDA " +
                            std::to_string(CUDART_VERSION / 1000) + "." + std::to_string(CUDART_VERSION % 1000 / 10) +
                            " runtime pyrseg was built with";
            } else {
                *why_none = std::string("no CUDA device (cudaGetDeviceCount: ") +
                            (err != cudaSuccess ? cudaGetErrorString(err) : "0 devices") + ")";
            }
        }
        cudaGetLastError();  // clear the sticky-free error state for later calls
        return out;
    }
    // The driver's CUDA version beside the runtime's: a report from a GPU machine then says what ran on what.
    int driver = 0;
    cudaDriverGetVersion(&driver);
    const auto version = [](int v) { return std::to_string(v / 1000) + "." + std::to_string(v % 1000 / 10); };
    const std::string versions = "driver CUDA " + version(driver) + ", runtime " + version(CUDART_VERSION);
    for (int d = 0; d < count; ++d) {
        cudaDeviceProp p{};
        if (cudaGetDeviceProperties(&p, d) == cudaSuccess) out.push_back(describe(d, p) + ", " + versions);
    }
    return out;
}

std::unique_ptr<core::PassExecutor> make_executor(const core::Plan& plan) {
    std::string why;
    const std::vector<std::string> devices = describe_devices(&why);
    if (devices.empty()) throw Error(ErrorCode::backend_unavailable, "backend 'cuda' is unavailable: " + why);
    std::vector<std::string> ids;
    for (size_t d = 0; d < devices.size(); ++d) ids.push_back(std::to_string(d));
    const auto chosen = core::device_from_environment("PYRSEG_CUDA_DEVICE", "CUDA", ids, devices);
    return gpu::make_gpu_executor(plan, make_device(int(chosen.value_or(0))));
}

std::unique_ptr<CudaDevice> make_device(int device) {
    return std::make_unique<StreamDevice>(device);
}

std::unique_ptr<CudaDevice> make_device(int device, cudaStream_t stream) {
    return std::make_unique<StreamDevice>(device, stream);
}

CurrentDevice::CurrentDevice(int device) {
    int current = -1;
    check(cudaGetDevice(&current), "cudaGetDevice");
    if (current == device) return;
    check(cudaSetDevice(device), "cudaSetDevice");
    previous_ = current;
}

CurrentDevice::~CurrentDevice() {
    if (previous_ >= 0) cudaSetDevice(previous_);
}

const core::BackendEntry kBackend = {[](std::string* why_none, bool* available) {
                                         std::vector<std::string> devices = describe_devices(why_none);
                                         *available = !devices.empty();
                                         return devices;
                                     },
                                     make_executor};

}  // namespace pyrseg::cuda
