// The Vulkan backend: gpu::Device over one command buffer per Segmenter, recorded as the passes are queued and
// submitted at finish() (once per frame, plus once per batch of fill rounds until the fills are GPU-shaped). The
// passes are core/gpu/gpu_executor.cpp; the kernels are shaders/pyr_vulkan.comp, one pipeline per kernel of the
// table (vulkan_runtime.cpp). Transfers go through two host-visible staging buffers.
#include "backends/vulkan/vulkan_backend.hpp"

#include <algorithm>
#include <array>
#include <cstring>
#include <string>
#include <utility>
#include <vector>

#include "backends/vulkan/vulkan_buffer.hpp"
#include "backends/vulkan/vulkan_runtime.hpp"
#include "core/gpu/device.hpp"
#include "core/gpu/gpu_executor.hpp"
#include "core/gpu/staging.hpp"
#include "pyrseg/error.hpp"

namespace pyrseg::vulkan {
namespace {

using std::size_t;
using std::uint32_t;

constexpr uint32_t kMaxTimestamps = 64;  // pass boundaries per frame

class VulkanDevice final : public gpu::Device {
public:
    explicit VulkanDevice(std::shared_ptr<Runtime> runtime) : rt_(std::move(runtime)) { create_command_objects(); }

    ~VulkanDevice() override {
        const VkDevice d = rt_->device;
        if (in_flight_) vkWaitForFences(d, 1, &fence_, VK_TRUE, UINT64_MAX);
        if (fence_ != VK_NULL_HANDLE) vkDestroyFence(d, fence_, nullptr);
        if (query_pool_ != VK_NULL_HANDLE) vkDestroyQueryPool(d, query_pool_, nullptr);
        if (command_pool_ != VK_NULL_HANDLE) vkDestroyCommandPool(d, command_pool_, nullptr);
        if (descriptor_pool_ != VK_NULL_HANDLE) vkDestroyDescriptorPool(d, descriptor_pool_, nullptr);
    }
    VulkanDevice(const VulkanDevice&) = delete;
    VulkanDevice& operator=(const VulkanDevice&) = delete;

    [[nodiscard]] std::string description() const override { return rt_->description; }

    // A storage buffer binds at most maxStorageBufferRange bytes (the points and normals twice that: they are bound
    // in two ranges), and is one allocation (maxMemoryAllocationSize).
    [[nodiscard]] gpu::DeviceLimits limits() const override {
        const VkDeviceSize range = aligned_range();
        gpu::DeviceLimits l;
        l.max_buffer_bytes.fill(size_t(std::min(range, rt_->max_allocation)));
        l.max_buffer_bytes[size_t(gpu::Buffer::points)] = size_t(std::min(2 * range, rt_->max_allocation));
        l.max_buffer_bytes[size_t(gpu::Buffer::normals)] = l.max_buffer_bytes[size_t(gpu::Buffer::points)];
        l.max_buffer_what = "maxStorageBufferRange, maxMemoryAllocationSize";
        VkDeviceSize heap = 0;
        for (uint32_t h = 0; h < rt_->memory.memoryHeapCount; ++h)
            heap = std::max(heap, rt_->memory.memoryHeaps[h].size);
        l.memory_bytes = size_t(heap);
        l.memory_what = "its largest memory heap";
        l.mask_texel_bytes = 4;  // GLSL has no byte access without extensions
        return l;
    }

    void allocate(const gpu::BufferSizes& sizes, uint32_t image_width) override {
        width_ = image_width;
        const size_t pixels = sizes[size_t(gpu::Buffer::out)] / 4;
        check_workgroups(pixels, std::max(pixels, sizes[size_t(gpu::Buffer::lut)] / 4));
        for (size_t b = 0; b < gpu::kBufferCount; ++b) {
            const std::string what = std::string("the ") + gpu::buffer_name(gpu::Buffer(b)) + " buffer";
            buffers_[b] = VulkanBuffer(*rt_, sizes[b], VulkanBuffer::Memory::device, what.c_str());
        }
        // Points and normals (same size) beyond one binding's range continue in bindings 10 and 11.
        const VkDeviceSize xyz = sizes[size_t(gpu::Buffer::points)];
        split_bytes_ = xyz <= rt_->properties.limits.maxStorageBufferRange ? xyz : aligned_range();
        const gpu::StagingBytes staging = gpu::staging_bytes(sizes);
        upload_ = VulkanBuffer(*rt_, staging.upload, VulkanBuffer::Memory::host, "the upload staging buffer");
        download_ = VulkanBuffer(*rt_, staging.download, VulkanBuffer::Memory::host, "the download staging buffer");
        staging_.reset(static_cast<unsigned char*>(upload_.mapped()), staging.upload,
                       static_cast<unsigned char*>(download_.mapped()), staging.download);
        write_descriptors();
        throw_on_validation_messages("the creation of a Vulkan Segmenter");
    }

    void upload(gpu::Buffer b, size_t offset, const void* src, size_t bytes) override {
        recording();
        copy(upload_.get(), staging_.stage_upload(src, bytes), buffer(b), offset, bytes);
        barrier(VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT);
    }

