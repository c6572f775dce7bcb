#include "backends/opencl/opencl_backend.hpp"

#include <algorithm>
#include <array>
#include <cstring>
#include <string>
#include <utility>
#include <vector>

#include "backends/opencl/opencl_runtime.hpp"
#include "core/segment_stats.hpp"
#include "core/staging.hpp"
#include "pyrseg/error.hpp"
#include "shaders/pyr_types.h"

namespace pyrseg::opencl {
namespace {

using std::size_t;
using std::uint32_t;

constexpr uint32_t kMaxBatch = 64;  // fill iterations between two reads of the convergence flags

// The kernels, in one place: their names and the per-dispatch argument count after the shared context.
enum Kernel : size_t {
    kNormals,
    kQuantize,
    kMetric,
    kBindMask,
    kMip,
    kInitLabels,
    kAnchor,
    kSweepRows,
    kSweepColumns,
    kEdges,
    kLutClear,
    kLutMark,
    kScanCount,
    kScanSums,
    kScanNumber,
    kCompact,
    kStats,
    kKernelCount
};
constexpr std::array<const char*, kKernelCount> kKernelNames = {
    "pyr_k_normals",     "pyr_k_quantize", "pyr_k_metric",     "pyr_k_bind_mask",     "pyr_k_mip",
    "pyr_k_init_labels", "pyr_k_anchor",   "pyr_k_sweep_rows", "pyr_k_sweep_columns", "pyr_k_edges",
    "pyr_k_lut_clear",   "pyr_k_lut_mark", "pyr_k_scan_count", "pyr_k_scan_sums",     "pyr_k_scan_number",
    "pyr_k_compact",     "pyr_k_stats"};
constexpr cl_uint kContextArgs = 7;  // PYR_CTX_PARAM in shaders/pyr_opencl.cl

class Buffer {
public:
    Buffer() = default;
    Buffer(cl_context context, size_t bytes, const char* what) {
        cl_int err = CL_SUCCESS;
        mem_ = clCreateBuffer(context, CL_MEM_READ_WRITE, std::max<size_t>(bytes, 4), nullptr, &err);
        check(err, what);
    }
    ~Buffer() {
        if (mem_ != nullptr) clReleaseMemObject(mem_);
    }
    Buffer(Buffer&& o) noexcept : mem_(std::exchange(o.mem_, nullptr)) {}
    Buffer& operator=(Buffer&& o) noexcept {
        std::swap(mem_, o.mem_);
        return *this;
    }
    Buffer(const Buffer&) = delete;
    Buffer& operator=(const Buffer&) = delete;
    [[nodiscard]] cl_mem get() const { return mem_; }

private:
    cl_mem mem_ = nullptr;
};

size_t round_up(size_t v, size_t m) {
    return (v + m - 1) / m * m;
}

class OpenclExecutor final : public core::PassExecutor {
public:
    OpenclExecutor(const core::Plan& plan, std::shared_ptr<const Runtime> runtime)
        : plan_(plan), rt_(std::move(runtime)) {
        const size_t pixels = plan.pixel_count();
        check_fits(pixels);
        cl_int err = CL_SUCCESS;
        queue_ = clCreateCommandQueue(rt_->context, rt_->device, 0, &err);
        check(err, "clCreateCommandQueue");
        points_ = Buffer(rt_->context, 3 * pixels * sizeof(float), "clCreateBuffer(points)");
        normals_ = Buffer(rt_->context, 3 * pixels * sizeof(float), "clCreateBuffer(normals)");
        quant_ = Buffer(rt_->context, 4 * pixels * sizeof(cl_int), "clCreateBuffer(quant)");
        mask_ = Buffer(rt_->context, size_t(plan.total_texels), "clCreateBuffer(mask)");
        labels_ = Buffer(rt_->context, size_t(plan.total_texels) * sizeof(cl_uint), "clCreateBuffer(labels)");
        // The statistics words, when asked for, follow the label table (shaders/pyr_opencl.cl).
        lut_ = Buffer(rt_->context, (plan_.lut_size() + plan_.stats_words()) * sizeof(cl_uint), "clCreateBuffer(lut)");
        sums_ = Buffer(rt_->context, (plan_.scan_chunks() + 1) * sizeof(cl_uint), "clCreateBuffer(scan sums)");
        flags_ = Buffer(rt_->context, kMaxBatch * sizeof(cl_int), "clCreateBuffer(flags)");
        out_ = Buffer(rt_->context, pixels * sizeof(cl_uint), "clCreateBuffer(labels out)");
        for (size_t k = 0; k < kKernelCount; ++k) {
            kernels_[k] = clCreateKernel(rt_->program, kKernelNames[k], &err);
            check(err, kKernelNames[k]);
            if (k == kScanSums) continue;  // the only kernel without the shared context
            const std::array<cl_mem, 6> ctx = {points_.get(), normals_.get(), quant_.get(),
                                               mask_.get(),   labels_.get(),  lut_.get()};
            for (cl_uint a = 0; a < ctx.size(); ++a)
                check(clSetKernelArg(kernels_[k], a, sizeof(cl_mem), &ctx[a]), "clSetKernelArg");
            const cl_uint w = cl_uint(plan.width);
            check(clSetKernelArg(kernels_[k], 6, sizeof(w), &w), "clSetKernelArg(width)");
        }
        host_flags_.resize(kMaxBatch);
        host_stats_.resize(plan_.stats_words());
    }

