// The Vulkan backend in the registry: pyrseg's own device (vulkan_runtime.cpp chooses it) and a VulkanDevice
// (vulkan_device.cpp) per Segmenter. The passes are core/gpu/gpu_executor.cpp; the kernels are
// shaders/pyr_vulkan.comp, one pipeline per kernel of the table. pyrseg/vulkan.hpp puts the same on the caller's
// device (vulkan_interop.cpp).
#include "backends/vulkan/vulkan_backend.hpp"

#include <memory>
#include <string>
#include <vector>

#include "backends/vulkan/vulkan_device.hpp"
#include "backends/vulkan/vulkan_runtime.hpp"
#include "core/gpu/gpu_executor.hpp"

namespace pyrseg::vulkan {

std::unique_ptr<core::PassExecutor> make_executor(const core::Plan& plan) {
    return gpu::make_gpu_executor(plan, std::make_unique<VulkanDevice>(runtime_for(choose_device()), false));
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

namespace {

// The device auto would get is a CPU (lavapipe, SwiftShader): its type, as enumerate_devices ranks it.
bool emulated(std::string* device) {
    try {
        const DeviceRef d = choose_device();
        if (!d.cpu) return false;
        *device = d.description;
        return true;
    } catch (const Error&) {
        return false;
    }
}

}  // namespace

const core::BackendEntry kBackend = {describe_devices, make_executor, emulated};

}  // namespace pyrseg::vulkan
