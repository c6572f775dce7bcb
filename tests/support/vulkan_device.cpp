#include "tests/support/vulkan_device.hpp"

#include <stdexcept>

namespace pyrseg::test {

VulkanDevice::VulkanDevice(const VulkanDeviceOptions& options) {
    auto app = VkApplicationInfo{};
    app.sType = VK_STRUCTURE_TYPE_APPLICATION_INFO;
    app.pApplicationName = options.application;
    app.apiVersion = VK_API_VERSION_1_1;
    auto info = VkInstanceCreateInfo{};
    info.sType = VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO;
    info.pNext = options.instance_next;
    info.pApplicationInfo = &app;
    info.enabledLayerCount = std::uint32_t(options.layers.size());
    info.ppEnabledLayerNames = options.layers.data();
    info.enabledExtensionCount = std::uint32_t(options.extensions.size());
    info.ppEnabledExtensionNames = options.extensions.data();
    if (vkCreateInstance(&info, nullptr, &instance_) != VK_SUCCESS) {
        instance_ = VK_NULL_HANDLE;
        why_unavailable_ = "no Vulkan instance (the loader found no driver)";
        return;
    }
    if (options.messenger != nullptr) {
        auto create = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
            vkGetInstanceProcAddr(instance_, "vkCreateDebugUtilsMessengerEXT"));
        if (create == nullptr || create(instance_, options.messenger, nullptr, &messenger_) != VK_SUCCESS) {
            release();
            throw std::runtime_error("vkCreateDebugUtilsMessengerEXT failed");
        }
    }

    std::uint32_t count = 0;
    vkEnumeratePhysicalDevices(instance_, &count, nullptr);
    std::vector<VkPhysicalDevice> physicals(count);
    if (count > 0) vkEnumeratePhysicalDevices(instance_, &count, physicals.data());
    for (VkPhysicalDevice p : physicals) {
        std::uint32_t families = 0;
        vkGetPhysicalDeviceQueueFamilyProperties(p, &families, nullptr);
        std::vector<VkQueueFamilyProperties> props(families);
        vkGetPhysicalDeviceQueueFamilyProperties(p, &families, props.data());
        for (std::uint32_t f = 0; f < families && physical_ == VK_NULL_HANDLE; ++f) {
            if ((props[f].queueFlags & VK_QUEUE_COMPUTE_BIT) != 0) {
                physical_ = p;
                family_ = f;
            }
        }
    }
    if (physical_ == VK_NULL_HANDLE) {
        why_unavailable_ = "no Vulkan device with a compute queue on this machine";
        return;
    }
    vkGetPhysicalDeviceMemoryProperties(physical_, &memory_);

    const float priority = 1.0f;
    auto queue_info = VkDeviceQueueCreateInfo{};
    queue_info.sType = VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO;
    queue_info.queueFamilyIndex = family_;
    queue_info.queueCount = 1;
    queue_info.pQueuePriorities = &priority;
    auto device_info = VkDeviceCreateInfo{};
    device_info.sType = VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO;
    device_info.queueCreateInfoCount = 1;
    device_info.pQueueCreateInfos = &queue_info;
    if (vkCreateDevice(physical_, &device_info, nullptr, &device_) != VK_SUCCESS) {
        device_ = VK_NULL_HANDLE;
        release();  // a constructor that throws runs no destructor
        throw std::runtime_error("vkCreateDevice failed on a device with a compute queue");
    }
    vkGetDeviceQueue(device_, family_, 0, &queue_);
}

VulkanDevice::~VulkanDevice() {
    release();
}

void VulkanDevice::release() {
    if (device_ != VK_NULL_HANDLE) {
        vkDeviceWaitIdle(device_);
        vkDestroyDevice(device_, nullptr);
        device_ = VK_NULL_HANDLE;
    }
    if (messenger_ != VK_NULL_HANDLE) {
        auto destroy = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
            vkGetInstanceProcAddr(instance_, "vkDestroyDebugUtilsMessengerEXT"));
        destroy(instance_, messenger_, nullptr);
        messenger_ = VK_NULL_HANDLE;
    }
    if (instance_ != VK_NULL_HANDLE) {
        vkDestroyInstance(instance_, nullptr);
        instance_ = VK_NULL_HANDLE;
    }
}

VulkanDevice::Buffer VulkanDevice::make_buffer(VkDeviceSize bytes, VkMemoryPropertyFlags flags) const {
    Buffer b;
    b.bytes = bytes;
    auto info = VkBufferCreateInfo{};
    info.sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO;
    info.size = bytes;
    info.usage = VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;
    info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
    if (vkCreateBuffer(device_, &info, nullptr, &b.buffer) != VK_SUCCESS) return {};
    VkMemoryRequirements req{};
    vkGetBufferMemoryRequirements(device_, b.buffer, &req);
    std::uint32_t type = 0;
    while (type < memory_.memoryTypeCount &&
           ((req.memoryTypeBits & (1u << type)) == 0 || (memory_.memoryTypes[type].propertyFlags & flags) != flags))
        ++type;
    auto alloc = VkMemoryAllocateInfo{};
    alloc.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO;
    alloc.allocationSize = req.size;
    alloc.memoryTypeIndex = type;
    if (type == memory_.memoryTypeCount || vkAllocateMemory(device_, &alloc, nullptr, &b.memory) != VK_SUCCESS ||
        vkBindBufferMemory(device_, b.buffer, b.memory, 0) != VK_SUCCESS) {
        destroy(b);
        return {};
    }
    if ((flags & VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT) != 0) {
        void* mapped = nullptr;
        if (vkMapMemory(device_, b.memory, 0, VK_WHOLE_SIZE, 0, &mapped) != VK_SUCCESS) {
            destroy(b);
            return {};
        }
        b.mapped = static_cast<unsigned char*>(mapped);
    }
    return b;
}

void VulkanDevice::destroy(const Buffer& buffer) const {
    if (buffer.buffer != VK_NULL_HANDLE) vkDestroyBuffer(device_, buffer.buffer, nullptr);
    if (buffer.memory != VK_NULL_HANDLE) vkFreeMemory(device_, buffer.memory, nullptr);
}

}  // namespace pyrseg::test
