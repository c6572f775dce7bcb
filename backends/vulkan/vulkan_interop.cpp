// pyrseg/vulkan.hpp: Segmenters on the caller's instance, device and queue, and frames on the caller's VkBuffers,
// recorded into the caller's command buffer or submitted with the caller's semaphores. The checks here are the
// Vulkan ones (the handles, the queue family, what the device offers, the semaphores); the buffers' sizes come from
// the caller, since Vulkan cannot tell them. The frame itself is core/device_frame.cpp's, as for every API.
#include "pyrseg/vulkan.hpp"

#include <algorithm>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <type_traits>
#include <vector>

#include "backends/vulkan/vulkan_device.hpp"
#include "backends/vulkan/vulkan_runtime.hpp"
#include "core/device_frame.hpp"
#include "core/executor.hpp"
#include "core/gpu/gpu_executor.hpp"
#include "pyrseg/error.hpp"

namespace pyrseg::vulkan {
namespace {

[[noreturn]] void bad(const std::string& what) {
    throw Error(ErrorCode::invalid_argument, what);
}

void check_device(const Device& d) {
    const auto null = [](const char* what) {
        bad(std::string("vulkan::Device needs an instance, a physical device, a device and a queue: its ") + what +
            " is VK_NULL_HANDLE");
    };
    if (d.instance == VK_NULL_HANDLE) null("instance");
    if (d.physical == VK_NULL_HANDLE) null("physical device");
    if (d.device == VK_NULL_HANDLE) null("device");
    if (d.queue == VK_NULL_HANDLE) null("queue");

    std::uint32_t count = 0;
    check(vkEnumeratePhysicalDevices(d.instance, &count, nullptr), "vkEnumeratePhysicalDevices");
    std::vector<VkPhysicalDevice> physicals(count);
    if (count > 0)
        check(vkEnumeratePhysicalDevices(d.instance, &count, physicals.data()), "vkEnumeratePhysicalDevices");
    if (std::find(physicals.begin(), physicals.end(), d.physical) == physicals.end()) {
        bad("the physical device is not one of the instance's (vkEnumeratePhysicalDevices)");
    }

    std::uint32_t family_count = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(d.physical, &family_count, nullptr);
    std::vector<VkQueueFamilyProperties> families(family_count);
    vkGetPhysicalDeviceQueueFamilyProperties(d.physical, &family_count, families.data());
    if (d.queue_family >= family_count) {
        bad("queue family " + std::to_string(d.queue_family) + " does not exist: the physical device has " +
            std::to_string(family_count));
    }
    if ((families[d.queue_family].queueFlags & VK_QUEUE_COMPUTE_BIT) == 0) {
        bad("queue family " + std::to_string(d.queue_family) +
            " has no compute (VK_QUEUE_COMPUTE_BIT); pyrseg's passes are compute shaders");
    }

    VkPhysicalDeviceProperties properties{};
    vkGetPhysicalDeviceProperties(d.physical, &properties);
    const std::string missing = missing_features(d.physical, properties);
    if (!missing.empty()) {
        throw Error(ErrorCode::backend_unavailable, std::string("pyrseg cannot run on the Vulkan device ") +
                                                        properties.deviceName + ": it lacks " + missing);
    }
}

VulkanDevice& device_of(Segmenter& segmenter) {
    auto* device = dynamic_cast<VulkanDevice*>(core::executor_of(segmenter).gpu_device());
    if (device == nullptr) {
        bad("this Segmenter does not run on Vulkan; make it with pyrseg::vulkan::make_segmenter on your device");
    }
    if (!device->external()) {
        bad("this Segmenter runs on pyrseg's own Vulkan device, not on yours; make it with "
            "pyrseg::vulkan::make_segmenter on your device");
    }
    return *device;
}

// A VkBuffer as an integer (a pointer type on 64-bit platforms, a uint64_t on 32-bit ones).
template <class Handle>
std::uint64_t handle_bits(Handle handle) {
    if constexpr (std::is_pointer_v<Handle>) {
        return static_cast<std::uint64_t>(reinterpret_cast<std::uintptr_t>(handle));
    } else {
        return static_cast<std::uint64_t>(handle);
    }
}

// The buffer as core::ExternalBuffer: its handle as an integer, and its bytes from the offset on.
core::ExternalBuffer external(VkBuffer buffer, VkDeviceSize offset, VkDeviceSize size) {
    core::ExternalBuffer b;
    if (buffer == VK_NULL_HANDLE) return b;
    b.handle = handle_bits(buffer);
    b.offset = std::size_t(offset);
    b.bytes = offset <= size ? std::size_t(size - offset) : 0;
    return b;
}

core::DeviceCloud cloud_of(const CloudBuffers& cloud) {
    core::DeviceCloud c;
    c.points = external(cloud.points, cloud.points_offset, cloud.points_bytes);
    c.normals = external(cloud.normals, cloud.normals_offset, cloud.normals_bytes);
    c.row_step_bytes = std::size_t(cloud.row_step_bytes);
    c.color.rgb = external(cloud.color, cloud.color_offset, cloud.color_bytes);
    c.color.row_step_bytes = std::size_t(cloud.color_row_step_bytes);
    return c;
}

core::DeviceDepth depth_of(const DepthBuffer& depth) {
    core::DeviceDepth d;
    d.samples = external(depth.samples, depth.offset, depth.bytes);
    d.view = depth.view;
    d.color.rgb = external(depth.color, depth.color_offset, depth.color_bytes);
    d.color.row_step_bytes = std::size_t(depth.color_row_step_bytes);
    return d;
}

core::DeviceLabels labels_of(const LabelBuffers& out) {
    core::DeviceLabels l;
    l.labels = external(out.labels, out.labels_offset, out.labels_bytes);
    l.row_step_bytes = std::size_t(out.row_step_bytes);
    l.count = external(out.count, out.count_offset, out.count_bytes);
    l.statistics = external(out.statistics, out.statistics_offset, out.statistics_bytes);
    l.graph = external(out.graph, out.graph_offset, out.graph_bytes);
    l.tracks = external(out.tracks, out.tracks_offset, out.tracks_bytes);
    return l;
}

void check_commands(VkCommandBuffer commands) {
    if (commands == VK_NULL_HANDLE) bad("the command buffer to record into is VK_NULL_HANDLE");
}

void check_semaphores(std::span<const VkSemaphore> wait, std::span<const VkPipelineStageFlags> wait_stages,
                      std::span<const VkSemaphore> signal) {
    if (wait.size() != wait_stages.size()) {
        bad("wait has " + std::to_string(wait.size()) + " semaphore(s) but wait_stages has " +
            std::to_string(wait_stages.size()) + " stage mask(s): one mask per semaphore");
    }
    for (std::size_t i = 0; i < wait.size(); ++i) {
        if (wait[i] == VK_NULL_HANDLE) bad("wait[" + std::to_string(i) + "] is a VK_NULL_HANDLE semaphore");
        if (wait_stages[i] == 0) bad("wait_stages[" + std::to_string(i) + "] is 0: give the stages that wait");
    }
    for (std::size_t i = 0; i < signal.size(); ++i) {
        if (signal[i] == VK_NULL_HANDLE) bad("signal[" + std::to_string(i) + "] is a VK_NULL_HANDLE semaphore");
    }
}

// The frame, and what it leaves behind when it fails once begun (nothing is recorded before the checks passed).
template <class Frame>
void run(VulkanDevice& device, Segmenter& segmenter, const Frame& frame, const core::DeviceLabels& labels,
         const std::function<void()>& begin) {
    try {
        core::run_device_frame(segmenter, frame, labels, begin);
    } catch (...) {
        device.abandon_frame();
        throw;
    }
}

}  // namespace

Segmenter make_segmenter(int width, int height, const Device& device, const Params& params, const Outputs& outputs) {
    check_device(device);
    return core::make_segmenter(width, height, params, outputs, "vulkan", [&](const core::Plan& plan) {
        return gpu::make_gpu_executor(plan, std::make_unique<VulkanDevice>(runtime_for(device), true));
    });
}

void record(Segmenter& segmenter, VkCommandBuffer commands, const CloudBuffers& cloud, const LabelBuffers& out) {
    VulkanDevice& device = device_of(segmenter);
    check_commands(commands);
    run(device, segmenter, cloud_of(cloud), labels_of(out), [&] { device.begin_record(commands); });
}

void record(Segmenter& segmenter, VkCommandBuffer commands, const DepthBuffer& depth, const LabelBuffers& out) {
    VulkanDevice& device = device_of(segmenter);
    check_commands(commands);
    run(device, segmenter, depth_of(depth), labels_of(out), [&] { device.begin_record(commands); });
}

void submit(Segmenter& segmenter, const CloudBuffers& cloud, const LabelBuffers& out, std::span<const VkSemaphore> wait,
            std::span<const VkPipelineStageFlags> wait_stages, std::span<const VkSemaphore> signal, VkFence fence) {
    VulkanDevice& device = device_of(segmenter);
    check_semaphores(wait, wait_stages, signal);
    run(device, segmenter, cloud_of(cloud), labels_of(out),
        [&] { device.begin_submit(wait, wait_stages, signal, fence); });
}

void submit(Segmenter& segmenter, const DepthBuffer& depth, const LabelBuffers& out, std::span<const VkSemaphore> wait,
            std::span<const VkPipelineStageFlags> wait_stages, std::span<const VkSemaphore> signal, VkFence fence) {
    VulkanDevice& device = device_of(segmenter);
    check_semaphores(wait, wait_stages, signal);
    run(device, segmenter, depth_of(depth), labels_of(out),
        [&] { device.begin_submit(wait, wait_stages, signal, fence); });
}

}  // namespace pyrseg::vulkan
