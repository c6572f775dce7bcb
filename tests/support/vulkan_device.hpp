#pragma once
// A Vulkan instance, device and compute queue that the caller owns, made as an application makes them for
// pyrseg::vulkan: the first device with a compute queue (lavapipe in CI). The interop tests (with the validation
// layer and a messenger of their own) and the device-frame bench share it; examples/vulkan_app.cpp spells the same
// steps out for readers, self-contained.
#include <vulkan/vulkan.h>

#include <cstdint>
#include <string>
#include <vector>

#include "pyrseg/vulkan.hpp"

namespace pyrseg::test {

struct VulkanDeviceOptions {
    const char* application = "pyrseg";
    std::vector<const char*> layers;
    std::vector<const char*> extensions;
    const void* instance_next = nullptr;  // VkInstanceCreateInfo::pNext: validation features, a messenger's info
    // A messenger made right after the instance and destroyed after the device, so that it sees both ends.
    const VkDebugUtilsMessengerCreateInfoEXT* messenger = nullptr;
};

class VulkanDevice {
public:
    // Throws std::runtime_error when a step that should succeed on a machine with a device fails; a machine
    // without a driver or a compute queue is why_unavailable() instead.
    explicit VulkanDevice(const VulkanDeviceOptions& options = {});
    ~VulkanDevice();
    VulkanDevice(const VulkanDevice&) = delete;
    VulkanDevice& operator=(const VulkanDevice&) = delete;

    // Why there is no device on this machine; empty when there is one.
    [[nodiscard]] const std::string& why_unavailable() const { return why_unavailable_; }
    [[nodiscard]] vulkan::Device handles() const { return {instance_, physical_, device_, family_, queue_}; }
    [[nodiscard]] VkInstance instance() const { return instance_; }
    [[nodiscard]] VkPhysicalDevice physical() const { return physical_; }
    [[nodiscard]] VkDevice device() const { return device_; }
    [[nodiscard]] VkQueue queue() const { return queue_; }
    [[nodiscard]] std::uint32_t family() const { return family_; }

    // A buffer with the transfer usages in memory with all of `flags`, mapped when they are host-visible; null
    // handles when the device has no such memory or the allocation fails. destroy() frees it.
    struct Buffer {
        VkBuffer buffer = VK_NULL_HANDLE;
        VkDeviceMemory memory = VK_NULL_HANDLE;
        VkDeviceSize bytes = 0;
        unsigned char* mapped = nullptr;
    };
    [[nodiscard]] Buffer make_buffer(VkDeviceSize bytes, VkMemoryPropertyFlags flags) const;
    void destroy(const Buffer& buffer) const;

private:
    void release();  // the device, the messenger, the instance: what of them there is

    std::string why_unavailable_;
    VkInstance instance_ = VK_NULL_HANDLE;
    VkDebugUtilsMessengerEXT messenger_ = VK_NULL_HANDLE;
    VkPhysicalDevice physical_ = VK_NULL_HANDLE;
    VkPhysicalDeviceMemoryProperties memory_{};
    std::uint32_t family_ = 0;
    VkDevice device_ = VK_NULL_HANDLE;
    VkQueue queue_ = VK_NULL_HANDLE;
};

}  // namespace pyrseg::test
