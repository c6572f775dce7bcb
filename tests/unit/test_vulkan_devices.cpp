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
// A frame whose buffers exceed what the device binds is refused up front with an error naming the limit; one
// that fits is accepted (lavapipe binds at most 128 MiB, which a 4128 x 3088 frame's quantized normals exceed).
TEST_F(VulkanDevices, ImagesBeyondTheStorageBufferRangeAreRefusedNamingTheLimit) {
    const std::shared_ptr<vulkan::Runtime> rt = vulkan::runtime_for(vulkan::choose_device());
    const std::uint64_t range = rt->properties.limits.maxStorageBufferRange;
    const int w = 4128;
    const int h = 3088;
    const std::uint64_t quant_bytes = 16ull * std::uint64_t(w) * std::uint64_t(h);  // the largest buffer
    if (quant_bytes <= range) {
        EXPECT_NO_THROW(Segmenter(w, h, {}, "vulkan")) << "the device binds " << range << " bytes";
        return;
    }
    try {
        Segmenter s(w, h, {}, "vulkan");
        FAIL() << "expected an error";
    } catch (const Error& e) {
        EXPECT_EQ(e.code(), ErrorCode::out_of_memory);
        EXPECT_NE(std::string(e.what()).find("maxStorageBufferRange"), std::string::npos) << e.what();
    }
    EXPECT_NO_THROW(Segmenter(2064, 1544, {}, "vulkan"));
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
