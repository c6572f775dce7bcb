// Labelled PCD output (PCL's PointXYZL layout) read back by pyrseg and by PCL itself, and the writers' promise that
// a failed write never leaves part of a file.

#include <algorithm>
#include <cstring>
#include <utility>

#include "io_test_util.hpp"

#if PYRSEG_TEST_PCL
#include <pcl/PCLPointCloud2.h>
#include <pcl/console/print.h>
#include <pcl/io/pcd_io.h>
#include <pcl/point_types.h>
#endif

namespace pyrseg::io::test {
namespace {

// Label 0 at the invalid points (as the segmenter leaves them), and values past 16 bits so that a narrower
// label type would show.
std::vector<std::uint32_t> make_labels(const PointCloud& cloud) {
    std::vector<std::uint32_t> labels(static_cast<std::size_t>(cloud.width) * static_cast<std::size_t>(cloud.height));
    for (std::size_t i = 0; i < labels.size(); ++i) {
        labels[i] = std::isnan(cloud.points[3 * i]) ? 0u : static_cast<std::uint32_t>(1 + i % 5 + (i % 3) * 70000);
    }
    return labels;
}

TEST(PcdLabels, BinaryIsPointXYZL) {
    ScratchDir dir;
    const PointCloud cloud = make_cloud(5, 3, false);
    const std::vector<std::uint32_t> labels = make_labels(cloud);
    write_pcd(dir / "l.pcd", cloud, labels.data(), PcdEncoding::binary);
    const std::string bytes = read_bytes(dir / "l.pcd");
    const std::string expected =
        "# .PCD v0.7 - Point Cloud Data file format\n"
        "VERSION 0.7\n"
        "FIELDS x y z label\n"
        "SIZE 4 4 4 4\n"
        "TYPE F F F U\n"
        "COUNT 1 1 1 1\n"
        "WIDTH 5\n"
        "HEIGHT 3\n"
        "VIEWPOINT 0 0 0 1 0 0 0\n"
        "POINTS 15\n"
        "DATA binary\n";
    ASSERT_EQ(bytes.substr(0, expected.size()), expected);
    ASSERT_EQ(bytes.size(), expected.size() + std::size_t{15} * 16);
    for (std::size_t i = 0; i < 15; ++i) {
        const char* point = bytes.data() + expected.size() + 16 * i;
        for (std::size_t c = 0; c < 3; ++c) {
            float value = 0;
            std::memcpy(&value, point + 4 * c, 4);
            const float expected_value = cloud.points[3 * i + c];
            EXPECT_TRUE(value == expected_value || (std::isnan(value) && std::isnan(expected_value))) << i;
        }
        std::uint32_t label = 0;
        std::memcpy(&label, point + 12, 4);
        EXPECT_EQ(label, labels[i]) << i;
    }
}

TEST(PcdLabels, AsciiWritesLabelsAsIntegers) {
    ScratchDir dir;
    PointCloud cloud = make_cloud(2, 2, false);
    cloud.points = {1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12};
    const std::vector<std::uint32_t> labels = {0, 7, 4000000000u, 1};
    write_pcd(dir / "a.pcd", cloud, labels.data(), PcdEncoding::ascii);
    const std::string bytes = read_bytes(dir / "a.pcd");
    EXPECT_NE(bytes.find("DATA ascii\n1 2 3 0\n4 5 6 7\n7 8 9 4000000000\n10 11 12 1\n"), std::string::npos) << bytes;
}

// pyrseg's own reader skips the label field and reads everything else as written.
class PcdLabelsRoundTrip : public ::testing::TestWithParam<std::tuple<std::string, bool>> {};

TEST_P(PcdLabelsRoundTrip, PointsAndNormalsReadBack) {
    const auto& [encoding, normals] = GetParam();
    ScratchDir dir;
    const PointCloud cloud = make_cloud(23, 17, normals);
    const std::vector<std::uint32_t> labels = make_labels(cloud);
    write_pcd(dir / "l.pcd", cloud, labels.data(), encoding_of(encoding));
    const PointCloud back = read_pcd(dir / "l.pcd");
    expect_same_cloud(cloud, back);
}

#if PYRSEG_TEST_PCL
// The point of the format: PCL users load it straight into the point type they use for labelled clouds.
TEST_P(PcdLabelsRoundTrip, PclLoadsItAsPointXYZL) {
    const auto& [encoding, normals] = GetParam();
    ScratchDir dir;
    const PointCloud cloud = make_cloud(23, 17, normals);
    const std::vector<std::uint32_t> labels = make_labels(cloud);
    write_pcd(dir / "l.pcd", cloud, labels.data(), encoding_of(encoding));
    pcl::PointCloud<pcl::PointXYZL> pcl_cloud;
    ASSERT_EQ(pcl::io::loadPCDFile((dir / "l.pcd").string(), pcl_cloud), 0);
    ASSERT_EQ(pcl_cloud.width, 23u);
    ASSERT_EQ(pcl_cloud.height, 17u);
    EXPECT_TRUE(pcl_cloud.isOrganized());
    for (std::size_t i = 0; i < labels.size(); ++i) {
        const pcl::PointXYZL& p = pcl_cloud[i];
        EXPECT_EQ(p.label, labels[i]) << i;
        for (int c = 0; c < 3; ++c) {
            const float expected = cloud.points[3 * i + static_cast<std::size_t>(c)];
            const float got = c == 0 ? p.x : c == 1 ? p.y : p.z;
            if (std::isnan(expected)) {
                EXPECT_TRUE(std::isnan(got)) << i;
            } else {
                EXPECT_EQ(got, expected) << i;
            }
        }
    }
    if (normals) {
        // PointXYZLNormal also has curvature, which the file lacks: PCL warns, and fills in the rest.
        const pcl::console::VERBOSITY_LEVEL verbosity = pcl::console::getVerbosityLevel();
        pcl::console::setVerbosityLevel(pcl::console::L_ERROR);
        pcl::PointCloud<pcl::PointXYZLNormal> with_normals;
        const int loaded = pcl::io::loadPCDFile((dir / "l.pcd").string(), with_normals);
        pcl::console::setVerbosityLevel(verbosity);
        ASSERT_EQ(loaded, 0);
        EXPECT_EQ(with_normals[0].normal_z, cloud.normals[2]);
        EXPECT_EQ(with_normals[1].label, labels[1]);
    }
}
#endif

// Further integer fields (the CLI's object, support, track) after the label: PCL reads each by name, in every
// encoding, and pyrseg's own reader still reads the points.
TEST_P(PcdLabelsRoundTrip, FurtherFieldsReadBackByName) {
    const auto& [encoding, normals] = GetParam();
    ScratchDir dir;
    const PointCloud cloud = make_cloud(23, 17, normals);
    const std::vector<std::uint32_t> labels = make_labels(cloud);
    std::vector<std::uint32_t> object(labels.size());
    std::vector<std::uint32_t> track(labels.size());
    for (std::size_t i = 0; i < labels.size(); ++i) {
        object[i] = labels[i] % 4;
        track[i] = 4000000000u - static_cast<std::uint32_t>(i);
    }
    const std::vector<PcdField> fields = {{"label", labels.data()}, {"object", object.data()}, {"track", track.data()}};
    write_pcd(dir / "f.pcd", cloud, fields, encoding_of(encoding));
    expect_same_cloud(cloud, read_pcd(dir / "f.pcd"));
#if PYRSEG_TEST_PCL
    pcl::PCLPointCloud2 blob;
    ASSERT_EQ(pcl::io::loadPCDFile((dir / "f.pcd").string(), blob), 0);
    ASSERT_EQ(blob.width * blob.height, labels.size());
    using Named = std::pair<const char*, const std::vector<std::uint32_t>*>;
    for (const auto& [name, values] : {Named{"label", &labels}, Named{"object", &object}, Named{"track", &track}}) {
        const auto field = std::find_if(blob.fields.begin(), blob.fields.end(),
                                        [&](const pcl::PCLPointField& f) { return f.name == name; });
        ASSERT_NE(field, blob.fields.end()) << name;
        EXPECT_EQ(field->datatype, pcl::PCLPointField::UINT32) << name;
        for (std::size_t i = 0; i < labels.size(); ++i) {
            std::uint32_t v = 0;
            std::memcpy(&v, blob.data.data() + i * blob.point_step + field->offset, 4);
            ASSERT_EQ(v, (*values)[i]) << name << " " << i;
        }
    }
#endif
}

INSTANTIATE_TEST_SUITE_P(AllEncodings, PcdLabelsRoundTrip,
                         ::testing::Combine(::testing::Values("ascii", "binary", "binary_compressed"),
                                            ::testing::Bool()),
                         [](const auto& p) {
                             return std::get<0>(p.param) + (std::get<1>(p.param) ? "_normals" : "_xyz");
                         });

// A field name PCL's header could not hold, or one taken twice, is refused before anything is written.
TEST(PcdLabels, FieldNamesMustBeOneNewWord) {
    ScratchDir dir;
    const PointCloud cloud = make_cloud(2, 2, false);
    const std::vector<std::uint32_t> values(4, 1);
    for (const std::string bad : {"", "two words", "x", "normal_y", "label", "tab\t"}) {
        const std::vector<PcdField> fields = {{"label", values.data()}, {bad, values.data()}};
        EXPECT_THROW(write_pcd(dir / "b.pcd", cloud, fields, PcdEncoding::binary), Error) << bad;
    }
    const std::vector<PcdField> missing = {{"object", nullptr}};
    EXPECT_THROW(write_pcd(dir / "b.pcd", cloud, missing, PcdEncoding::binary), Error);
    EXPECT_TRUE(files_in(dir.path()).empty());
}

TEST(AtomicWrite, ReplacesTheFileAndLeavesNothingElse) {
    ScratchDir dir;
    const PointCloud small = make_cloud(2, 2, false);
    const PointCloud larger = make_cloud(30, 20, true);
    write_pcd(dir / "c.pcd", small, PcdEncoding::binary);
    write_pcd(dir / "c.pcd", larger, PcdEncoding::binary);
    expect_same_cloud(read_pcd(dir / "c.pcd"), larger);
    EXPECT_EQ(files_in(dir.path()), std::vector<fs::path>{"c.pcd"});
    // A directory in the way is an io error, and no temporary file stays behind.
    fs::create_directory(dir / "d.pcd");
    ErrorCode code{};
    std::string message;
    EXPECT_EQ(outcome([&] { write_pcd(dir / "d.pcd", small, PcdEncoding::binary); }, &message, &code), "error");
    EXPECT_EQ(code, ErrorCode::io);
    EXPECT_NE(message.find("d.pcd"), std::string::npos) << message;
    EXPECT_EQ(files_in(dir.path()).size(), 2u);
}

}  // namespace
}  // namespace pyrseg::io::test