    void download(gpu::Buffer b, size_t offset, void* dst, size_t bytes) override {
        recording();
        copy(buffer(b), offset, download_.get(), staging_.stage_download(dst, bytes), bytes);
    }

    void zero(gpu::Buffer b, size_t offset, size_t bytes) override {
        recording();
        vkCmdFillBuffer(commands_, buffer(b), offset, bytes, 0);
        barrier(VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT);
    }

    // 1D: `nx` invocations in groups of PYR_GROUP_1D over a 2D grid of workgroups (PYR_I); 2D: 8 x 8 groups;
    // 3: `nx` workgroups (PYR_GID), over a 2D grid likewise.
    void dispatch(gpu::Kernel k, uint32_t nx, uint32_t ny, const gpu::Args& args) override {
        if (nx == 0 || ny == 0) return;
        recording();
        uint32_t gx = 0;
        uint32_t gy = 0;
        if (gpu::kernel_dims(k) != 2) {
            // 1D: groups of PYR_GROUP_1D invocations; 3: one workgroup per index.
            const uint32_t groups = gpu::kernel_dims(k) == 3 ? nx : (nx + PYR_GROUP_1D - 1) / PYR_GROUP_1D;
            gx = std::min(groups, max_groups_x_);
            gy = (groups + gx - 1) / gx;
        } else {
            gx = (nx + PYR_GROUP_2D - 1) / PYR_GROUP_2D;
            gy = (ny + PYR_GROUP_2D - 1) / PYR_GROUP_2D;
        }
        std::array<uint32_t, kPushConstantBytes / 4> constants{};
        constants[0] = width_;
        std::copy(args.words.begin(), args.words.end(), constants.begin() + 1);
        constants.back() = uint32_t(split_bytes_ / 4);
        vkCmdBindPipeline(commands_, VK_PIPELINE_BIND_POINT_COMPUTE, rt_->pipelines[size_t(k)]);
        vkCmdPushConstants(commands_, rt_->pipeline_layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, kPushConstantBytes,
                           constants.data());
        vkCmdDispatch(commands_, gx, gy, 1);
        barrier(VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT);
    }

    // Closes the interval named before and opens one named `pass` (nullptr: the frame's end).
    void mark(const char* pass) override {
        if (!rt_->timestamps || timestamp_count_ == kMaxTimestamps) return;
        recording();
        vkCmdWriteTimestamp(commands_, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, query_pool_, timestamp_count_);
        timestamp_names_[timestamp_count_++] = pass;
    }

    void finish() override {
        if (!recording_) return;
        auto to_host = make_info<VkMemoryBarrier>(VK_STRUCTURE_TYPE_MEMORY_BARRIER);
        to_host.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
        to_host.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
        vkCmdPipelineBarrier(commands_, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &to_host, 0,
                             nullptr, 0, nullptr);
        check(vkEndCommandBuffer(commands_), "vkEndCommandBuffer");
        recording_ = false;
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
        throw_on_validation_messages("a frame");
        staging_.complete();
    }

    bool pass_times(std::vector<PassTiming>& timings) override {
        if (!rt_->timestamps || timestamp_count_ < 2) return false;
        std::array<std::uint64_t, kMaxTimestamps> ticks{};
        check(vkGetQueryPoolResults(rt_->device, query_pool_, 0, timestamp_count_, sizeof(ticks), ticks.data(),
                                    sizeof(std::uint64_t), VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT),
              "vkGetQueryPoolResults");
        for (PassTiming& t : timings) t.milliseconds = 0.0;
        const double ms_per_tick = double(rt_->properties.limits.timestampPeriod) * 1e-6;
        for (uint32_t k = 0; k + 1 < timestamp_count_; ++k) {
            for (PassTiming& t : timings) {
                if (timestamp_names_[k] != nullptr && std::strcmp(t.pass, timestamp_names_[k]) == 0)
                    t.milliseconds += double(ticks[k + 1] - ticks[k]) * ms_per_tick;
            }
        }
        return true;
    }

    // A frame that an error abandoned leaves nothing behind: its half-recorded commands are dropped (recording()
    // resets the command buffer), and so are its staged transfers.
    void begin_frame() override {
        if (recording_) {
            vkEndCommandBuffer(commands_);
            recording_ = false;
        }
        staging_.restart();
        timestamp_count_ = 0;
        reset_queries_ = true;
    }

private:
    [[nodiscard]] VkBuffer buffer(gpu::Buffer b) const { return buffers_[size_t(b)].get(); }

