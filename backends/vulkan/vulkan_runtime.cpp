#include "backends/vulkan/vulkan_runtime.hpp"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <optional>
#include <string>
#include <tuple>
#include <vector>

#include "backends/vulkan/vulkan_modules.hpp"
#include "core/device_choice.hpp"
#include "core/gpu/api_error.hpp"
#include "pyrseg/error.hpp"

namespace pyrseg::vulkan {
namespace {

constexpr const char* kValidationLayer = "VK_LAYER_KHRONOS_validation";

bool validation_requested() {
    const char* env = std::getenv("PYRSEG_VULKAN_VALIDATION");
    return env != nullptr && *env != '\0' && std::strcmp(env, "0") != 0;
}

// Messages from the validation layer, kept until throw_on_validation_messages() reports them.
struct ValidationLog {
    std::mutex mutex;
    std::vector<std::string> pending;
};

ValidationLog& validation_log() {
    static ValidationLog log;
    return log;
}

VKAPI_ATTR VkBool32 VKAPI_CALL on_validation_message(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                                     VkDebugUtilsMessageTypeFlagsEXT /*types*/,
                                                     const VkDebugUtilsMessengerCallbackDataEXT* data, void* /*user*/) {
    const char* level = (severity & VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT) != 0 ? "error" : "warning";
    std::string text = std::string("[") + level + "] " + (data->pMessage != nullptr ? data->pMessage : "?");
    std::fprintf(stderr, "pyrseg: Vulkan validation %s\n", text.c_str());
    ValidationLog& log = validation_log();
    const std::lock_guard lock(log.mutex);
    log.pending.push_back(std::move(text));
    return VK_FALSE;
}

// The process's instance, created on first use; `why` says why there is none.
struct Instance {
    VkInstance handle = VK_NULL_HANDLE;
    VkDebugUtilsMessengerEXT messenger = VK_NULL_HANDLE;
    std::string why;

    Instance() {
        const bool validate = validation_requested();
        std::vector<const char*> layers;
        std::vector<const char*> extensions;
        if (validate) {
            std::uint32_t count = 0;
            vkEnumerateInstanceLayerProperties(&count, nullptr);
            std::vector<VkLayerProperties> available(count);
            vkEnumerateInstanceLayerProperties(&count, available.data());
            const bool found = std::any_of(available.begin(), available.end(), [](const VkLayerProperties& l) {
                return std::strcmp(l.layerName, kValidationLayer) == 0;
            });
            if (!found) {
                why = std::string("PYRSEG_VULKAN_VALIDATION is set but the layer ") + kValidationLayer +
                      " is not installed (Debian: vulkan-validationlayers)";
                return;
            }
            layers.push_back(kValidationLayer);
            extensions.push_back(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
        }
        auto app = make_info<VkApplicationInfo>(VK_STRUCTURE_TYPE_APPLICATION_INFO);
        app.pApplicationName = "pyrseg";
        app.pEngineName = "pyrseg";
        app.apiVersion = VK_API_VERSION_1_1;
        auto messenger_info =
            make_info<VkDebugUtilsMessengerCreateInfoEXT>(VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT);
        messenger_info.messageSeverity =
            VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
        messenger_info.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT |
                                     VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                                     VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
        messenger_info.pfnUserCallback = on_validation_message;
        auto info = make_info<VkInstanceCreateInfo>(VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO);
        info.pNext = validate ? &messenger_info : nullptr;  // also reports on instance creation itself
        info.pApplicationInfo = &app;
        info.enabledLayerCount = std::uint32_t(layers.size());
        info.ppEnabledLayerNames = layers.data();
        info.enabledExtensionCount = std::uint32_t(extensions.size());
        info.ppEnabledExtensionNames = extensions.data();
        const VkResult r = vkCreateInstance(&info, nullptr, &handle);
        if (r != VK_SUCCESS) {
            handle = VK_NULL_HANDLE;
            why = r == VK_ERROR_INCOMPATIBLE_DRIVER
                      ? "no Vulkan driver found (the loader found no ICD; on Debian, install mesa-vulkan-drivers for "
                        "lavapipe, or your GPU vendor's driver)"
                      : std::string("vkCreateInstance failed: ") + result_name(r);
            return;
        }
        if (validate) {
            auto create = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
                vkGetInstanceProcAddr(handle, "vkCreateDebugUtilsMessengerEXT"));
            if (create != nullptr) create(handle, &messenger_info, nullptr, &messenger);
        }
    }
    ~Instance() {
        if (messenger != VK_NULL_HANDLE) {
            auto destroy = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
                vkGetInstanceProcAddr(handle, "vkDestroyDebugUtilsMessengerEXT"));
            if (destroy != nullptr) destroy(handle, messenger, nullptr);
        }
        if (handle != VK_NULL_HANDLE) vkDestroyInstance(handle, nullptr);
    }
    Instance(const Instance&) = delete;
    Instance& operator=(const Instance&) = delete;
};

Instance& instance() {
    static Instance the_instance;
    return the_instance;
}

const char* type_name(VkPhysicalDeviceType type) {
    switch (type) {
        case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU:
            return "discrete GPU";
        case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU:
            return "integrated GPU";
        case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU:
            return "virtual GPU";
        case VK_PHYSICAL_DEVICE_TYPE_CPU:
            return "CPU";
        default:
            return "other";
    }
}

int preference(VkPhysicalDeviceType type) {
    switch (type) {
        case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU:
            return 4;
        case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU:
            return 3;
        case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU:
            return 2;
        case VK_PHYSICAL_DEVICE_TYPE_CPU:
            return 1;
        default:
            return 0;
    }
}

std::string version_text(std::uint32_t v) {
    return std::to_string(VK_API_VERSION_MAJOR(v)) + "." + std::to_string(VK_API_VERSION_MINOR(v)) + "." +
           std::to_string(VK_API_VERSION_PATCH(v));
}

// The first queue family that runs compute, or -1.
int compute_family(VkPhysicalDevice physical) {
    std::uint32_t count = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(physical, &count, nullptr);
    std::vector<VkQueueFamilyProperties> families(count);
    vkGetPhysicalDeviceQueueFamilyProperties(physical, &count, families.data());
    for (std::uint32_t f = 0; f < count; ++f) {
        if ((families[f].queueFlags & VK_QUEUE_COMPUTE_BIT) != 0) return int(f);
    }
    return -1;
}

}  // namespace

