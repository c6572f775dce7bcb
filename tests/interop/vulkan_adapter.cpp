#include "interop/vulkan_adapter.hpp"

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <exception>
#include <variant>

namespace pyrseg::test {
namespace {

std::unique_ptr<Adapter> make_vulkan_adapter() {
    return std::make_unique<VulkanAdapter>();
}

INSTANTIATE_TEST_SUITE_P(Vulkan, DeviceFrames, ::testing::Values(AdapterMaker{"vulkan", &make_vulkan_adapter}),
                         adapter_name);

constexpr const char* kValidationLayer = "VK_LAYER_KHRONOS_validation";

VKAPI_ATTR VkBool32 VKAPI_CALL on_message(VkDebugUtilsMessageSeverityFlagBitsEXT /*severity*/,
                                          VkDebugUtilsMessageTypeFlagsEXT /*types*/,
                                          const VkDebugUtilsMessengerCallbackDataEXT* data, void* user) {
    auto* messages = static_cast<ValidationMessages*>(user);
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

// A frame's input region: the buffer the recorded way fills by a copy in its own command buffer.
const Region& input_of(const Frame& frame) {
    return std::holds_alternative<CloudFrame>(frame.in) ? std::get<CloudFrame>(frame.in).points
                                                        : std::get<DepthFrame>(frame.in).samples;
}

}  // namespace

VulkanAdapter::~VulkanAdapter() {
    if (device_ && device_->device() != VK_NULL_HANDLE) {
        vkDeviceWaitIdle(device_->device());
        for (const VulkanDevice::Buffer& b : buffers_) device_->destroy(b);
        for (VkSemaphore s : semaphores_) vkDestroySemaphore(device_->device(), s, nullptr);
        for (VkFence f : fences_) vkDestroyFence(device_->device(), f, nullptr);
        if (pool_ != VK_NULL_HANDLE) vkDestroyCommandPool(device_->device(), pool_, nullptr);
    }
    device_.reset();  // the device, then the messenger, which sees both, then the instance
    EXPECT_EQ(messages_.count, 0) << "the validation layer reported " << messages_.count << " message(s); the first: "
                                  << (messages_.first.empty() ? "" : messages_.first.front());
    for (const std::string& m : messages_.first) std::printf("validation: %s\n", m.c_str());
}

std::string VulkanAdapter::open() {
    validation_ = has_layer(kValidationLayer) && has_extension(nullptr, VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
    if (!validation_) {
        std::printf("note: %s or VK_EXT_debug_utils is not installed: running without validation\n", kValidationLayer);
    }
    VulkanDeviceOptions options;
    options.application = "pyrseg interop test";
    const bool sync = validation_ && has_extension(kValidationLayer, VK_EXT_VALIDATION_FEATURES_EXTENSION_NAME);
    auto messenger = VkDebugUtilsMessengerCreateInfoEXT{};
    messenger.sType = VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT;
    messenger.messageSeverity =
        VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
    messenger.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT |
                            VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                            VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
    messenger.pfnUserCallback = on_message;
    messenger.pUserData = &messages_;
    // Synchronization validation: a missing barrier in pyrseg's frames is a hazard the layer reports.
    const VkValidationFeatureEnableEXT enables[] = {VK_VALIDATION_FEATURE_ENABLE_SYNCHRONIZATION_VALIDATION_EXT};
    auto features = VkValidationFeaturesEXT{};
    features.sType = VK_STRUCTURE_TYPE_VALIDATION_FEATURES_EXT;
    features.pNext = &messenger;
    features.enabledValidationFeatureCount = 1;
    features.pEnabledValidationFeatures = enables;
    if (validation_) {
        options.layers.push_back(kValidationLayer);
        options.extensions.push_back(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
        if (sync) options.extensions.push_back(VK_EXT_VALIDATION_FEATURES_EXTENSION_NAME);
        options.instance_next = sync ? static_cast<const void*>(&features) : &messenger;
        options.messenger = &messenger;
    }
    device_.emplace(options);
    if (!device_->why_unavailable().empty()) {
        messages_ = {};  // the loader's own, about the missing driver or device
        return device_->why_unavailable();
    }
    auto pool = VkCommandPoolCreateInfo{};
    pool.sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO;
    pool.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
    pool.queueFamilyIndex = device_->family();
    EXPECT_EQ(vkCreateCommandPool(vk_device(), &pool, nullptr, &pool_), VK_SUCCESS);
    return "";
}

std::vector<Way> VulkanAdapter::ways() const {
    return {{"recorded into the caller's command buffers"},
            {"submitted with semaphores and a fence"},
            {"recorded into a command buffer never begun", true}};
}

Segmenter VulkanAdapter::make_segmenter(int width, int height, const Params& params, const Outputs& outputs) {
    return vulkan::make_segmenter(width, height, device(), params, outputs);
}

int VulkanAdapter::allocate(std::size_t bytes) {
    const VulkanDevice::Buffer b = device_->make_buffer(
        std::max<std::size_t>(bytes, 4), VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT);
    EXPECT_NE(b.mapped, nullptr) << "no host-visible coherent memory";
    if (b.mapped != nullptr) std::memset(b.mapped, 0xAB, b.bytes);
    buffers_.push_back(b);
    return int(buffers_.size()) - 1;
}

std::size_t VulkanAdapter::size(int buffer) const {
    return this->buffer(buffer).bytes;
}

void VulkanAdapter::upload(int buffer, std::size_t offset, const void* data, std::size_t bytes) {
    std::memcpy(this->buffer(buffer).mapped + offset, data, bytes);
}

std::vector<unsigned char> VulkanAdapter::download(int buffer, std::size_t offset, std::size_t bytes) {
    EXPECT_EQ(vkQueueWaitIdle(queue()), VK_SUCCESS);
    const unsigned char* at = this->buffer(buffer).mapped + offset;
    return {at, at + bytes};
}

void VulkanAdapter::run(Segmenter& segmenter, std::span<const Frame> frames, std::size_t way) {
    switch (way) {
        case recorded:
            return run_recorded(segmenter, frames);
        case submitted:
            return run_submitted(segmenter, frames);
        default:
            return run_never_begun(segmenter, frames);
    }
}

// Two command buffers: a copy that fills the first frame's input and the first half of the frames in the first,
// the rest and a copy of the last frame's labels in the second, submitted in that order. Synchronization validation
// reports the copies if pyrseg's frames do not order themselves after the upload and before the read-back.
void VulkanAdapter::run_recorded(Segmenter& segmenter, std::span<const Frame> frames) {
    const std::size_t half = (frames.size() + 1) / 2;
    // A refusal's frame may name no input or no labels buffer: then there is nothing to copy in or out.
    const Region& input = input_of(frames.front());
    const int labels = frames.back().out.labels.buffer;
    VkCommandBuffer first = begin();
    VkCommandBuffer second = begin();
    if (input.buffer != Region::kNone) {
        const VulkanDevice::Buffer& target = buffer(input.buffer);
        const VulkanDevice::Buffer& staging = buffer(allocate(target.bytes));
        std::memcpy(staging.mapped, target.mapped, target.bytes);
        std::memset(target.mapped, 0xAB, target.bytes);
        const VkBufferCopy upload{0, 0, target.bytes};
        vkCmdCopyBuffer(first, staging.buffer, target.buffer, 1, &upload);
    }
    // A refused frame: what was recorded before it runs all the same, and the test checks that it wrote nothing.
    std::exception_ptr refusal;
    try {
        for (std::size_t f = 0; f < frames.size(); ++f) record(segmenter, f < half ? first : second, frames[f]);
    } catch (...) {
        refusal = std::current_exception();
    }
    const VulkanDevice::Buffer* last = nullptr;
    const VulkanDevice::Buffer* readback = nullptr;
    if (!refusal && labels != Region::kNone) {
        last = &buffer(labels);
        readback = &buffer(allocate(last->bytes));
        const VkBufferCopy fetch{0, 0, last->bytes};
        vkCmdCopyBuffer(second, last->buffer, readback->buffer, 1, &fetch);
    }
    EXPECT_EQ(vkEndCommandBuffer(first), VK_SUCCESS);
    auto info = VkSubmitInfo{};
    info.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO;
    info.commandBufferCount = 1;
    info.pCommandBuffers = &first;
    EXPECT_EQ(vkQueueSubmit(queue(), 1, &info, VK_NULL_HANDLE), VK_SUCCESS);
    submit_and_wait(second);
    free(first);
    if (refusal) std::rethrow_exception(refusal);
    if (last != nullptr) {
        EXPECT_EQ(std::memcmp(readback->mapped, last->mapped, last->bytes), 0)
            << "the labels copied after the frames differ";
    }
}

// Frame 0 signals a; frame 1 waits for a and signals b; the others follow; the last one's fence tells the test that
// all of them completed, and the test's own submission then waits for b.
void VulkanAdapter::run_submitted(Segmenter& segmenter, std::span<const Frame> frames) {
    const VkSemaphore a = semaphore();
    const VkSemaphore b = semaphore();
    const VkFence done = fence();
    const VkPipelineStageFlags stage = VK_PIPELINE_STAGE_TRANSFER_BIT;
    const std::size_t n = frames.size();
    for (std::size_t f = 0; f < n; ++f) {
        const std::span<const VkSemaphore> wait = f == 1 ? std::span(&a, 1) : std::span<const VkSemaphore>();
        const std::span<const VkPipelineStageFlags> stages =
            f == 1 ? std::span(&stage, 1) : std::span<const VkPipelineStageFlags>();
        std::span<const VkSemaphore> signal;
        if (f == 0 && n > 1) signal = std::span(&a, 1);
        if (f == 1) signal = std::span(&b, 1);
        try {
            submit(segmenter, frames[f], wait, stages, signal, f + 1 == n ? done : VK_NULL_HANDLE);
        } catch (...) {
            EXPECT_EQ(vkQueueWaitIdle(queue()), VK_SUCCESS);
            EXPECT_EQ(vkGetFenceStatus(vk_device(), done), VK_NOT_READY) << "something was submitted";
            throw;
        }
    }
    ASSERT_EQ(vkWaitForFences(vk_device(), 1, &done, VK_TRUE, kVulkanTimeoutNs), VK_SUCCESS) << "the frames hang";
    if (n < 2) return;
    submit_and_wait(VK_NULL_HANDLE, b);
    // Frame 1 waited for a, so a is unsignalled again: signalling it once more is valid (the validation layer
    // reports it otherwise).
    auto signal = VkSubmitInfo{};
    signal.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO;
    signal.signalSemaphoreCount = 1;
    signal.pSignalSemaphores = &a;
    ASSERT_EQ(vkQueueSubmit(queue(), 1, &signal, VK_NULL_HANDLE), VK_SUCCESS);
    submit_and_wait(VK_NULL_HANDLE, a);
}

// Refusals only: a frame refused before pyrseg records anything leaves a command buffer that was never begun
// untouched, which the validation layer would report otherwise.
void VulkanAdapter::run_never_begun(Segmenter& segmenter, std::span<const Frame> frames) {
    VkCommandBuffer initial = allocate_commands();
    try {
        for (const Frame& f : frames) record(segmenter, initial, f);
    } catch (...) {
        free(initial);
        EXPECT_EQ(messages_.count, 0) << "recorded into the command buffer before the checks";
        throw;
    }
    free(initial);
}

void VulkanAdapter::record(Segmenter& segmenter, VkCommandBuffer commands, const Frame& frame) const {
    const vulkan::LabelBuffers out = labels(frame.out);
    if (std::holds_alternative<CloudFrame>(frame.in)) {
        vulkan::record(segmenter, commands, cloud(std::get<CloudFrame>(frame.in)), out);
    } else {
        vulkan::record(segmenter, commands, depth(std::get<DepthFrame>(frame.in)), out);
    }
}

void VulkanAdapter::submit(Segmenter& segmenter, const Frame& frame, std::span<const VkSemaphore> wait,
                           std::span<const VkPipelineStageFlags> stages, std::span<const VkSemaphore> signal,
                           VkFence fence) const {
    const vulkan::LabelBuffers out = labels(frame.out);
    if (std::holds_alternative<CloudFrame>(frame.in)) {
        vulkan::submit(segmenter, cloud(std::get<CloudFrame>(frame.in)), out, wait, stages, signal, fence);
    } else {
        vulkan::submit(segmenter, depth(std::get<DepthFrame>(frame.in)), out, wait, stages, signal, fence);
    }
}

vulkan::CloudBuffers VulkanAdapter::cloud(const CloudFrame& frame) const {
    vulkan::CloudBuffers c;
    if (frame.points.buffer != Region::kNone) {
        c.points = buffer(frame.points.buffer).buffer;
        c.points_offset = frame.points.offset;
        c.points_bytes = buffer(frame.points.buffer).bytes;
    }
    if (frame.normals.buffer != Region::kNone) {
        c.normals = buffer(frame.normals.buffer).buffer;
        c.normals_offset = frame.normals.offset;
        c.normals_bytes = buffer(frame.normals.buffer).bytes;
    }
    c.row_step_bytes = frame.row_step_bytes;
    if (frame.color.buffer != Region::kNone) {
        c.color = buffer(frame.color.buffer).buffer;
        c.color_offset = frame.color.offset;
        c.color_bytes = buffer(frame.color.buffer).bytes;
    }
    c.color_row_step_bytes = frame.color_row_step_bytes;
    return c;
}

vulkan::DepthBuffer VulkanAdapter::depth(const DepthFrame& frame) const {
    vulkan::DepthBuffer d;
    if (frame.samples.buffer != Region::kNone) {
        d.samples = buffer(frame.samples.buffer).buffer;
        d.offset = frame.samples.offset;
        d.bytes = buffer(frame.samples.buffer).bytes;
    }
    d.view = frame.view;
    if (frame.color.buffer != Region::kNone) {
        d.color = buffer(frame.color.buffer).buffer;
        d.color_offset = frame.color.offset;
        d.color_bytes = buffer(frame.color.buffer).bytes;
    }
    d.color_row_step_bytes = frame.color_row_step_bytes;
    return d;
}

vulkan::LabelBuffers VulkanAdapter::labels(const LabelFrame& frame) const {
    vulkan::LabelBuffers l;
    if (frame.labels.buffer != Region::kNone) {
        l.labels = buffer(frame.labels.buffer).buffer;
        l.labels_offset = frame.labels.offset;
        l.labels_bytes = buffer(frame.labels.buffer).bytes;
    }
    l.row_step_bytes = frame.row_step_bytes;
    if (frame.count.buffer != Region::kNone) {
        l.count = buffer(frame.count.buffer).buffer;
        l.count_offset = frame.count.offset;
        l.count_bytes = buffer(frame.count.buffer).bytes;
    }
    if (frame.statistics.buffer != Region::kNone) {
        l.statistics = buffer(frame.statistics.buffer).buffer;
        l.statistics_offset = frame.statistics.offset;
        l.statistics_bytes = buffer(frame.statistics.buffer).bytes;
    }
    if (frame.graph.buffer != Region::kNone) {
        l.graph = buffer(frame.graph.buffer).buffer;
        l.graph_offset = frame.graph.offset;
        l.graph_bytes = buffer(frame.graph.buffer).bytes;
    }
    if (frame.tracks.buffer != Region::kNone) {
        l.tracks = buffer(frame.tracks.buffer).buffer;
        l.tracks_offset = frame.tracks.offset;
        l.tracks_bytes = buffer(frame.tracks.buffer).bytes;
    }
    return l;
}

VkCommandBuffer VulkanAdapter::allocate_commands() {
    auto info = VkCommandBufferAllocateInfo{};
    info.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO;
    info.commandPool = pool_;
    info.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    info.commandBufferCount = 1;
    VkCommandBuffer commands = VK_NULL_HANDLE;
    EXPECT_EQ(vkAllocateCommandBuffers(vk_device(), &info, &commands), VK_SUCCESS);
    return commands;
}

VkCommandBuffer VulkanAdapter::begin() {
    VkCommandBuffer commands = allocate_commands();
    auto begin = VkCommandBufferBeginInfo{};
    begin.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO;
    begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    EXPECT_EQ(vkBeginCommandBuffer(commands, &begin), VK_SUCCESS);
    return commands;
}

VkSemaphore VulkanAdapter::semaphore() {
    auto info = VkSemaphoreCreateInfo{};
    info.sType = VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO;
    VkSemaphore s = VK_NULL_HANDLE;
    EXPECT_EQ(vkCreateSemaphore(vk_device(), &info, nullptr, &s), VK_SUCCESS);
    semaphores_.push_back(s);
    return s;
}

VkFence VulkanAdapter::fence() {
    auto info = VkFenceCreateInfo{};
    info.sType = VK_STRUCTURE_TYPE_FENCE_CREATE_INFO;
    VkFence f = VK_NULL_HANDLE;
    EXPECT_EQ(vkCreateFence(vk_device(), &info, nullptr, &f), VK_SUCCESS);
    fences_.push_back(f);
    return f;
}

void VulkanAdapter::submit_and_wait(VkCommandBuffer commands, VkSemaphore wait) {
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
    ASSERT_EQ(vkQueueSubmit(queue(), 1, &info, done), VK_SUCCESS);
    ASSERT_EQ(vkWaitForFences(vk_device(), 1, &done, VK_TRUE, kVulkanTimeoutNs), VK_SUCCESS) << "the submission hangs";
    if (commands != VK_NULL_HANDLE) free(commands);
}

void VulkanAdapter::free(VkCommandBuffer commands) {
    vkFreeCommandBuffers(vk_device(), pool_, 1, &commands);
}

}  // namespace pyrseg::test
