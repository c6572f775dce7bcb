#pragma once
// A VkBuffer with its own memory: device-local for the passes' buffers, host-visible and coherent (and mapped)
// for the staging buffers the frames travel through.
#include <vulkan/vulkan.h>

#include "backends/vulkan/vulkan_runtime.hpp"

namespace pyrseg::vulkan {

class VulkanBuffer {
public:
    enum class Memory { device, host };
    VulkanBuffer() = default;
    // Throws pyrseg::Error (out_of_memory when the device has no room) naming `what`.
    VulkanBuffer(const Runtime& rt, VkDeviceSize bytes, Memory memory, const char* what);
    ~VulkanBuffer();
    VulkanBuffer(VulkanBuffer&& o) noexcept;
    VulkanBuffer& operator=(VulkanBuffer&& o) noexcept;
    VulkanBuffer(const VulkanBuffer&) = delete;
    VulkanBuffer& operator=(const VulkanBuffer&) = delete;

    [[nodiscard]] VkBuffer get() const { return buffer_; }
    [[nodiscard]] VkDeviceSize size() const { return size_; }
    [[nodiscard]] void* mapped() const { return mapped_; }  // host memory only

private:
    void release() noexcept;
    VkDevice device_ = VK_NULL_HANDLE;
    VkBuffer buffer_ = VK_NULL_HANDLE;
    VkDeviceMemory memory_ = VK_NULL_HANDLE;
    VkDeviceSize size_ = 0;
    void* mapped_ = nullptr;
};

}  // namespace pyrseg::vulkan
