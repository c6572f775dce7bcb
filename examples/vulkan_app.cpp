// A Vulkan application that owns its instance, device, queue and buffers, and runs pyrseg on them
// (pyrseg/vulkan.hpp). Each depth frame, as a camera SDK gives it (uint16 millimetres and the intrinsics), goes
// into one of the application's VkBuffers; pyrseg's frame is recorded into the application's own command buffer;
// the labels and the segment count come back in the application's buffers. A CPU Segmenter's host path checks
// them. Exits 77 when there is no Vulkan device.
#include <pyrseg/pyrseg.hpp>
#include <pyrseg/synthetic.hpp>
#include <pyrseg/vulkan.hpp>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <vector>

namespace {

constexpr int kWidth = 640;  // the camera's frame
constexpr int kHeight = 480;

// The application's Vulkan objects: the first device with a compute queue.
struct App {
    VkInstance instance = VK_NULL_HANDLE;
    VkPhysicalDevice physical = VK_NULL_HANDLE;
    std::uint32_t family = 0;
    VkDevice device = VK_NULL_HANDLE;
    VkQueue queue = VK_NULL_HANDLE;
    VkCommandPool pool = VK_NULL_HANDLE;

    bool create() {
        VkApplicationInfo app{};
        app.sType = VK_STRUCTURE_TYPE_APPLICATION_INFO;
        app.pApplicationName = "pyrseg vulkan_app";
        app.apiVersion = VK_API_VERSION_1_1;  // pyrseg needs Vulkan 1.1
        VkInstanceCreateInfo info{};
        info.sType = VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO;
        info.pApplicationInfo = &app;
        if (vkCreateInstance(&info, nullptr, &instance) != VK_SUCCESS) return false;
        std::uint32_t count = 0;
        vkEnumeratePhysicalDevices(instance, &count, nullptr);
        std::vector<VkPhysicalDevice> physicals(count);
        if (count > 0) vkEnumeratePhysicalDevices(instance, &count, physicals.data());
        for (VkPhysicalDevice p : physicals) {
            std::uint32_t n = 0;
            vkGetPhysicalDeviceQueueFamilyProperties(p, &n, nullptr);
            std::vector<VkQueueFamilyProperties> families(n);
            vkGetPhysicalDeviceQueueFamilyProperties(p, &n, families.data());
            for (std::uint32_t f = 0; f < n && physical == VK_NULL_HANDLE; ++f) {
                if ((families[f].queueFlags & VK_QUEUE_COMPUTE_BIT) != 0) {
                    physical = p;
                    family = f;
                }
            }
        }
        if (physical == VK_NULL_HANDLE) return false;
        const float priority = 1.0f;
        VkDeviceQueueCreateInfo queue_info{};
        queue_info.sType = VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO;
        queue_info.queueFamilyIndex = family;
        queue_info.queueCount = 1;
        queue_info.pQueuePriorities = &priority;
        VkDeviceCreateInfo device_info{};
        device_info.sType = VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO;
        device_info.queueCreateInfoCount = 1;
        device_info.pQueueCreateInfos = &queue_info;
        if (vkCreateDevice(physical, &device_info, nullptr, &device) != VK_SUCCESS) return false;
        vkGetDeviceQueue(device, family, 0, &queue);
        VkCommandPoolCreateInfo pool_info{};
        pool_info.sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO;
        pool_info.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
        pool_info.queueFamilyIndex = family;
        return vkCreateCommandPool(device, &pool_info, nullptr, &pool) == VK_SUCCESS;
    }

    void destroy() {
        if (pool != VK_NULL_HANDLE) vkDestroyCommandPool(device, pool, nullptr);
        if (device != VK_NULL_HANDLE) vkDestroyDevice(device, nullptr);
        if (instance != VK_NULL_HANDLE) vkDestroyInstance(instance, nullptr);
    }
};

// A buffer the host maps (a real application would keep the frames in device-local memory and upload them with
// its own copies; pyrseg reads and writes any VkBuffer with the transfer usages).
struct Buffer {
    VkBuffer buffer = VK_NULL_HANDLE;
    VkDeviceMemory memory = VK_NULL_HANDLE;
    VkDeviceSize bytes = 0;
    void* mapped = nullptr;

    bool create(const App& app, VkDeviceSize size) {
        bytes = size;
        VkBufferCreateInfo info{};
        info.sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO;
        info.size = size;
        info.usage = VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;
        if (vkCreateBuffer(app.device, &info, nullptr, &buffer) != VK_SUCCESS) return false;
        VkMemoryRequirements req{};
        vkGetBufferMemoryRequirements(app.device, buffer, &req);
        VkPhysicalDeviceMemoryProperties memory_types{};
        vkGetPhysicalDeviceMemoryProperties(app.physical, &memory_types);
        const VkMemoryPropertyFlags want = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
        VkMemoryAllocateInfo alloc{};
        alloc.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO;
        alloc.allocationSize = req.size;
        alloc.memoryTypeIndex = memory_types.memoryTypeCount;
        for (std::uint32_t t = 0; t < memory_types.memoryTypeCount; ++t) {
            if ((req.memoryTypeBits & (1u << t)) != 0 && (memory_types.memoryTypes[t].propertyFlags & want) == want) {
                alloc.memoryTypeIndex = t;
                break;
            }
        }
        return alloc.memoryTypeIndex < memory_types.memoryTypeCount &&
               vkAllocateMemory(app.device, &alloc, nullptr, &memory) == VK_SUCCESS &&
               vkBindBufferMemory(app.device, buffer, memory, 0) == VK_SUCCESS &&
               vkMapMemory(app.device, memory, 0, VK_WHOLE_SIZE, 0, &mapped) == VK_SUCCESS;
    }

