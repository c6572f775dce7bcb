// `pyrseg segment` with PLY: organized PLY in (the same labels as the same cloud as PCD), coloured PLY out (--ply,
// --write ...,ply), run as a user runs it.
#include <gtest/gtest.h>

#include <unistd.h>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "cli/cli_runner.hpp"
#include "pyrseg/io.hpp"
#include "pyrseg/synthetic.hpp"

namespace {

namespace fs = std::filesystem;

using pyrseg::cli_test::CliRun;
using pyrseg::cli_test::run;

class CliPly : public ::testing::Test {
protected:
    void SetUp() override {
        dir_ = fs::temp_directory_path() / ("pyrseg_cli_ply_test_" + std::to_string(::getpid()));
        fs::remove_all(dir_);
        fs::create_directories(dir_);
    }
    void TearDown() override {
        std::error_code ec;
        fs::remove_all(dir_, ec);
    }

    // A small synthetic bin-picking frame (mm), without normals so that both runs estimate them the same way.
    static pyrseg::io::PointCloud scene_cloud(std::uint64_t seed) {
        return pyrseg::cli_test::scene_cloud(96, 72, seed, 4);
    }

    static std::vector<unsigned char> labels_of(const fs::path& npy) { return pyrseg::io::read_npy(npy).bytes; }

    fs::path dir_;
};

#if PYRSEG_HAVE_PLY

TEST_F(CliPly, PlyInputGivesTheLabelsOfTheSameCloudAsPcdAndPlyOutReadsBack) {
    const pyrseg::io::PointCloud cloud = scene_cloud(3);
    pyrseg::io::write_pcd(dir_ / "frame.pcd", cloud, pyrseg::io::PcdEncoding::binary);
    pyrseg::io::write_ply(dir_ / "frame.ply", cloud, nullptr, true);
    CliRun r =
        run("segment " + (dir_ / "frame.pcd").string() + " --backend cpu --labels " + (dir_ / "pcd.npy").string());
    ASSERT_EQ(r.status, 0) << r.output;
    r = run("segment " + (dir_ / "frame.ply").string() + " --backend cpu --labels " + (dir_ / "ply.npy").string() +
            " --ply " + (dir_ / "segments.ply").string());
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_NE(r.output.find("PLY, 96 x 72, normals estimated"), std::string::npos) << r.output;
    const std::vector<unsigned char> from_pcd = labels_of(dir_ / "pcd.npy");
    EXPECT_EQ(labels_of(dir_ / "ply.npy"), from_pcd);
    std::size_t labelled = 0;
    for (std::size_t i = 0; i < from_pcd.size(); i += 4) labelled += from_pcd[i] != 0 ? 1 : 0;
    EXPECT_GT(labelled, 1000u);  // the comparison means something: many pixels segmented

    const pyrseg::io::PointCloud out = pyrseg::io::read_ply(dir_ / "segments.ply");
    EXPECT_EQ(out.width, 96);
    EXPECT_EQ(out.height, 72);
    ASSERT_EQ(out.points.size(), cloud.points.size());
    for (std::size_t i = 0; i < cloud.points.size(); ++i) {
        if (std::isnan(cloud.points[i])) {
            EXPECT_TRUE(std::isnan(out.points[i])) << i;
        } else {
            EXPECT_EQ(out.points[i], cloud.points[i]) << i;
        }
    }
    // The PLY written is itself an input that gives the same labels.
    r = run("segment " + (dir_ / "segments.ply").string() + " --backend cpu --labels " + (dir_ / "again.npy").string());
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_EQ(labels_of(dir_ / "again.npy"), from_pcd);
}

TEST_F(CliPly, BatchWritesPlyAndNeverOverwritesItsInput) {
    fs::create_directories(dir_ / "in");
    pyrseg::io::write_ply(dir_ / "in" / "a.ply", scene_cloud(5), nullptr, true);
    pyrseg::io::write_pcd(dir_ / "in" / "b.pcd", scene_cloud(6), pyrseg::io::PcdEncoding::binary);
    CliRun r = run("segment " + (dir_ / "in").string() + " --out-dir " + (dir_ / "out").string() +
                   " --write labels,ply --progress lines --backend cpu");
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_NE(r.output.find("batch: 2 frames, 2 segmented, 0 failed"), std::string::npos) << r.output;
    for (const char* name : {"a", "b"}) {
        EXPECT_TRUE(fs::exists(dir_ / "out" / (std::string(name) + ".labels.npy"))) << name;
        const pyrseg::io::PointCloud c = pyrseg::io::read_ply(dir_ / "out" / (std::string(name) + ".ply"));
        EXPECT_EQ(c.width, 96) << name;
        EXPECT_EQ(c.height, 72) << name;
    }
    // Into the input's own folder, NAME.ply would replace the input: refused before anything is read (a usage
    // error since issue 32: the batch's plan names every output first), the input untouched.
    const auto before = fs::file_size(dir_ / "in" / "a.ply");
    r = run("segment " + (dir_ / "in" / "a.ply").string() + " --out-dir " + (dir_ / "in").string() +
            " --write ply --progress lines --backend cpu");
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_NE(r.output.find("refusing to overwrite"), std::string::npos) << r.output;
    r = run("segment " + (dir_ / "in" / "a.ply").string() + " --ply " + (dir_ / "in" / "a.ply").string());
    EXPECT_EQ(r.status, 1) << r.output;
    EXPECT_EQ(fs::file_size(dir_ / "in" / "a.ply"), before);
    EXPECT_NO_THROW(pyrseg::io::read_ply(dir_ / "in" / "a.ply"));
}

TEST_F(CliPly, DepthImageOptionsAndUnorganizedPlyAreRefused) {
    pyrseg::io::write_ply(dir_ / "a.ply", scene_cloud(7), nullptr, true);
    CliRun r = run("segment " + (dir_ / "a.ply").string() + " --intrinsics 500,500,48,36 --labels " +
                   (dir_ / "o.npy").string());
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_NE(r.output.find("--intrinsics applies to depth images, not to .ply"), std::string::npos) << r.output;
    r = run("segment " + (dir_ / "a.ply").string() + " --out-dir " + (dir_ / "o").string() + " --write ply,bogus");
    EXPECT_EQ(r.status, 2) << r.output;
    FILE* f = std::fopen((dir_ / "flat.ply").c_str(), "w");
    ASSERT_NE(f, nullptr);
    std::fputs(
        "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\nproperty float z\n"
        "end_header\n1 2 3\n4 5 6\n",
        f);
    std::fclose(f);
    r = run("segment " + (dir_ / "flat.ply").string() + " --labels " + (dir_ / "o.npy").string());
    EXPECT_EQ(r.status, 1) << r.output;
    EXPECT_NE(r.output.find("flat.ply: PLY cloud is not organized"), std::string::npos) << r.output;
}

#else

TEST_F(CliPly, WithoutPclPlyIsAClearError) {
    const CliRun r = run("segment " + (dir_ / "a.ply").string() + " --labels " + (dir_ / "o.npy").string());
    EXPECT_EQ(r.status, 1) << r.output;
    EXPECT_NE(r.output.find("without PLY support"), std::string::npos) << r.output;
}

#endif

}  // namespace