    ~OpenclExecutor() override {
        for (cl_kernel k : kernels_) {
            if (k != nullptr) clReleaseKernel(k);
        }
        if (queue_ != nullptr) clReleaseCommandQueue(queue_);
    }

    [[nodiscard]] uint32_t fill_rounds() const override { return fill_rounds_; }

    void bind_cloud(const CloudView& cloud) override {
        fill_rounds_ = 0;
        upload(cloud, cloud.points, points_, host_points_);
        normals_given_ = cloud.normals != nullptr;
        if (normals_given_) upload(cloud, cloud.normals, normals_, host_normals_);
        from_mask_ = false;
    }

    void bind_mask(const MaskView& mask) override {
        fill_rounds_ = 0;
        const size_t w = size_t(plan_.width);
        const size_t stride = mask.row_stride == 0 ? w : mask.row_stride;
        if (host_mask_.empty()) {
            host_mask_.resize(2 * plan_.pixel_count());  // once per Segmenter
            staging_ = Buffer(rt_->context, host_mask_.size(), "clCreateBuffer(mask staging)");
        }
        for (size_t y = 0; y < size_t(plan_.height); ++y) {
            for (size_t x = 0; x < w; ++x) {
                host_mask_[2 * (y * w + x)] = mask.fillable[y * stride + x];
                host_mask_[2 * (y * w + x) + 1] = mask.valid == nullptr ? 1 : mask.valid[y * stride + x];
            }
        }
        check(clEnqueueWriteBuffer(queue_, staging_.get(), CL_TRUE, 0, host_mask_.size(), host_mask_.data(), 0, nullptr,
                                   nullptr),
              "clEnqueueWriteBuffer(mask)");
        const cl_mem staging = staging_.get();
        run_1d(kBindMask, plan_.pixel_count(), arg(staging), arg(cl_uint(plan_.pixel_count())),
               arg(plan_.full().offset));
        from_mask_ = true;
        finish();
    }

    void estimate_normals() override {
        run_2d(kNormals, plan_.width, plan_.height, arg(cl_uint(plan_.height)),
               arg(cl_uint(plan_.params.normal_radius)));
        finish();
    }

    void quantize() override {
        run_1d(kQuantize, plan_.pixel_count(), arg(cl_uint(plan_.pixel_count())));
        finish();
    }

    void metric() override {
        const core::Thresholds t = plan_.thresholds;
        run_2d(kMetric, plan_.width, plan_.height, arg(cl_uint(plan_.height)), arg(plan_.full().offset),
               arg(cl_int(t.curvature)), arg(cl_float(t.depth)));
        finish();
    }

    void mip(int parent_level) override {
        const PyrLevel p = plan_.level(parent_level);
        const PyrLevel c = plan_.level(parent_level + 1);
        run_2d(kMip, p.width, p.height, arg(p.width), arg(p.height), arg(p.offset), arg(c.width), arg(c.height),
               arg(c.offset));
        finish();
    }

    void init_labels(int level, uint32_t mode) override {
        const PyrLevel l = plan_.level(level);
        const PyrLevel p = level > 1 ? plan_.level(level - 1) : PyrLevel{0, 0, 0};
        run_2d(kInitLabels, l.width, l.height, arg(l.width), arg(l.height), arg(l.offset), arg(p.width), arg(p.height),
               arg(p.offset), arg(cl_uint(mode)));
        finish();
    }