std::string missing_features(VkPhysicalDevice physical, const VkPhysicalDeviceProperties& p) {
    std::string missing;
    const auto need = [&](bool ok, const std::string& what) {
        if (!ok) missing += (missing.empty() ? "" : "; ") + what;
    };
    need(p.apiVersion >= VK_API_VERSION_1_1, "Vulkan 1.1 (the device has " + version_text(p.apiVersion) + ")");
    need(compute_family(physical) >= 0, "a compute queue");
    need(p.limits.maxComputeWorkGroupInvocations >= 64, "64 invocations per workgroup");
    need(p.limits.maxComputeWorkGroupSize[0] >= 64 && p.limits.maxComputeWorkGroupSize[1] >= 8,
         "workgroups of 64 x 1 and 8 x 8");
    need(p.limits.maxPushConstantsSize >= kPushConstantBytes,
         std::to_string(kPushConstantBytes) + " bytes of push constants");
    need(p.limits.maxPerStageDescriptorStorageBuffers >= kBindingCount,
         std::to_string(kBindingCount) + " storage buffers per stage");
    return missing;
}

const char* result_name(VkResult result) {
    switch (result) {
        case VK_SUCCESS:
            return "VK_SUCCESS";
        case VK_NOT_READY:
            return "VK_NOT_READY";
        case VK_TIMEOUT:
            return "VK_TIMEOUT";
        case VK_ERROR_OUT_OF_HOST_MEMORY:
            return "VK_ERROR_OUT_OF_HOST_MEMORY";
        case VK_ERROR_OUT_OF_DEVICE_MEMORY:
            return "VK_ERROR_OUT_OF_DEVICE_MEMORY";
        case VK_ERROR_INITIALIZATION_FAILED:
            return "VK_ERROR_INITIALIZATION_FAILED";
        case VK_ERROR_DEVICE_LOST:
            return "VK_ERROR_DEVICE_LOST";
        case VK_ERROR_MEMORY_MAP_FAILED:
            return "VK_ERROR_MEMORY_MAP_FAILED";
        case VK_ERROR_LAYER_NOT_PRESENT:
            return "VK_ERROR_LAYER_NOT_PRESENT";
        case VK_ERROR_EXTENSION_NOT_PRESENT:
            return "VK_ERROR_EXTENSION_NOT_PRESENT";
        case VK_ERROR_FEATURE_NOT_PRESENT:
            return "VK_ERROR_FEATURE_NOT_PRESENT";
        case VK_ERROR_INCOMPATIBLE_DRIVER:
            return "VK_ERROR_INCOMPATIBLE_DRIVER";
        case VK_ERROR_TOO_MANY_OBJECTS:
            return "VK_ERROR_TOO_MANY_OBJECTS";
        case VK_ERROR_OUT_OF_POOL_MEMORY:
            return "VK_ERROR_OUT_OF_POOL_MEMORY";
        case VK_ERROR_INVALID_SHADER_NV:
            return "VK_ERROR_INVALID_SHADER_NV";
        default:
            return "a Vulkan error";
    }
}

