// The two shared PCL sample scans (640x480, x y z rgba, binary_compressed, metres, page-padded by old PCL).
#include <random>

#include "io_test_util.hpp"

namespace pyrseg::io::test {
namespace {

const fs::path kSharedDir = PYRSEG_SHARED_DATA_DIR;

class RealScan : public ::testing::TestWithParam<std::string> {
protected:
    void SetUp() override {
        path_ = kSharedDir / GetParam();
        if (!fs::exists(path_)) GTEST_SKIP() << "shared sample data not found: " << path_ << " (no ../shared/data)";
    }
    fs::path path_;
};

TEST_P(RealScan, ReadsOrganizedCloudInMetres) {
    const PointCloud cloud = read_pcd(path_);
    ASSERT_EQ(cloud.width, 640);
    ASSERT_EQ(cloud.height, 480);
    ASSERT_EQ(cloud.points.size(), 3u * 640 * 480);
    EXPECT_TRUE(cloud.normals.empty());
    std::size_t finite = 0, in_range = 0;
    for (std::size_t i = 0; i < 640 * 480; ++i) {
        const float* p = &cloud.points[3 * i];
        const bool ok = std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]);
        // Invalid pixels are NaN in all three coordinates, never half-valid.
        EXPECT_TRUE(ok || (std::isnan(p[0]) && std::isnan(p[1]) && std::isnan(p[2]))) << "pixel " << i;
        if (!ok) continue;
        ++finite;
        if (p[2] > 0.3f && p[2] < 5.0f) ++in_range;
    }
    EXPECT_GT(finite, 640u * 480u / 2) << "finite points";
    EXPECT_EQ(in_range, finite) << "z outside 0.3..5 m";
    RecordProperty("finite_points", static_cast<int>(finite));
}

TEST_P(RealScan, RoundTripsThroughEveryEncoding) {
    const PointCloud cloud = read_pcd(path_);
    ScratchDir dir;
    for (const auto& encoding : encodings()) {
        SCOPED_TRACE(encoding);
        write_pcd(dir / "copy.pcd", cloud, encoding_of(encoding));
        expect_same_cloud(cloud, read_pcd(dir / "copy.pcd"));
    }
}

TEST_P(RealScan, CorruptedCopiesFailCleanly) {
    const std::string full = read_bytes(path_);
    ScratchDir dir;
    std::mt19937 rng(4242u);
    for (int trial = 0; trial < 24; ++trial) {
        std::string bytes = full;
        // Flips in the header, the block sizes and the first part of the LZF stream, where they matter most.
        const std::size_t pos = rng() % (trial % 2 ? 220 : 20000);
        bytes[pos] = static_cast<char>(bytes[pos] ^ static_cast<char>(1 + rng() % 255));
        if (trial % 6 == 5) bytes.resize(rng() % bytes.size());
        write_bytes(dir / "bad.pcd", bytes);
        ASSERT_NE(outcome([&] { read_pcd(dir / "bad.pcd"); }), "other") << "trial " << trial;
    }
}

INSTANTIATE_TEST_SUITE_P(Shared, RealScan,
                         ::testing::Values("table_scene_mug_stereo_textured.pcd", "milk_cartoon_all_small_clorox.pcd"),
                         [](const auto& p) { return p.param.substr(0, p.param.find('_')); });

}  // namespace
}  // namespace pyrseg::io::test