    // Rounds of row and column sweeps until one changes nothing. Each round of a batch sets its own flag; the flags
    // are read once per batch, and batches grow, so a long convergence costs few reads.
    void fill_to_fixed_point(int level, uint32_t anchor_max) override {
        const PyrLevel l = plan_.level(level);
        if (anchor_max != 0) {
            const size_t count = size_t(l.width) * l.height;
            run_1d(kAnchor, count, arg(l.offset), arg(cl_uint(count)), arg(cl_uint(anchor_max)));
        }
        for (uint32_t batch = 2;; batch = std::min(kMaxBatch, batch * 2)) {
            const cl_int zero = 0;
            check(clEnqueueFillBuffer(queue_, flags_.get(), &zero, sizeof(zero), 0, batch * sizeof(cl_int), 0, nullptr,
                                      nullptr),
                  "clEnqueueFillBuffer(flags)");
            for (uint32_t slot = 0; slot < batch; ++slot) sweep_round(l, 0, slot);
            check(clEnqueueReadBuffer(queue_, flags_.get(), CL_TRUE, 0, batch * sizeof(cl_int), host_flags_.data(), 0,
                                      nullptr, nullptr),
                  "clEnqueueReadBuffer(flags)");
            const auto unchanged = std::find(host_flags_.begin(), host_flags_.begin() + batch, 0);
            if (unchanged != host_flags_.begin() + batch) {
                fill_rounds_ += uint32_t(unchanged - host_flags_.begin()) + 1;
                break;
            }
            fill_rounds_ += batch;
        }
        finish();
    }

    void fill_once(int level) override {
        sweep_round(plan_.level(level), 1, 0);
        finish();
    }

    void label_edges() override {
        run_2d(kEdges, plan_.width, plan_.height, arg(cl_uint(plan_.height)), arg(plan_.full().offset));
        finish();
    }

    void compact(bool apply) override {
        const cl_uint count = cl_uint(plan_.lut_size());
        const cl_uint chunk = PYR_SCAN_CHUNK;
        const cl_uint chunks = cl_uint(plan_.scan_chunks());
        const cl_uint pixels = cl_uint(plan_.pixel_count());
        const cl_mem sums = sums_.get();
        run_1d(kLutClear, count, arg(count));
        run_1d(kLutMark, pixels, arg(pixels), arg(plan_.full().offset));
        run_1d(kScanCount, chunks, arg(count), arg(chunk), arg(sums));
        // OpenCL takes a buffer argument as the cl_mem handle's bytes.
        check(clSetKernelArg(kernels_[kScanSums], 0, sizeof(sums), &sums),  // NOLINT(bugprone-sizeof-expression)
              "clSetKernelArg");
        check(clSetKernelArg(kernels_[kScanSums], 1, sizeof(chunks), &chunks), "clSetKernelArg");
        enqueue(kScanSums, 1, std::array<size_t, 2>{1, 1}.data(), nullptr);
        run_1d(kScanNumber, chunks, arg(count), arg(chunk), arg(sums));
        run_1d(kCompact, pixels, arg(pixels), arg(plan_.full().offset), arg(cl_uint(apply ? 1 : 0)), arg(out_.get()));
        check(clEnqueueReadBuffer(queue_, sums_.get(), CL_TRUE, chunks * sizeof(cl_uint), sizeof(cl_uint),
                                  &segment_count_, 0, nullptr, nullptr),
              "clEnqueueReadBuffer(segment count)");
        finish();
    }

    void segment_stats() override {
        const size_t base = plan_.lut_size();
        const size_t words = std::min(plan_.stats_words(), size_t(segment_count_) * PYR_STATS_WORDS);
        const cl_uint zero = 0;
        if (words != 0) {
            check(clEnqueueFillBuffer(queue_, lut_.get(), &zero, sizeof(zero), base * sizeof(cl_uint),
                                      words * sizeof(cl_uint), 0, nullptr, nullptr),
                  "clEnqueueFillBuffer(statistics)");
        }
        const cl_uint runs = plan_.stats_runs_per_row() * cl_uint(plan_.height);
        run_1d(kStats, runs, arg(cl_uint(plan_.height)), arg(plan_.full().offset), arg(runs),
               arg(cl_uint(from_mask_ ? 0 : 1)), arg(cl_float(plan_.stats_point_scale())), arg(cl_uint(base)),
               arg(plan_.stats_slots));
        finish();
    }

