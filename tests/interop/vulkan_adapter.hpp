#pragma once
// The Vulkan side of the shared device-frame checks (device_frames.hpp): the test's own instance, device and queue
// (tests/support/vulkan_device.hpp), host-visible coherent buffers the test reads through their mapping, frames
// recorded into the test's command buffers or submitted by pyrseg with semaphores and a fence. The instance runs
// the Khronos validation layer (with synchronization validation where the layer has it) and a messenger of the
// test's own: any warning or error it reports fails the test as the adapter closes.
#include <cstdint>
#include <deque>
#include <optional>
#include <string>
#include <vector>

#include "interop/device_frames.hpp"
#include "pyrseg/vulkan.hpp"
#include "support/vulkan_device.hpp"

namespace pyrseg::test {

inline constexpr std::uint64_t kVulkanTimeoutNs = 60'000'000'000;  // a frame that never completes fails, not hangs

// The validation layer's warnings and errors on the test's instance (pyrseg has no messenger there).
struct ValidationMessages {
    int count = 0;
    std::vector<std::string> first;
};

class VulkanAdapter final : public Adapter {
public:
    enum WayIndex : std::size_t { recorded, submitted, never_begun };

    VulkanAdapter() = default;
    ~VulkanAdapter() override;
    VulkanAdapter(const VulkanAdapter&) = delete;
    VulkanAdapter& operator=(const VulkanAdapter&) = delete;

    [[nodiscard]] std::string open() override;
    [[nodiscard]] std::string backend_name() const override { return "vulkan"; }
    [[nodiscard]] std::vector<Way> ways() const override;
    [[nodiscard]] Segmenter make_segmenter(int width, int height, const Params& params,
                                           const Outputs& outputs = {}) override;
    [[nodiscard]] int allocate(std::size_t bytes) override;
    [[nodiscard]] std::size_t size(int buffer) const override;
    void upload(int buffer, std::size_t offset, const void* data, std::size_t bytes) override;
    [[nodiscard]] std::vector<unsigned char> download(int buffer, std::size_t offset, std::size_t bytes) override;
    void run(Segmenter& segmenter, std::span<const Frame> frames, std::size_t way) override;

    // For the Vulkan-only tests: the application's objects, and the shared frames in Vulkan's terms.
    [[nodiscard]] vulkan::Device device() const { return device_->handles(); }
    [[nodiscard]] VkDevice vk_device() const { return device_->device(); }
    [[nodiscard]] VkPhysicalDevice physical() const { return device_->physical(); }
    [[nodiscard]] VkQueue queue() const { return device_->queue(); }
    [[nodiscard]] const VulkanDevice::Buffer& buffer(int index) const { return buffers_.at(std::size_t(index)); }
    [[nodiscard]] vulkan::CloudBuffers cloud(const CloudFrame& frame) const;
    [[nodiscard]] vulkan::DepthBuffer depth(const DepthFrame& frame) const;
    [[nodiscard]] vulkan::LabelBuffers labels(const LabelFrame& frame) const;
    // A command buffer of the test's pool in the initial state (recording anything into it is a validation error),
    // and one in the recording state.
    [[nodiscard]] VkCommandBuffer allocate_commands();
    [[nodiscard]] VkCommandBuffer begin();
    [[nodiscard]] VkSemaphore semaphore();
    [[nodiscard]] VkFence fence();
    // Submits `commands` (ended here, then freed) after `wait` (at all commands), and waits for it.
    void submit_and_wait(VkCommandBuffer commands, VkSemaphore wait = VK_NULL_HANDLE);
    void free(VkCommandBuffer commands);

    bool validation_ = false;
    ValidationMessages messages_;

private:
    void record(Segmenter& segmenter, VkCommandBuffer commands, const Frame& frame) const;
    void submit(Segmenter& segmenter, const Frame& frame, std::span<const VkSemaphore> wait,
                std::span<const VkPipelineStageFlags> stages, std::span<const VkSemaphore> signal, VkFence fence) const;
    void run_recorded(Segmenter& segmenter, std::span<const Frame> frames);
    void run_submitted(Segmenter& segmenter, std::span<const Frame> frames);
    void run_never_begun(Segmenter& segmenter, std::span<const Frame> frames);

    std::optional<VulkanDevice> device_;
    VkCommandPool pool_ = VK_NULL_HANDLE;
    std::deque<VulkanDevice::Buffer> buffers_;  // buffer() hands out references, which push_back keeps valid
    std::vector<VkSemaphore> semaphores_;
    std::vector<VkFence> fences_;
};

}  // namespace pyrseg::test
