// read_pcd on files pyrseg's writer never produces but PCL and other tools do.
#include "io_test_util.hpp"

namespace pyrseg::io::test {
namespace {

const std::vector<FieldSpec> kMixedFields = {
    {"x", 'F', 8, 1},        {"_", 'U', 1, 3},        {"y", 'F', 4, 1},         {"rgb", 'F', 4, 1},
    {"normal_z", 'F', 4, 1}, {"z", 'F', 4, 1},        {"intensity", 'U', 2, 1}, {"label", 'I', 4, 1},
    {"normal_x", 'F', 8, 1}, {"normal_y", 'F', 4, 1}, {"curvature", 'F', 4, 1}, {"fpfh", 'F', 4, 33},
    {"big", 'U', 8, 1},      {"small", 'I', 1, 1},    {"_", 'U', 1, 2},
};

// Point i of the mixed cloud, in field order; every xyz/normal value is exact in float.
std::vector<double> mixed_point(int i) {
    const bool invalid = i == 5;
    const double nan = std::numeric_limits<double>::quiet_NaN();
    const double x = invalid ? nan : i * 0.25 - 1.0, y = invalid ? nan : i * 0.5, z = invalid ? nan : 1.0 + i;
    const double nx = invalid ? nan : 0.5, ny = invalid ? nan : -0.25, nz = invalid ? nan : -0.75 + i / 64.0;
    std::vector<double> v = {x, 0, 0, 0, y, 4286611584.0, nz, z, 1000.0 + i, -7.0 * i, nx, ny, 0.01};
    for (int k = 0; k < 33; ++k) v.push_back(k * 0.5);
    v.push_back(1e12);
    v.push_back(-100);
    v.push_back(0);
    v.push_back(0);
    return v;
}

class PcdForeign : public ::testing::TestWithParam<std::string> {};

TEST_P(PcdForeign, SkipsOtherFieldsAndConvertsDoubles) {
    ScratchDir dir;
    const int w = 4, h = 3;
    std::vector<std::vector<double>> values;
    for (int i = 0; i < w * h; ++i) values.push_back(mixed_point(i));
    write_bytes(dir / "mixed.pcd", build_pcd(kMixedFields, w, h, values, GetParam()));
    const PointCloud cloud = read_pcd(dir / "mixed.pcd");
    ASSERT_EQ(cloud.width, w);
    ASSERT_EQ(cloud.height, h);
    ASSERT_EQ(cloud.points.size(), 3u * w * h);
    ASSERT_EQ(cloud.normals.size(), 3u * w * h);
    for (int i = 0; i < w * h; ++i) {
        const auto& v = values[static_cast<std::size_t>(i)];
        const auto k = static_cast<std::size_t>(3 * i);
        const float expected[6] = {static_cast<float>(v[0]),  static_cast<float>(v[4]),  static_cast<float>(v[7]),
                                   static_cast<float>(v[10]), static_cast<float>(v[11]), static_cast<float>(v[6])};
        const float got[6] = {cloud.points[k],  cloud.points[k + 1],  cloud.points[k + 2],
                              cloud.normals[k], cloud.normals[k + 1], cloud.normals[k + 2]};
        for (int c = 0; c < 6; ++c) {
            if (std::isnan(expected[c])) {
                EXPECT_TRUE(std::isnan(got[c])) << "point " << i << " value " << c;
            } else {
                EXPECT_EQ(got[c], expected[c]) << "point " << i << " value " << c;
            }
        }
    }
}

TEST(PcdRead, IgnoresBytesAfterBinaryData) {
    // PCL's older writers padded binary files to a page boundary (both shared sample scans end that way).
    ScratchDir dir;
    const PointCloud cloud = make_cloud(6, 5, true);
    for (const auto encoding : {PcdEncoding::binary, PcdEncoding::binary_compressed}) {
        write_pcd(dir / "p.pcd", cloud, encoding);
        write_bytes(dir / "p.pcd", read_bytes(dir / "p.pcd") + std::string(4000, '\0'));
        expect_same_cloud(cloud, read_pcd(dir / "p.pcd"));
    }
}

INSTANTIATE_TEST_SUITE_P(AllEncodings, PcdForeign, ::testing::Values("ascii", "binary", "binary_compressed"));

std::string xyz_ascii(const std::string& header_tail, const std::string& body) {
    return "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\n" + header_tail + "DATA ascii\n" + body;
}

TEST(PcdRead, LenientHeaderLayout) {
    ScratchDir dir;
    const std::string body = "1 2 3\n4 5 6\n7 8 9\n10 11 12\n";
    const std::string variants[] = {
        // no COUNT, no VIEWPOINT, no comment
        xyz_ascii("WIDTH 2\nHEIGHT 2\nPOINTS 4\n", body),
        // comments and blank lines anywhere, indentation, extra spaces
        "# a\n\nVERSION .7\n# b\n  FIELDS   x y\tz  \nSIZE 4 4 4\n\nTYPE f f f\nCOUNT 1 1 1\n#\nWIDTH 2\nHEIGHT 2\n"
        "POINTS 4\nDATA ascii   \n" +
            body,
        // CRLF line endings in header and data, keywords in another order
        "VERSION 0.7\r\nFIELDS x y z\r\nTYPE F F F\r\nSIZE 4 4 4\r\nHEIGHT 2\r\nWIDTH 2\r\nPOINTS 4\r\n"
        "VIEWPOINT 1 2 3 0 1 0 0\r\nDATA ascii\r\n1 2 3\r\n4 5 6\r\n7 8 9\r\n10 11 12\r\n",
        // version 0.6 (no VIEWPOINT in that version)
        "VERSION 0.6\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 2\nHEIGHT 2\nPOINTS 4\nDATA ascii\n" +
            body,
    };
    for (const auto& text : variants) {
        write_bytes(dir / "v.pcd", text);
        PointCloud cloud;
        ASSERT_EQ(outcome([&] { cloud = read_pcd(dir / "v.pcd"); }), "ok") << text;
        ASSERT_EQ(cloud.points.size(), 12u);
        for (std::size_t i = 0; i < 12; ++i) EXPECT_EQ(cloud.points[i], static_cast<float>(i + 1)) << text;
        EXPECT_TRUE(cloud.normals.empty());
    }
}

TEST(PcdRead, AsciiNumberSpellings) {
    ScratchDir dir;
    write_bytes(dir / "n.pcd",
                xyz_ascii("WIDTH 2\nHEIGHT 2\nPOINTS 4\n", "+1.5 NaN -nan\n\n  inf\t-INF  1e-3 \n\n-0 0x 7\n4 5 6"));
    std::string message;
    EXPECT_EQ(outcome([&] { read_pcd(dir / "n.pcd"); }, &message), "error");  // "0x" is no number
    EXPECT_NE(message.find("'0x'"), std::string::npos) << message;
    EXPECT_NE(message.find("field 'y'"), std::string::npos) << message;

    write_bytes(dir / "n.pcd", xyz_ascii("WIDTH 2\nHEIGHT 2\nPOINTS 4\n",
                                         "+1.5 NaN -nan\n\n  inf\t-INF  1e-3 \n\n-0 0 7\n4 5 6\n\n\n"));
    const PointCloud c = read_pcd(dir / "n.pcd");
    EXPECT_EQ(c.points[0], 1.5f);
    EXPECT_TRUE(std::isnan(c.points[1]) && std::isnan(c.points[2]));
    EXPECT_EQ(c.points[3], std::numeric_limits<float>::infinity());
    EXPECT_EQ(c.points[4], -std::numeric_limits<float>::infinity());
    EXPECT_EQ(c.points[5], 1e-3f);
    EXPECT_TRUE(std::signbit(c.points[6]));
    EXPECT_EQ(c.points[11], 6.0f);
}

TEST(PcdRead, NormalsInAnyOrderAndF8) {
    ScratchDir dir;
    const std::vector<FieldSpec> fields = {{"normal_y"}, {"z", 'F', 8}, {"normal_z", 'F', 8},
                                           {"x"},        {"normal_x"},  {"y"}};
    std::vector<std::vector<double>> values;
    for (int i = 0; i < 6; ++i) values.push_back({0.1 * i, 2.0 + i, 0.3, -1.0 * i, 0.5, 0.25 * i});
    for (const auto& data : encodings()) {
        write_bytes(dir / "o.pcd", build_pcd(fields, 3, 2, values, data));
        const PointCloud c = read_pcd(dir / "o.pcd");
        for (std::size_t i = 0; i < 6; ++i) {
            const auto& v = values[i];
            EXPECT_EQ(c.points[3 * i], static_cast<float>(v[3])) << data;
            EXPECT_EQ(c.points[3 * i + 1], static_cast<float>(v[5])) << data;
            EXPECT_EQ(c.points[3 * i + 2], static_cast<float>(v[1])) << data;
            EXPECT_EQ(c.normals[3 * i], static_cast<float>(v[4])) << data;
            EXPECT_EQ(c.normals[3 * i + 1], static_cast<float>(v[0])) << data;
            EXPECT_EQ(c.normals[3 * i + 2], static_cast<float>(v[2])) << data;
        }
    }
}

}  // namespace
}  // namespace pyrseg::io::test