// Vulkan's codes for the kinds of failure core/gpu/api_error.hpp gives their meaning.
void fail(VkResult result, const char* what) {
    std::optional<gpu::Fault> fault;
    if (result == VK_ERROR_OUT_OF_DEVICE_MEMORY || result == VK_ERROR_OUT_OF_HOST_MEMORY) {
        fault = gpu::Fault::out_of_memory;
    } else if (result == VK_ERROR_DEVICE_LOST) {
        fault = gpu::Fault::device_lost;
    }
    gpu::throw_api_failure(
        {"Vulkan", what, std::string(result_name(result)) + " (" + std::to_string(int(result)) + ")", fault,
         "; the device was lost: this Segmenter cannot run it any more (make a new one, or use another backend)"});
}

void throw_on_validation_messages(const char* during) {
    ValidationLog& log = validation_log();
    const std::lock_guard lock(log.mutex);
    if (log.pending.empty()) return;
    std::string message = std::string("Vulkan validation layer reported ") + std::to_string(log.pending.size()) +
                          " message(s) during " + during + "; the first: " + log.pending.front();
    log.pending.clear();
    throw Error(ErrorCode::internal, message);
}

std::vector<DeviceRef> enumerate_devices(std::string* why_none) {
    std::vector<DeviceRef> all;
    Instance& inst = instance();
    if (inst.handle == VK_NULL_HANDLE) {
        if (why_none != nullptr) *why_none = inst.why;
        return all;
    }
    std::uint32_t count = 0;
    vkEnumeratePhysicalDevices(inst.handle, &count, nullptr);
    std::vector<VkPhysicalDevice> physicals(count);
    if (count > 0) vkEnumeratePhysicalDevices(inst.handle, &count, physicals.data());
    for (std::uint32_t i = 0; i < count; ++i) {
        VkPhysicalDeviceProperties p{};
        vkGetPhysicalDeviceProperties(physicals[i], &p);
        DeviceRef ref;
        ref.physical = physicals[i];
        ref.index = i;
        ref.preference = preference(p.deviceType);
        ref.cpu = p.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU;
        ref.description = std::to_string(i) + " " + p.deviceName + " (" + type_name(p.deviceType) + ", Vulkan " +
                          version_text(p.apiVersion) + ")";
        ref.unusable = missing_features(physicals[i], p);
        if (!ref.unusable.empty()) ref.description += " [unusable: lacks " + ref.unusable + "]";
        all.push_back(ref);
    }
    const bool any_usable = std::any_of(all.begin(), all.end(), [](const DeviceRef& d) { return d.unusable.empty(); });
    if (!any_usable && why_none != nullptr) {
        if (all.empty()) {
            *why_none = "no Vulkan device (the loader found a driver but it reports no device)";
        } else {
            *why_none = "no usable Vulkan device:";
            for (const DeviceRef& d : all) *why_none += " " + d.description;
        }
    }
    return all;
}