    void read_back(Result& out, const Outputs& outputs) override {
        const size_t pixels = plan_.pixel_count();
        out.width = plan_.width;
        out.height = plan_.height;
        out.segment_count = segment_count_;
        out.labels.resize(pixels);
        read(out_, 0, pixels * sizeof(cl_uint), out.labels.data(), "labels");
        if (outputs.raw_labels) {
            out.raw_labels.resize(pixels);
            read(labels_, size_t(plan_.full().offset) * sizeof(cl_uint), pixels * sizeof(cl_uint),
                 out.raw_labels.data(), "raw labels");
        } else {
            out.raw_labels.clear();
        }
        if (outputs.fillable_mask) {
            out.fillable_mask.resize(pixels);
            read(mask_, plan_.full().offset, pixels, out.fillable_mask.data(), "fillable mask");
        } else {
            out.fillable_mask.clear();
        }
        out.normals.clear();
        if (outputs.normals && !from_mask_) {
            out.normals.resize(3 * pixels);
            read(normals_, 0, 3 * pixels * sizeof(float), out.normals.data(), "normals");
        }
        out.segments.clear();
        if (plan_.stats_slots != 0) {
            const size_t words = std::min(host_stats_.size(), size_t(segment_count_) * PYR_STATS_WORDS);
            if (words != 0)
                read(lut_, plan_.lut_size() * sizeof(cl_uint), words * sizeof(cl_uint), host_stats_.data(),
                     "statistics");
            core::decode_segment_stats(host_stats_.data(), segment_count_, plan_, !from_mask_, out.segments);
        }
    }

private:
    // An argument for run_1d/run_2d: its bytes, set right after the shared context arguments.
    struct Arg {
        size_t size;
        std::array<unsigned char, 16> bytes;  // the largest argument passed is a cl_mem
    };
    template <class T>
    static Arg arg(T value) {
        // T may be cl_mem, an opaque pointer passed by its bytes: sizeof is intended.
        static_assert(sizeof(T) <= sizeof(Arg::bytes));  // NOLINT(bugprone-sizeof-expression)
        Arg a{sizeof(T), {}};                            // NOLINT(bugprone-sizeof-expression)
        std::memcpy(a.bytes.data(), &value, sizeof(T));  // NOLINT(bugprone-sizeof-expression)
        return a;
    }

    template <class... Args>
    void set_args(Kernel k, const Args&... args) {
        cl_uint index = kContextArgs;
        (check(clSetKernelArg(kernels_[k], index++, args.size, args.bytes.data()), kKernelNames[k]), ...);
    }

    template <class... Args>
    void run_1d(Kernel k, size_t count, const Args&... args) {
        if (count == 0) return;
        set_args(k, args...);
        const size_t local = 64;
        const std::array<size_t, 2> global = {round_up(count, local), 1};
        const std::array<size_t, 2> local_size = {local, 1};
        enqueue(k, 1, global.data(), local_size.data());
    }

    template <class... Args>
    void run_2d(Kernel k, uint32_t width, uint32_t height, const Args&... args) {
        if (width == 0 || height == 0) return;
        set_args(k, args...);
        const std::array<size_t, 2> local = {8, 8};
        const std::array<size_t, 2> global = {round_up(width, local[0]), round_up(height, local[1])};
        enqueue(k, 2, global.data(), local.data());
    }

    template <class... Args>
    void run_2d(Kernel k, int width, int height, const Args&... args) {
        run_2d(k, uint32_t(width), uint32_t(height), args...);
    }

    void enqueue(Kernel k, cl_uint dims, const size_t* global, const size_t* local) {
        // A device may allow fewer work-items per group than the fixed sizes ask: then the runtime chooses.
        if (local != nullptr && (dims == 1 ? local[0] : local[0] * local[1]) > max_group(k)) local = nullptr;
        check(clEnqueueNDRangeKernel(queue_, kernels_[k], dims, nullptr, global, local, 0, nullptr, nullptr),
              kKernelNames[k]);
    }

