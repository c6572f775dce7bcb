// PLY through PCL: write_ply -> read_ply, files PCL and a Photoneo PhoXi write, clouds that are not organized, and
// malformed files, each of which must load or throw pyrseg::Error naming the file, never crash or hang (PCL's
// reader aborts on some headers: io/ply.cpp checks them first).
#include <algorithm>
#include <cmath>
#include <random>
#include <sstream>

#include "io_test_util.hpp"

#if PYRSEG_HAVE_PLY && PYRSEG_TEST_PCL
#include <pcl/io/ply_io.h>
#include <pcl/point_types.h>
#endif

namespace pyrseg::io::test {
namespace {

#if PYRSEG_HAVE_PLY

// ---- building PLY files byte by byte

// An organized W x H binary cloud of x y z floats: point i is (i, -i, 1 + i).
std::string grid_binary(int w, int h) {
    std::string s = xyz_header("binary_little_endian", w * h, grid_lines(w, h));
    for (int i = 0; i < w * h; ++i) {
        put(s, float(i));
        put(s, float(-i));
        put(s, 1.0f + float(i));
    }
    return s;
}

std::string grid_ascii(int w, int h) {
    std::string s = xyz_header("ascii", w * h, grid_lines(w, h));
    for (int i = 0; i < w * h; ++i)
        s += std::to_string(i) + " " + std::to_string(-i) + " " + std::to_string(1 + i) + "\n";
    return s;
}

// What PhoXi Control saves ("organized" PLY): every pixel a vertex (0 0 0 where there is no measurement), the size
// in an obj_info line, and after the vertices the camera, frame and calibration elements.
std::string phoxi_ply(int w, int h, const std::string& size_line) {
    std::string s =
        "ply\nformat binary_little_endian 1.0\n" + size_line + "\nelement vertex " + std::to_string(w * h) +
        "\nproperty float x\nproperty float y\nproperty float z\nproperty float nx\nproperty float ny\n"
        "property float nz\nproperty uchar red\nproperty uchar green\nproperty uchar blue\nproperty float Texture32\n"
        "property float Depth32\nelement camera 1\nproperty float view_px\nproperty float view_py\n"
        "property float view_pz\nproperty float x_axisx\nproperty float x_axisy\nproperty float x_axisz\n"
        "property float y_axisx\nproperty float y_axisy\nproperty float y_axisz\nproperty float z_axisx\n"
        "property float z_axisy\nproperty float z_axisz\nelement phoxi_frame_params 1\nproperty uint32 frame_width\n"
        "property uint32 frame_height\nproperty uint32 frame_index\nproperty float frame_start_time\n"
        "property float frame_duration\nproperty float frame_computation_duration\n"
        "property float frame_transfer_duration\nproperty int32 total_scan_count\nelement camera_matrix 1\n";
    for (int i = 0; i < 9; ++i) s += "property float cm" + std::to_string(i) + "\n";
    s += "element camera_resolution 1\nproperty float width\nproperty float height\nend_header\n";
    for (int i = 0; i < w * h; ++i) {
        const bool missing = i % 5 == 2;
        for (float v : {missing ? 0.0f : float(i) * 1.5f, missing ? 0.0f : -float(i),
                        missing ? 0.0f : 800.0f + float(i), 0.0f, missing ? 0.0f : -0.6f, missing ? 0.0f : -0.8f}) {
            put(s, v);
        }
        s += "\x10\x20\x30";
        put(s, 0.5f);
        put(s, missing ? 0.0f : 800.0f + float(i));
    }
    for (int i = 0; i < 12; ++i) put(s, i % 4 == 3 ? 1.0f : 0.0f);
    for (std::uint32_t v : {std::uint32_t(w), std::uint32_t(h), 7u}) put(s, v);
    for (int i = 0; i < 4; ++i) put(s, 12.5f);
    put(s, std::int32_t{1});
    for (int i = 0; i < 9; ++i) put(s, float(i));
    put(s, float(w));
    put(s, float(h));
    return s;
}

std::string expect_error(const fs::path& path, ErrorCode expected_code = ErrorCode::format) {
    return expect_load_error(
        path, [&] { read_ply(path); }, expected_code);
}

void expect_error_containing(const fs::path& path, const std::string& text) {
    expect_load_error_containing(
        path, [&] { read_ply(path); }, text);
}

// ---- write_ply -> read_ply

// Binary PLY gives every float back; PCL writes ascii PLY with 6 significant digits.
void expect_cloud_back(const PointCloud& a, const PointCloud& b, bool binary) {
    if (binary) {
        expect_same_cloud(a, b);
        return;
    }
    EXPECT_EQ(a.width, b.width);
    EXPECT_EQ(a.height, b.height);
    for (const auto& [x, y] : {std::pair{&a.points, &b.points}, std::pair{&a.normals, &b.normals}}) {
        ASSERT_EQ(x->size(), y->size());
        for (std::size_t i = 0; i < x->size(); ++i) {
            const float u = (*x)[i], v = (*y)[i];
            if (std::isnan(u) || std::isnan(v)) {
                EXPECT_TRUE(std::isnan(u) && std::isnan(v)) << i << ": " << u << " vs " << v;
            } else {
                EXPECT_NEAR(u, v, 1e-5f * std::max(1.0f, std::abs(u))) << i;
            }
        }
    }
}

class PlyRoundTrip : public ::testing::TestWithParam<std::tuple<bool, bool>> {};

TEST_P(PlyRoundTrip, PreservesPointsNormalsAndNaN) {
    const auto& [binary, normals] = GetParam();
    ScratchDir dir;
    const PointCloud cloud = make_cloud(23, 17, normals);
    const auto path = dir / "cloud.ply";
    write_ply(path, cloud, nullptr, binary);
    const PointCloud back = read_ply(path);
    expect_cloud_back(cloud, back, binary);
    EXPECT_EQ(back.normals.empty(), !normals);
}

TEST_P(PlyRoundTrip, LabelsDoNotChangeTheCloud) {
    const auto& [binary, normals] = GetParam();
    ScratchDir dir;
    const PointCloud cloud = make_cloud(9, 8, normals);
    std::vector<std::uint32_t> labels(72);
    for (std::size_t i = 0; i < labels.size(); ++i) labels[i] = std::uint32_t(i % 5);
    write_ply(dir / "l.ply", cloud, labels.data(), binary);
    expect_cloud_back(cloud, read_ply(dir / "l.ply"), binary);
}

// A point with one non-finite coordinate is invalid to pyrseg: written as a gap, it reads back NaN NaN NaN.
TEST_P(PlyRoundTrip, PartlyNonFinitePointsBecomeGaps) {
    const auto& [binary, normals] = GetParam();
    ScratchDir dir;
    PointCloud cloud = make_cloud(5, 2, normals);
    cloud.points[3 * 1 + 2] = std::numeric_limits<float>::quiet_NaN();
    cloud.points[3 * 5 + 1] = std::numeric_limits<float>::infinity();
    cloud.points[3 * 6] = -std::numeric_limits<float>::infinity();
    write_ply(dir / "p.ply", cloud, nullptr, binary);
    const PointCloud back = read_ply(dir / "p.ply");
    for (const std::size_t i : {1u, 5u, 6u}) {
        for (std::size_t c = 0; c < 3; ++c) EXPECT_TRUE(std::isnan(back.points[3 * i + c])) << i;
    }
    EXPECT_NEAR(back.points[3 * 4], cloud.points[3 * 4], 1e-5f);
}

TEST_P(PlyRoundTrip, EveryPointInvalid) {
    const auto& [binary, normals] = GetParam();
    ScratchDir dir;
    PointCloud cloud = make_cloud(4, 3, normals);
    std::fill(cloud.points.begin(), cloud.points.end(), std::numeric_limits<float>::quiet_NaN());
    write_ply(dir / "none.ply", cloud, nullptr, binary);
    const PointCloud back = read_ply(dir / "none.ply");
    EXPECT_EQ(back.width, 4);
    EXPECT_EQ(back.height, 3);
    for (float v : back.points) EXPECT_TRUE(std::isnan(v));
}

INSTANTIATE_TEST_SUITE_P(BinaryAndAscii, PlyRoundTrip, ::testing::Combine(::testing::Bool(), ::testing::Bool()),
                         [](const auto& p) {
                             return std::string(std::get<0>(p.param) ? "binary" : "ascii") +
                                    (std::get<1>(p.param) ? "_normals" : "_xyz");
                         });

// What CloudCompare and MeshLab see: only the valid points as vertices, each coloured by its label (label 0 gray),
// and the grid in obj_info and range_grid.
TEST(PlyWrite, ValidPointsColouredByLabelAndTheGrid) {
    ScratchDir dir;
    const PointCloud cloud = make_cloud(6, 5, false);
    std::vector<std::uint32_t> labels(30);
    for (std::size_t i = 0; i < labels.size(); ++i) labels[i] = std::uint32_t(i % 4 == 0 ? 0 : 100 + i);
    write_ply(dir / "c.ply", cloud, labels.data(), false);
    std::istringstream in(read_bytes(dir / "c.ply"));
    std::string line, header;
    while (std::getline(in, line) && line != "end_header") header += line + "\n";
    for (const char* expected :
         {"format ascii 1.0\n", "obj_info num_cols 6\n", "obj_info num_rows 5\n",
          "property float x\nproperty float y\nproperty float z\n",
          "property uchar red\nproperty uchar green\nproperty uchar blue\n", "element range_grid 30\n"}) {
        EXPECT_NE(header.find(expected), std::string::npos) << expected << " not in:\n" << header;
    }
    EXPECT_EQ(header.find("nan"), std::string::npos);
    std::vector<std::size_t> valid;
    for (std::size_t i = 0; i < 30; ++i) {
        if (!std::isnan(cloud.points[3 * i])) valid.push_back(i);
    }
    EXPECT_NE(header.find("element vertex " + std::to_string(valid.size()) + "\n"), std::string::npos) << header;
    for (const std::size_t i : valid) {
        ASSERT_TRUE(std::getline(in, line));
        std::istringstream fields(line);
        float x = 0, y = 0, z = 0;
        int r = 0, g = 0, b = 0;
        fields >> x >> y >> z >> r >> g >> b;
        ASSERT_FALSE(fields.fail()) << line;
        EXPECT_NEAR(x, cloud.points[3 * i], 1e-5f) << line;
        EXPECT_NEAR(z, cloud.points[3 * i + 2], 1e-5f) << line;
        const std::array<std::uint8_t, 3> c =
            labels[i] == 0 ? std::array<std::uint8_t, 3>{128, 128, 128} : label_color(labels[i]);
        EXPECT_EQ(r, c[0]) << "point " << i;
        EXPECT_EQ(g, c[1]) << "point " << i;
        EXPECT_EQ(b, c[2]) << "point " << i;
    }
    // range_grid: one line per cell, "1 k" for the k-th vertex, "0" for a gap.
    std::size_t k = 0;
    for (std::size_t i = 0; i < 30; ++i) {
        ASSERT_TRUE(std::getline(in, line));
        const bool is_valid = k < valid.size() && valid[k] == i;
        EXPECT_EQ(line, is_valid ? "1 " + std::to_string(k) : "0") << "cell " << i;
        if (is_valid) ++k;
    }
}

TEST(PlyWrite, BadCloudsAndUnwritablePathsAreErrors) {
    ScratchDir dir;
    PointCloud cloud = make_cloud(4, 3, false);
    std::string message;
    ErrorCode code{};
    EXPECT_EQ(outcome([&] { write_ply(dir / "no" / "such" / "dir.ply", cloud, nullptr, true); }, &message, &code),
              "error");
    EXPECT_EQ(code, ErrorCode::io);
    EXPECT_NE(message.find("dir.ply"), std::string::npos) << message;
    cloud.points.pop_back();
    EXPECT_EQ(outcome([&] { write_ply(dir / "short.ply", cloud, nullptr, true); }, &message, &code), "error");
    EXPECT_EQ(code, ErrorCode::invalid_argument);
    cloud = make_cloud(4, 3, true);
    cloud.normals.resize(5);
    EXPECT_EQ(outcome([&] { write_ply(dir / "normals.ply", cloud, nullptr, true); }, &message, &code), "error");
    EXPECT_EQ(code, ErrorCode::invalid_argument);
}

// ---- files from elsewhere

TEST(PlyRead, BinaryAndAsciiWithAnObjInfoGrid) {
    ScratchDir dir;
    write_bytes(dir / "b.ply", grid_binary(5, 4));
    write_bytes(dir / "a.ply", grid_ascii(5, 4));
    for (const char* name : {"b.ply", "a.ply"}) {
        const PointCloud c = read_ply(dir / name);
        EXPECT_EQ(c.width, 5);
        EXPECT_EQ(c.height, 4);
        EXPECT_TRUE(c.normals.empty());
        ASSERT_EQ(c.points.size(), 60u);
        EXPECT_EQ(c.points[3 * 7], 7.0f) << name;
        EXPECT_EQ(c.points[3 * 7 + 1], -7.0f) << name;
        EXPECT_EQ(c.points[3 * 19 + 2], 20.0f) << name;
    }
}

TEST(PlyRead, BigEndianDoublesAndNormalXNames) {
    ScratchDir dir;
    std::string s =
        "ply\nformat binary_big_endian 1.0\ncomment big-endian doubles\n" + grid_lines(3, 2) +
        "element vertex 6\nproperty double x\nproperty double y\nproperty double z\nproperty uchar quality\n"
        "property double normal_x\nproperty double normal_y\nproperty double normal_z\nend_header\n";
    for (int i = 0; i < 6; ++i) {
        for (double v : {0.25 * i, -0.5 * i, 2.0 + i}) put(s, v, true);
        s += '\x07';
        for (double v : {0.0, 0.6, -0.8}) put(s, v, true);
    }
    write_bytes(dir / "be.ply", s);
    const PointCloud c = read_ply(dir / "be.ply");
    EXPECT_EQ(c.width, 3);
    EXPECT_EQ(c.height, 2);
    ASSERT_EQ(c.normals.size(), 18u);
    EXPECT_EQ(c.points[3 * 5], 1.25f);
    EXPECT_EQ(c.points[3 * 5 + 1], -2.5f);
    EXPECT_EQ(c.points[3 * 5 + 2], 7.0f);
    EXPECT_EQ(c.normals[3 * 4 + 1], 0.6f);
    EXPECT_EQ(c.normals[3 * 4 + 2], -0.8f);
}

// Photoneo PhoXi Control's organized PLY: the size in "obj_info Photoneo PLY PointCloud ( Width = W; Height = H)",
// which PCL's reader does not parse; seen with and without spaces, and as a comment.
TEST(PlyRead, PhoxiOrganizedExport) {
    ScratchDir dir;
    for (const char* size_line : {"obj_info Photoneo PLY PointCloud ( Width = 5; Height = 4)",
                                  "obj_info Photoneo PLY PointCloud (Width=5; Height=4; Ordered)",
                                  "comment Photoneo PLY PointCloud ( Width = 5; Height = 4)"}) {
        write_bytes(dir / "phoxi.ply", phoxi_ply(5, 4, size_line));
        const PointCloud c = read_ply(dir / "phoxi.ply");
        EXPECT_EQ(c.width, 5) << size_line;
        EXPECT_EQ(c.height, 4) << size_line;
        ASSERT_EQ(c.normals.size(), 60u) << size_line;
        EXPECT_EQ(c.points[3 * 6], 9.0f);
        EXPECT_EQ(c.points[3 * 6 + 2], 806.0f);
        EXPECT_EQ(c.points[3 * 7 + 2], 0.0f);  // no measurement: 0 0 0, as stored
        EXPECT_EQ(c.normals[3 * 6 + 2], -0.8f);
    }
    write_bytes(dir / "phoxi.ply", phoxi_ply(5, 4, "obj_info Photoneo PLY PointCloud ( Width = 4; Height = 4)"));
    expect_error_containing(dir / "phoxi.ply", "Width = 4, Height = 4");
}

TEST(PlyRead, StanfordRangeGrid) {
    ScratchDir dir;
    // 3 x 2 cells, vertices for cells 0, 2, 3, 5.
    std::string s = "ply\nformat binary_little_endian 1.0\n" + grid_lines(3, 2) +
                    "element vertex 4\nproperty float x\nproperty float y\nproperty float z\nelement range_grid 6\n"
                    "property list uchar int vertex_indices\nend_header\n";
    for (int i = 0; i < 4; ++i) {
        for (float v : {float(i), 1.0f, 2.0f}) put(s, v);
    }
    const int cells[6] = {0, -1, 1, 2, -1, 3};
    for (int v : cells) {
        if (v < 0) {
            s += '\0';
        } else {
            s += '\x01';
            put(s, std::int32_t{v});
        }
    }
    write_bytes(dir / "range.ply", s);
    const PointCloud c = read_ply(dir / "range.ply");
    EXPECT_EQ(c.width, 3);
    EXPECT_EQ(c.height, 2);
    EXPECT_EQ(c.points[3 * 3], 2.0f);
    EXPECT_EQ(c.points[3 * 5], 3.0f);
    EXPECT_TRUE(std::isnan(c.points[3 * 1]));
    EXPECT_TRUE(std::isnan(c.points[3 * 4 + 2]));
    // An index past the vertices: PCL refuses it.
    s[s.size() - 4] = '\x09';
    write_bytes(dir / "range.ply", s);
    expect_error(dir / "range.ply");
}

#if PYRSEG_TEST_PCL
// PCL's own writers keep the grid in the camera element (viewportx, viewporty), or in obj_info and range_grid.
TEST(PlyRead, WhatPclItselfWrites) {
    ScratchDir dir;
    pcl::PointCloud<pcl::PointXYZ> organized(7, 3);
    for (std::size_t i = 0; i < organized.size(); ++i) organized[i] = pcl::PointXYZ(float(i), 0.5f, 3.0f);
    organized[4].x = organized[4].y = organized[4].z = std::numeric_limits<float>::quiet_NaN();
    ASSERT_EQ(pcl::io::savePLYFileBinary((dir / "camera.ply").string(), organized), 0);
    ASSERT_EQ(pcl::io::savePLYFileASCII((dir / "camera_ascii.ply").string(), organized), 0);
    ASSERT_EQ(pcl::PLYWriter().write((dir / "range.ply").string(), organized, true, false), 0);
    for (const char* name : {"camera.ply", "camera_ascii.ply", "range.ply"}) {
        const PointCloud c = read_ply(dir / name);
        EXPECT_EQ(c.width, 7) << name;
        EXPECT_EQ(c.height, 3) << name;
        EXPECT_EQ(c.points[3 * 6], 6.0f) << name;
        EXPECT_TRUE(std::isnan(c.points[3 * 4 + 2])) << name;
    }
    pcl::PointCloud<pcl::PointXYZ> unorganized;
    for (int i = 0; i < 21; ++i) unorganized.push_back(pcl::PointXYZ(float(i), 0.5f, 3.0f));
    ASSERT_EQ(pcl::io::savePLYFileBinary((dir / "flat.ply").string(), unorganized), 0);
    expect_error_containing(dir / "flat.ply", "not organized");
}

// PCL's console messages are silenced while pyrseg calls it: only the exception speaks.
TEST(PlyRead, PclPrintsNothing) {
    ScratchDir dir;
    pcl::PointCloud<pcl::PointXYZ> organized(4, 2);
    for (std::size_t i = 0; i < organized.size(); ++i) organized[i] = pcl::PointXYZ(1.0f, 2.0f, 3.0f);
    ASSERT_EQ(pcl::io::savePLYFileBinary((dir / "camera.ply").string(), organized), 0);
    std::string bytes = read_bytes(dir / "camera.ply");
    write_bytes(dir / "cut.ply", bytes.substr(0, bytes.size() - 30));
    ::testing::internal::CaptureStdout();
    ::testing::internal::CaptureStderr();
    read_ply(dir / "camera.ply");  // PCL warns about the camera properties it does not use
    const std::string result = outcome([&] { read_ply(dir / "cut.ply"); });
    const std::string out = ::testing::internal::GetCapturedStdout();
    const std::string err = ::testing::internal::GetCapturedStderr();
    EXPECT_EQ(result, "error");
    EXPECT_EQ(out + err, "");
}
#endif

// ---- not organized

TEST(PlyRead, UnorganizedCloudsAreRefusedWithTheReason) {
    ScratchDir dir;
    write_bytes(dir / "flat.ply", xyz_header("ascii", 3, "comment no grid\n") + "1 2 3\n4 5 6\n7 8 9\n");
    const std::string message = expect_error(dir / "flat.ply");
    EXPECT_NE(message.find("flat.ply: PLY cloud is not organized (3 vertices, no obj_info num_cols/num_rows grid)"),
              std::string::npos)
        << message;
    EXPECT_NE(message.find("structured-light"), std::string::npos) << message;
    write_bytes(dir / "one_row.ply", xyz_header("ascii", 3, grid_lines(3, 1)) + "1 2 3\n4 5 6\n7 8 9\n");
    expect_error_containing(dir / "one_row.ply", "not organized");
    write_bytes(dir / "phoxi_unorganized.ply",
                xyz_header("ascii", 3, "obj_info Photoneo PLY PointCloud\n") + "1 2 3\n4 5 6\n7 8 9\n");
    expect_error_containing(dir / "phoxi_unorganized.ply", "not organized");
}

// ---- malformed files

// PCL writes invalid points of an ascii PLY as nan: they stay readable, as NaN.
TEST(PlyAscii, NanAndInfinityTokensAreValues) {
    ScratchDir dir;
    write_bytes(dir / "nan.ply", xyz_header("ascii", 4, grid_lines(2, 2)) + "1 2 3\nnan nan nan\n+1 -2 inf\n1 2 3\n");
    const PointCloud c = read_ply(dir / "nan.ply");
    ASSERT_EQ(c.points.size(), 12u);
    EXPECT_TRUE(std::isnan(c.points[3]));
    EXPECT_EQ(c.points[6], 1.0f);
}

TEST(PlyMalformed, EachNamedCase) {
    ScratchDir dir;
    const std::string good = grid_binary(4, 3);
    std::string negative_count = xyz_header("ascii", 4, grid_lines(2, 2));
    negative_count.replace(negative_count.find("vertex 4"), 8, "vertex -4");
    struct Case {
        const char* name;
        std::string bytes;
        const char* says;
    };
    const std::vector<Case> cases = {
        {"empty", "", "empty file"},
        {"magic", "plx" + good.substr(3), "not a PLY file"},
        {"pcd", "# .PCD v0.7\nVERSION 0.7\n", "not a PLY file"},
        {"no_end_header", good.substr(0, good.find("end_header")), "no end_header"},
        {"truncated_binary", good.substr(0, good.size() - 5), "truncated"},
        {"truncated_ascii", grid_ascii(4, 3).substr(0, grid_ascii(4, 3).size() - 20), ""},
        {"no_x",
         "ply\nformat ascii 1.0\n" + grid_lines(2, 2) +
             "element vertex 4\nproperty float y\nproperty float z\nend_header\n1 2\n1 2\n1 2\n1 2\n",
         "no property x"},
        {"int_x",
         "ply\nformat ascii 1.0\n" + grid_lines(2, 2) +
             "element vertex 4\nproperty int x\nproperty float y\nproperty float z\nend_header\n" +
             "1 2 3\n1 2 3\n1 2 3\n1 2 3\n",
         "not float or double"},
        {"no_vertex", "ply\nformat ascii 1.0\nelement face 0\nproperty list uchar int vertex_indices\nend_header\n",
         "no element vertex"},
        {"grid_vs_count", xyz_header("binary_little_endian", 20, grid_lines(4, 3)) + std::string(240, '\0'),
         "but element vertex has 20"},
        {"grid_larger_than_count", xyz_header("binary_little_endian", 5, grid_lines(4, 3)) + std::string(60, '\0'),
         "but element vertex has 5"},
        {"grid_huge", xyz_header("binary_little_endian", 5, grid_lines(400000, 300000)) + std::string(60, '\0'),
         "too large"},
        {"grid_negative", xyz_header("binary_little_endian", 12, grid_lines(-4, 3)) + std::string(144, '\0'),
         "positive integer"},
        {"only_num_cols", xyz_header("binary_little_endian", 12, "obj_info num_cols 4\n") + std::string(144, '\0'),
         "only one of"},
        {"huge_count", xyz_header("binary_little_endian", 1000000000, grid_lines(40000, 25000)) + std::string(64, '\0'),
         "truncated"},
        {"negative_count", negative_count + "1 2 3\n1 2 3\n1 2 3\n1 2 3\n", "is not a count"},
        {"leading_space_obj_info",
         xyz_header("ascii", 4, " obj_info num_cols 2\nobj_info num_rows 2\n") + "1 2 3\n1 2 3\n1 2 3\n1 2 3\n",
         "starts with whitespace"},
        {"element_without_properties",
         "ply\nformat binary_little_endian 1.0\n" + grid_lines(2, 2) +
             "element vertex 4\nproperty float x\nproperty float y\nproperty float z\nelement face 100000000000\n"
             "end_header\n" +
             std::string(48, '\0'),
         "no properties"},
        {"blue_without_red",
         "ply\nformat ascii 1.0\n" + grid_lines(2, 2) +
             "element vertex 4\nproperty float x\nproperty float y\nproperty float z\nproperty uchar blue\n"
             "end_header\n1 2 3 4\n1 2 3 4\n1 2 3 4\n1 2 3 4\n",
         "colour"},
        {"vertex_list",
         "ply\nformat ascii 1.0\n" + grid_lines(2, 2) +
             "element vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
             "property list uchar float f\nend_header\n1 2 3 0\n1 2 3 0\n1 2 3 0\n1 2 3 0\n",
         "list property"},
        {"range_grid_without_grid",
         "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\nproperty float z\n"
         "element range_grid 4\nproperty list uchar int vertex_indices\nend_header\n1 2 3\n1 2 3\n1 0\n0\n0\n1 1\n",
         "not organized"},
        // PCL's ascii parser read these as NaN, inf and 44 (300 cast to a uchar), silently.
        {"ascii_not_a_number", xyz_header("ascii", 4, grid_lines(2, 2)) + "1 2 3\n1 abc 3\n1 2 3\n1 2 3\n",
         "instance 1: property 'y': 'abc' is not a float value"},
        {"ascii_beyond_float", xyz_header("ascii", 4, grid_lines(2, 2)) + "1 2 3\n1 2 3\n1 2 1e50\n1 2 3\n",
         "property 'z': '1e50' is not a float value"},
        {"ascii_uchar_300",
         xyz_header("ascii", 4, grid_lines(2, 2), "property uchar red\nproperty uchar green\nproperty uchar blue\n") +
             "1 2 3 0 0 0\n1 2 3 300 0 0\n1 2 3 0 0 0\n1 2 3 0 0 0\n",
         "property 'red': '300' is not a uchar value"},
        {"ascii_short_line", xyz_header("ascii", 4, grid_lines(2, 2)) + "1 2 3\n1 2\n1 2 3\n1 2 3 4 5 6\n",
         "the line ends before property 'z'"},
        {"unknown_keyword", "ply\nformat ascii 1.0\nfrobnicate\n", "unknown keyword"},
        {"bad_format", "ply\nformat binary_middle_endian 1.0\n", "unknown format"},
        {"bad_version", "ply\nformat ascii 2.0\n", "version"},
        {"bad_type", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float16 x\n", "unknown property type"},
        {"garbage", std::string("\x7f\x45\x4c\x46\x02\x01\x01\0\0\0\0\0\0\0\0\0", 16) + std::string(300, '\xa5'),
         "not a PLY file"},
        {"garbage_after_magic", "ply\n" + std::string(300, '\xa5'), "no end_header"},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(c.name);
        const fs::path path = dir / (std::string(c.name) + ".ply");
        write_bytes(path, c.bytes);
        if (*c.says == '\0') {
            expect_error(path);
        } else {
            expect_error_containing(path, c.says);
        }
    }
}

TEST(PlyMalformed, MissingFilesAndFoldersAreIoErrors) {
    ScratchDir dir;
    expect_error(dir / "missing.ply", ErrorCode::io);
    fs::create_directories(dir / "folder.ply");
    expect_error(dir / "folder.ply", ErrorCode::io);
}

// Deterministic fuzzing: each file cut at many lengths, and its header (then its data) with bytes flipped by a
// seeded generator. Every case must load or throw pyrseg::Error naming the file; a crash or hang fails the run.
TEST(PlyMalformed, TruncationsAndByteFlipsNeverCrash) {
    ScratchDir dir;
    std::vector<std::uint32_t> labels(35);
    for (std::size_t i = 0; i < labels.size(); ++i) labels[i] = std::uint32_t(i % 3);
    write_ply(dir / "written_binary.ply", make_cloud(7, 5, true), labels.data(), true);
    write_ply(dir / "written_ascii.ply", make_cloud(7, 5, true), labels.data(), false);
    const std::vector<std::string> bases = {read_bytes(dir / "written_binary.ply"),
                                            read_bytes(dir / "written_ascii.ply"),
                                            phoxi_ply(4, 3, "obj_info Width = 4; Height = 3"), grid_ascii(3, 3)};
    std::mt19937 rng(20240611);
    const fs::path path = dir / "fuzz.ply";
    int loaded = 0, refused = 0;
    auto attempt = [&](const std::string& bytes) {
        write_bytes(path, bytes);
        std::string message;
        const std::string result = outcome([&] { read_ply(path); }, &message);
        if (result == "error") {
            ++refused;
            EXPECT_NE(message.find("fuzz.ply"), std::string::npos) << message;
        } else if (result == "ok") {
            ++loaded;
        }
    };
    for (const std::string& base : bases) {
        const std::size_t header = base.find("end_header\n") + 11;
        for (std::size_t len = 0; len < base.size(); len += (len < header + 64 ? 1 : 7)) attempt(base.substr(0, len));
        for (int round = 0; round < 300; ++round) {
            std::string bytes = base;
            const int flips = 1 + int(rng() % 3);
            for (int f = 0; f < flips; ++f) {
                const std::size_t at = round < 200 ? rng() % header : header + rng() % (bytes.size() - header);
                bytes[at] = char(rng() % 2 == 0 ? bytes[at] ^ char(1u << (rng() % 8)) : char(rng() % 256));
            }
            attempt(bytes);
        }
    }
    EXPECT_GT(loaded, 0);
    EXPECT_GT(refused, 0);
}

#else  // !PYRSEG_HAVE_PLY

TEST(PlyWithoutPcl, ReadAndWriteSaySo) {
    ScratchDir dir;
    std::string message;
    ErrorCode code{};
    EXPECT_EQ(outcome([&] { read_ply(dir / "a.ply"); }, &message, &code), "error");
    EXPECT_EQ(code, ErrorCode::format);
    EXPECT_NE(message.find("a.ply"), std::string::npos) << message;
    EXPECT_NE(message.find("without PLY support"), std::string::npos) << message;
    EXPECT_EQ(outcome([&] { write_ply(dir / "b.ply", make_cloud(2, 2, false), nullptr, true); }, &message, &code),
              "error");
    EXPECT_NE(message.find("without PLY support"), std::string::npos) << message;
}

#endif

}  // namespace
}  // namespace pyrseg::io::test
