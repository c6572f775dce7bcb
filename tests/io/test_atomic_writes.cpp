// Every writer of the io library is all or nothing (issue 18): a file is written under a temporary name beside its
// target, checked and renamed, so a write that fails halfway (a full disk; here the process's file size limit, in
// a child process since the limit is process-wide) is an io error naming the file, leaves the old file as it was
// and leaves no temporary file. /dev/full, written in place (a device cannot be replaced), is an io error too.
#include <gtest/gtest.h>

#include <cstdint>
#include <functional>
#include <ostream>
#include <random>
#include <string>
#include <vector>

#include "io_test_util.hpp"

namespace pyrseg::io::test {
namespace {

struct Writer {
    std::string name;  // the test's name and the file's
    // Writes a small file, then one far past 64 KiB, to `path`.
    std::function<void(const fs::path& path)> small;
    std::function<void(const fs::path& path)> large;
};

std::vector<std::uint8_t> noise_bytes(std::size_t n) {
    std::mt19937 rng(7);
    std::vector<std::uint8_t> v(n);
    for (std::uint8_t& b : v) b = static_cast<std::uint8_t>(rng());  // incompressible: a PNG stays large
    return v;
}

std::vector<SegmentStats> many_segments(std::uint32_t n) {
    std::vector<SegmentStats> out(n);
    for (std::uint32_t i = 0; i < n; ++i) {
        out[i].label = i + 1;
        out[i].pixel_count = 100 + i;
        out[i].x_max = out[i].y_max = 9;
    }
    return out;
}

std::vector<Writer> writers() {
    static const PointCloud small_cloud = make_cloud(2, 2, false);
    static const PointCloud large_cloud = make_cloud(300, 200, true);  // 1.4 MB of points and normals
    static const std::vector<std::uint32_t> labels(std::size_t{300} * 200, 7);
    static const std::vector<std::uint8_t> bytes = noise_bytes(std::size_t{400} * 300 * 3);
    static const std::vector<float> floats(std::size_t{400} * 300 * 3, 1.5f);
    std::vector<Writer> out;
    for (const auto& [encoding, name] :
         {std::pair{PcdEncoding::ascii, "pcd_ascii"}, std::pair{PcdEncoding::binary, "pcd_binary"},
          std::pair{PcdEncoding::binary_compressed, "pcd_compressed"}}) {
        out.push_back({std::string(name) + ".pcd", [=](const fs::path& p) { write_pcd(p, small_cloud, encoding); },
                       [=](const fs::path& p) { write_pcd(p, large_cloud, labels.data(), encoding); }});
    }
#if PYRSEG_HAVE_PLY
    // PCL's PLY writer reports no write error: write_ply reads its file back.
    for (const bool binary : {true, false}) {
        out.push_back({binary ? "ply_binary.ply" : "ply_ascii.ply",
                       [=](const fs::path& p) { write_ply(p, small_cloud, nullptr, binary); },
                       [=](const fs::path& p) { write_ply(p, large_cloud, labels.data(), binary); }});
    }
#endif
    out.push_back({"labels.npy", [](const fs::path& p) { write_npy(p, labels.data(), 2, 2); },
                   [](const fs::path& p) { write_npy(p, labels.data(), 200, 300); }});
    out.push_back({"mask.npy", [](const fs::path& p) { write_npy(p, bytes.data(), 2, 2); },
                   [](const fs::path& p) { write_npy(p, bytes.data(), 300, 400); }});
    out.push_back({"image.npy", [](const fs::path& p) { write_npy(p, floats.data(), 2, 2, 3); },
                   [](const fs::path& p) { write_npy(p, floats.data(), 300, 400, 3); }});
    out.push_back({"rgb.png", [](const fs::path& p) { write_png_rgb(p, bytes.data(), 2, 2); },
                   [](const fs::path& p) { write_png_rgb(p, bytes.data(), 400, 300); }});
    out.push_back({"gray16.png",
                   [](const fs::path& p) {
                       const std::vector<std::uint16_t> g(4, 700);
                       write_png_gray16(p, g.data(), 2, 2);
                   },
                   [](const fs::path& p) {
                       std::vector<std::uint16_t> g(std::size_t{400} * 300);
                       for (std::size_t i = 0; i < g.size(); ++i)
                           g[i] = std::uint16_t(bytes[2 * i] << 8 | bytes[2 * i + 1]);
                       write_png_gray16(p, g.data(), 400, 300);
                   }});
    out.push_back({"gray8.png", [](const fs::path& p) { write_png_gray8(p, bytes.data(), 2, 2); },
                   [](const fs::path& p) { write_png_gray8(p, bytes.data(), 400, 300); }});
    out.push_back({"depth.tif", [](const fs::path& p) { write_tiff_float(p, floats.data(), 2, 2); },
                   [](const fs::path& p) { write_tiff_float(p, floats.data(), 400, 300); }});
    for (const char* name : {"stats.csv", "stats.json"}) {
        out.push_back({name, [](const fs::path& p) { write_segment_stats(p, many_segments(2), SegmentTable{}); },
                       [](const fs::path& p) { write_segment_stats(p, many_segments(5000), SegmentTable{}); }});
    }
    return out;
}

void PrintTo(const Writer& w, std::ostream* os) {
    *os << w.name;
}

class AtomicWrites : public ::testing::TestWithParam<Writer> {};

TEST_P(AtomicWrites, AWriteCutShortIsAnIoErrorAndLeavesTheOldFile) {
    const Writer& w = GetParam();
    ScratchDir dir;
    const fs::path file = dir / w.name;
    w.small(file);
    const std::string before = read_bytes(file);
    ASSERT_FALSE(before.empty());
    EXPECT_EQ(outcome_of_write_past_size_limit([&] { w.large(file); }, w.name), "io error naming " + w.name);
    EXPECT_TRUE(read_bytes(file) == before) << "the old file was changed";
    EXPECT_EQ(files_in(dir.path()), std::vector<fs::path>{w.name});
    // Without the limit the same write replaces the file, leaving nothing else.
    w.large(file);
    EXPECT_GT(read_bytes(file).size(), std::size_t{64} << 10);
    EXPECT_EQ(files_in(dir.path()), std::vector<fs::path>{w.name});
}

TEST_P(AtomicWrites, DevFullIsAnIoError) {
    if (!fs::exists("/dev/full")) GTEST_SKIP() << "no /dev/full on this system";
    ErrorCode code{};
    std::string message;
    EXPECT_EQ(outcome([&] { GetParam().large("/dev/full"); }, &message, &code), "error");
    EXPECT_EQ(code, ErrorCode::io) << message;
    EXPECT_NE(message.find("/dev/full"), std::string::npos) << message;
}

INSTANTIATE_TEST_SUITE_P(Writers, AtomicWrites, ::testing::ValuesIn(writers()),
                         [](const ::testing::TestParamInfo<Writer>& param_info) {
                             std::string name = param_info.param.name;
                             for (char& c : name) {
                                 if (c == '.') c = '_';
                             }
                             return name;
                         });

}  // namespace
}  // namespace pyrseg::io::test
