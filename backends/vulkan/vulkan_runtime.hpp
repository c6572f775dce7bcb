#pragma once
// The Vulkan instance, physical devices and the device choice, and per device the logical device, queue,
// descriptor set layout, pipeline layout and one compute pipeline per entry point, shared by every Segmenter of the
// process. With PYRSEG_VULKAN_VALIDATION=1 the Khronos validation layer is on and its messages are collected.
// A runtime may also sit on the caller's device and queue (pyrseg/vulkan.hpp): the same layouts and pipelines,
// on a device pyrseg does not own.
#include <vulkan/vulkan.h>

#include <array>
#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "core/gpu/device.hpp"
#include "pyrseg/vulkan.hpp"

namespace pyrseg::vulkan {

// The storage bindings of shaders/pyr_vulkan.comp: the buffers in gpu::Buffer order, then the upper parts of the points
// and normals buffers (a frame whose xyz arrays exceed maxStorageBufferRange binds them in two ranges). Its push
// constants: the image width, the dispatch's argument words, and where the upper parts start (in floats).
inline constexpr std::uint32_t kBindingCount = gpu::kBufferCount + 2;
inline constexpr std::uint32_t kPointsHiBinding = gpu::kBufferCount;
inline constexpr std::uint32_t kNormalsHiBinding = gpu::kBufferCount + 1;
inline constexpr std::uint32_t kPushConstantBytes = 4 * (2 + PYR_ARG_WORDS);

struct DeviceRef {
    VkPhysicalDevice physical = VK_NULL_HANDLE;
    std::uint32_t index = 0;
    std::string description;  // "0 llvmpipe (LLVM 15.0.6, 256 bits) (CPU, Vulkan 1.3.230, Mesa 22.3.6)"
    std::string unusable;     // why pyrseg cannot use it (empty when it can)
    int preference = 0;       // discrete GPU first, then integrated, virtual, CPU
    bool cpu = false;         // VK_PHYSICAL_DEVICE_TYPE_CPU: the API in software (lavapipe, SwiftShader)
};

// Every physical device; when none is usable, *why_none says why. Never throws.
[[nodiscard]] std::vector<DeviceRef> enumerate_devices(std::string* why_none);

// What pyrseg needs of a device that not every Vulkan device has ("Vulkan 1.1; a compute queue"); empty when it
// has all of it.
[[nodiscard]] std::string missing_features(VkPhysicalDevice physical, const VkPhysicalDeviceProperties& properties);

// $PYRSEG_VULKAN_DEVICE (an index, or text found in the description), else the most preferred usable device.
// Throws pyrseg::Error(backend_unavailable) naming the reason.
[[nodiscard]] DeviceRef choose_device();

struct Runtime {
    VkPhysicalDevice physical = VK_NULL_HANDLE;
    VkDevice device = VK_NULL_HANDLE;
    VkQueue queue = VK_NULL_HANDLE;
    std::uint32_t queue_family = 0;
    std::mutex queue_mutex;  // vkQueueSubmit needs the queue externally synchronised
    VkPhysicalDeviceProperties properties{};
    VkPhysicalDeviceMemoryProperties memory{};
    VkDeviceSize max_allocation = 0;  // maxMemoryAllocationSize (Vulkan 1.1)
    bool timestamps = false;          // the queue family writes timestamps
    bool owns_device = true;          // false: the caller's device, which pyrseg never destroys
    // VK_ERROR_DEVICE_LOST was seen on it: the Segmenters on it keep failing, the next ones get a new device.
    std::atomic<bool> lost{false};
    std::string description;
    VkDescriptorSetLayout set_layout = VK_NULL_HANDLE;
    VkPipelineLayout pipeline_layout = VK_NULL_HANDLE;
    std::array<VkPipeline, gpu::kKernelCount> pipelines{};  // per kernel of the table

    Runtime() = default;
    Runtime(const Runtime&) = delete;
    Runtime& operator=(const Runtime&) = delete;
    ~Runtime();
};

// The shared runtime of a device, created on first use.
[[nodiscard]] std::shared_ptr<Runtime> runtime_for(const DeviceRef& device);
// The runtime on the caller's device and queue (checked by the caller of this function), shared by the Segmenters
// on them while any lives; its destruction destroys the pipelines and layouts, never the device.
[[nodiscard]] std::shared_ptr<Runtime> runtime_for(const Device& device);

// With PYRSEG_VULKAN_VALIDATION=1: throws pyrseg::Error quoting the validation messages reported since the last
// call (each is also printed to stderr as it arrives). Without validation it does nothing.
void throw_on_validation_messages(const char* during);

// A Vulkan info struct, zeroed, with its sType.
template <class T>
[[nodiscard]] T make_info(VkStructureType type) {
    T info{};
    info.sType = type;
    return info;
}

[[nodiscard]] const char* result_name(VkResult result);
[[noreturn]] void fail(VkResult result, const char* what);
inline void check(VkResult result, const char* what) {
    if (result != VK_SUCCESS) fail(result, what);
}

}  // namespace pyrseg::vulkan
