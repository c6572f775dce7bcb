// gpu::StagingArena (core/gpu/staging.hpp), which the Vulkan and CUDA backends move frames through.
#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <vector>

#include "core/gpu/staging.hpp"

namespace pyrseg::gpu {
namespace {

TEST(GpuStaging, UploadsAndDownloadsArePackedAndDelivered) {
    std::vector<unsigned char> up(64);
    std::vector<unsigned char> down(64);
    StagingArena arena;
    arena.reset(up.data(), up.size(), down.data(), down.size());
    const std::array<std::uint32_t, 3> words = {1, 2, 3};
    const std::size_t a = arena.stage_upload(words.data(), sizeof(words));
    const std::size_t b = arena.stage_upload(words.data(), 4);
    EXPECT_EQ(a, 0u);
    EXPECT_EQ(b, 16u) << "each staging area starts 16-byte aligned";
    EXPECT_EQ(up[0], 1);
    EXPECT_EQ(up[16], 1);
    std::uint32_t k = 0;
    const std::size_t at = arena.stage_download(&k, 4);
    down[at] = 42;  // what the device's copy would have written
    EXPECT_EQ(k, 0u) << "nothing reaches the destination before complete()";
    arena.complete();
    EXPECT_EQ(k, 42u);
    EXPECT_EQ(arena.stage_upload(words.data(), 4), 0u) << "after complete() the areas start over";
}

TEST(GpuStaging, OverflowIsAnErrorNotAnOverrun) {
    std::vector<unsigned char> up(32);
    std::vector<unsigned char> down(8);
    StagingArena arena;
    arena.reset(up.data(), up.size(), down.data(), down.size());
    const std::array<unsigned char, 20> bytes{};
    (void)arena.stage_upload(bytes.data(), bytes.size());
    EXPECT_THROW((void)arena.stage_upload(bytes.data(), bytes.size()), Error);
    std::array<unsigned char, 16> sink{};
    EXPECT_THROW((void)arena.stage_download(sink.data(), sink.size()), Error);
}

}  // namespace
}  // namespace pyrseg::gpu