    void destroy(const App& app) {
        if (buffer != VK_NULL_HANDLE) vkDestroyBuffer(app.device, buffer, nullptr);
        if (memory != VK_NULL_HANDLE) vkFreeMemory(app.device, memory, nullptr);
    }
};

// Three frames through pyrseg on the application's device; 0 when each matches the host path.
int run(const App& app, Buffer& depth, Buffer& labels, Buffer& count) {
    const int width = kWidth;
    const int height = kHeight;
    const pyrseg::Params params = pyrseg::sensor_preset(pyrseg::SensorKind::kinect_v1);
    pyrseg::Segmenter segmenter = pyrseg::vulkan::make_segmenter(
        width, height, {app.instance, app.physical, app.device, app.family, app.queue}, params);
    pyrseg::Segmenter host(width, height, params, "cpu");  // the check

    VkCommandBufferAllocateInfo allocate{};
    allocate.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO;
    allocate.commandPool = app.pool;
    allocate.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    allocate.commandBufferCount = 1;
    VkCommandBuffer commands = VK_NULL_HANDLE;
    vkAllocateCommandBuffers(app.device, &allocate, &commands);
    VkFenceCreateInfo fence_info{};
    fence_info.sType = VK_STRUCTURE_TYPE_FENCE_CREATE_INFO;
    VkFence done = VK_NULL_HANDLE;
    vkCreateFence(app.device, &fence_info, nullptr, &done);

    std::vector<std::uint16_t> samples(std::size_t(width) * std::size_t(height));
    int mismatches = 0;
    for (std::uint64_t frame = 1; frame <= 3; ++frame) {
        // Stands in for the camera SDK: whole millimetres (0: no data) and the camera's intrinsics.
        pyrseg::synthetic::SceneOptions camera;
        camera.sensor = pyrseg::synthetic::Sensor::kinect_v1;
        camera.seed = frame;
        const pyrseg::synthetic::Scene scene = pyrseg::synthetic::generate(camera);
        for (std::size_t i = 0; i < samples.size(); ++i) {
            const float z = scene.points[3 * i + 2];
            samples[i] = std::isfinite(z) ? std::uint16_t(std::lround(z)) : 0;
        }
        std::memcpy(depth.mapped, samples.data(), 2 * samples.size());  // the frame arrives in a VkBuffer

        pyrseg::DepthView view;  // everything about the frame but the samples, which are on the device
        view.format = pyrseg::DepthFormat::u16;
        view.width = width;
        view.height = height;
        view.metres_per_unit = 0.001;
        view.fx = scene.fx;
        view.fy = scene.fy;
        view.cx = scene.cx;
        view.cy = scene.cy;
        pyrseg::vulkan::DepthBuffer in{depth.buffer, 0, depth.bytes, view};
        pyrseg::vulkan::LabelBuffers out;
        out.labels = labels.buffer;
        out.labels_bytes = labels.bytes;
        out.count = count.buffer;
        out.count_bytes = count.bytes;

        // pyrseg's frame in the application's command buffer, which would hold the application's own work too.
        VkCommandBufferBeginInfo begin{};
        begin.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO;
        begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
        vkBeginCommandBuffer(commands, &begin);
        pyrseg::vulkan::record(segmenter, commands, in, out);
        vkEndCommandBuffer(commands);
        VkSubmitInfo submit{};
        submit.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO;
        submit.commandBufferCount = 1;
        submit.pCommandBuffers = &commands;
        vkQueueSubmit(app.queue, 1, &submit, done);
        vkWaitForFences(app.device, 1, &done, VK_TRUE, UINT64_MAX);
        vkResetFences(app.device, 1, &done);

        // The results, in the application's buffers; the host path of the same frame for comparison.
        std::uint32_t segments = 0;
        std::memcpy(&segments, count.mapped, 4);
        view.depth = samples.data();
        const pyrseg::Result expected = host.segment(view);
        const bool same = segments == expected.segment_count &&
                          std::memcmp(labels.mapped, expected.labels.data(), 4 * expected.labels.size()) == 0;
        std::printf("frame %llu: %u segments (%s)\n", static_cast<unsigned long long>(frame), segments,
                    same ? "matches the host path" : "DIFFERS from the host path");
        if (!same) ++mismatches;
    }
    vkDestroyFence(app.device, done, nullptr);
    vkFreeCommandBuffers(app.device, app.pool, 1, &commands);
    return mismatches == 0 ? 0 : 1;
}

}  // namespace

int main() {
    App app;
    if (!app.create()) {
        std::printf("no Vulkan device with a compute queue: skipped\n");
        app.destroy();
        return 77;
    }
    const VkDeviceSize pixels = VkDeviceSize(kWidth) * kHeight;
    Buffer depth, labels, count;
    int status = 1;
    if (depth.create(app, 2 * pixels) && labels.create(app, 4 * pixels) && count.create(app, 4)) {
        try {
            status = run(app, depth, labels, count);  // the Segmenter lives inside: destroyed before the device
        } catch (const pyrseg::Error& e) {
            std::fprintf(stderr, "pyrseg: %s\n", e.what());
        }
    } else {
        std::fprintf(stderr, "could not create the buffers\n");
    }
    vkDeviceWaitIdle(app.device);
    for (Buffer* b : {&depth, &labels, &count}) b->destroy(app);
    app.destroy();
    return status;
}