DeviceRef choose_device() {
    std::string why;
    const std::vector<DeviceRef> all = enumerate_devices(&why);
    const bool any_usable = std::any_of(all.begin(), all.end(), [](const DeviceRef& d) { return d.unusable.empty(); });
    if (!any_usable) throw Error(ErrorCode::backend_unavailable, "backend 'vulkan' is unavailable: " + why);
    std::vector<std::string> ids;
    std::vector<std::string> descriptions;
    for (const DeviceRef& d : all) {
        ids.push_back(std::to_string(d.index));
        descriptions.push_back(d.description);
    }
    if (const auto chosen = core::device_from_environment("PYRSEG_VULKAN_DEVICE", "Vulkan", ids, descriptions)) {
        const DeviceRef& d = all[*chosen];
        if (!d.unusable.empty()) {
            throw Error(ErrorCode::backend_unavailable, "PYRSEG_VULKAN_DEVICE='" +
                                                            std::string(std::getenv("PYRSEG_VULKAN_DEVICE")) +
                                                            "' selects " + d.description);
        }
        return d;
    }
    const DeviceRef* best = nullptr;
    for (const DeviceRef& d : all) {
        if (d.unusable.empty() && (best == nullptr || d.preference > best->preference)) best = &d;
    }
    return *best;
}

// The caller's device is left as it is: its Segmenters waited for their own submissions, and the caller's
// command buffers that used the pipelines must have completed before (pyrseg/vulkan.hpp).
Runtime::~Runtime() {
    if (device == VK_NULL_HANDLE) return;
    if (owns_device) vkDeviceWaitIdle(device);
    for (VkPipeline p : pipelines) {
        if (p != VK_NULL_HANDLE) vkDestroyPipeline(device, p, nullptr);
    }
    if (pipeline_layout != VK_NULL_HANDLE) vkDestroyPipelineLayout(device, pipeline_layout, nullptr);
    if (set_layout != VK_NULL_HANDLE) vkDestroyDescriptorSetLayout(device, set_layout, nullptr);
    if (owns_device) vkDestroyDevice(device, nullptr);
}

namespace {

void create_pipelines(Runtime& rt) {
    std::array<VkDescriptorSetLayoutBinding, kBindingCount> bindings{};
    for (std::uint32_t b = 0; b < kBindingCount; ++b) {
        bindings[b].binding = b;
        bindings[b].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
        bindings[b].descriptorCount = 1;
        bindings[b].stageFlags = VK_SHADER_STAGE_COMPUTE_BIT;
    }
    auto set_info = make_info<VkDescriptorSetLayoutCreateInfo>(VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO);
    set_info.bindingCount = kBindingCount;
    set_info.pBindings = bindings.data();
    check(vkCreateDescriptorSetLayout(rt.device, &set_info, nullptr, &rt.set_layout), "vkCreateDescriptorSetLayout");
    const VkPushConstantRange push{VK_SHADER_STAGE_COMPUTE_BIT, 0, kPushConstantBytes};
    auto layout_info = make_info<VkPipelineLayoutCreateInfo>(VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO);
    layout_info.setLayoutCount = 1;
    layout_info.pSetLayouts = &rt.set_layout;
    layout_info.pushConstantRangeCount = 1;
    layout_info.pPushConstantRanges = &push;
    check(vkCreatePipelineLayout(rt.device, &layout_info, nullptr, &rt.pipeline_layout), "vkCreatePipelineLayout");

    for (std::size_t e = 0; e < gpu::kKernelCount; ++e) {
        const char* entry = gpu::kernel_glsl_name(gpu::Kernel(e));
        const SpirvModule* found = nullptr;
        for (std::size_t m = 0; m < kSpirvModuleCount; ++m) {
            if (std::strcmp(kSpirvModules[m].entry, entry) == 0) found = &kSpirvModules[m];
        }
        if (found == nullptr) {
            throw Error(ErrorCode::internal, std::string("Vulkan: no SPIR-V was built for PYR_ENTRY_") + entry);
        }
        auto module_info = make_info<VkShaderModuleCreateInfo>(VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO);
        module_info.codeSize = found->word_count * sizeof(std::uint32_t);
        module_info.pCode = found->words;
        VkShaderModule module = VK_NULL_HANDLE;
        check(vkCreateShaderModule(rt.device, &module_info, nullptr, &module), "vkCreateShaderModule");
        auto info = make_info<VkComputePipelineCreateInfo>(VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO);
        info.stage.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
        info.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
        info.stage.module = module;
        info.stage.pName = "main";
        info.layout = rt.pipeline_layout;
        const VkResult r = vkCreateComputePipelines(rt.device, VK_NULL_HANDLE, 1, &info, nullptr, &rt.pipelines[e]);
        vkDestroyShaderModule(rt.device, module, nullptr);
        if (r != VK_SUCCESS) {
            fail(r, (std::string("vkCreateComputePipelines(PYR_ENTRY_") + entry + ")").c_str());
        }
    }
}

// The physical device's properties and limits, and whether `family` writes timestamps.
void read_properties(Runtime& rt, VkPhysicalDevice physical, std::uint32_t family) {
    rt.physical = physical;
    rt.queue_family = family;
    vkGetPhysicalDeviceProperties(physical, &rt.properties);
    vkGetPhysicalDeviceMemoryProperties(physical, &rt.memory);
    auto maintenance3 =
        make_info<VkPhysicalDeviceMaintenance3Properties>(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_MAINTENANCE_3_PROPERTIES);
    auto properties2 = make_info<VkPhysicalDeviceProperties2>(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2);
    properties2.pNext = &maintenance3;
    vkGetPhysicalDeviceProperties2(physical, &properties2);
    rt.max_allocation = maintenance3.maxMemoryAllocationSize;
    std::uint32_t family_count = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(physical, &family_count, nullptr);
    std::vector<VkQueueFamilyProperties> families(family_count);
    vkGetPhysicalDeviceQueueFamilyProperties(physical, &family_count, families.data());
    rt.timestamps =
        family < family_count && families[family].timestampValidBits > 0 && rt.properties.limits.timestampPeriod > 0;
}

}  // namespace

