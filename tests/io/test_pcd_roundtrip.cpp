// write_pcd -> read_pcd for every encoding, and the exact shape of what write_pcd produces.
#include <cstring>

#include "io_test_util.hpp"

namespace pyrseg::io::test {
namespace {

class PcdRoundTrip : public ::testing::TestWithParam<std::tuple<std::string, bool>> {};

TEST_P(PcdRoundTrip, PreservesPointsNormalsAndNaN) {
    const auto& [encoding, normals] = GetParam();
    ScratchDir dir;
    const PointCloud cloud = make_cloud(23, 17, normals);
    const auto path = dir / "cloud.pcd";
    write_pcd(path, cloud, encoding_of(encoding));
    const PointCloud back = read_pcd(path);
    expect_same_cloud(cloud, back);
    EXPECT_EQ(back.normals.empty(), !normals);
}

TEST_P(PcdRoundTrip, PreservesAwkwardFloats) {
    const auto& [encoding, normals] = GetParam();
    ScratchDir dir;
    PointCloud cloud = make_cloud(4, 3, normals);
    const float specials[] = {0.0f,
                              -0.0f,
                              1e-38f,
                              1.17549435e-38f,
                              1.4e-45f,
                              3.40282347e38f,
                              -123456.789f,
                              0.1f,
                              1.0f / 3.0f,
                              std::numeric_limits<float>::infinity(),
                              -std::numeric_limits<float>::infinity(),
                              std::numeric_limits<float>::quiet_NaN()};
    for (std::size_t i = 0; i < cloud.points.size(); ++i) cloud.points[i] = specials[i % std::size(specials)];
    const auto path = dir / "special.pcd";
    write_pcd(path, cloud, encoding_of(encoding));
    const PointCloud back = read_pcd(path);
    expect_same_cloud(cloud, back);
    for (std::size_t i = 0; i < cloud.points.size(); ++i) {
        if (!std::isnan(cloud.points[i])) {
            EXPECT_EQ(std::signbit(back.points[i]), std::signbit(cloud.points[i])) << i;
        }
    }
}

INSTANTIATE_TEST_SUITE_P(AllEncodings, PcdRoundTrip,
                         ::testing::Combine(::testing::Values("ascii", "binary", "binary_compressed"),
                                            ::testing::Bool()),
                         [](const auto& p) {
                             return std::get<0>(p.param) + (std::get<1>(p.param) ? "_normals" : "_xyz");
                         });

TEST(PcdWrite, HeaderIsWhatPclWrites) {
    ScratchDir dir;
    const PointCloud cloud = make_cloud(5, 4, true);
    write_pcd(dir / "a.pcd", cloud, PcdEncoding::binary_compressed);
    const std::string bytes = read_bytes(dir / "a.pcd");
    const std::string expected =
        "# .PCD v0.7 - Point Cloud Data file format\n"
        "VERSION 0.7\n"
        "FIELDS x y z normal_x normal_y normal_z\n"
        "SIZE 4 4 4 4 4 4\n"
        "TYPE F F F F F F\n"
        "COUNT 1 1 1 1 1 1\n"
        "WIDTH 5\n"
        "HEIGHT 4\n"
        "VIEWPOINT 0 0 0 1 0 0 0\n"
        "POINTS 20\n"
        "DATA binary_compressed\n";
    ASSERT_GE(bytes.size(), expected.size() + 8);
    EXPECT_EQ(bytes.substr(0, expected.size()), expected);
    std::uint32_t compressed = 0, uncompressed = 0;
    std::memcpy(&compressed, bytes.data() + expected.size(), 4);
    std::memcpy(&uncompressed, bytes.data() + expected.size() + 4, 4);
    EXPECT_EQ(uncompressed, 20u * 6u * 4u);
    EXPECT_EQ(bytes.size(), expected.size() + 8 + compressed);  // nothing after the block
}

TEST(PcdWrite, BinaryIsArrayOfStructures) {
    ScratchDir dir;
    const PointCloud cloud = make_cloud(3, 2, false);
    write_pcd(dir / "b.pcd", cloud, PcdEncoding::binary);
    const std::string bytes = read_bytes(dir / "b.pcd");
    const auto data = bytes.find("DATA binary\n") + std::strlen("DATA binary\n");
    ASSERT_EQ(bytes.size() - data, 6u * 12u);
    EXPECT_EQ(std::memcmp(bytes.data() + data, cloud.points.data(), 72), 0);
}

TEST(PcdWrite, AsciiWritesNanAsPclDoes) {
    ScratchDir dir;
    PointCloud cloud = make_cloud(2, 2, false);
    cloud.points[0] = -std::numeric_limits<float>::quiet_NaN();
    cloud.points[1] = 0.5f;
    write_pcd(dir / "c.pcd", cloud, PcdEncoding::ascii);
    const std::string bytes = read_bytes(dir / "c.pcd");
    EXPECT_NE(bytes.find("DATA ascii\nnan 0.5 "), std::string::npos) << bytes;
    EXPECT_EQ(bytes.find("-nan"), std::string::npos);
}

TEST(PcdWrite, RejectsInconsistentClouds) {
    ScratchDir dir;
    PointCloud cloud = make_cloud(4, 3, true);
    cloud.points.pop_back();
    ErrorCode code{};
    std::string message;
    EXPECT_EQ(outcome([&] { write_pcd(dir / "x.pcd", cloud, PcdEncoding::binary); }, &message, &code), "error");
    EXPECT_EQ(code, ErrorCode::invalid_argument);
    EXPECT_NE(message.find("x.pcd"), std::string::npos) << message;

    cloud = make_cloud(4, 3, true);
    cloud.normals.resize(6);
    EXPECT_EQ(outcome([&] { write_pcd(dir / "x.pcd", cloud, PcdEncoding::ascii); }), "error");
    cloud = PointCloud{};
    EXPECT_EQ(outcome([&] { write_pcd(dir / "x.pcd", cloud, PcdEncoding::binary_compressed); }), "error");
}

TEST(PcdWrite, UnwritablePathIsAnIoError) {
    ScratchDir dir;
    const PointCloud cloud = make_cloud(4, 3, false);
    ErrorCode code{};
    std::string message;
    EXPECT_EQ(outcome([&] { write_pcd(dir / "missing" / "x.pcd", cloud, PcdEncoding::binary); }, &message, &code),
              "error");
    EXPECT_EQ(code, ErrorCode::io);
    EXPECT_NE(message.find("x.pcd"), std::string::npos) << message;
    EXPECT_EQ(outcome([&] { write_pcd(dir.path(), cloud, PcdEncoding::binary); }, &message, &code), "error");
    EXPECT_EQ(code, ErrorCode::io);
}

}  // namespace
}  // namespace pyrseg::io::test
