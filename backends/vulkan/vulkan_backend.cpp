#include "backends/vulkan/vulkan_backend.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <chrono>
#include <cstring>
#include <initializer_list>
#include <string>
#include <utility>

#include "backends/vulkan/vulkan_buffer.hpp"
#include "backends/vulkan/vulkan_runtime.hpp"
#include "core/segment_stats.hpp"
#include "core/staging.hpp"
#include "pyrseg/error.hpp"
#include "shaders/pyr_types.h"

namespace pyrseg::vulkan {
namespace {

using std::size_t;
using std::uint32_t;

constexpr uint32_t kGroup1D = 64;        // PYR_GROUP_1D in shaders/pyr_vulkan.comp
constexpr uint32_t kGroup2D = 8;         // PYR_GROUP_2D
constexpr uint32_t kFillsPerFrame = 2;   // steps 2 and 4 (or the small-image fallback's one)
constexpr uint32_t kFirstBudget = 8;     // fill rounds recorded per fill until a frame needs more
constexpr size_t kMaxOps = 128;          // commands of one frame, kept to record it again
constexpr uint32_t kMaxTimestamps = 64;  // pass boundaries per frame

enum Binding : uint32_t { kPoints, kNormalsBuf, kQuant, kMask, kLabels, kLut, kSums, kFlags, kOut };

double ms_since(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

// One command of a frame, as the pipeline asked for it. A frame whose fills did not converge within the recorded
// rounds is recorded again from these with more rounds.
struct Op {
    enum Kind {
        upload_cloud,
        upload_mask,
        pass_start,
        normals,
        quantize,
        metric,
        mip,
        init_labels,
        fill,
        fill_once,
        edges,
        compact,
        stats
    } kind = upload_cloud;
    uint32_t a = 0;
    uint32_t b = 0;
    const char* name = nullptr;
};

class VulkanExecutor final : public core::PassExecutor {
public:
    VulkanExecutor(const core::Plan& plan, std::shared_ptr<Runtime> runtime) : plan_(plan), rt_(std::move(runtime)) {
        check_limits();
        const VkDeviceSize pixels = plan.pixel_count();
        const VkDeviceSize texels = plan.total_texels;
        using M = VulkanBuffer::Memory;
        buffers_[kPoints] = VulkanBuffer(*rt_, 12 * pixels, M::device, "the points buffer");
        buffers_[kNormalsBuf] = VulkanBuffer(*rt_, 12 * pixels, M::device, "the normals buffer");
        buffers_[kQuant] = VulkanBuffer(*rt_, 16 * pixels, M::device, "the quantized-normals buffer");
        buffers_[kMask] = VulkanBuffer(*rt_, 4 * texels, M::device, "the mask pyramid");
        buffers_[kLabels] = VulkanBuffer(*rt_, 4 * texels, M::device, "the label pyramid");
        buffers_[kLut] = VulkanBuffer(*rt_, 4 * lut_words(), M::device, "the compaction table and statistics");
        buffers_[kSums] = VulkanBuffer(*rt_, 4 * (VkDeviceSize(plan_.scan_chunks()) + 1), M::device, "the scan sums");
        buffers_[kOut] = VulkanBuffer(*rt_, 4 * pixels, M::device, "the labels output");
        upload_ = VulkanBuffer(*rt_, 24 * pixels, M::host, "the upload staging buffer");
        download_ =
            VulkanBuffer(*rt_, core::StagedResults::kBytesPerPixel * pixels, M::host, "the download staging buffer");
        if (plan_.stats_slots != 0) {
            stats_download_ =
                VulkanBuffer(*rt_, 4 * VkDeviceSize(plan_.stats_words()), M::host, "the statistics staging buffer");
        }
        create_command_objects();
        size_flags(kFirstBudget);
        throw_on_validation_messages("the creation of a Vulkan Segmenter");
    }

    ~VulkanExecutor() override {
        const VkDevice d = rt_->device;
        if (in_flight_) vkWaitForFences(d, 1, &fence_, VK_TRUE, UINT64_MAX);
        if (fence_ != VK_NULL_HANDLE) vkDestroyFence(d, fence_, nullptr);
        if (query_pool_ != VK_NULL_HANDLE) vkDestroyQueryPool(d, query_pool_, nullptr);
        if (command_pool_ != VK_NULL_HANDLE) vkDestroyCommandPool(d, command_pool_, nullptr);
        if (descriptor_pool_ != VK_NULL_HANDLE) vkDestroyDescriptorPool(d, descriptor_pool_, nullptr);
    }

    VulkanExecutor(const VulkanExecutor&) = delete;
    VulkanExecutor& operator=(const VulkanExecutor&) = delete;

    void bind_cloud(const CloudView& cloud) override {
        start_frame();
        const auto start = std::chrono::steady_clock::now();
        auto* staging = static_cast<float*>(upload_.mapped());
        core::pack_xyz(cloud, cloud.points, staging);
        normals_given_ = cloud.normals != nullptr;
        if (normals_given_) core::pack_xyz(cloud, cloud.normals, staging + 3 * plan_.pixel_count());
        from_mask_ = false;
        host_upload_ms_ = ms_since(start);
        push({Op::upload_cloud, normals_given_ ? 1u : 0u});
    }

    void bind_mask(const MaskView& mask) override {
        start_frame();
        const auto start = std::chrono::steady_clock::now();
        const size_t w = size_t(plan_.width);
        const size_t stride = mask.row_stride == 0 ? w : mask.row_stride;
        auto* staging = static_cast<uint32_t*>(upload_.mapped());
        for (size_t y = 0; y < size_t(plan_.height); ++y) {
            for (size_t x = 0; x < w; ++x) {
                const bool fillable = mask.fillable[y * stride + x] != 0;
                const bool valid = mask.valid == nullptr || mask.valid[y * stride + x] != 0;
                staging[y * w + x] = (fillable ? 1u : 0u) | (valid ? 2u : 0u);
            }
        }
        from_mask_ = true;
        host_upload_ms_ = ms_since(start);
        push({Op::upload_mask});
    }

    void begin_pass(const char* pass) override { push({Op::pass_start, 0, 0, pass}); }
    void estimate_normals() override { push({Op::normals}); }
    void quantize() override { push({Op::quantize}); }
    void metric() override { push({Op::metric}); }
    void mip(int parent_level) override { push({Op::mip, uint32_t(parent_level)}); }
    void init_labels(int level, uint32_t mode) override { push({Op::init_labels, uint32_t(level), mode}); }
    void fill_to_fixed_point(int level, uint32_t anchor_max) override { push({Op::fill, uint32_t(level), anchor_max}); }
    void fill_once(int level) override { push({Op::fill_once, uint32_t(level)}); }
    void label_edges() override { push({Op::edges}); }
    void compact(bool apply) override { push({Op::compact, apply ? 1u : 0u}); }
    void segment_stats() override { push({Op::stats}); }

    // Runs the frame: one submission, unless a fill needed more rounds than were recorded; then the frame is
    // recorded again with twice the rounds (kept for the frames after) and run again.
    void read_back(Result& out, const Outputs& outputs) override {
        for (;;) {
            record_download(outputs);
            submit_and_wait();
            throw_on_validation_messages("a frame");
            if (fills_converged()) break;
            size_flags(fill_budget_ * 2);
            start_commands();
            for (size_t k = 0; k < op_count_; ++k) record(ops_[k]);
        }
        const auto start = std::chrono::steady_clock::now();
        const size_t pixels = plan_.pixel_count();
        const auto* staged = static_cast<const unsigned char*>(download_.mapped());
        const auto* readback = static_cast<const uint32_t*>(readback_.mapped());
        out.width = plan_.width;
        out.height = plan_.height;
        out.segment_count = readback[0];
        core::unstage_results(staged, pixels, true, outputs, !from_mask_, out);
        out.segments.clear();
        if (plan_.stats_slots != 0) {
            download_statistics(out.segment_count);
            core::decode_segment_stats(static_cast<const uint32_t*>(stats_download_.mapped()), out.segment_count, plan_,
                                       !from_mask_, out.segments);
        }
        host_download_ms_ = ms_since(start);
    }

    // The device's timestamps per pass; upload and download add the host's copies to and from staging memory.
    bool device_timings(std::vector<PassTiming>& timings) override {
        if (!rt_->timestamps || timestamp_count_ < 2) return false;
        std::array<std::uint64_t, kMaxTimestamps> ticks{};
        check(vkGetQueryPoolResults(rt_->device, query_pool_, 0, timestamp_count_, sizeof(ticks), ticks.data(),
                                    sizeof(std::uint64_t), VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT),
              "vkGetQueryPoolResults");
        for (PassTiming& t : timings) {
            t.milliseconds = std::strcmp(t.pass, "upload") == 0     ? host_upload_ms_
                             : std::strcmp(t.pass, "download") == 0 ? host_download_ms_
                                                                    : 0.0;
        }
        const double ms_per_tick = double(rt_->properties.limits.timestampPeriod) * 1e-6;
        for (uint32_t k = 0; k + 1 < timestamp_count_; ++k) {
            for (PassTiming& t : timings) {
                if (std::strcmp(t.pass, timestamp_names_[k]) == 0) {
                    t.milliseconds += double(ticks[k + 1] - ticks[k]) * ms_per_tick;
                }
            }
        }
        return true;
    }

private:
    // --- frames and commands ---

    void start_frame() {
        op_count_ = 0;
        start_commands();
    }

    void start_commands() {
        check(vkResetCommandBuffer(commands_, 0), "vkResetCommandBuffer");
        auto begin = make_info<VkCommandBufferBeginInfo>(VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO);
        begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
        check(vkBeginCommandBuffer(commands_, &begin), "vkBeginCommandBuffer");
        if (rt_->timestamps) vkCmdResetQueryPool(commands_, query_pool_, 0, kMaxTimestamps);
        vkCmdBindDescriptorSets(commands_, VK_PIPELINE_BIND_POINT_COMPUTE, rt_->pipeline_layout, 0, 1, &descriptor_set_,
                                0, nullptr);
        fills_in_frame_ = 0;
        timestamp_count_ = 0;
        timestamp("upload");
    }

    void push(const Op& op) {
        if (op_count_ == kMaxOps) throw Error(ErrorCode::internal, "Vulkan: more commands in one frame than expected");
        ops_[op_count_++] = op;
        record(op);
    }

    void record(const Op& op) {
        switch (op.kind) {
            case Op::upload_cloud: {
                const VkDeviceSize bytes = 12 * VkDeviceSize(plan_.pixel_count());
                copy(upload_.get(), 0, buffers_[kPoints].get(), 0, bytes);
                if (op.a != 0) copy(upload_.get(), bytes, buffers_[kNormalsBuf].get(), 0, bytes);
                barrier(VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT);
                break;
            }
            case Op::upload_mask:
                copy(upload_.get(), 0, buffers_[kPoints].get(), 0, 4 * VkDeviceSize(plan_.pixel_count()));
                barrier(VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT);
                dispatch_1d(kBindMask, pixels(), {pixels(), plan_.full().offset});
                break;
            case Op::pass_start:
                timestamp(op.name);
                break;
            case Op::normals:
                dispatch_2d(kNormals, width(), height(), {height(), uint32_t(plan_.params.normal_radius)});
                break;
            case Op::quantize:
                dispatch_1d(kQuantize, pixels(), {pixels()});
                break;
            case Op::metric:
                dispatch_2d(kMetric, width(), height(),
                            {height(), plan_.full().offset, std::bit_cast<uint32_t>(plan_.thresholds.curvature),
                             std::bit_cast<uint32_t>(plan_.thresholds.depth)});
                break;
            case Op::mip: {
                const PyrLevel p = plan_.level(int(op.a));
                const PyrLevel c = plan_.level(int(op.a) + 1);
                dispatch_2d(kMip, p.width, p.height, {p.width, p.height, p.offset, c.width, c.height, c.offset});
                break;
            }
            case Op::init_labels: {
                const PyrLevel l = plan_.level(int(op.a));
                const PyrLevel p = op.a > 1 ? plan_.level(int(op.a) - 1) : PyrLevel{0, 0, 0};
                dispatch_2d(kInitLabels, l.width, l.height,
                            {l.width, l.height, l.offset, p.width, p.height, p.offset, op.b});
                break;
            }
            case Op::fill:
                record_fill(plan_.level(int(op.a)), op.b);
                break;
            case Op::fill_once: {
                const PyrLevel l = plan_.level(int(op.a));
                const uint32_t scratch = kFillsPerFrame * fill_budget_;  // a slot nobody reads
                sweep_round(l, 1, scratch, scratch);
                break;
            }
            case Op::edges:
                dispatch_2d(kEdges, width(), height(), {height(), plan_.full().offset});
                break;
            case Op::compact:
                record_compact(op.a);
                break;
            case Op::stats:
                vkCmdFillBuffer(commands_, buffers_[kLut].get(), 4 * VkDeviceSize(plan_.lut_size()),
                                4 * VkDeviceSize(plan_.stats_words()), 0);
                barrier(VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT);
                dispatch_1d(kStats, stats_runs(),
                            {height(), plan_.full().offset, stats_runs(), from_mask_ ? 0u : 1u,
                             std::bit_cast<uint32_t>(plan_.stats_point_scale()), plan_.lut_size(), plan_.stats_slots});
                break;
        }
    }

    // Steps 2 and 4: fill_budget_ rounds of row and column sweeps. Round r sets flags[first + r] when it changed a
    // label and is skipped on the device when round r - 1 changed nothing; the host reads the flags after the frame.
    void record_fill(const PyrLevel& l, uint32_t anchor_max) {
        if (fills_in_frame_ == kFillsPerFrame) throw Error(ErrorCode::internal, "Vulkan: more fills than expected");
        if (anchor_max != 0) {
            const uint32_t count = l.width * l.height;
            dispatch_1d(kAnchor, count, {l.offset, count, anchor_max});
        }
        const uint32_t first = fills_in_frame_++ * fill_budget_;
        vkCmdFillBuffer(commands_, buffers_[kFlags].get(), 4 * VkDeviceSize(first), 4 * VkDeviceSize(fill_budget_), 0);
        barrier(VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT);
        for (uint32_t r = 0; r < fill_budget_; ++r) sweep_round(l, 0, first + r, first);
    }

    void sweep_round(const PyrLevel& l, uint32_t once, uint32_t slot, uint32_t first) {
        dispatch_1d(kSweepRows, l.height, {l.width, l.height, l.offset, once, slot, first});
        dispatch_1d(kSweepColumns, l.width, {l.width, l.height, l.offset, once, slot, first});
    }

    // Step 7: mark the labels present, number the marks by a chunked scan (K lands after the chunk sums), map.
    void record_compact(uint32_t apply) {
        const uint32_t count = plan_.lut_size();
        const uint32_t chunks = plan_.scan_chunks();
        vkCmdFillBuffer(commands_, buffers_[kLut].get(), 0, 4 * VkDeviceSize(count), 0);
        barrier(VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT);
        dispatch_1d(kLutMark, pixels(), {pixels(), plan_.full().offset});
        dispatch_1d(kScanCount, chunks, {count, PYR_SCAN_CHUNK, chunks});
        dispatch_1d(kScanSums, 1, {chunks});
        dispatch_1d(kScanNumber, chunks, {count, PYR_SCAN_CHUNK, chunks});
        dispatch_1d(kCompact, pixels(), {pixels(), plan_.full().offset, apply});
    }

    // The results into staging memory: labels, then (as asked) raw labels, mask and normals at fixed offsets; K
    // and the fill flags into the small readback buffer.
    void record_download(const Outputs& outputs) {
        timestamp("download");
        using S = core::StagedResults;
        const VkDeviceSize px = pixels();
        const VkDeviceSize full = plan_.full().offset;
        const VkBuffer staged = download_.get();
        copy(buffers_[kOut].get(), 0, staged, S::kLabels * px, 4 * px);
        if (outputs.raw_labels) copy(buffers_[kLabels].get(), 4 * full, staged, S::kRawLabels * px, 4 * px);
        if (outputs.fillable_mask) copy(buffers_[kMask].get(), 4 * full, staged, S::kMask * px, 4 * px);
        if (outputs.normals && !from_mask_) copy(buffers_[kNormalsBuf].get(), 0, staged, S::kNormals * px, 12 * px);
        copy(buffers_[kSums].get(), 4 * VkDeviceSize(plan_.scan_chunks()), readback_.get(), 0, 4);
        copy(buffers_[kFlags].get(), 0, readback_.get(), 4, 4 * VkDeviceSize(kFillsPerFrame) * fill_budget_);
        to_host_barrier();
        timestamp(nullptr);  // the end of the last interval
        check(vkEndCommandBuffer(commands_), "vkEndCommandBuffer");
    }

    // The K slots the frame used, in a second small submission once K is known (the whole table of slots can be
    // far larger than what a frame fills).
    void download_statistics(uint32_t segments) {
        const VkDeviceSize bytes =
            4 * VkDeviceSize(std::min<size_t>(plan_.stats_words(), size_t(segments) * PYR_STATS_WORDS));
        if (bytes == 0) return;
        check(vkResetCommandBuffer(commands_, 0), "vkResetCommandBuffer");
        auto begin = make_info<VkCommandBufferBeginInfo>(VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO);
        begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
        check(vkBeginCommandBuffer(commands_, &begin), "vkBeginCommandBuffer");
        copy(buffers_[kLut].get(), 4 * VkDeviceSize(plan_.lut_size()), stats_download_.get(), 0, bytes);
        to_host_barrier();
        check(vkEndCommandBuffer(commands_), "vkEndCommandBuffer");
        submit_and_wait();
        throw_on_validation_messages("reading the segment statistics");
    }

    void submit_and_wait() {
        check(vkResetFences(rt_->device, 1, &fence_), "vkResetFences");
        auto submit = make_info<VkSubmitInfo>(VK_STRUCTURE_TYPE_SUBMIT_INFO);
        submit.commandBufferCount = 1;
        submit.pCommandBuffers = &commands_;
        {
            const std::lock_guard lock(rt_->queue_mutex);
            check(vkQueueSubmit(rt_->queue, 1, &submit, fence_), "vkQueueSubmit");
        }
        in_flight_ = true;
        check(vkWaitForFences(rt_->device, 1, &fence_, VK_TRUE, UINT64_MAX), "vkWaitForFences");
        in_flight_ = false;
    }

    [[nodiscard]] uint32_t fill_rounds() const override {
        const auto* flags = static_cast<const uint32_t*>(readback_.mapped()) + 1;
        uint32_t rounds = 0;
        for (uint32_t f = 0; f < fills_in_frame_; ++f) {
            const uint32_t* begin = flags + size_t(f) * fill_budget_;
            rounds += uint32_t(std::find(begin, begin + fill_budget_, 0u) - begin) + 1;
        }
        return rounds;
    }

    // A fill converged when one of its rounds changed nothing.
    [[nodiscard]] bool fills_converged() const {
        const auto* flags = static_cast<const uint32_t*>(readback_.mapped()) + 1;
        for (uint32_t f = 0; f < fills_in_frame_; ++f) {
            const uint32_t* begin = flags + size_t(f) * fill_budget_;
            if (std::find(begin, begin + fill_budget_, 0u) == begin + fill_budget_) return false;
        }
        return true;
    }

    // The flags buffer (kFillsPerFrame rounds of budget, plus the step-6 scratch slot) and its readback copy.
    void size_flags(uint32_t budget) {
        fill_budget_ = budget;
        const VkDeviceSize slots = VkDeviceSize(kFillsPerFrame) * budget + 1;
        buffers_[kFlags] = VulkanBuffer(*rt_, 4 * slots, VulkanBuffer::Memory::device, "the fill flags");
        readback_ = VulkanBuffer(*rt_, 4 * (slots + 1), VulkanBuffer::Memory::host, "the readback buffer");
        write_descriptors();
    }

    // --- recording helpers ---

    void dispatch(Entry e, uint32_t groups_x, uint32_t groups_y, std::initializer_list<uint32_t> args) {
        std::array<uint32_t, kPushConstantBytes / 4> constants{};
        constants[0] = width();
        std::copy(args.begin(), args.end(), constants.begin() + 1);
        vkCmdBindPipeline(commands_, VK_PIPELINE_BIND_POINT_COMPUTE, rt_->pipelines[e]);
        vkCmdPushConstants(commands_, rt_->pipeline_layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, kPushConstantBytes,
                           constants.data());
        vkCmdDispatch(commands_, groups_x, groups_y, 1);
        barrier(VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT);
    }

    // `count` invocations in groups of 64, laid out over a 2D grid of workgroups (PYR_LINEAR_ID).
    void dispatch_1d(Entry e, uint32_t count, std::initializer_list<uint32_t> args) {
        if (count == 0) return;
        const uint32_t groups = (count + kGroup1D - 1) / kGroup1D;
        const uint32_t gx = std::min(groups, max_groups_x_);
        dispatch(e, gx, (groups + gx - 1) / gx, args);
    }

    void dispatch_2d(Entry e, uint32_t w, uint32_t h, std::initializer_list<uint32_t> args) {
        if (w == 0 || h == 0) return;
        dispatch(e, (w + kGroup2D - 1) / kGroup2D, (h + kGroup2D - 1) / kGroup2D, args);
    }

    // Copies made before are visible to the host after the fence.
    void to_host_barrier() {
        auto to_host = make_info<VkMemoryBarrier>(VK_STRUCTURE_TYPE_MEMORY_BARRIER);
        to_host.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
        to_host.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
        vkCmdPipelineBarrier(commands_, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &to_host, 0,
                             nullptr, 0, nullptr);
    }

    // Everything written before (at src_stage) is visible to the shaders and copies after.
    void barrier(VkPipelineStageFlags src_stage, VkAccessFlags src_access) {
        auto b = make_info<VkMemoryBarrier>(VK_STRUCTURE_TYPE_MEMORY_BARRIER);
        b.srcAccessMask = src_access;
        b.dstAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_READ_BIT |
                          VK_ACCESS_TRANSFER_WRITE_BIT;
        vkCmdPipelineBarrier(commands_, src_stage,
                             VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 1, &b, 0,
                             nullptr, 0, nullptr);
    }

    void copy(VkBuffer src, VkDeviceSize src_offset, VkBuffer dst, VkDeviceSize dst_offset, VkDeviceSize bytes) {
        const VkBufferCopy region{src_offset, dst_offset, bytes};
        vkCmdCopyBuffer(commands_, src, dst, 1, &region);
    }

    // Closes the interval named before and opens one named `name` (nullptr: the frame's end).
    void timestamp(const char* name) {
        if (!rt_->timestamps || timestamp_count_ == kMaxTimestamps) return;
        vkCmdWriteTimestamp(commands_, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, query_pool_, timestamp_count_);
        timestamp_names_[timestamp_count_++] = name;
    }

    // --- host side ---

    void create_command_objects() {
        const VkDevice d = rt_->device;
        const VkDescriptorPoolSize size{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, kBindingCount};
        auto pool = make_info<VkDescriptorPoolCreateInfo>(VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO);
        pool.maxSets = 1;
        pool.poolSizeCount = 1;
        pool.pPoolSizes = &size;
        check(vkCreateDescriptorPool(d, &pool, nullptr, &descriptor_pool_), "vkCreateDescriptorPool");
        auto set = make_info<VkDescriptorSetAllocateInfo>(VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO);
        set.descriptorPool = descriptor_pool_;
        set.descriptorSetCount = 1;
        set.pSetLayouts = &rt_->set_layout;
        check(vkAllocateDescriptorSets(d, &set, &descriptor_set_), "vkAllocateDescriptorSets");

        auto cp = make_info<VkCommandPoolCreateInfo>(VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO);
        cp.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
        cp.queueFamilyIndex = rt_->queue_family;
        check(vkCreateCommandPool(d, &cp, nullptr, &command_pool_), "vkCreateCommandPool");
        auto cb = make_info<VkCommandBufferAllocateInfo>(VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO);
        cb.commandPool = command_pool_;
        cb.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
        cb.commandBufferCount = 1;
        check(vkAllocateCommandBuffers(d, &cb, &commands_), "vkAllocateCommandBuffers");
        auto fence = make_info<VkFenceCreateInfo>(VK_STRUCTURE_TYPE_FENCE_CREATE_INFO);
        check(vkCreateFence(d, &fence, nullptr, &fence_), "vkCreateFence");
        if (rt_->timestamps) {
            auto q = make_info<VkQueryPoolCreateInfo>(VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO);
            q.queryType = VK_QUERY_TYPE_TIMESTAMP;
            q.queryCount = kMaxTimestamps;
            check(vkCreateQueryPool(d, &q, nullptr, &query_pool_), "vkCreateQueryPool");
        }
    }

    void write_descriptors() {
        std::array<VkDescriptorBufferInfo, kBindingCount> infos{};
        std::array<VkWriteDescriptorSet, kBindingCount> writes{};
        for (uint32_t b = 0; b < kBindingCount; ++b) {
            infos[b] = VkDescriptorBufferInfo{buffers_[b].get(), 0, VK_WHOLE_SIZE};
            writes[b] = make_info<VkWriteDescriptorSet>(VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET);
            writes[b].dstSet = descriptor_set_;
            writes[b].dstBinding = b;
            writes[b].descriptorCount = 1;
            writes[b].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
            writes[b].pBufferInfo = &infos[b];
        }
        vkUpdateDescriptorSets(rt_->device, kBindingCount, writes.data(), 0, nullptr);
    }

    // The device's limits against this image: buffer sizes, allocation size, memory, workgroup counts.
    void check_limits() {
        const VkPhysicalDeviceLimits& lim = rt_->properties.limits;
        max_groups_x_ = lim.maxComputeWorkGroupCount[0];
        const auto mib = [](VkDeviceSize b) { return std::to_string(b >> 20) + " MiB"; };
        const std::string image = "a " + std::to_string(plan_.width) + " x " + std::to_string(plan_.height) + " image";
        const VkDeviceSize largest =
            std::max({16 * VkDeviceSize(plan_.pixel_count()), 4 * VkDeviceSize(plan_.total_texels), 4 * lut_words()});
        if (largest > lim.maxStorageBufferRange) {
            throw Error(ErrorCode::out_of_memory, image + " needs a storage buffer of " + mib(largest) + " but " +
                                                      rt_->description + " binds at most " +
                                                      mib(lim.maxStorageBufferRange) + " (maxStorageBufferRange)");
        }
        if (24 * VkDeviceSize(plan_.pixel_count()) > rt_->max_allocation) {
            throw Error(ErrorCode::out_of_memory, image + " needs staging buffers of " +
                                                      mib(24 * VkDeviceSize(plan_.pixel_count())) + " but " +
                                                      rt_->description + " allocates at most " +
                                                      mib(rt_->max_allocation) + " (maxMemoryAllocationSize)");
        }
        VkDeviceSize heap = 0;
        for (uint32_t h = 0; h < rt_->memory.memoryHeapCount; ++h)
            heap = std::max(heap, rt_->memory.memoryHeaps[h].size);
        const VkDeviceSize total = 92 * VkDeviceSize(plan_.pixel_count()) + 8 * VkDeviceSize(plan_.total_texels) +
                                   4 * lut_words() + 4 * VkDeviceSize(plan_.stats_words());
        if (total > heap) {
            throw Error(ErrorCode::out_of_memory, image + " needs " + mib(total) +
                                                      " of buffers but the largest heap of " + rt_->description +
                                                      " has " + mib(heap));
        }
        const uint64_t groups_1d =
            (uint64_t(std::max<size_t>(plan_.pixel_count(), plan_.lut_size())) + kGroup1D - 1) / kGroup1D;
        const uint64_t rows_1d = (groups_1d + max_groups_x_ - 1) / max_groups_x_;
        const uint64_t gx = (uint64_t(plan_.width) + kGroup2D - 1) / kGroup2D;
        const uint64_t gy = (uint64_t(plan_.height) + kGroup2D - 1) / kGroup2D;
        if (rows_1d > lim.maxComputeWorkGroupCount[1] || gx > lim.maxComputeWorkGroupCount[0] ||
            gy > lim.maxComputeWorkGroupCount[1]) {
            throw Error(ErrorCode::image_too_large, image + " needs more workgroups than " + rt_->description +
                                                        " dispatches (maxComputeWorkGroupCount " +
                                                        std::to_string(lim.maxComputeWorkGroupCount[0]) + " x " +
                                                        std::to_string(lim.maxComputeWorkGroupCount[1]) + ")");
        }
    }

    [[nodiscard]] uint32_t width() const { return uint32_t(plan_.width); }
    [[nodiscard]] uint32_t height() const { return uint32_t(plan_.height); }
    [[nodiscard]] uint32_t pixels() const { return uint32_t(plan_.pixel_count()); }
    [[nodiscard]] uint32_t stats_runs() const { return plan_.stats_runs_per_row() * height(); }
    // The compaction table, then the statistics words when asked for (shaders/pyr_vulkan.comp, binding 5).
    [[nodiscard]] VkDeviceSize lut_words() const { return VkDeviceSize(plan_.lut_size()) + plan_.stats_words(); }

    const core::Plan& plan_;
    std::shared_ptr<Runtime> rt_;
    std::array<VulkanBuffer, kBindingCount> buffers_;
    VulkanBuffer upload_, download_, readback_, stats_download_;
    VkDescriptorPool descriptor_pool_ = VK_NULL_HANDLE;
    VkDescriptorSet descriptor_set_ = VK_NULL_HANDLE;
    VkCommandPool command_pool_ = VK_NULL_HANDLE;
    VkCommandBuffer commands_ = VK_NULL_HANDLE;
    VkFence fence_ = VK_NULL_HANDLE;
    VkQueryPool query_pool_ = VK_NULL_HANDLE;
    uint32_t max_groups_x_ = 65535;
    std::array<Op, kMaxOps> ops_{};
    size_t op_count_ = 0;
    uint32_t fill_budget_ = kFirstBudget;
    uint32_t fills_in_frame_ = 0;
    std::array<const char*, kMaxTimestamps> timestamp_names_{};
    uint32_t timestamp_count_ = 0;
    double host_upload_ms_ = 0;
    double host_download_ms_ = 0;
    bool normals_given_ = false;
    bool from_mask_ = false;
    bool in_flight_ = false;  // submitted and not yet waited for
};

}  // namespace

std::unique_ptr<core::PassExecutor> make_executor(const core::Plan& plan) {
    return std::make_unique<VulkanExecutor>(plan, runtime_for(choose_device()));
}

std::vector<std::string> describe_devices(std::string* why_none, bool* any_usable) {
    std::vector<std::string> out;
    *any_usable = false;
    for (const DeviceRef& d : enumerate_devices(why_none)) {
        out.push_back(d.description);
        if (d.unusable.empty()) *any_usable = true;
    }
    return out;
}

}  // namespace pyrseg::vulkan