    // Begins the command buffer when nothing is being recorded; the frame's first one resets the timestamps.
    void recording() {
        if (recording_) return;
        check(vkResetCommandBuffer(commands_, 0), "vkResetCommandBuffer");
        auto begin = make_info<VkCommandBufferBeginInfo>(VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO);
        begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
        check(vkBeginCommandBuffer(commands_, &begin), "vkBeginCommandBuffer");
        recording_ = true;
        if (rt_->timestamps && reset_queries_) vkCmdResetQueryPool(commands_, query_pool_, 0, kMaxTimestamps);
        reset_queries_ = false;
        vkCmdBindDescriptorSets(commands_, VK_PIPELINE_BIND_POINT_COMPUTE, rt_->pipeline_layout, 0, 1, &descriptor_set_,
                                0, nullptr);
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

    void create_command_objects() {
        const VkDevice d = rt_->device;
        max_groups_x_ = rt_->properties.limits.maxComputeWorkGroupCount[0];
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

    // maxStorageBufferRange, rounded down to minStorageBufferOffsetAlignment (where a second range may start).
    [[nodiscard]] VkDeviceSize aligned_range() const {
        const VkPhysicalDeviceLimits& lim = rt_->properties.limits;
        const VkDeviceSize align = std::max<VkDeviceSize>(lim.minStorageBufferOffsetAlignment, 4);
        return VkDeviceSize(lim.maxStorageBufferRange) / align * align;
    }

    void write_descriptors() {
        std::array<VkDescriptorBufferInfo, kBindingCount> infos{};
        std::array<VkWriteDescriptorSet, kBindingCount> writes{};
        for (uint32_t b = 0; b < kBindingCount; ++b) {
            if (b < gpu::kBufferCount) {
                const VkDeviceSize size = buffers_[b].size();
                const bool xyz = b == uint32_t(gpu::Buffer::points) || b == uint32_t(gpu::Buffer::normals);
                infos[b] = VkDescriptorBufferInfo{buffers_[b].get(), 0, xyz ? std::min(size, split_bytes_) : size};
            } else {
                // The upper part (or, when the whole array fits below, the lower one again: never read).
                const VulkanBuffer& whole =
                    buffers_[size_t(b == kPointsHiBinding ? gpu::Buffer::points : gpu::Buffer::normals)];
                const bool split = whole.size() > split_bytes_;
                infos[b] = VkDescriptorBufferInfo{whole.get(), split ? split_bytes_ : 0,
                                                  split ? whole.size() - split_bytes_ : whole.size()};
            }
            writes[b] = make_info<VkWriteDescriptorSet>(VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET);
            writes[b].dstSet = descriptor_set_;
            writes[b].dstBinding = b;
            writes[b].descriptorCount = 1;
            writes[b].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
            writes[b].pBufferInfo = &infos[b];
        }
        vkUpdateDescriptorSets(rt_->device, kBindingCount, writes.data(), 0, nullptr);
    }

    // The grids this image's dispatches need, against maxComputeWorkGroupCount.
    void check_workgroups(size_t pixels, size_t largest_1d) const {
        const VkPhysicalDeviceLimits& lim = rt_->properties.limits;
        const size_t height = width_ == 0 ? 0 : pixels / width_;
        const uint64_t groups_1d = (uint64_t(largest_1d) + PYR_GROUP_1D - 1) / PYR_GROUP_1D;
        const uint64_t rows_1d = (groups_1d + max_groups_x_ - 1) / max_groups_x_;
        const uint64_t gx = (uint64_t(width_) + PYR_GROUP_2D - 1) / PYR_GROUP_2D;
        const uint64_t gy = (uint64_t(height) + PYR_GROUP_2D - 1) / PYR_GROUP_2D;
        if (rows_1d > lim.maxComputeWorkGroupCount[1] || gx > lim.maxComputeWorkGroupCount[0] ||
            gy > lim.maxComputeWorkGroupCount[1]) {
            throw Error(ErrorCode::image_too_large, "a " + std::to_string(width_) + " x " + std::to_string(height) +
                                                        " image needs more workgroups than " + rt_->description +
                                                        " dispatches (maxComputeWorkGroupCount " +
                                                        std::to_string(lim.maxComputeWorkGroupCount[0]) + " x " +
                                                        std::to_string(lim.maxComputeWorkGroupCount[1]) + ")");
        }
    }

    std::shared_ptr<Runtime> rt_;
    std::array<VulkanBuffer, gpu::kBufferCount> buffers_;
    VkDeviceSize split_bytes_ = 0;  // where the points' and normals' second binding starts
    VulkanBuffer upload_, download_;
    gpu::StagingArena staging_;
    VkDescriptorPool descriptor_pool_ = VK_NULL_HANDLE;
    VkDescriptorSet descriptor_set_ = VK_NULL_HANDLE;
    VkCommandPool command_pool_ = VK_NULL_HANDLE;
    VkCommandBuffer commands_ = VK_NULL_HANDLE;
    VkFence fence_ = VK_NULL_HANDLE;
    VkQueryPool query_pool_ = VK_NULL_HANDLE;
    uint32_t max_groups_x_ = 65535;
    uint32_t width_ = 0;
    std::array<const char*, kMaxTimestamps> timestamp_names_{};
    uint32_t timestamp_count_ = 0;
    bool reset_queries_ = true;
    bool recording_ = false;
    bool in_flight_ = false;  // submitted and not yet waited for
};

}  // namespace

std::unique_ptr<core::PassExecutor> make_executor(const core::Plan& plan) {
    return gpu::make_gpu_executor(plan, std::make_unique<VulkanDevice>(runtime_for(choose_device())));
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

const core::BackendEntry kBackend = {describe_devices, make_executor};

}  // namespace pyrseg::vulkan
