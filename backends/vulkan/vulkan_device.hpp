#pragma once
// gpu::Device over Vulkan: pyrseg's own device and queue, or the caller's (pyrseg/vulkan.hpp). Host frames are
// recorded into one command buffer of the Segmenter's, submitted and waited at finish(). Device-resident frames
// (core/device_frame.hpp) are recorded into the caller's command buffer, or into one of a small ring of pyrseg's
// own that submit() sends to the queue with the caller's semaphores, with no host wait.
#include <vulkan/vulkan.h>

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "backends/vulkan/vulkan_buffer.hpp"
#include "backends/vulkan/vulkan_runtime.hpp"
#include "core/gpu/device.hpp"
#include "core/gpu/staging.hpp"

namespace pyrseg::vulkan {

class VulkanDevice final : public gpu::Device {
public:
    // On the runtime's device and queue: pyrseg's own (host frames only), or the caller's (`external`: device
    // frames too).
    VulkanDevice(std::shared_ptr<Runtime> runtime, bool external);
    ~VulkanDevice() override;
    VulkanDevice(const VulkanDevice&) = delete;
    VulkanDevice& operator=(const VulkanDevice&) = delete;

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

    // For the interop functions, once a device frame's checks passed and before its passes are queued: the frame
    // is recorded into the caller's command buffer (submit() then only closes it with the final barrier), or into
    // one of pyrseg's own that submit() sends to the queue after `wait` (at `wait_stages`), signalling `signal`,
    // then `fence` (when not null) on an empty batch. Each records the frame's leading barrier.
    [[nodiscard]] bool external() const { return external_; }
    void begin_record(VkCommandBuffer commands);
    void begin_submit(std::span<const VkSemaphore> wait, std::span<const VkPipelineStageFlags> wait_stages,
                      std::span<const VkSemaphore> signal, VkFence fence);
    // A device frame that failed after begin_record/begin_submit: what is half-recorded is left behind.
    void abandon_frame() { abandon(); }

private:
    // Every VkResult of the device goes through here: a lost device is marked on the shared runtime.
    void check(VkResult result, const char* what) const;
    enum class Mode { host, record, submit };
    static constexpr std::size_t kRingSize = 3;  // pyrseg's command buffers for submitted device frames

    struct RingSlot {
        VkCommandBuffer commands = VK_NULL_HANDLE;
        VkFence fence = VK_NULL_HANDLE;
        bool pending = false;  // submitted and not yet waited for
    };

    [[nodiscard]] VkBuffer buffer(gpu::Buffer b) const { return buffers_[std::size_t(b)].get(); }
    void recording();
    void abandon();
    void begin_device_frame();
    void barrier(VkPipelineStageFlags src_stage, VkAccessFlags src_access);
    void copy(VkBuffer src, VkDeviceSize src_offset, VkBuffer dst, VkDeviceSize dst_offset, VkDeviceSize bytes);
    void copy_rows(VkBuffer src, VkDeviceSize src_offset, VkDeviceSize src_pitch, VkBuffer dst, VkDeviceSize dst_offset,
                   VkDeviceSize dst_pitch, VkDeviceSize row_bytes, std::size_t rows);
    void create_command_objects();
    [[nodiscard]] VkDeviceSize aligned_range() const;
    void write_descriptors();
    void check_workgroups(std::size_t pixels, std::size_t largest_1d) const;

    std::shared_ptr<Runtime> rt_;
    bool external_ = false;
    std::array<VulkanBuffer, gpu::kBufferCount> buffers_;
    VkDeviceSize split_bytes_ = 0;  // where the points' and normals' second binding starts
    VulkanBuffer upload_, download_;
    gpu::StagingArena staging_;
    VkDescriptorPool descriptor_pool_ = VK_NULL_HANDLE;
    VkDescriptorSet descriptor_set_ = VK_NULL_HANDLE;
    VkCommandPool command_pool_ = VK_NULL_HANDLE;
    VkCommandBuffer host_commands_ = VK_NULL_HANDLE;  // host frames
    VkFence fence_ = VK_NULL_HANDLE;                  // host frames
    VkQueryPool query_pool_ = VK_NULL_HANDLE;
    std::uint32_t max_groups_x_ = 65535;
    std::uint32_t width_ = 0;
    static constexpr std::uint32_t kMaxTimestamps = 64;  // pass boundaries per frame
    std::array<const char*, kMaxTimestamps> timestamp_names_{};
    std::uint32_t timestamp_count_ = 0;
    bool reset_queries_ = true;
    bool recording_ = false;  // host_commands_ is being recorded
    bool in_flight_ = false;  // host_commands_ submitted and not yet waited for

    // Device frames.
    Mode mode_ = Mode::host;
    bool armed_ = false;                         // begin_record/begin_submit ran; the frame's begin_frame() is next
    VkCommandBuffer commands_ = VK_NULL_HANDLE;  // what the frame is recorded into
    std::array<RingSlot, kRingSize> ring_{};
    std::size_t ring_next_ = 0;
    std::vector<VkSemaphore> wait_, signal_;
    std::vector<VkPipelineStageFlags> wait_stages_;
    VkFence caller_fence_ = VK_NULL_HANDLE;
    std::vector<VkBufferCopy> regions_;
};

}  // namespace pyrseg::vulkan
