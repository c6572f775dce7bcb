// Segment statistics tables: CSV for spreadsheets, JSON for programs; both read back to what was written.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "io_test_util.hpp"
#include "pyrseg/io.hpp"

namespace pyrseg::io::test {
namespace {

std::vector<SegmentStats> two_segments() {
    SegmentStats a;
    a.label = 1;
    a.pixel_count = 1200;
    a.fillable_count = 1100;
    a.x_min = 3;
    a.y_min = 4;
    a.x_max = 50;
    a.y_max = 61;
    a.centroid = {-12.5, 0.1, 1234.0625};
    a.mean_normal = {0.0, 0.6, -0.8};
    a.z_min = 1200;
    a.z_max = 1300.5;
    a.plane_normal = {0.0, 0.6, -0.8};
    a.plane_offset = 987.25;
    a.plane_rms = 0.5;
    a.curvature = 0.001;
    a.planar = true;
    a.axes = {{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}};
    a.extents = {40, 30, 2};
    SegmentStats b = a;
    b.label = 7;
    b.pixel_count = 1;
    b.fillable_count = 1;
    b.centroid = {1.0 / 3.0, 2.0, 3.0};
    return {a, b};
}

std::string slurp(const fs::path& path) {
    std::ifstream in(path);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
}

TEST(SegmentTable, JsonReadsBackExactly) {
    ScratchDir dir;
    const fs::path path = dir.path() / "frame.stats.json";
    write_segment_stats(path, two_segments(), SegmentTable{640, 480, 1000.0, "scan.pcd"});
    const nlohmann::json doc = nlohmann::json::parse(slurp(path));
    EXPECT_EQ(doc["source"], "scan.pcd");
    EXPECT_EQ(doc["width"], 640);
    EXPECT_EQ(doc["height"], 480);
    EXPECT_EQ(doc["unit_mm"], 1000.0);
    EXPECT_EQ(doc["segment_count"], 2);
    ASSERT_EQ(doc["segments"].size(), 2u);
    const nlohmann::json& b = doc["segments"][1];
    EXPECT_EQ(b["label"], 7);
    EXPECT_EQ(b["pixel_count"], 1);
    EXPECT_EQ(b["fillable_count"], 1);
    EXPECT_EQ(b["bbox"], nlohmann::json({3, 4, 50, 61}));
    EXPECT_EQ(b["centroid"][0].get<double>(), 1.0 / 3.0) << "doubles are written to round-trip";
    EXPECT_EQ(b["mean_normal"][2].get<double>(), -0.8);
    EXPECT_EQ(b["depth_range"], nlohmann::json({1200.0, 1300.5}));
    EXPECT_EQ(b["plane"]["normal"], nlohmann::json({0.0, 0.6, -0.8}));
    EXPECT_EQ(b["plane"]["offset"].get<double>(), 987.25);
    EXPECT_EQ(b["plane"]["rms"].get<double>(), 0.5);
    EXPECT_EQ(b["plane"]["curvature"].get<double>(), 0.001);
    EXPECT_EQ(b["plane"]["planar"], true);
    EXPECT_EQ(b["box"]["centre"][0].get<double>(), 1.0 / 3.0);
    EXPECT_EQ(b["box"]["axes"][1], nlohmann::json({0.0, 1.0, 0.0}));
    EXPECT_EQ(b["box"]["extents"], nlohmann::json({40.0, 30.0, 2.0}));
}

TEST(SegmentTable, CsvHasAHeaderAndOneLinePerSegment) {
    ScratchDir dir;
    const fs::path path = dir.path() / "frame.stats.CSV";
    write_segment_stats(path, two_segments(), SegmentTable{640, 480, 1.0, "x"});
    std::istringstream text(slurp(path));
    std::string line;
    std::vector<std::string> lines;
    while (std::getline(text, line)) lines.push_back(line);
    ASSERT_EQ(lines.size(), 3u);
    EXPECT_EQ(
        lines[0],
        "label,pixel_count,fillable_count,x_min,y_min,x_max,y_max,centroid_x,centroid_y,centroid_z,"
        "normal_x,normal_y,normal_z,z_min,z_max,plane_nx,plane_ny,plane_nz,plane_offset,plane_rms,curvature,planar,"
        "axis0_x,axis0_y,axis0_z,axis1_x,axis1_y,axis1_z,axis2_x,axis2_y,axis2_z,extent0,extent1,extent2");
    EXPECT_EQ(lines[1],
              "1,1200,1100,3,4,50,61,-12.5,0.1,1234.0625,0.0,0.6,-0.8,1200.0,1300.5,0.0,0.6,-0.8,987.25,0.5,0.001,1,"
              "1.0,0.0,0.0,0.0,1.0,0.0,0.0,0.0,1.0,40.0,30.0,2.0");
}

TEST(SegmentTable, AMasksMissingGeometryIsEmptyInCsvAndNullInJson) {
    ScratchDir dir;
    std::vector<SegmentStats> segments = two_segments();
    for (double& v : segments[0].centroid) v = std::numeric_limits<double>::quiet_NaN();
    for (double& v : segments[0].mean_normal) v = std::numeric_limits<double>::quiet_NaN();
    constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
    segments[0].z_min = segments[0].z_max = segments[0].plane_offset = kNaN;
    segments[0].plane_rms = segments[0].curvature = kNaN;
    segments[0].planar = false;
    segments[0].fillable_count = 0;
    segments[0].plane_normal.fill(kNaN);
    for (auto& axis : segments[0].axes) axis.fill(kNaN);
    segments[0].extents.fill(kNaN);
    write_segment_stats(dir.path() / "m.csv", segments, SegmentTable{});
    write_segment_stats(dir.path() / "m.json", segments, SegmentTable{});
    EXPECT_NE(slurp(dir.path() / "m.csv").find("1,1200,0,3,4,50,61" + std::string(27, ',') + "\n"), std::string::npos);
    const nlohmann::json doc = nlohmann::json::parse(slurp(dir.path() / "m.json"));
    EXPECT_TRUE(doc["segments"][0]["centroid"][1].is_null());
    EXPECT_TRUE(doc["segments"][0]["plane"]["rms"].is_null());
    EXPECT_TRUE(doc["segments"][0]["box"]["extents"][2].is_null());
}

TEST(SegmentTable, AnUnwritablePathIsAnErrorNamingIt) {
    const fs::path path = "/nonexistent-dir/stats.json";
    try {
        write_segment_stats(path, two_segments(), SegmentTable{});
        FAIL() << "no error";
    } catch (const Error& e) {
        EXPECT_EQ(e.code(), ErrorCode::io);
        EXPECT_NE(std::string(e.what()).find(path.string()), std::string::npos) << e.what();
    }
}

}  // namespace
}  // namespace pyrseg::io::test
