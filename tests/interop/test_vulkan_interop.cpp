// pyrseg/vulkan.hpp on an instance, device, queue and buffers this test creates itself, as an application would:
// device-resident frames give the host path's labels and segment count byte for byte (clouds with and without
// normals, both metrics, depth images u16 and f32 with odd row steps and intrinsics that change between frames),
// recorded into the test's command buffer or submitted by pyrseg with semaphores and a fence; bad input is a
// pyrseg::Error that records, submits and writes nothing. The test's instance runs the Khronos validation layer
// (with synchronization validation where the layer has it) and a messenger of its own: any warning or error fails.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <deque>
#include <string>
#include <vector>

#include "pyrseg/backend.hpp"
#include "pyrseg/error.hpp"
#include "pyrseg/presets.hpp"
#include "pyrseg/segmenter.hpp"
#include "pyrseg/synthetic.hpp"
#include "pyrseg/vulkan.hpp"
#include "support/oracle.hpp"

namespace pyrseg::test {
namespace {

constexpr const char* kValidationLayer = "VK_LAYER_KHRONOS_validation";
constexpr std::uint64_t kTimeoutNs = 60'000'000'000;  // a frame that never completes fails instead of hanging

// The validation layer's warnings and errors on the test's instance (pyrseg has no messenger there).
struct Messages {
    int count = 0;
    std::vector<std::string> first;
};

VKAPI_ATTR VkBool32 VKAPI_CALL on_message(VkDebugUtilsMessageSeverityFlagBitsEXT /*severity*/,
                                          VkDebugUtilsMessageTypeFlagsEXT /*types*/,
                                          const VkDebugUtilsMessengerCallbackDataEXT* data, void* user) {
    auto* messages = static_cast<Messages*>(user);
    ++messages->count;
    if (messages->first.size() < 5) messages->first.emplace_back(data->pMessage != nullptr ? data->pMessage : "?");
    return VK_FALSE;
}

bool has_layer(const char* name) {
    std::uint32_t count = 0;
    vkEnumerateInstanceLayerProperties(&count, nullptr);
    std::vector<VkLayerProperties> layers(count);
    vkEnumerateInstanceLayerProperties(&count, layers.data());
    return std::any_of(layers.begin(), layers.end(),
                       [&](const VkLayerProperties& l) { return std::strcmp(l.layerName, name) == 0; });
}

bool has_extension(const char* layer, const char* name) {
    std::uint32_t count = 0;
    vkEnumerateInstanceExtensionProperties(layer, &count, nullptr);
    std::vector<VkExtensionProperties> extensions(count);
    vkEnumerateInstanceExtensionProperties(layer, &count, extensions.data());
    return std::any_of(extensions.begin(), extensions.end(),
                       [&](const VkExtensionProperties& e) { return std::strcmp(e.extensionName, name) == 0; });
}

// A host-visible, coherent, mapped VkBuffer: the test writes inputs and reads outputs through the mapping.
struct HostBuffer {
    VkBuffer buffer = VK_NULL_HANDLE;
    VkDeviceMemory memory = VK_NULL_HANDLE;
    VkDeviceSize bytes = 0;
    unsigned char* data = nullptr;
};

// The application's side: the first Vulkan device with a compute queue (lavapipe in CI).
class VulkanApp : public ::testing::Test {
protected:
    void SetUp() override {
        validation_ = has_layer(kValidationLayer) && has_extension(nullptr, VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
        if (!validation_) {
            std::printf("note: %s or VK_EXT_debug_utils is not installed: running without validation\n",
                        kValidationLayer);
        }
        std::vector<const char*> layers;
        std::vector<const char*> extensions;
        const bool sync = validation_ && has_extension(kValidationLayer, VK_EXT_VALIDATION_FEATURES_EXTENSION_NAME);
        if (validation_) {
            layers.push_back(kValidationLayer);
            extensions.push_back(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
            if (sync) extensions.push_back(VK_EXT_VALIDATION_FEATURES_EXTENSION_NAME);
        }
        auto messenger_info = VkDebugUtilsMessengerCreateInfoEXT{};
        messenger_info.sType = VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT;
        messenger_info.messageSeverity =
            VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
        messenger_info.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT |
                                     VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                                     VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
        messenger_info.pfnUserCallback = on_message;
        messenger_info.pUserData = &messages_;
        // Synchronization validation: a missing barrier in pyrseg's frames is a hazard the layer reports.
        const VkValidationFeatureEnableEXT enables[] = {VK_VALIDATION_FEATURE_ENABLE_SYNCHRONIZATION_VALIDATION_EXT};
        auto features = VkValidationFeaturesEXT{};
        features.sType = VK_STRUCTURE_TYPE_VALIDATION_FEATURES_EXT;
        features.pNext = &messenger_info;
        features.enabledValidationFeatureCount = 1;
        features.pEnabledValidationFeatures = enables;
        auto app = VkApplicationInfo{};
        app.sType = VK_STRUCTURE_TYPE_APPLICATION_INFO;
        app.pApplicationName = "pyrseg interop test";
        app.apiVersion = VK_API_VERSION_1_1;
        auto info = VkInstanceCreateInfo{};
        info.sType = VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO;
        info.pNext = validation_ ? (sync ? static_cast<const void*>(&features) : &messenger_info) : nullptr;
        info.pApplicationInfo = &app;
        info.enabledLayerCount = std::uint32_t(layers.size());
        info.ppEnabledLayerNames = layers.data();
        info.enabledExtensionCount = std::uint32_t(extensions.size());
        info.ppEnabledExtensionNames = extensions.data();
        if (vkCreateInstance(&info, nullptr, &instance_) != VK_SUCCESS) {
            instance_ = VK_NULL_HANDLE;
            messages_ = {};  // the loader's own, about the missing driver
            GTEST_SKIP() << "no Vulkan instance (the loader found no driver)";
        }
        if (validation_) {
            auto create = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
                vkGetInstanceProcAddr(instance_, "vkCreateDebugUtilsMessengerEXT"));
            ASSERT_NE(create, nullptr);
            ASSERT_EQ(create(instance_, &messenger_info, nullptr, &messenger_), VK_SUCCESS);
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
            messages_ = {};
            GTEST_SKIP() << "no Vulkan device with a compute queue on this machine";
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
        ASSERT_EQ(vkCreateDevice(physical_, &device_info, nullptr, &device_), VK_SUCCESS);
        vkGetDeviceQueue(device_, family_, 0, &queue_);
        auto pool = VkCommandPoolCreateInfo{};
        pool.sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO;
        pool.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
        pool.queueFamilyIndex = family_;
        ASSERT_EQ(vkCreateCommandPool(device_, &pool, nullptr, &pool_), VK_SUCCESS);
    }

    void TearDown() override {
        if (device_ != VK_NULL_HANDLE) {
            vkDeviceWaitIdle(device_);
            for (const HostBuffer& b : buffers_) {
                vkDestroyBuffer(device_, b.buffer, nullptr);
                vkFreeMemory(device_, b.memory, nullptr);
            }
            for (VkSemaphore s : semaphores_) vkDestroySemaphore(device_, s, nullptr);
            for (VkFence f : fences_) vkDestroyFence(device_, f, nullptr);
            if (pool_ != VK_NULL_HANDLE) vkDestroyCommandPool(device_, pool_, nullptr);
            vkDestroyDevice(device_, nullptr);
        }
        if (messenger_ != VK_NULL_HANDLE) {
            auto destroy = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
                vkGetInstanceProcAddr(instance_, "vkDestroyDebugUtilsMessengerEXT"));
            destroy(instance_, messenger_, nullptr);
        }
        if (instance_ != VK_NULL_HANDLE) vkDestroyInstance(instance_, nullptr);
        EXPECT_EQ(messages_.count, 0) << "the validation layer reported " << messages_.count
                                      << " message(s); the first: "
                                      << (messages_.first.empty() ? "" : messages_.first.front());
        for (const std::string& m : messages_.first) std::printf("validation: %s\n", m.c_str());
    }

    [[nodiscard]] vulkan::Device device() const { return {instance_, physical_, device_, family_, queue_}; }

    HostBuffer& buffer(std::size_t bytes, const void* data = nullptr, std::size_t at = 0) {
        HostBuffer b;
        b.bytes = std::max<std::size_t>(bytes, 4);
        auto info = VkBufferCreateInfo{};
        info.sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO;
        info.size = b.bytes;
        info.usage = VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;
        info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
        EXPECT_EQ(vkCreateBuffer(device_, &info, nullptr, &b.buffer), VK_SUCCESS);
        VkMemoryRequirements req{};
        vkGetBufferMemoryRequirements(device_, b.buffer, &req);
        const VkMemoryPropertyFlags want = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
        std::uint32_t type = 0;
        while (type < memory_.memoryTypeCount &&
               ((req.memoryTypeBits & (1u << type)) == 0 || (memory_.memoryTypes[type].propertyFlags & want) != want))
            ++type;
        EXPECT_LT(type, memory_.memoryTypeCount) << "no host-visible coherent memory";
        auto alloc = VkMemoryAllocateInfo{};
        alloc.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO;
        alloc.allocationSize = req.size;
        alloc.memoryTypeIndex = type;
        EXPECT_EQ(vkAllocateMemory(device_, &alloc, nullptr, &b.memory), VK_SUCCESS);
        EXPECT_EQ(vkBindBufferMemory(device_, b.buffer, b.memory, 0), VK_SUCCESS);
        void* mapped = nullptr;
        EXPECT_EQ(vkMapMemory(device_, b.memory, 0, VK_WHOLE_SIZE, 0, &mapped), VK_SUCCESS);
        b.data = static_cast<unsigned char*>(mapped);
        std::memset(b.data, 0xAB, b.bytes);
        if (data != nullptr) std::memcpy(b.data + at, data, bytes - at);
        buffers_.push_back(b);
        return buffers_.back();
    }

    template <class T>
    std::vector<T> read(const HostBuffer& b, std::size_t count, std::size_t offset = 0) const {
        std::vector<T> out(count);
        std::memcpy(out.data(), b.data + offset, count * sizeof(T));
        return out;
    }

    // A command buffer of the test's pool, in the initial state: recording anything into it is a validation error.
    VkCommandBuffer allocate() {
        auto info = VkCommandBufferAllocateInfo{};
        info.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO;
        info.commandPool = pool_;
        info.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
        info.commandBufferCount = 1;
        VkCommandBuffer commands = VK_NULL_HANDLE;
        EXPECT_EQ(vkAllocateCommandBuffers(device_, &info, &commands), VK_SUCCESS);
        return commands;
    }

    // The same, in the recording state.
    VkCommandBuffer begin() {
        VkCommandBuffer commands = allocate();
        auto begin = VkCommandBufferBeginInfo{};
        begin.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO;
        begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
        EXPECT_EQ(vkBeginCommandBuffer(commands, &begin), VK_SUCCESS);
        return commands;
    }

    VkSemaphore semaphore() {
        auto info = VkSemaphoreCreateInfo{};
        info.sType = VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO;
        VkSemaphore s = VK_NULL_HANDLE;
        EXPECT_EQ(vkCreateSemaphore(device_, &info, nullptr, &s), VK_SUCCESS);
        semaphores_.push_back(s);
        return s;
    }

    VkFence fence() {
        auto info = VkFenceCreateInfo{};
        info.sType = VK_STRUCTURE_TYPE_FENCE_CREATE_INFO;
        VkFence f = VK_NULL_HANDLE;
        EXPECT_EQ(vkCreateFence(device_, &info, nullptr, &f), VK_SUCCESS);
        fences_.push_back(f);
        return f;
    }

    // Submits `commands` (ended here) after `wait` (at all commands), and waits for it.
    void submit_and_wait(VkCommandBuffer commands, VkSemaphore wait = VK_NULL_HANDLE) {
        const VkFence done = fence();
        const VkPipelineStageFlags stage = VK_PIPELINE_STAGE_ALL_COMMANDS_BIT;
        auto info = VkSubmitInfo{};
        info.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO;
        if (wait != VK_NULL_HANDLE) {
            info.waitSemaphoreCount = 1;
            info.pWaitSemaphores = &wait;
            info.pWaitDstStageMask = &stage;
        }
        if (commands != VK_NULL_HANDLE) {
            EXPECT_EQ(vkEndCommandBuffer(commands), VK_SUCCESS);
            info.commandBufferCount = 1;
            info.pCommandBuffers = &commands;
        }
        ASSERT_EQ(vkQueueSubmit(queue_, 1, &info, done), VK_SUCCESS);
        ASSERT_EQ(vkWaitForFences(device_, 1, &done, VK_TRUE, kTimeoutNs), VK_SUCCESS) << "the submission hangs";
        if (commands != VK_NULL_HANDLE) vkFreeCommandBuffers(device_, pool_, 1, &commands);
    }

    bool validation_ = false;
    Messages messages_;
    VkInstance instance_ = VK_NULL_HANDLE;
    VkDebugUtilsMessengerEXT messenger_ = VK_NULL_HANDLE;
    VkPhysicalDevice physical_ = VK_NULL_HANDLE;
    VkPhysicalDeviceMemoryProperties memory_{};
    std::uint32_t family_ = 0;
    VkDevice device_ = VK_NULL_HANDLE;
    VkQueue queue_ = VK_NULL_HANDLE;
    VkCommandPool pool_ = VK_NULL_HANDLE;
    std::deque<HostBuffer> buffers_;  // buffer() hands out references, which push_back keeps valid
    std::vector<VkSemaphore> semaphores_;
    std::vector<VkFence> fences_;
};

// Rows of `width` items of `item` bytes copied `pitch` bytes apart (the rest 0xCD), as an SDK pads them.
std::vector<unsigned char> pitched(const void* packed, int width, int height, std::size_t item, std::size_t pitch) {
    std::vector<unsigned char> out(pitch * std::size_t(height), 0xCD);
    for (int y = 0; y < height; ++y) {
        std::memcpy(out.data() + std::size_t(y) * pitch,
                    static_cast<const unsigned char*>(packed) + std::size_t(y) * std::size_t(width) * item,
                    std::size_t(width) * item);
    }
    return out;
}

// The labels of a device frame's buffer, rows `pitch` bytes apart from `offset` on, packed again.
std::vector<std::uint32_t> unpitch(const unsigned char* bytes, int width, int height, std::size_t pitch) {
    std::vector<std::uint32_t> out(std::size_t(width) * std::size_t(height));
    for (int y = 0; y < height; ++y) {
        std::memcpy(out.data() + std::size_t(y) * std::size_t(width), bytes + std::size_t(y) * pitch,
                    4 * std::size_t(width));
    }
    return out;
}

struct Scene {
    const char* what = "";
    int width = 0;
    int height = 0;
    synthetic::Sensor sensor = synthetic::Sensor::structured_light;
    bool normals = false;
    Params params;
    std::size_t cloud_pad = 0;   // extra bytes per row of points
    std::size_t labels_pad = 0;  // extra bytes per row of labels
};

const Scene kScenes[] = {
    {"paper metric, estimated normals, packed", 131, 97, synthetic::Sensor::structured_light, false, Params{}, 0, 0},
    {"given normals, padded rows", 67, 45, synthetic::Sensor::structured_light, true, Params{}, 20, 12},
    {"kinect-v1 preset (robust metric), padded", 101, 77, synthetic::Sensor::kinect_v1, false,
     sensor_preset(SensorKind::kinect_v1), 4, 4},
    {"a thin strip", 57, 9, synthetic::Sensor::structured_light, false, Params{}, 8, 0},
};

enum class How { record, submit };

// Frames of every scene, several back to back before anything is read, against the CPU backend's host path.
class VulkanCloud : public VulkanApp {
protected:
    void frames(How how);
};

void VulkanCloud::frames(How how) {
    for (const Scene& s : kScenes) {
        SCOPED_TRACE(s.what);
        synthetic::SceneOptions o;
        o.width = s.width;
        o.height = s.height;
        o.sensor = s.sensor;
        const synthetic::Scene scene = synthetic::generate(o);
        CloudView view;
        view.points = scene.points.data();
        view.normals = s.normals ? scene.normals.data() : nullptr;
        view.width = s.width;
        view.height = s.height;
        Segmenter cpu(s.width, s.height, s.params, "cpu");
        const Result expected = cpu.segment(view);
        ASSERT_GT(expected.segment_count, 0u);

        const std::size_t cloud_pitch = 12 * std::size_t(s.width) + s.cloud_pad;
        const std::size_t labels_pitch = 4 * std::size_t(s.width) + s.labels_pad;
        const std::size_t labels_bytes = labels_pitch * std::size_t(s.height);
        const auto points = pitched(scene.points.data(), s.width, s.height, 12, cloud_pitch);
        const auto normals = pitched(scene.normals.data(), s.width, s.height, 12, cloud_pitch);
        Segmenter segmenter = vulkan::make_segmenter(s.width, s.height, device(), s.params);
        EXPECT_EQ(segmenter.backend_name(), "vulkan");
        vulkan::CloudBuffers in;
        // Recorded frames: the test's command buffer itself copies the points into the input buffer, just before
        // the frames read them. Submitted ones: the host writes them.
        const HostBuffer& p = buffer(points.size() + 16);
        const HostBuffer& staging = buffer(points.size() + 16);
        std::memcpy((how == How::record ? staging : p).data + 16, points.data(), points.size());
        in.points = p.buffer;
        in.points_offset = 16;  // data need not start at the buffer's start
        in.points_bytes = p.bytes;
        if (s.normals) {
            const HostBuffer& n = buffer(normals.size(), normals.data());
            in.normals = n.buffer;
            in.normals_bytes = n.bytes;
        }
        in.row_step_bytes = s.cloud_pad == 0 ? 0 : cloud_pitch;

        // Five frames into five label buffers (K into the first and last), all queued before anything is read: the
        // later ones reuse pyrseg's buffers after the earlier ones, in queue order, and the ring of pyrseg's command
        // buffers comes round.
        constexpr int kFrames = 5;
        std::vector<const HostBuffer*> labels;
        std::vector<const HostBuffer*> counts;
        std::vector<vulkan::LabelBuffers> outs;
        labels.reserve(kFrames);
        counts.reserve(kFrames);
        outs.reserve(kFrames);
        for (int f = 0; f < kFrames; ++f) {
            const HostBuffer& l = buffer(labels_bytes + 8);
            const HostBuffer& c = buffer(16);
            vulkan::LabelBuffers out;
            out.labels = l.buffer;
            out.labels_offset = 8;
            out.labels_bytes = l.bytes;
            out.row_step_bytes = s.labels_pad == 0 ? 0 : labels_pitch;
            if (f == 0 || f == kFrames - 1) {
                out.count = c.buffer;
                out.count_offset = 8;
                out.count_bytes = c.bytes;
            }
            labels.push_back(&l);
            counts.push_back(&c);
            outs.push_back(out);
        }
        const HostBuffer& readback = buffer(labels_bytes + 8);
        if (how == How::record) {
            // Two command buffers: the upload and frames 0..2 in the first, frames 3..4 and a copy of the last
            // one's labels in the second, submitted in that order. Synchronization validation reports the copies
            // if pyrseg's frames do not order themselves after the upload and before the copy.
            VkCommandBuffer first = begin();
            const VkBufferCopy upload{16, 16, points.size()};
            vkCmdCopyBuffer(first, staging.buffer, p.buffer, 1, &upload);
            for (int f = 0; f < 3; ++f) vulkan::record(segmenter, first, in, outs[std::size_t(f)]);
            VkCommandBuffer second = begin();
            for (int f = 3; f < kFrames; ++f) vulkan::record(segmenter, second, in, outs[std::size_t(f)]);
            const VkBufferCopy fetch{0, 0, labels_bytes + 8};
            vkCmdCopyBuffer(second, labels.back()->buffer, readback.buffer, 1, &fetch);
            EXPECT_EQ(vkEndCommandBuffer(first), VK_SUCCESS);
            auto info = VkSubmitInfo{};
            info.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO;
            info.commandBufferCount = 1;
            info.pCommandBuffers = &first;
            ASSERT_EQ(vkQueueSubmit(queue_, 1, &info, VK_NULL_HANDLE), VK_SUCCESS);
            submit_and_wait(second);
            vkFreeCommandBuffers(device_, pool_, 1, &first);
        } else {
            // Frame 0 signals a; frame 1 waits for a and signals b; the others follow; the last one's fence tells
            // the test that all of them completed, and the test's own submission then waits for b.
            const VkSemaphore a = semaphore();
            const VkSemaphore b = semaphore();
            const VkFence done = fence();
            const VkPipelineStageFlags stage = VK_PIPELINE_STAGE_TRANSFER_BIT;
            vulkan::submit(segmenter, in, outs[0], {}, {}, {&a, 1});
            vulkan::submit(segmenter, in, outs[1], {&a, 1}, {&stage, 1}, {&b, 1});
            for (int f = 2; f < kFrames - 1; ++f) vulkan::submit(segmenter, in, outs[std::size_t(f)]);
            vulkan::submit(segmenter, in, outs[kFrames - 1], {}, {}, {}, done);
            ASSERT_EQ(vkWaitForFences(device_, 1, &done, VK_TRUE, kTimeoutNs), VK_SUCCESS) << "the frames hang";
            submit_and_wait(VK_NULL_HANDLE, b);
            // Frame 1 waited for a, so a is unsignalled again: signalling it once more is valid (the validation
            // layer reports it otherwise).
            auto signal = VkSubmitInfo{};
            signal.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO;
            signal.signalSemaphoreCount = 1;
            signal.pSignalSemaphores = &a;
            ASSERT_EQ(vkQueueSubmit(queue_, 1, &signal, VK_NULL_HANDLE), VK_SUCCESS);
            submit_and_wait(VK_NULL_HANDLE, a);
            std::memcpy(readback.data, labels.back()->data, labels_bytes + 8);
        }
        EXPECT_TRUE(segmenter.last_timings().empty());
        EXPECT_TRUE(same_bytes("labels copied after the frame",
                               unpitch(readback.data + 8, s.width, s.height, labels_pitch), expected.labels, s.width));

        for (int f = 0; f < kFrames; ++f) {
            SCOPED_TRACE("frame " + std::to_string(f));
            const HostBuffer& l = *labels[std::size_t(f)];
            EXPECT_TRUE(
                same_bytes("labels", unpitch(l.data + 8, s.width, s.height, labels_pitch), expected.labels, s.width));
            EXPECT_EQ(read<std::uint32_t>(l, 2)[1], 0xABABABABu) << "written before the offset";
            if (s.labels_pad != 0) {
                EXPECT_EQ(read<std::uint32_t>(l, 1, 8 + 4 * std::size_t(s.width))[0], 0xABABABABu)
                    << "written in a row's padding";
            }
            const std::uint32_t count = read<std::uint32_t>(*counts[std::size_t(f)], 1, 8)[0];
            if (f == 0 || f == kFrames - 1) {
                EXPECT_EQ(count, expected.segment_count);
            } else {
                EXPECT_EQ(count, 0xABABABABu) << "K written without a count buffer";
            }
        }
        // The same Segmenter's host path, on the test's queue.
        const Result host = segmenter.segment(view);
        EXPECT_TRUE(same_bytes("host path labels", host.labels, expected.labels, s.width));
        EXPECT_EQ(host.segment_count, expected.segment_count);
    }
}

TEST_F(VulkanCloud, FramesRecordedIntoTheCallersCommandBufferMatchTheHostPath) {
    frames(How::record);
}

TEST_F(VulkanCloud, FramesSubmittedWithSemaphoresAndAFenceMatchTheHostPath) {
    frames(How::submit);
}

// The harness itself: the test's messenger sees what the layer reports, hazards between unsynchronised copies
// included, so that a missing barrier in pyrseg's frames fails the tests above.
TEST_F(VulkanApp, TheMessengerSeesValidationErrorsAndHazards) {
    if (!validation_) GTEST_SKIP() << "the validation layer is not installed";
    const HostBuffer& a = buffer(64);
    const HostBuffer& b = buffer(64);
    VkCommandBuffer commands = begin();
    const VkBufferCopy region{0, 0, 64};
    vkCmdCopyBuffer(commands, a.buffer, b.buffer, 1, &region);
    vkCmdFillBuffer(commands, b.buffer, 0, 64, 0);  // writes after a write, with no barrier between
    submit_and_wait(commands);
    ASSERT_GT(messages_.count, 0) << "no hazard reported: synchronization validation is off";
    EXPECT_NE(messages_.first.front().find("SYNC-HAZARD-WRITE-AFTER-WRITE"), std::string::npos)
        << messages_.first.front();
    messages_ = {};
}

TEST_F(VulkanApp, DepthFramesMatchTheHostPath) {
    synthetic::SceneOptions o;
    o.width = 93;
    o.height = 61;
    o.sensor = synthetic::Sensor::kinect_v1;
    const synthetic::Scene scene = synthetic::generate(o);
    const int w = o.width;
    const int h = o.height;
    std::vector<std::uint16_t> u16(std::size_t(w) * std::size_t(h));
    std::vector<float> f32(u16.size());
    for (std::size_t i = 0; i < u16.size(); ++i) {
        const float z = scene.points[3 * i + 2];
        u16[i] = std::isfinite(z) ? std::uint16_t(std::lround(z)) : 0;
        f32[i] = i % 53 == 1 ? -z : z * 0.001f;  // metres; NaN and negative samples are missing data
    }
    const Params params = sensor_preset(SensorKind::kinect_v1);
    Segmenter cpu(w, h, params, "cpu");
    Segmenter segmenter = vulkan::make_segmenter(w, h, device(), params);
    struct Case {
        const char* what;
        const void* samples;
        DepthFormat format;
        std::size_t sample;
        std::size_t pad;
        std::size_t offset;
        double metres_per_unit;
        double fx_scale;
    };
    const Case cases[] = {
        {"u16 mm, packed", u16.data(), DepthFormat::u16, 2, 0, 0, 0.001, 1.0},
        {"u16 mm, rows of 2W+6 bytes, from byte 6", u16.data(), DepthFormat::u16, 2, 6, 6, 0.001, 1.0},
        {"f32 m, rows of 4W+12 bytes, other intrinsics", f32.data(), DepthFormat::f32, 4, 12, 8, 1.0, 1.2},
        {"u16 mm again, first intrinsics", u16.data(), DepthFormat::u16, 2, 2, 2, 0.001, 1.0},
        {"u16 mm, third intrinsics", u16.data(), DepthFormat::u16, 2, 0, 4, 0.001, 0.9},
    };
    struct Frame {
        vulkan::DepthBuffer in;
        vulkan::LabelBuffers out;
        const HostBuffer* labels = nullptr;
        const HostBuffer* count = nullptr;
        Result expected;
    };
    std::vector<Frame> frames;
    for (const Case& c : cases) {
        const std::size_t pitch = c.sample * std::size_t(w) + c.pad;
        const auto bytes = pitched(c.samples, w, h, c.sample, pitch);
        const DepthView view{
            bytes.data(),   c.format,      w, h, pitch, c.metres_per_unit, scene.fx * c.fx_scale, scene.fy,
            scene.cx + 0.3, scene.cy - 0.2};
        Frame f;
        f.expected = cpu.segment(view);
        EXPECT_GT(f.expected.segment_count, 1u) << c.what;
        const HostBuffer& samples = buffer(c.offset + bytes.size());
        std::memcpy(samples.data + c.offset, bytes.data(), bytes.size());
        f.in.samples = samples.buffer;
        f.in.offset = c.offset;
        f.in.bytes = samples.bytes;
        f.in.view = view;
        f.in.view.depth = nullptr;
        f.labels = &buffer(4 * std::size_t(w) * std::size_t(h));
        f.count = &buffer(4);
        f.out.labels = f.labels->buffer;
        f.out.labels_bytes = f.labels->bytes;
        f.out.count = f.count->buffer;
        f.out.count_bytes = f.count->bytes;
        frames.push_back(f);
    }
    const auto check = [&](const char* how) {
        for (std::size_t i = 0; i < frames.size(); ++i) {
            SCOPED_TRACE(std::string(how) + ": " + cases[i].what);
            const Frame& f = frames[i];
            EXPECT_TRUE(
                same_bytes("labels", read<std::uint32_t>(*f.labels, f.expected.labels.size()), f.expected.labels, w));
            EXPECT_EQ(read<std::uint32_t>(*f.count, 1)[0], f.expected.segment_count);
            std::memset(f.labels->data, 0xAB, f.labels->bytes);
            std::memset(f.count->data, 0xAB, f.count->bytes);
        }
    };
    // Every frame recorded into one command buffer before it runs: each carries its own intrinsics' tables.
    VkCommandBuffer commands = begin();
    for (const Frame& f : frames) vulkan::record(segmenter, commands, f.in, f.out);
    submit_and_wait(commands);
    check("recorded");
    // Every frame submitted back to back; the last one's fence says they are done.
    const VkFence done = fence();
    for (std::size_t i = 0; i < frames.size(); ++i)
        vulkan::submit(segmenter, frames[i].in, frames[i].out, {}, {}, {},
                       i + 1 == frames.size() ? done : VK_NULL_HANDLE);
    ASSERT_EQ(vkWaitForFences(device_, 1, &done, VK_TRUE, kTimeoutNs), VK_SUCCESS);
    check("submitted");
    // Host frames and device frames alternate on one Segmenter.
    for (std::size_t i = 0; i < frames.size(); ++i) {
        SCOPED_TRACE(std::string("alternating: ") + cases[i].what);
        const Frame& f = frames[i];
        const HostBuffer* samples = nullptr;
        for (const HostBuffer& b : buffers_) {
            if (b.buffer == f.in.samples) samples = &b;
        }
        ASSERT_NE(samples, nullptr);
        DepthView view = f.in.view;
        view.depth = samples->data + f.in.offset;
        const Result host = segmenter.segment(view);
        EXPECT_TRUE(same_bytes("host labels", host.labels, f.expected.labels, w));
        VkCommandBuffer one = begin();
        vulkan::record(segmenter, one, f.in, f.out);
        submit_and_wait(one);
    }
    check("alternating");
}

TEST_F(VulkanApp, MakeSegmenterChecksTheDevice) {
    const auto expect_error = [&](const vulkan::Device& d, const std::string& words) {
        SCOPED_TRACE(words);
        try {
            Segmenter s = vulkan::make_segmenter(16, 16, d);
            ADD_FAILURE() << "no error; expected one naming " << words;
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
        }
    };
    vulkan::Device d = device();
    d.instance = VK_NULL_HANDLE;
    expect_error(d, "instance is VK_NULL_HANDLE");
    d = device();
    d.physical = VK_NULL_HANDLE;
    expect_error(d, "physical device is VK_NULL_HANDLE");
    d = device();
    d.device = VK_NULL_HANDLE;
    expect_error(d, "device is VK_NULL_HANDLE");
    d = device();
    d.queue = VK_NULL_HANDLE;
    expect_error(d, "queue is VK_NULL_HANDLE");
    d = device();
    d.queue_family = 1000;
    expect_error(d, "queue family 1000 does not exist");

    // A physical device of another instance.
    auto info = VkInstanceCreateInfo{};
    info.sType = VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO;
    auto app = VkApplicationInfo{};
    app.sType = VK_STRUCTURE_TYPE_APPLICATION_INFO;
    app.apiVersion = VK_API_VERSION_1_1;
    info.pApplicationInfo = &app;
    VkInstance other = VK_NULL_HANDLE;
    ASSERT_EQ(vkCreateInstance(&info, nullptr, &other), VK_SUCCESS);
    std::uint32_t count = 1;
    VkPhysicalDevice other_physical = VK_NULL_HANDLE;
    vkEnumeratePhysicalDevices(other, &count, &other_physical);
    if (other_physical != VK_NULL_HANDLE && other_physical != physical_) {
        d = device();
        d.physical = other_physical;
        expect_error(d, "not one of the instance's");
    }
    vkDestroyInstance(other, nullptr);

    // Segmenters on the same device share pipelines; each works alone.
    Segmenter a = vulkan::make_segmenter(16, 16, device());
    Segmenter b = vulkan::make_segmenter(32, 8, device());
    EXPECT_EQ(a.backend_name(), "vulkan");
    EXPECT_EQ(b.backend_name(), "vulkan");
}

TEST_F(VulkanApp, BadInputIsAnErrorAndRecordsSubmitsAndWritesNothing) {
    constexpr int kW = 32;
    constexpr int kH = 24;
    constexpr std::size_t kPixels = std::size_t(kW) * kH;
    std::vector<float> points(3 * kPixels);
    for (std::size_t i = 0; i < kPixels; ++i) {  // a wall 1 m away, 2 mm between pixels
        points[3 * i] = float(2 * int(i % kW) - kW);
        points[3 * i + 1] = float(2 * int(i / kW) - kH);
        points[3 * i + 2] = 1000.0f;
    }
    std::vector<std::uint16_t> depth(kPixels, 1000);
    Segmenter segmenter = vulkan::make_segmenter(kW, kH, device());
    const std::vector<std::uint32_t> sentinel(kPixels, 0xDEADBEEFu);
    const HostBuffer& points_buffer = buffer(4 * points.size(), points.data());
    const HostBuffer& depth_buffer = buffer(2 * depth.size(), depth.data());
    const HostBuffer& labels_buffer = buffer(4 * sentinel.size(), sentinel.data());
    const HostBuffer& count_buffer = buffer(4, sentinel.data());
    vulkan::CloudBuffers good_cloud;
    good_cloud.points = points_buffer.buffer;
    good_cloud.points_bytes = points_buffer.bytes;
    vulkan::DepthBuffer good_depth;
    good_depth.samples = depth_buffer.buffer;
    good_depth.bytes = depth_buffer.bytes;
    good_depth.view = DepthView{nullptr, DepthFormat::u16, kW, kH, 0, 0.001, 500, 500, 16, 12};
    vulkan::LabelBuffers good_out;
    good_out.labels = labels_buffer.buffer;
    good_out.labels_bytes = labels_buffer.bytes;
    good_out.count = count_buffer.buffer;
    good_out.count_bytes = count_buffer.bytes;
    const VkFence unused = fence();
    const auto untouched = [&] {
        EXPECT_EQ(read<std::uint32_t>(labels_buffer, sentinel.size()), sentinel) << "the labels buffer was written";
        EXPECT_EQ(read<std::uint32_t>(count_buffer, 1)[0], 0xDEADBEEFu) << "the count was written";
    };
    // Each refusal: recorded into a command buffer that was never begun (anything recorded there would be a
    // validation error), recorded alone into a fresh command buffer that then runs, and submitted with a fence
    // that must stay unsignalled: none of them records or writes a thing.
    const auto expect_error = [&](const auto& frame, const vulkan::LabelBuffers& out, const std::string& words) {
        SCOPED_TRACE(words);
        VkCommandBuffer initial = allocate();
        EXPECT_THROW(vulkan::record(segmenter, initial, frame, out), Error);
        vkFreeCommandBuffers(device_, pool_, 1, &initial);
        EXPECT_EQ(messages_.count, 0) << "recorded into the command buffer before the checks";
        VkCommandBuffer commands = begin();
        try {
            vulkan::record(segmenter, commands, frame, out);
            ADD_FAILURE() << "record: no error; expected one naming " << words;
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
        }
        submit_and_wait(commands);
        untouched();
        try {
            vulkan::submit(segmenter, frame, out, {}, {}, {}, unused);
            ADD_FAILURE() << "submit: no error; expected one naming " << words;
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
        }
        ASSERT_EQ(vkQueueWaitIdle(queue_), VK_SUCCESS);
        EXPECT_EQ(vkGetFenceStatus(device_, unused), VK_NOT_READY) << "something was submitted";
        untouched();
    };

    vulkan::CloudBuffers c = good_cloud;
    c.points_bytes -= 4;
    expect_error(c, good_out, "needs");  // one float short
    c = good_cloud;
    c.points_offset = 8;
    expect_error(c, good_out, "needs");  // the offset leaves too little
    c = good_cloud;
    c.points_offset = c.points_bytes + 64;
    expect_error(c, good_out, "holds 0 bytes");  // past the end
    c = good_cloud;
    c.row_step_bytes = 12 * kW - 4;
    expect_error(c, good_out, "smaller than a row");
    c = good_cloud;
    c.row_step_bytes = 12 * kW + 2;
    expect_error(c, good_out, "multiples of 4");
    c = good_cloud;
    c.points = VK_NULL_HANDLE;
    expect_error(c, good_out, "points buffer is missing");
    c = good_cloud;
    c.normals = points_buffer.buffer;
    c.normals_bytes = 100;
    expect_error(c, good_out, "normals buffer holds 100 bytes");
    vulkan::LabelBuffers o = good_out;
    o.count_offset = 4;
    expect_error(good_cloud, o, "segment count buffer holds 0 bytes");
    o = good_out;
    o.row_step_bytes = 4 * kW + 4;  // rows that no longer fit the buffer
    expect_error(good_cloud, o, "needs");
    o = good_out;
    o.labels_offset = 2;
    expect_error(good_cloud, o, "multiples of 4");
    o = good_out;
    o.labels = VK_NULL_HANDLE;
    expect_error(good_cloud, o, "labels buffer is missing");

    vulkan::DepthBuffer d = good_depth;
    for (const double m : {0.0, -0.001, std::nan(""), double(INFINITY)}) {
        d = good_depth;
        d.view.metres_per_unit = m;
        expect_error(d, good_out, "metres_per_unit");
    }
    d = good_depth;
    d.view.fx = 0;
    expect_error(d, good_out, "fx");
    d = good_depth;
    d.view.fy = std::nan("");
    expect_error(d, good_out, "fy");
    d = good_depth;
    d.view.cx = INFINITY;
    expect_error(d, good_out, "cx");
    d = good_depth;
    d.view.depth = depth.data();
    expect_error(d, good_out, "must be null");
    d = good_depth;
    d.view.row_step_bytes = 2 * kW + 1;
    expect_error(d, good_out, "multiples of 2");
    d = good_depth;
    d.bytes -= 2;
    expect_error(d, good_out, "depth samples buffer holds");
    d = good_depth;
    d.view.width = kW - 1;
    expect_error(d, good_out, "31 x 24");

    // The command buffer, the semaphores, and Segmenters that are not on the test's device.
    const auto expect_throw = [&](const auto& call, const std::string& words) {
        SCOPED_TRACE(words);
        try {
            call();
            ADD_FAILURE() << "no error; expected one naming " << words;
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
        }
        ASSERT_EQ(vkQueueWaitIdle(queue_), VK_SUCCESS);
        EXPECT_EQ(vkGetFenceStatus(device_, unused), VK_NOT_READY) << "something was submitted";
        untouched();
    };
    expect_throw([&] { vulkan::record(segmenter, VK_NULL_HANDLE, good_cloud, good_out); }, "VK_NULL_HANDLE");
    const VkSemaphore s = semaphore();
    const VkPipelineStageFlags stages[] = {VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT};
    expect_throw(
        [&] {
            vulkan::submit(segmenter, good_cloud, good_out, {&s, 1}, stages, {}, unused);
        },
        "wait has 1 semaphore(s) but wait_stages has 2");
    expect_throw(
        [&] {
            vulkan::submit(segmenter, good_depth, good_out, {&s, 1}, {}, {}, unused);
        },
        "wait has 1 semaphore(s) but wait_stages has 0");
    const VkSemaphore null_semaphore = VK_NULL_HANDLE;
    expect_throw(
        [&] {
            vulkan::submit(segmenter, good_cloud, good_out, {}, {}, {&null_semaphore, 1}, unused);
        },
        "signal[0] is a VK_NULL_HANDLE");
    const VkPipelineStageFlags no_stage = 0;
    expect_throw(
        [&] {
            vulkan::submit(segmenter, good_cloud, good_out, {&s, 1}, {&no_stage, 1}, {}, unused);
        },
        "wait_stages[0] is 0");
    Segmenter cpu(kW, kH, {}, "cpu");
    expect_throw(
        [&] {
            VkCommandBuffer commands = begin();
            try {
                vulkan::record(cpu, commands, good_cloud, good_out);
            } catch (...) {
                submit_and_wait(commands);
                throw;
            }
        },
        "does not run on Vulkan");
    expect_throw([&] { vulkan::submit(cpu, good_depth, good_out, {}, {}, {}, unused); }, "does not run on Vulkan");
    Segmenter moved = std::move(cpu);
    expect_throw([&] { vulkan::submit(cpu, good_cloud, good_out); }, "moved from");  // NOLINT(bugprone-use-after-move)

    // After every refusal the Segmenter still segments, both ways.
    VkCommandBuffer commands = begin();
    vulkan::record(segmenter, commands, good_cloud, good_out);
    submit_and_wait(commands);
    EXPECT_EQ(read<std::uint32_t>(count_buffer, 1)[0], 1u) << "a flat wall at 1 m: one segment";
    std::memset(count_buffer.data, 0, 4);
    vulkan::submit(segmenter, good_depth, good_out, {}, {}, {}, unused);
    ASSERT_EQ(vkWaitForFences(device_, 1, &unused, VK_TRUE, kTimeoutNs), VK_SUCCESS);
    EXPECT_EQ(read<std::uint32_t>(count_buffer, 1)[0], 1u) << "a flat wall at 1 m: one segment";
}

// A Segmenter on pyrseg's own Vulkan device takes no buffers of the caller's.
TEST_F(VulkanApp, ASegmenterOnPyrsegsOwnDeviceIsRefused) {
    bool available = false;
    for (const BackendInfo& b : list_backends()) available = available || (b.name == "vulkan" && b.available);
    if (!available) GTEST_SKIP() << "pyrseg's own Vulkan device is unavailable";
    Segmenter own(16, 16, {}, "vulkan");
    constexpr std::size_t kPixels = std::size_t(16) * 16;
    const HostBuffer& labels = buffer(4 * kPixels);
    vulkan::CloudBuffers in;
    in.points = buffer(12 * kPixels).buffer;
    in.points_bytes = 12 * kPixels;
    vulkan::LabelBuffers out;
    out.labels = labels.buffer;
    out.labels_bytes = labels.bytes;
    VkCommandBuffer commands = begin();
    try {
        vulkan::record(own, commands, in, out);
        ADD_FAILURE() << "no error";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("pyrseg's own Vulkan device"), std::string::npos) << e.what();
    }
    submit_and_wait(commands);
}

}  // namespace
}  // namespace pyrseg::test
