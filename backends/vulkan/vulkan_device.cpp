// The Vulkan backend's gpu::Device. Host frames: one command buffer per Segmenter, recorded as the passes are
// queued and submitted at finish() (once per frame, plus once for the statistics). Device-resident frames on the
// caller's device (pyrseg/vulkan.hpp): recorded into the caller's command buffer, or into one of a ring of pyrseg's
// own submitted with the caller's semaphores; the caller's buffers are copied in and out with vkCmdCopyBuffer. The
// passes are core/gpu/gpu_executor.cpp; the kernels are shaders/pyr_vulkan.comp, one pipeline per kernel of the
// table (vulkan_runtime.cpp). Host transfers go through two host-visible staging buffers.
#include "backends/vulkan/vulkan_device.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cstring>
#include <mutex>
#include <string>
#include <type_traits>
#include <utility>

#include "pyrseg/error.hpp"

namespace pyrseg::vulkan {
namespace {

using std::size_t;
using std::uint32_t;

// A core::ExternalBuffer's handle as the VkBuffer it was made from (a 64-bit pointer type on 64-bit platforms,
// a uint64_t on the others).
template <class Handle>
Handle handle_cast(std::uint64_t handle) {
    if constexpr (std::is_pointer_v<Handle>) {
        static_assert(sizeof(std::uintptr_t) == sizeof(handle));
        return std::bit_cast<Handle>(handle);
    } else {
        return static_cast<Handle>(handle);
    }
}

VkBuffer as_buffer(std::uint64_t handle) {
    return handle_cast<VkBuffer>(handle);
}

// What pyrseg's copies and shaders do.
constexpr VkPipelineStageFlags kPyrsegStages = VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT;
constexpr VkAccessFlags kPyrsegAccess =
    VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_READ_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;

}  // namespace

VulkanDevice::VulkanDevice(std::shared_ptr<Runtime> runtime, bool external)
    : rt_(std::move(runtime)), external_(external) {
    create_command_objects();
}

VulkanDevice::~VulkanDevice() {
    const VkDevice d = rt_->device;
    if (in_flight_) vkWaitForFences(d, 1, &fence_, VK_TRUE, UINT64_MAX);
    for (const RingSlot& slot : ring_) {
        if (slot.pending) vkWaitForFences(d, 1, &slot.fence, VK_TRUE, UINT64_MAX);
        if (slot.fence != VK_NULL_HANDLE) vkDestroyFence(d, slot.fence, nullptr);
    }
    if (fence_ != VK_NULL_HANDLE) vkDestroyFence(d, fence_, nullptr);
    if (query_pool_ != VK_NULL_HANDLE) vkDestroyQueryPool(d, query_pool_, nullptr);
    if (command_pool_ != VK_NULL_HANDLE) vkDestroyCommandPool(d, command_pool_, nullptr);
    if (descriptor_pool_ != VK_NULL_HANDLE) vkDestroyDescriptorPool(d, descriptor_pool_, nullptr);
}

// A storage buffer binds at most maxStorageBufferRange bytes (the points and normals twice that: they are bound in
// two ranges), and is one allocation (maxMemoryAllocationSize).
gpu::DeviceLimits VulkanDevice::limits() const {
    const VkDeviceSize range = aligned_range();
    gpu::DeviceLimits l;
    l.max_buffer_bytes.fill(size_t(std::min(range, rt_->max_allocation)));
    l.max_buffer_bytes[size_t(gpu::Buffer::points)] = size_t(std::min(2 * range, rt_->max_allocation));
    l.max_buffer_bytes[size_t(gpu::Buffer::normals)] = l.max_buffer_bytes[size_t(gpu::Buffer::points)];
    l.max_buffer_what = "maxStorageBufferRange, maxMemoryAllocationSize";
    VkDeviceSize heap = 0;
    for (uint32_t h = 0; h < rt_->memory.memoryHeapCount; ++h) heap = std::max(heap, rt_->memory.memoryHeaps[h].size);
    l.memory_bytes = size_t(heap);
    l.memory_what = "its largest memory heap";
    l.mask_texel_bytes = 4;  // GLSL has no byte access without extensions
    return l;
}

void VulkanDevice::allocate(const gpu::BufferSizes& sizes, uint32_t image_width) {
    width_ = image_width;
    const size_t pixels = sizes[size_t(gpu::Buffer::out)] / 4;
    check_workgroups(pixels, std::max(pixels, sizes[size_t(gpu::Buffer::lut)] / 4));
    for (size_t b = 0; b < gpu::kBufferCount; ++b) {
        const std::string what = std::string("the ") + gpu::buffer_name(gpu::Buffer(b)) + " buffer";
        buffers_[b] = VulkanBuffer(*rt_, sizes[b], VulkanBuffer::Memory::device, what.c_str());
    }
    // Points and normals (same size) beyond one binding's range continue in the two bindings after the buffer table's
    // (vulkan_runtime.hpp).
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

void VulkanDevice::upload(gpu::Buffer b, size_t offset, const void* src, size_t bytes) {
    recording();
    copy(upload_.get(), staging_.stage_upload(src, bytes), buffer(b), offset, bytes);
    barrier(VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT);
}

void VulkanDevice::download(gpu::Buffer b, size_t offset, void* dst, size_t bytes) {
    recording();
    copy(buffer(b), offset, download_.get(), staging_.stage_download(dst, bytes), bytes);
}

void VulkanDevice::zero(gpu::Buffer b, size_t offset, size_t bytes) {
    recording();
    vkCmdFillBuffer(commands_, buffer(b), offset, bytes, 0);
    barrier(VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT);
}

// 1D: `nx` invocations in groups of PYR_GROUP_1D over a 2D grid of workgroups (PYR_I); 2D: 8 x 8 groups;
// 3: `nx` workgroups (PYR_GID), over a 2D grid likewise.
void VulkanDevice::dispatch(gpu::Kernel k, uint32_t nx, uint32_t ny, const gpu::Args& args) {
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

// Closes the interval named before and opens one named `pass` (nullptr: the frame's end). Host frames only: a
// device frame writes no timestamps into the caller's command buffer.
void VulkanDevice::mark(const char* pass) {
    if (mode_ != Mode::host || !rt_->timestamps || timestamp_count_ == kMaxTimestamps) return;
    recording();
    vkCmdWriteTimestamp(commands_, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, query_pool_, timestamp_count_);
    timestamp_names_[timestamp_count_++] = pass;
}

void VulkanDevice::finish() {
    if (mode_ != Mode::host || !recording_) return;
    auto to_host = make_info<VkMemoryBarrier>(VK_STRUCTURE_TYPE_MEMORY_BARRIER);
    to_host.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    to_host.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
    vkCmdPipelineBarrier(commands_, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &to_host, 0,
                         nullptr, 0, nullptr);
    check(vkEndCommandBuffer(commands_), "vkEndCommandBuffer");
    recording_ = false;
    check(vkResetFences(rt_->device, 1, &fence_), "vkResetFences");
    auto info = make_info<VkSubmitInfo>(VK_STRUCTURE_TYPE_SUBMIT_INFO);
    info.commandBufferCount = 1;
    info.pCommandBuffers = &host_commands_;
    {
        const std::lock_guard lock(rt_->queue_mutex);
        check(vkQueueSubmit(rt_->queue, 1, &info, fence_), "vkQueueSubmit");
    }
    in_flight_ = true;
    check(vkWaitForFences(rt_->device, 1, &fence_, VK_TRUE, UINT64_MAX), "vkWaitForFences");
    in_flight_ = false;
    throw_on_validation_messages("a frame");
    staging_.complete();
}

void VulkanDevice::fail_like(gpu::Fault fault, const char* what) const {
    if (fault == gpu::Fault::device_lost) rt_->lost = true;
    fail(fault == gpu::Fault::out_of_memory ? VK_ERROR_OUT_OF_DEVICE_MEMORY : VK_ERROR_DEVICE_LOST, what);
}

void VulkanDevice::check(VkResult result, const char* what) const {
    if (result == VK_SUCCESS) return;
    if (result == VK_ERROR_DEVICE_LOST) rt_->lost = true;
    fail(result, what);
}

bool VulkanDevice::pass_times(std::vector<PassTiming>& timings) {
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

// A new frame: a device frame that begin_record/begin_submit just opened goes on; anything else half-recorded
// (a frame an error abandoned) is dropped, with its staged transfers and timestamps.
void VulkanDevice::begin_frame() {
    if (!armed_) abandon();
    armed_ = false;
    staging_.restart();
    timestamp_count_ = 0;
    reset_queries_ = true;
}

// Rows between the caller's buffer and pyrseg's, in order with the passes: vkCmdCopyBuffer, one region a row
// (one in all when both sides are packed).
void VulkanDevice::copy_in(gpu::Buffer dst, size_t offset, const core::ExternalBuffer& src, size_t pitch,
                           size_t row_bytes, size_t rows) {
    recording();
    copy_rows(as_buffer(src.handle), src.offset, pitch, buffer(dst), offset, row_bytes, row_bytes, rows);
    barrier(VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT);
}

// The copies out come last in a frame: submit()'s final barrier publishes their writes to whatever follows, and
// the next frame's leading barrier orders its writes to pyrseg's buffers after their reads.
void VulkanDevice::copy_out(const core::ExternalBuffer& dst, size_t pitch, gpu::Buffer src, size_t offset,
                            size_t row_bytes, size_t rows) {
    recording();
    copy_rows(buffer(src), offset, row_bytes, as_buffer(dst.handle), dst.offset, pitch, row_bytes, rows);
}

// vkCmdUpdateBuffer copies the bytes into the command buffer as it records: the frame may run much later.
void VulkanDevice::upload_inline(gpu::Buffer b, size_t offset, const void* src, size_t bytes) {
    if (bytes == 0) return;
    if (bytes > 65536 || bytes % 4 != 0 || offset % 4 != 0) {
        throw Error(ErrorCode::internal, "Vulkan: an inline upload of " + std::to_string(bytes) + " bytes at " +
                                             std::to_string(offset) +
                                             " (vkCmdUpdateBuffer takes up to 65536 bytes, "
                                             "multiples of 4 at multiples of 4)");
    }
    recording();
    vkCmdUpdateBuffer(commands_, buffer(b), offset, bytes, src);
    barrier(VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT);
}

// The end of a device frame: pyrseg's writes made available and visible to whatever follows (the caller's
// commands, the host after a fence); then, when pyrseg owns the command buffer, to the queue without a host wait.
void VulkanDevice::submit() {
    if (mode_ == Mode::host) {
        throw Error(ErrorCode::internal, "Vulkan: a device frame ends that begin_record/begin_submit did not begin");
    }
    auto done = make_info<VkMemoryBarrier>(VK_STRUCTURE_TYPE_MEMORY_BARRIER);
    done.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;
    done.dstAccessMask = VK_ACCESS_MEMORY_READ_BIT | VK_ACCESS_MEMORY_WRITE_BIT | VK_ACCESS_HOST_READ_BIT;
    vkCmdPipelineBarrier(commands_, kPyrsegStages, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT | VK_PIPELINE_STAGE_HOST_BIT, 0,
                         1, &done, 0, nullptr, 0, nullptr);
    const Mode mode = std::exchange(mode_, Mode::host);
    const VkCommandBuffer commands = std::exchange(commands_, VK_NULL_HANDLE);
    if (mode == Mode::record) return;

    RingSlot& slot = ring_[ring_next_];
    check(vkEndCommandBuffer(commands), "vkEndCommandBuffer");
    check(vkResetFences(rt_->device, 1, &slot.fence), "vkResetFences");
    auto info = make_info<VkSubmitInfo>(VK_STRUCTURE_TYPE_SUBMIT_INFO);
    info.waitSemaphoreCount = uint32_t(wait_.size());
    info.pWaitSemaphores = wait_.data();
    info.pWaitDstStageMask = wait_stages_.data();
    info.commandBufferCount = 1;
    info.pCommandBuffers = &commands;
    info.signalSemaphoreCount = uint32_t(signal_.size());
    info.pSignalSemaphores = signal_.data();
    const std::lock_guard lock(rt_->queue_mutex);
    check(vkQueueSubmit(rt_->queue, 1, &info, slot.fence), "vkQueueSubmit");
    slot.pending = true;
    ring_next_ = (ring_next_ + 1) % kRingSize;
    // One fence per batch: the caller's on an empty one right after, signalled once everything before completed.
    if (caller_fence_ != VK_NULL_HANDLE) check(vkQueueSubmit(rt_->queue, 0, nullptr, caller_fence_), "vkQueueSubmit");
}

void VulkanDevice::begin_record(VkCommandBuffer commands) {
    abandon();
    mode_ = Mode::record;
    commands_ = commands;
    begin_device_frame();
}

// The next command buffer of the ring, once the frame it last carried has completed (the only host wait, when
// all of them are pending).
void VulkanDevice::begin_submit(std::span<const VkSemaphore> wait, std::span<const VkPipelineStageFlags> wait_stages,
                                std::span<const VkSemaphore> signal, VkFence fence) {
    abandon();
    RingSlot& slot = ring_[ring_next_];
    if (slot.pending) {
        check(vkWaitForFences(rt_->device, 1, &slot.fence, VK_TRUE, UINT64_MAX), "vkWaitForFences");
        slot.pending = false;
    }
    check(vkResetCommandBuffer(slot.commands, 0), "vkResetCommandBuffer");
    auto begin = make_info<VkCommandBufferBeginInfo>(VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO);
    begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    check(vkBeginCommandBuffer(slot.commands, &begin), "vkBeginCommandBuffer");
    wait_.assign(wait.begin(), wait.end());
    wait_stages_.assign(wait_stages.begin(), wait_stages.end());
    signal_.assign(signal.begin(), signal.end());
    caller_fence_ = fence;
    mode_ = Mode::submit;
    commands_ = slot.commands;
    begin_device_frame();
}

// Everything written on the device before (the caller's input, the previous frame's use of pyrseg's buffers) is
// visible to the frame's copies and shaders; then pyrseg's descriptor set is bound.
void VulkanDevice::begin_device_frame() {
    auto b = make_info<VkMemoryBarrier>(VK_STRUCTURE_TYPE_MEMORY_BARRIER);
    b.srcAccessMask = VK_ACCESS_MEMORY_WRITE_BIT;
    b.dstAccessMask = kPyrsegAccess;
    vkCmdPipelineBarrier(commands_, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, kPyrsegStages, 0, 1, &b, 0, nullptr, 0,
                         nullptr);
    vkCmdBindDescriptorSets(commands_, VK_PIPELINE_BIND_POINT_COMPUTE, rt_->pipeline_layout, 0, 1, &descriptor_set_, 0,
                            nullptr);
    armed_ = true;
}

// Drops a half-recorded frame: a host frame's command buffer is ended (recording() resets it), a ring buffer that
// was never submitted is ended (begin_submit resets it). What went into the caller's command buffer stays there.
void VulkanDevice::abandon() {
    if (mode_ == Mode::host && recording_) {
        vkEndCommandBuffer(host_commands_);
        recording_ = false;
    }
    if (mode_ == Mode::submit) vkEndCommandBuffer(commands_);
    mode_ = Mode::host;
    commands_ = VK_NULL_HANDLE;
    armed_ = false;
}

// Host frames: begins the command buffer when nothing is being recorded; the frame's first one resets the
// timestamps. A device frame is being recorded since begin_record/begin_submit.
void VulkanDevice::recording() {
    if (mode_ != Mode::host || recording_) return;
    check(vkResetCommandBuffer(host_commands_, 0), "vkResetCommandBuffer");
    auto begin = make_info<VkCommandBufferBeginInfo>(VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO);
    begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    check(vkBeginCommandBuffer(host_commands_, &begin), "vkBeginCommandBuffer");
    recording_ = true;
    commands_ = host_commands_;
    if (external_) {
        // The caller's queue may still run device frames on pyrseg's buffers, submitted or recorded before.
        auto b = make_info<VkMemoryBarrier>(VK_STRUCTURE_TYPE_MEMORY_BARRIER);
        b.srcAccessMask = VK_ACCESS_MEMORY_WRITE_BIT;
        b.dstAccessMask = kPyrsegAccess;
        vkCmdPipelineBarrier(commands_, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, kPyrsegStages, 0, 1, &b, 0, nullptr, 0,
                             nullptr);
    }
    if (rt_->timestamps && reset_queries_) vkCmdResetQueryPool(commands_, query_pool_, 0, kMaxTimestamps);
    reset_queries_ = false;
    vkCmdBindDescriptorSets(commands_, VK_PIPELINE_BIND_POINT_COMPUTE, rt_->pipeline_layout, 0, 1, &descriptor_set_, 0,
                            nullptr);
}

// Everything written before (at src_stage) is visible to the shaders and copies after.
void VulkanDevice::barrier(VkPipelineStageFlags src_stage, VkAccessFlags src_access) {
    auto b = make_info<VkMemoryBarrier>(VK_STRUCTURE_TYPE_MEMORY_BARRIER);
    b.srcAccessMask = src_access;
    b.dstAccessMask = kPyrsegAccess;
    vkCmdPipelineBarrier(commands_, src_stage, kPyrsegStages, 0, 1, &b, 0, nullptr, 0, nullptr);
}

void VulkanDevice::copy(VkBuffer src, VkDeviceSize src_offset, VkBuffer dst, VkDeviceSize dst_offset,
                        VkDeviceSize bytes) {
    const VkBufferCopy region{src_offset, dst_offset, bytes};
    vkCmdCopyBuffer(commands_, src, dst, 1, &region);
}

void VulkanDevice::copy_rows(VkBuffer src, VkDeviceSize src_offset, VkDeviceSize src_pitch, VkBuffer dst,
                             VkDeviceSize dst_offset, VkDeviceSize dst_pitch, VkDeviceSize row_bytes, size_t rows) {
    if (rows == 0 || row_bytes == 0) return;
    if (src_pitch == row_bytes && dst_pitch == row_bytes) {
        copy(src, src_offset, dst, dst_offset, row_bytes * rows);
        return;
    }
    regions_.clear();
    regions_.reserve(rows);
    for (size_t y = 0; y < rows; ++y)
        regions_.push_back(VkBufferCopy{src_offset + y * src_pitch, dst_offset + y * dst_pitch, row_bytes});
    vkCmdCopyBuffer(commands_, src, dst, uint32_t(regions_.size()), regions_.data());
}

void VulkanDevice::create_command_objects() {
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
    check(vkAllocateCommandBuffers(d, &cb, &host_commands_), "vkAllocateCommandBuffers");
    const auto fence_info = make_info<VkFenceCreateInfo>(VK_STRUCTURE_TYPE_FENCE_CREATE_INFO);
    check(vkCreateFence(d, &fence_info, nullptr, &fence_), "vkCreateFence");
    if (external_) {
        for (RingSlot& slot : ring_) {
            check(vkAllocateCommandBuffers(d, &cb, &slot.commands), "vkAllocateCommandBuffers");
            check(vkCreateFence(d, &fence_info, nullptr, &slot.fence), "vkCreateFence");
        }
    }
    if (rt_->timestamps) {
        auto q = make_info<VkQueryPoolCreateInfo>(VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO);
        q.queryType = VK_QUERY_TYPE_TIMESTAMP;
        q.queryCount = kMaxTimestamps;
        check(vkCreateQueryPool(d, &q, nullptr, &query_pool_), "vkCreateQueryPool");
    }
}

// maxStorageBufferRange, rounded down to minStorageBufferOffsetAlignment (where a second range may start).
VkDeviceSize VulkanDevice::aligned_range() const {
    const VkPhysicalDeviceLimits& lim = rt_->properties.limits;
    const VkDeviceSize align = std::max<VkDeviceSize>(lim.minStorageBufferOffsetAlignment, 4);
    return VkDeviceSize(lim.maxStorageBufferRange) / align * align;
}

void VulkanDevice::write_descriptors() {
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
void VulkanDevice::check_workgroups(size_t pixels, size_t largest_1d) const {
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

}  // namespace pyrseg::vulkan
