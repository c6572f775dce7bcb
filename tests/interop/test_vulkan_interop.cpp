// What only Vulkan's interop has, on the adapter's instance, device and queue (vulkan_adapter.hpp, with the
// validation layer; the checks every API shares are device_frames.cpp): the test's messenger sees the layer's
// hazards, make_segmenter checks the device it is given, buffer sizes and offsets the caller states are checked, the
// command buffer and semaphores are, a Segmenter on pyrseg's own device or moved from takes no buffers, and a frame
// with tracks recorded once runs as the stream's next frame each time it is submitted.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <string>
#include <utility>
#include <vector>

#include "interop/vulkan_adapter.hpp"
#include "pyrseg/backend.hpp"

namespace pyrseg::test {
namespace {

using VulkanInterop = ApiTest<VulkanAdapter>;

// The harness itself: the test's messenger sees what the layer reports, hazards between unsynchronised copies
// included, so that a missing barrier in pyrseg's frames fails the shared tests.
TEST_F(VulkanInterop, TheMessengerSeesValidationErrorsAndHazards) {
    VulkanAdapter& vk = api();
    if (!vk.validation_) GTEST_SKIP() << "the validation layer is not installed";
    const VulkanDevice::Buffer& a = vk.buffer(vk.allocate(64));
    const VulkanDevice::Buffer& b = vk.buffer(vk.allocate(64));
    VkCommandBuffer commands = vk.begin();
    const VkBufferCopy region{0, 0, 64};
    vkCmdCopyBuffer(commands, a.buffer, b.buffer, 1, &region);
    vkCmdFillBuffer(commands, b.buffer, 0, 64, 0);  // writes after a write, with no barrier between
    vk.submit_and_wait(commands);
    ASSERT_GT(vk.messages_.count, 0) << "no hazard reported: synchronization validation is off";
    EXPECT_NE(vk.messages_.first.front().find("SYNC-HAZARD-WRITE-AFTER-WRITE"), std::string::npos)
        << vk.messages_.first.front();
    vk.messages_ = {};
}

TEST_F(VulkanInterop, MakeSegmenterChecksTheDevice) {
    VulkanAdapter& vk = api();
    const auto refused = [&](const vulkan::Device& d, const std::string& words) {
        expect_error([&] { Segmenter s = vulkan::make_segmenter(16, 16, d); }, words);
    };
    vulkan::Device d = vk.device();
    d.instance = VK_NULL_HANDLE;
    refused(d, "instance is VK_NULL_HANDLE");
    d = vk.device();
    d.physical = VK_NULL_HANDLE;
    refused(d, "physical device is VK_NULL_HANDLE");
    d = vk.device();
    d.device = VK_NULL_HANDLE;
    refused(d, "device is VK_NULL_HANDLE");
    d = vk.device();
    d.queue = VK_NULL_HANDLE;
    refused(d, "queue is VK_NULL_HANDLE");
    d = vk.device();
    d.queue_family = 1000;
    refused(d, "queue family 1000 does not exist");

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
    if (other_physical != VK_NULL_HANDLE && other_physical != vk.physical()) {
        d = vk.device();
        d.physical = other_physical;
        refused(d, "not one of the instance's");
    }
    vkDestroyInstance(other, nullptr);

    // Segmenters on the same device share pipelines; each works alone.
    Segmenter a = vulkan::make_segmenter(16, 16, vk.device());
    Segmenter b = vulkan::make_segmenter(32, 8, vk.device());
    EXPECT_EQ(a.backend_name(), "vulkan");
    EXPECT_EQ(b.backend_name(), "vulkan");
}

// Vulkan cannot ask a buffer its size: the caller states it, with the offsets, and pyrseg checks what it states.
TEST_F(VulkanInterop, StatedSizesAndOffsetsAreChecked) {
    VulkanAdapter& vk = api();
    Refusals r(vk);
    CloudFrame c = r.cloud;
    c.points.offset = vk.size(c.points.buffer) + 64;
    r.expect({c, r.out}, "holds 0 bytes");  // past the end
    c = r.cloud;
    c.normals = {vk.allocate(100), 0};
    r.expect({c, r.out}, "normals buffer holds 100 bytes");
    LabelFrame o = r.out;
    o.count.offset = 4;
    r.expect({r.cloud, o}, "segment count buffer holds 0 bytes");
    o = r.out;
    o.labels.offset = 2;
    r.expect({r.cloud, o}, "multiples of 4");
    DepthFrame d = r.depth;
    d.samples = {vk.allocate(2 * r.wall.depth.size() - 2), 0};
    r.expect({d, r.out}, "depth samples buffer holds");
    r.expect_still_segments();
}

TEST_F(VulkanInterop, TheCommandBufferSemaphoresAndSegmenterAreChecked) {
    VulkanAdapter& vk = api();
    Refusals r(vk);
    const vulkan::CloudBuffers cloud = vk.cloud(r.cloud);
    const vulkan::DepthBuffer depth = vk.depth(r.depth);
    const vulkan::LabelBuffers out = vk.labels(r.out);
    const VkFence unused = vk.fence();
    const auto refused = [&](const auto& call, const std::string& words) {
        expect_error(call, words);
        ASSERT_EQ(vkQueueWaitIdle(vk.queue()), VK_SUCCESS);
        EXPECT_EQ(vkGetFenceStatus(vk.vk_device(), unused), VK_NOT_READY) << "something was submitted";
        r.expect_untouched();
    };
    refused([&] { vulkan::record(r.segmenter, VK_NULL_HANDLE, cloud, out); }, "VK_NULL_HANDLE");
    const VkSemaphore s = vk.semaphore();
    const VkPipelineStageFlags stages[] = {VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT};
    refused(
        [&] {
            vulkan::submit(r.segmenter, cloud, out, {&s, 1}, stages, {}, unused);
        },
        "wait has 1 semaphore(s) but wait_stages has 2");
    refused(
        [&] {
            vulkan::submit(r.segmenter, depth, out, {&s, 1}, {}, {}, unused);
        },
        "wait has 1 semaphore(s) but wait_stages has 0");
    const VkSemaphore null_semaphore = VK_NULL_HANDLE;
    refused(
        [&] {
            vulkan::submit(r.segmenter, cloud, out, {}, {}, {&null_semaphore, 1}, unused);
        },
        "signal[0] is a VK_NULL_HANDLE");
    const VkPipelineStageFlags no_stage = 0;
    refused(
        [&] {
            vulkan::submit(r.segmenter, cloud, out, {&s, 1}, {&no_stage, 1}, {}, unused);
        },
        "wait_stages[0] is 0");
    Segmenter cpu(Wall::kWidth, Wall::kHeight, {}, "cpu");
    Segmenter moved = std::move(cpu);
    refused([&] { vulkan::submit(cpu, cloud, out); }, "moved from");  // NOLINT(bugprone-use-after-move)
    r.expect_still_segments();
}

// A Segmenter on pyrseg's own Vulkan device takes no buffers of the caller's.
TEST_F(VulkanInterop, ASegmenterOnPyrsegsOwnDeviceIsRefused) {
    bool available = false;
    for (const BackendInfo& b : list_backends()) available = available || (b.name == "vulkan" && b.available);
    if (!available) GTEST_SKIP() << "pyrseg's own Vulkan device is unavailable";
    Refusals r(api());
    Segmenter own(Wall::kWidth, Wall::kHeight, {}, "vulkan");
    r.expect(own, {r.cloud, r.out}, "pyrseg's own Vulkan device");
}

// A frame with tracks recorded once, after the stream's first frame, and submitted three times, new points uploaded
// before each: each run is the stream's next frame (K' and the frame's number live on the device), and
// decode_device_tracks gives the tracks the CPU's host stream of the same frames gets.
TEST_F(VulkanInterop, ARecordedFrameWithTracksRunsAsTheStreamsNextFrameEachTime) {
    VulkanAdapter& vk = api();
    const PanningStream stream = panning_stream({0, 3, 7, 8});
    const std::vector<Window>& windows = stream.windows;
    Segmenter cpu(PanningStream::kWidth, PanningStream::kHeight, stream.params, "cpu", stream.outputs);
    Segmenter segmenter =
        vk.make_segmenter(PanningStream::kWidth, PanningStream::kHeight, stream.params, stream.outputs);
    EXPECT_EQ(segmenter.segment(stream.cloud(0)).tracks, cpu.segment(stream.cloud(0)).tracks);
    const std::size_t point_bytes = 4 * windows[0].points.size();
    const CloudFrame in{{vk.allocate(point_bytes), 0}, {}, 0};
    LabelFrame out;
    out.labels = {vk.allocate(4 * windows[0].depth.size()), 0};
    out.count = {vk.allocate(4), 0};
    out.statistics = {vk.allocate(segmenter.device_statistics_bytes()), 0};
    out.tracks = {vk.allocate(segmenter.device_tracks_bytes()), 0};
    VkCommandBuffer commands = vk.allocate_commands();
    auto begin = VkCommandBufferBeginInfo{};
    begin.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO;
    ASSERT_EQ(vkBeginCommandBuffer(commands, &begin), VK_SUCCESS);
    vulkan::record(segmenter, commands, vk.cloud(in), vk.labels(out));
    ASSERT_EQ(vkEndCommandBuffer(commands), VK_SUCCESS);
    const auto words_of = [&](const Region& r, std::size_t bytes) {
        const std::vector<unsigned char> b = vk.download(r.buffer, r.offset, bytes);
        std::vector<std::uint32_t> w(bytes / 4);
        std::memcpy(w.data(), b.data(), bytes);
        return w;
    };
    std::size_t matched = 0;
    for (std::size_t f = 1; f < windows.size(); ++f) {
        SCOPED_TRACE("run " + std::to_string(f));
        const Result expected = cpu.segment(stream.cloud(f));
        vk.upload(in.points.buffer, 0, windows[f].points.data(), point_bytes);
        auto info = VkSubmitInfo{};
        info.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO;
        info.commandBufferCount = 1;
        info.pCommandBuffers = &commands;
        ASSERT_EQ(vkQueueSubmit(vk.queue(), 1, &info, VK_NULL_HANDLE), VK_SUCCESS);
        const std::uint32_t count = words_of(out.count, 4)[0];
        ASSERT_EQ(count, expected.segment_count);
        std::vector<SegmentStats> segments;
        const std::vector<std::uint32_t> stats = words_of(out.statistics, segmenter.device_statistics_bytes());
        segmenter.decode_device_statistics(stats.data(), count, segments);
        const std::vector<std::uint32_t> track_words = words_of(out.tracks, segmenter.device_tracks_bytes());
        std::vector<SegmentTrack> tracks;
        segmenter.decode_device_tracks(track_words.data(), segments, tracks);
        EXPECT_EQ(tracks, expected.tracks);
        for (const SegmentTrack& t : tracks) matched += t.how != TrackMatch::new_track ? 1 : 0;
    }
    EXPECT_GT(matched, 5u) << "a stream whose tracks carry over";
    vk.free(commands);
}

}  // namespace
}  // namespace pyrseg::test
