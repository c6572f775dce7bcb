// Vulkan device choice (PYRSEG_VULKAN_DEVICE by index or by name, a clear error for one that matches nothing), and
// the validation layer's messages turning into errors, as the whole suite relies on.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstdlib>
#include <memory>
#include <string>

#include "pyrseg/backend.hpp"
#include "pyrseg/error.hpp"
#include "pyrseg/segmenter.hpp"
#include "pyrseg/synthetic.hpp"
#if PYRSEG_TEST_VULKAN_INTERNALS
#include "backends/vulkan/vulkan_runtime.hpp"
#endif

namespace pyrseg {
namespace {

const BackendInfo* vulkan_info() {
    static const std::vector<BackendInfo> all = list_backends();
    for (const BackendInfo& b : all) {
        if (b.name == "vulkan") return &b;
    }
    return nullptr;
}

class VulkanDevices : public ::testing::Test {
protected:
    void SetUp() override {
        const BackendInfo* info = vulkan_info();
        if (info == nullptr || !info->available) {
            GTEST_SKIP() << "vulkan unavailable: " << (info != nullptr ? info->reason : "unknown backend");
        }
    }
    void TearDown() override { unsetenv("PYRSEG_VULKAN_DEVICE"); }
};

TEST_F(VulkanDevices, ChosenByIndexOrByName) {
    ASSERT_EQ(setenv("PYRSEG_VULKAN_DEVICE", "0", 1), 0);
    EXPECT_EQ(Segmenter(16, 16, {}, "vulkan").backend_name(), "vulkan");
    // The first device's name, as `pyrseg backends` prints it ("0 llvmpipe (...)").
    const std::string description = vulkan_info()->devices.front();
    const std::string name = description.substr(description.find(' ') + 1, 6);
    ASSERT_EQ(setenv("PYRSEG_VULKAN_DEVICE", name.c_str(), 1), 0);
    EXPECT_EQ(Segmenter(16, 16, {}, "vulkan").backend_name(), "vulkan");
}

TEST_F(VulkanDevices, ADeviceThatMatchesNothingIsAnErrorListingTheDevices) {
    ASSERT_EQ(setenv("PYRSEG_VULKAN_DEVICE", "no such device", 1), 0);
    try {
        Segmenter s(16, 16, {}, "vulkan");
        FAIL() << "expected an error";
    } catch (const Error& e) {
        EXPECT_EQ(e.code(), ErrorCode::backend_unavailable);
        const std::string what = e.what();
        EXPECT_NE(what.find("no such device"), std::string::npos) << what;
        EXPECT_NE(what.find(vulkan_info()->devices.front()), std::string::npos) << what;
    }
}

#if PYRSEG_TEST_VULKAN_INTERNALS
// Frames larger than one storage buffer's range still run: the points and normals are bound in two ranges and the
// quantized normals take 8 bytes a pixel, so a 4128 x 3088 frame fits lavapipe's 128 MiB, with the labels the CPU
// backend gives. A frame whose buffers exceed even that is refused up front with an error naming the limit.
TEST_F(VulkanDevices, FramesBeyondOneStorageBufferRangeRunOrAreRefusedNamingTheLimit) {
    const std::shared_ptr<vulkan::Runtime> rt = vulkan::runtime_for(vulkan::choose_device());
    const std::uint64_t range = rt->properties.limits.maxStorageBufferRange;
    synthetic::SceneOptions o;
    o.width = 4128;
    o.height = 3088;
    o.object_count = 6;
    const synthetic::Scene scene = synthetic::generate(o);
    const CloudView view{scene.points.data(), nullptr, o.width, o.height};
    Outputs outputs;
    outputs.normals = true;
    Segmenter vulkan(o.width, o.height, {}, "vulkan", outputs);
    Segmenter cpu(o.width, o.height, {}, "cpu", outputs);
    const Result a = vulkan.segment(view);
    const Result b = cpu.segment(view);
    EXPECT_GT(12ull * std::uint64_t(o.width) * std::uint64_t(o.height), std::min<std::uint64_t>(range, 1ull << 40))
        << "on this device the frame's points fit one binding: the split is not exercised";
    EXPECT_EQ(a.segment_count, b.segment_count);
    EXPECT_TRUE(a.labels == b.labels) << "labels differ from the CPU backend's";
    EXPECT_TRUE(a.normals == b.normals) << "normals differ from the CPU backend's";

    const int big_w = 4 * 4128;
    const int big_h = 4 * 3088;
    if (8ull * std::uint64_t(big_w) * std::uint64_t(big_h) <= range) return;  // the quantized normals fit too
    try {
        Segmenter s(big_w, big_h, {}, "vulkan");
        FAIL() << "expected an error";
    } catch (const Error& e) {
        EXPECT_EQ(e.code(), ErrorCode::out_of_memory);
        EXPECT_NE(std::string(e.what()).find("maxStorageBufferRange"), std::string::npos) << e.what();
    }
}

// With PYRSEG_VULKAN_VALIDATION=1 (ctest sets it for every test) a misuse of the API is reported by the Khronos
// layer, and pyrseg turns the report into an error: a frame with a validation message fails its test.
TEST_F(VulkanDevices, ValidationMessagesBecomeErrors) {
    const char* env = std::getenv("PYRSEG_VULKAN_VALIDATION");
    if (env == nullptr || std::string(env) != "1") GTEST_SKIP() << "PYRSEG_VULKAN_VALIDATION is not 1";
    const std::shared_ptr<vulkan::Runtime> rt = vulkan::runtime_for(vulkan::choose_device());
    EXPECT_NO_THROW(vulkan::throw_on_validation_messages("nothing"));
    auto info = vulkan::make_info<VkBufferCreateInfo>(VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO);
    info.size = 0;  // VUID-VkBufferCreateInfo-size-00912: size must be greater than 0
    info.usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
    VkBuffer buffer = VK_NULL_HANDLE;
    vkCreateBuffer(rt->device, &info, nullptr, &buffer);
    if (buffer != VK_NULL_HANDLE) vkDestroyBuffer(rt->device, buffer, nullptr);
    try {
        vulkan::throw_on_validation_messages("a deliberate misuse");
        FAIL() << "the validation layer reported nothing";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("VkBufferCreateInfo-size"), std::string::npos) << e.what();
    }
    EXPECT_NO_THROW(vulkan::throw_on_validation_messages("nothing"));  // reported once
}
#endif

}  // namespace
}  // namespace pyrseg
