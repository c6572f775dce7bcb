// The CUDA backend: the kernels of shaders/pyr_cuda.cuh launched on one stream per Segmenter. Passes are queued
// without host synchronisation; the host waits only for the fills' batched convergence flags and for the results.
// Per-pass times come from CUDA events recorded at the pass boundaries.
#include "backends/cuda/cuda_backend.hpp"

#include <cuda_runtime.h>

#include <algorithm>
#include <array>
#include <cstring>
#include <string>
#include <utility>

#include "core/device_choice.hpp"
#include "core/segment_stats.hpp"
#include "core/staging.hpp"
#include "pyrseg/error.hpp"
#include "shaders/pyr_cuda.cuh"

namespace pyrseg::cuda {
namespace {

using std::size_t;
using std::uint32_t;

constexpr uint32_t kBlock1D = 256;
constexpr uint32_t kBlock2DX = 32;  // a warp along a row: coalesced loads
constexpr uint32_t kBlock2DY = 8;
constexpr uint32_t kMaxBatch = 64;  // fill rounds between two reads of the convergence flags
constexpr uint32_t kMaxEvents = 64;

[[noreturn]] void fail(cudaError_t err, const char* what) {
    const ErrorCode code = err == cudaErrorMemoryAllocation ? ErrorCode::out_of_memory : ErrorCode::internal;
    throw Error(code, std::string("CUDA: ") + what + " failed: " + cudaGetErrorName(err) + " (" +
                          cudaGetErrorString(err) + ")");
}

void check(cudaError_t err, const char* what) {
    if (err != cudaSuccess) fail(err, what);
}

// A device (or pinned host) allocation owned by one Segmenter.
template <bool Host>
class Memory {
public:
    Memory() = default;
    Memory(size_t bytes, const char* what) {
        bytes = std::max<size_t>(bytes, 4);
        if constexpr (Host) {
            check(cudaMallocHost(&ptr_, bytes), what);
        } else {
            check(cudaMalloc(&ptr_, bytes), what);
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
    Memory(Memory&& o) noexcept : ptr_(std::exchange(o.ptr_, nullptr)) {}
    Memory& operator=(Memory&& o) noexcept {
        std::swap(ptr_, o.ptr_);
        return *this;
    }
    Memory(const Memory&) = delete;
    Memory& operator=(const Memory&) = delete;
    template <class T>
    [[nodiscard]] T* as() const {
        return static_cast<T*>(ptr_);
    }

private:
    void* ptr_ = nullptr;
};

struct Launch {
    dim3 grid;
    dim3 block;
};

Launch linear(uint32_t count) {
    const uint32_t blocks = (count + kBlock1D - 1) / kBlock1D;
    const uint32_t x = std::min<uint32_t>(blocks, 65535u);
    return {dim3(x, (blocks + x - 1) / x), dim3(kBlock1D)};
}

Launch planar(uint32_t w, uint32_t h) {
    return {dim3((w + kBlock2DX - 1) / kBlock2DX, (h + kBlock2DY - 1) / kBlock2DY), dim3(kBlock2DX, kBlock2DY)};
}

class CudaExecutor final : public core::PassExecutor {
public:
    CudaExecutor(const core::Plan& plan, int device) : plan_(plan), device_(device) {
        check(cudaSetDevice(device), "cudaSetDevice");
        const size_t pixels = plan.pixel_count();
        const size_t texels = size_t(plan.total_texels);
        check_fits(pixels, texels);
        check(cudaStreamCreateWithFlags(&stream_, cudaStreamNonBlocking), "cudaStreamCreate");
        points_ = Memory<false>(12 * pixels, "cudaMalloc(points)");
        normals_ = Memory<false>(12 * pixels, "cudaMalloc(normals)");
        quant_ = Memory<false>(16 * pixels, "cudaMalloc(quant)");
        mask_ = Memory<false>(texels, "cudaMalloc(mask)");
        labels_ = Memory<false>(4 * texels, "cudaMalloc(labels)");
        lut_ = Memory<false>(4 * size_t(plan_.lut_size()), "cudaMalloc(lut)");
        sums_ = Memory<false>(4 * (size_t(plan_.scan_chunks()) + 1), "cudaMalloc(scan sums)");
        flags_ = Memory<false>(4 * kMaxBatch, "cudaMalloc(flags)");
        out_ = Memory<false>(4 * pixels, "cudaMalloc(labels out)");
        if (plan_.stats_slots != 0) {
            stats_ = Memory<false>(4 * plan_.stats_words(), "cudaMalloc(statistics)");
            host_stats_ = Memory<true>(4 * plan_.stats_words(), "cudaMallocHost(statistics)");
        }
        staging_in_ = Memory<true>(24 * pixels, "cudaMallocHost(upload staging)");
        staging_out_ = Memory<true>(core::StagedResults::kBytesPerPixel * pixels, "cudaMallocHost(download staging)");
        host_flags_ = Memory<true>(4 * (kMaxBatch + 1), "cudaMallocHost(flags)");
        for (cudaEvent_t& e : events_) check(cudaEventCreate(&e), "cudaEventCreate");
        ctx_ = PyrCudaCtx{points_.as<const float>(), normals_.as<float>(),   quant_.as<int>(),
                          mask_.as<unsigned char>(), labels_.as<unsigned>(), lut_.as<unsigned>(),
                          stats_.as<unsigned>(),     uint32_t(plan.width)};
    }

    ~CudaExecutor() override {
        if (stream_ != nullptr) {
            cudaStreamSynchronize(stream_);
            cudaStreamDestroy(stream_);
        }
        for (cudaEvent_t e : events_) {
            if (e != nullptr) cudaEventDestroy(e);
        }
    }
    CudaExecutor(const CudaExecutor&) = delete;
    CudaExecutor& operator=(const CudaExecutor&) = delete;

    [[nodiscard]] uint32_t fill_rounds() const override { return fill_rounds_; }

    void bind_cloud(const CloudView& cloud) override {
        fill_rounds_ = 0;
        select();
        event_count_ = 0;
        record_event("upload");
        const size_t bytes = 12 * plan_.pixel_count();
        core::pack_xyz(cloud, cloud.points, staging_in_.as<float>());
        copy_in(points_.as<void>(), staging_in_.as<void>(), bytes);
        from_mask_ = false;
        if (cloud.normals != nullptr) {
            auto* normals = staging_in_.as<unsigned char>() + bytes;
            core::pack_xyz(cloud, cloud.normals, reinterpret_cast<float*>(normals));
            copy_in(normals_.as<void>(), normals, bytes);
        }
    }

    void bind_mask(const MaskView& mask) override {
        fill_rounds_ = 0;
        select();
        event_count_ = 0;
        record_event("upload");
        const size_t w = size_t(plan_.width);
        const size_t stride = mask.row_stride == 0 ? w : mask.row_stride;
        auto* staged = staging_in_.as<unsigned char>();
        for (size_t y = 0; y < size_t(plan_.height); ++y) {
            for (size_t x = 0; x < w; ++x) {
                staged[2 * (y * w + x)] = mask.fillable[y * stride + x];
                staged[2 * (y * w + x) + 1] = mask.valid == nullptr ? 1 : mask.valid[y * stride + x];
            }
        }
        // The pair bytes travel in the points buffer, which a mask frame does not otherwise use.
        copy_in(points_.as<void>(), staged, 2 * plan_.pixel_count());
        const Launch l = linear(pixels());
        pyr_k_bind_mask<<<l.grid, l.block, 0, stream_>>>(ctx_, points_.as<const unsigned char>(), pixels(),
                                                         plan_.full().offset);
        launched("pyr_k_bind_mask");
        from_mask_ = true;
    }

    void begin_pass(const char* pass) override { record_event(pass); }

    void estimate_normals() override {
        const Launch l = planar(width(), height());
        pyr_k_normals<<<l.grid, l.block, 0, stream_>>>(ctx_, height(), uint32_t(plan_.params.normal_radius));
        launched("pyr_k_normals");
    }

    void quantize() override {
        const Launch l = linear(pixels());
        pyr_k_quantize<<<l.grid, l.block, 0, stream_>>>(ctx_, pixels());
        launched("pyr_k_quantize");
    }

    void metric() override {
        const Launch l = planar(width(), height());
        pyr_k_metric<<<l.grid, l.block, 0, stream_>>>(ctx_, height(), plan_.full().offset, plan_.thresholds.curvature,
                                                      plan_.thresholds.depth);
        launched("pyr_k_metric");
    }

    void mip(int parent_level) override {
        const PyrLevel p = plan_.level(parent_level);
        const Launch l = planar(p.width, p.height);
        pyr_k_mip<<<l.grid, l.block, 0, stream_>>>(ctx_, p, plan_.level(parent_level + 1));
        launched("pyr_k_mip");
    }

    void init_labels(int level, uint32_t mode) override {
        const PyrLevel lv = plan_.level(level);
        const PyrLevel parent = level > 1 ? plan_.level(level - 1) : PyrLevel{0, 0, 0};
        const Launch l = planar(lv.width, lv.height);
        pyr_k_init_labels<<<l.grid, l.block, 0, stream_>>>(ctx_, lv, parent, mode);
        launched("pyr_k_init_labels");
    }

    // Rounds of row and column sweeps in growing batches (2, 4, ... 64 rounds). Within a batch, a round after one
    // that changed nothing returns at once on the device; the host reads a batch's flags with one copy and stops
    // after the first batch with a round that changed nothing.
    void fill_to_fixed_point(int level, uint32_t anchor_max) override {
        const PyrLevel lv = plan_.level(level);
        if (anchor_max != 0) {
            const uint32_t count = lv.width * lv.height;
            const Launch l = linear(count);
            pyr_k_anchor<<<l.grid, l.block, 0, stream_>>>(ctx_, lv.offset, count, anchor_max);
            launched("pyr_k_anchor");
        }
        auto* flags = host_flags_.as<uint32_t>();
        for (uint32_t batch = 2;; batch = std::min(kMaxBatch, batch * 2)) {
            check(cudaMemsetAsync(flags_.as<void>(), 0, 4 * size_t(batch), stream_), "cudaMemsetAsync(flags)");
            for (uint32_t slot = 0; slot < batch; ++slot) sweep_round(lv, 0, slot, 0);
            check(cudaMemcpyAsync(flags, flags_.as<void>(), 4 * size_t(batch), cudaMemcpyDeviceToHost, stream_),
                  "cudaMemcpyAsync(flags)");
            check(cudaStreamSynchronize(stream_), "cudaStreamSynchronize(fill)");
            const uint32_t* unchanged = std::find(flags, flags + batch, 0u);
            if (unchanged != flags + batch) {
                fill_rounds_ += uint32_t(unchanged - flags) + 1;
                break;
            }
            fill_rounds_ += batch;
        }
    }

    void fill_once(int level) override { sweep_round(plan_.level(level), 1, 0, 0); }

    void label_edges() override {
        const Launch l = planar(width(), height());
        pyr_k_edges<<<l.grid, l.block, 0, stream_>>>(ctx_, plan_.full());
        launched("pyr_k_edges");
    }

    void compact(bool apply) override {
        const uint32_t count = plan_.lut_size();
        const uint32_t chunks = plan_.scan_chunks();
        check(cudaMemsetAsync(lut_.as<void>(), 0, 4 * size_t(count), stream_), "cudaMemsetAsync(lut)");
        Launch l = linear(pixels());
        pyr_k_lut_mark<<<l.grid, l.block, 0, stream_>>>(ctx_, pixels(), plan_.full().offset);
        launched("pyr_k_lut_mark");
        l = linear(chunks);
        pyr_k_scan_count<<<l.grid, l.block, 0, stream_>>>(ctx_, count, PYR_SCAN_CHUNK, chunks, sums_.as<unsigned>());
        launched("pyr_k_scan_count");
        pyr_k_scan_sums<<<1, 1, 0, stream_>>>(sums_.as<unsigned>(), chunks);
        launched("pyr_k_scan_sums");
        pyr_k_scan_number<<<l.grid, l.block, 0, stream_>>>(ctx_, count, PYR_SCAN_CHUNK, chunks, sums_.as<unsigned>());
        launched("pyr_k_scan_number");
        l = linear(pixels());
        pyr_k_compact<<<l.grid, l.block, 0, stream_>>>(ctx_, pixels(), plan_.full().offset, apply ? 1u : 0u,
                                                       out_.as<unsigned>());
        launched("pyr_k_compact");
        check(cudaMemcpyAsync(host_flags_.as<uint32_t>() + kMaxBatch, sums_.as<uint32_t>() + chunks, 4,
                              cudaMemcpyDeviceToHost, stream_),
              "cudaMemcpyAsync(segment count)");
    }

    // K is known on the device only: all slots are cleared, and read_back fetches the K used.
    void segment_stats() override {
        check(cudaMemsetAsync(stats_.as<void>(), 0, 4 * plan_.stats_words(), stream_), "cudaMemsetAsync(statistics)");
        const uint32_t runs = plan_.stats_runs_per_row() * height();
        const Launch l = linear(runs);
        pyr_k_stats<<<l.grid, l.block, 0, stream_>>>(ctx_, plan_.full(), runs, from_mask_ ? 0u : 1u,
                                                     plan_.stats_point_scale(), plan_.stats_slots);
        launched("pyr_k_stats");
    }

    void read_back(Result& out, const Outputs& outputs) override {
        record_event("download");
        const size_t px = plan_.pixel_count();
        const size_t full = plan_.full().offset;
        using S = core::StagedResults;
        auto* staged = staging_out_.as<unsigned char>();
        copy_out(staged + S::kLabels * px, out_.as<void>(), 4 * px);
        if (outputs.raw_labels) copy_out(staged + S::kRawLabels * px, labels_.as<uint32_t>() + full, 4 * px);
        if (outputs.fillable_mask) copy_out(staged + S::kMask * px, mask_.as<unsigned char>() + full, px);
        if (outputs.normals && !from_mask_) copy_out(staged + S::kNormals * px, normals_.as<void>(), 12 * px);
        record_event(nullptr);
        check(cudaStreamSynchronize(stream_), "cudaStreamSynchronize(frame)");
        out.width = plan_.width;
        out.height = plan_.height;
        out.segment_count = host_flags_.as<uint32_t>()[kMaxBatch];
        core::unstage_results(staged, px, false, outputs, !from_mask_, out);
        out.segments.clear();
        if (plan_.stats_slots != 0) {
            const size_t words = std::min(plan_.stats_words(), size_t(out.segment_count) * PYR_STATS_WORDS);
            copy_out(host_stats_.as<void>(), stats_.as<void>(), 4 * words);
            check(cudaStreamSynchronize(stream_), "cudaStreamSynchronize(statistics)");
            core::decode_segment_stats(host_stats_.as<uint32_t>(), out.segment_count, plan_, !from_mask_, out.segments);
        }
    }

    // The events' times per pass: each pass runs from its event to the next one.
    bool device_timings(std::vector<PassTiming>& timings) override {
        if (event_count_ < 2) return false;
        for (PassTiming& t : timings) t.milliseconds = 0.0;
        for (uint32_t k = 0; k + 1 < event_count_; ++k) {
            float ms = 0.0f;
            check(cudaEventElapsedTime(&ms, events_[k], events_[k + 1]), "cudaEventElapsedTime");
            for (PassTiming& t : timings) {
                if (std::strcmp(t.pass, event_names_[k]) == 0) t.milliseconds += double(ms);
            }
        }
        return true;
    }

private:
    void select() const { check(cudaSetDevice(device_), "cudaSetDevice"); }

    void sweep_round(const PyrLevel& lv, uint32_t once, uint32_t slot, uint32_t first) {
        Launch l = linear(lv.height);
        pyr_k_sweep_rows<<<l.grid, l.block, 0, stream_>>>(ctx_, lv, once, flags_.as<unsigned>(), slot, first);
        launched("pyr_k_sweep_rows");
        l = linear(lv.width);
        pyr_k_sweep_columns<<<l.grid, l.block, 0, stream_>>>(ctx_, lv, once, flags_.as<unsigned>(), slot, first);
        launched("pyr_k_sweep_columns");
    }

    void record_event(const char* name) {
        if (event_count_ == kMaxEvents) return;
        check(cudaEventRecord(events_[event_count_], stream_), "cudaEventRecord");
        event_names_[event_count_++] = name;
    }

    void launched(const char* kernel) const { check(cudaGetLastError(), kernel); }

    void copy_in(void* dst, const void* src, size_t bytes) {
        check(cudaMemcpyAsync(dst, src, bytes, cudaMemcpyHostToDevice, stream_), "cudaMemcpyAsync(upload)");
    }

    void copy_out(void* dst, const void* src, size_t bytes) {
        check(cudaMemcpyAsync(dst, src, bytes, cudaMemcpyDeviceToHost, stream_), "cudaMemcpyAsync(download)");
    }

    void check_fits(size_t pixels, size_t texels) const {
        size_t free_bytes = 0;
        size_t total_bytes = 0;
        check(cudaMemGetInfo(&free_bytes, &total_bytes), "cudaMemGetInfo");
        const size_t needed = 44 * pixels + 5 * texels + 4 * size_t(plan_.lut_size()) + 4 * plan_.stats_words();
        if (needed > free_bytes) {
            throw Error(ErrorCode::out_of_memory,
                        "a " + std::to_string(plan_.width) + " x " + std::to_string(plan_.height) + " image needs " +
                            std::to_string(needed >> 20) + " MiB on CUDA device " + std::to_string(device_) +
                            ", which has " + std::to_string(free_bytes >> 20) + " MiB free");
        }
    }

    [[nodiscard]] uint32_t width() const { return uint32_t(plan_.width); }
    [[nodiscard]] uint32_t height() const { return uint32_t(plan_.height); }
    [[nodiscard]] uint32_t pixels() const { return uint32_t(plan_.pixel_count()); }

    const core::Plan& plan_;
    int device_;
    cudaStream_t stream_ = nullptr;
    Memory<false> points_, normals_, quant_, mask_, labels_, lut_, sums_, flags_, out_, stats_;
    Memory<true> staging_in_, staging_out_, host_flags_, host_stats_;
    PyrCudaCtx ctx_{};
    std::array<cudaEvent_t, kMaxEvents> events_{};
    std::array<const char*, kMaxEvents> event_names_{};
    uint32_t event_count_ = 0;
    bool from_mask_ = false;
    uint32_t fill_rounds_ = 0;
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
    return std::make_unique<CudaExecutor>(plan, int(chosen.value_or(0)));
}

}  // namespace pyrseg::cuda