std::shared_ptr<Runtime> runtime_for(const DeviceRef& device) {
    static std::mutex mutex;
    static std::map<VkPhysicalDevice, std::shared_ptr<Runtime>> cache;
    const std::lock_guard lock(mutex);
    if (auto it = cache.find(device.physical); it != cache.end()) {
        if (!it->second->lost) return it->second;
        cache.erase(it);  // destroyed with the last Segmenter on it
    }

    auto rt = std::make_shared<Runtime>();
    rt->description = device.description;
    read_properties(*rt, device.physical, std::uint32_t(compute_family(device.physical)));

    const float priority = 1.0f;
    auto queue_info = make_info<VkDeviceQueueCreateInfo>(VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO);
    queue_info.queueFamilyIndex = rt->queue_family;
    queue_info.queueCount = 1;
    queue_info.pQueuePriorities = &priority;
    auto info = make_info<VkDeviceCreateInfo>(VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO);
    info.queueCreateInfoCount = 1;
    info.pQueueCreateInfos = &queue_info;
    check(vkCreateDevice(device.physical, &info, nullptr, &rt->device), "vkCreateDevice");
    vkGetDeviceQueue(rt->device, rt->queue_family, 0, &rt->queue);
    create_pipelines(*rt);
    throw_on_validation_messages("the creation of the Vulkan device and pipelines");
    cache.emplace(device.physical, rt);
    return rt;
}

std::shared_ptr<Runtime> runtime_for(const Device& device) {
    // Shared while a Segmenter uses it, and destroyed with the last one: a later device of the caller's with the
    // same handle value gets a runtime of its own.
    static std::mutex mutex;
    static std::map<std::tuple<VkDevice, std::uint32_t, VkQueue>, std::weak_ptr<Runtime>> cache;
    const std::lock_guard lock(mutex);
    const auto key = std::make_tuple(device.device, device.queue_family, device.queue);
    if (auto it = cache.find(key); it != cache.end()) {
        if (auto rt = it->second.lock()) return rt;
    }
    auto rt = std::make_shared<Runtime>();
    rt->owns_device = false;
    read_properties(*rt, device.physical, device.queue_family);
    rt->device = device.device;
    rt->queue = device.queue;
    rt->description = std::string("the caller's Vulkan device: ") + rt->properties.deviceName + " (" +
                      type_name(rt->properties.deviceType) + ", Vulkan " + version_text(rt->properties.apiVersion) +
                      ")";
    create_pipelines(*rt);
    std::erase_if(cache, [](const auto& entry) { return entry.second.expired(); });
    cache[key] = rt;
    return rt;
}

}  // namespace pyrseg::vulkan