    size_t max_group(Kernel k) {
        if (group_limits_[k] == 0) {
            size_t size = 1;
            clGetKernelWorkGroupInfo(kernels_[k], rt_->device, CL_KERNEL_WORK_GROUP_SIZE, sizeof(size), &size, nullptr);
            group_limits_[k] = size;
        }
        return group_limits_[k];
    }

    void sweep_round(const PyrLevel& l, cl_uint once, cl_uint slot) {
        const cl_mem flags = flags_.get();
        run_1d(kSweepRows, l.height, arg(l.width), arg(l.height), arg(l.offset), arg(once), arg(flags), arg(slot));
        run_1d(kSweepColumns, l.width, arg(l.width), arg(l.height), arg(l.offset), arg(once), arg(flags), arg(slot));
    }

    // Packed clouds are written straight from the caller's memory; strided ones through a staging copy made
    // once per Segmenter.
    void upload(const CloudView& cloud, const float* data, const Buffer& buffer, std::vector<float>& staging) {
        const size_t w = size_t(plan_.width);
        const size_t h = size_t(plan_.height);
        const float* src = data;
        if (!core::is_packed_xyz(cloud)) {
            if (staging.empty()) staging.resize(3 * w * h);
            core::pack_xyz(cloud, data, staging.data());
            src = staging.data();
        }
        check(
            clEnqueueWriteBuffer(queue_, buffer.get(), CL_TRUE, 0, 3 * w * h * sizeof(float), src, 0, nullptr, nullptr),
            "clEnqueueWriteBuffer(cloud)");
    }

    void read(const Buffer& buffer, size_t offset, size_t bytes, void* dst, const char* what) {
        const cl_int err = clEnqueueReadBuffer(queue_, buffer.get(), CL_TRUE, offset, bytes, dst, 0, nullptr, nullptr);
        if (err != CL_SUCCESS) fail(err, (std::string("clEnqueueReadBuffer(") + what + ")").c_str());
    }

    // Every pass ends with the queue drained, so that the pipeline's per-pass host timings are the passes' times.
    void finish() { check(clFinish(queue_), "clFinish"); }

    void check_fits(size_t pixels) const {
        const size_t largest = std::max({3 * pixels * sizeof(float), 4 * pixels * sizeof(cl_int),
                                         size_t(plan_.total_texels) * sizeof(cl_uint),
                                         (plan_.lut_size() + plan_.stats_words()) * sizeof(cl_uint)});
        const size_t total = 6 * pixels * sizeof(float) + 4 * pixels * sizeof(cl_int) + pixels * sizeof(cl_uint) +
                             size_t(plan_.total_texels) * (1 + sizeof(cl_uint)) +
                             (plan_.lut_size() + plan_.stats_words()) * sizeof(cl_uint);
        const auto mib = [](size_t b) { return std::to_string(b >> 20) + " MiB"; };
        if (largest > rt_->max_alloc || total > rt_->global_mem) {
            throw Error(ErrorCode::out_of_memory,
                        "a " + std::to_string(plan_.width) + " x " + std::to_string(plan_.height) + " image needs " +
                            mib(total) + " in buffers of up to " + mib(largest) + " on " + rt_->description +
                            ", which has " + mib(rt_->global_mem) + " with buffers of up to " + mib(rt_->max_alloc));
        }
    }

    const core::Plan& plan_;
    std::shared_ptr<const Runtime> rt_;
    cl_command_queue queue_ = nullptr;
    std::array<cl_kernel, kKernelCount> kernels_{};
    std::array<size_t, kKernelCount> group_limits_{};
    Buffer points_, normals_, quant_, mask_, labels_, lut_, sums_, flags_, out_, staging_;
    std::vector<float> host_points_, host_normals_;  // staging for strided clouds
    std::vector<unsigned char> host_mask_;
    std::vector<cl_int> host_flags_;
    std::vector<cl_uint> host_stats_;
    cl_uint segment_count_ = 0;
    uint32_t fill_rounds_ = 0;
    bool normals_given_ = false;
    bool from_mask_ = false;
};

}  // namespace

std::unique_ptr<core::PassExecutor> make_executor(const core::Plan& plan) {
    return std::make_unique<OpenclExecutor>(plan, runtime_for(choose_device()));
}

std::vector<std::string> describe_devices(std::string* why_none) {
    std::vector<std::string> out;
    for (const DeviceRef& d : enumerate_devices(why_none)) out.push_back(d.description);
    return out;
}

}  // namespace pyrseg::opencl
