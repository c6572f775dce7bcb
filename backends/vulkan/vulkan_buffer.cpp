#include "backends/vulkan/vulkan_buffer.hpp"

#include <string>
#include <utility>

#include "pyrseg/error.hpp"

namespace pyrseg::vulkan {
namespace {

// The first allowed memory type with all of `want`, else (for `fallback`) the first allowed one with `need`.
std::uint32_t memory_type(const VkPhysicalDeviceMemoryProperties& memory, std::uint32_t allowed,
                          VkMemoryPropertyFlags want, VkMemoryPropertyFlags need, const char* what) {
    for (VkMemoryPropertyFlags flags : {want, need}) {
        for (std::uint32_t t = 0; t < memory.memoryTypeCount; ++t) {
            if ((allowed & (1u << t)) != 0 && (memory.memoryTypes[t].propertyFlags & flags) == flags) return t;
        }
    }
    throw Error(ErrorCode::internal, std::string("Vulkan: no suitable memory type for ") + what);
}

}  // namespace

VulkanBuffer::VulkanBuffer(const Runtime& rt, VkDeviceSize bytes, Memory memory, const char* what)
    : device_(rt.device), size_(bytes < 4 ? 4 : bytes) {
    auto info = make_info<VkBufferCreateInfo>(VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO);
    info.size = size_;
    info.usage =
        VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;
    info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
    try {
        check(vkCreateBuffer(device_, &info, nullptr, &buffer_), what);
        VkMemoryRequirements req{};
        vkGetBufferMemoryRequirements(device_, buffer_, &req);
        const bool host = memory == Memory::host;
        const VkMemoryPropertyFlags need =
            host ? VkMemoryPropertyFlags(VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT)
                 : 0;
        const VkMemoryPropertyFlags want = host ? need | VkMemoryPropertyFlags(VK_MEMORY_PROPERTY_HOST_CACHED_BIT)
                                                : VkMemoryPropertyFlags(VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
        auto alloc = make_info<VkMemoryAllocateInfo>(VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO);
        alloc.allocationSize = req.size;
        alloc.memoryTypeIndex = memory_type(rt.memory, req.memoryTypeBits, want, need, what);
        check(vkAllocateMemory(device_, &alloc, nullptr, &memory_), what);
        check(vkBindBufferMemory(device_, buffer_, memory_, 0), what);
        if (host) check(vkMapMemory(device_, memory_, 0, VK_WHOLE_SIZE, 0, &mapped_), what);
    } catch (...) {
        release();
        throw;
    }
}

VulkanBuffer::~VulkanBuffer() {
    release();
}

void VulkanBuffer::release() noexcept {
    if (device_ == VK_NULL_HANDLE) return;
    if (mapped_ != nullptr) vkUnmapMemory(device_, memory_);
    if (buffer_ != VK_NULL_HANDLE) vkDestroyBuffer(device_, buffer_, nullptr);
    if (memory_ != VK_NULL_HANDLE) vkFreeMemory(device_, memory_, nullptr);
    mapped_ = nullptr;
    buffer_ = VK_NULL_HANDLE;
    memory_ = VK_NULL_HANDLE;
}

VulkanBuffer::VulkanBuffer(VulkanBuffer&& o) noexcept
    : device_(std::exchange(o.device_, VK_NULL_HANDLE)),
      buffer_(std::exchange(o.buffer_, VK_NULL_HANDLE)),
      memory_(std::exchange(o.memory_, VK_NULL_HANDLE)),
      size_(std::exchange(o.size_, 0)),
      mapped_(std::exchange(o.mapped_, nullptr)) {}

VulkanBuffer& VulkanBuffer::operator=(VulkanBuffer&& o) noexcept {
    if (this != &o) {
        release();
        device_ = std::exchange(o.device_, VK_NULL_HANDLE);
        buffer_ = std::exchange(o.buffer_, VK_NULL_HANDLE);
        memory_ = std::exchange(o.memory_, VK_NULL_HANDLE);
        size_ = std::exchange(o.size_, 0);
        mapped_ = std::exchange(o.mapped_, nullptr);
    }
    return *this;
}

}  // namespace pyrseg::vulkan
