// The pyrseg command-line tool, run as a user runs it: exit codes, messages, files written.
#include <gtest/gtest.h>

#include <unistd.h>
#include <algorithm>
#include <array>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <vector>

#include "cli/cli_runner.hpp"
#include "pyrseg/backend.hpp"
#include "pyrseg/io.hpp"
#include "pyrseg/params.hpp"
#include "pyrseg/synthetic.hpp"

namespace {

namespace fs = std::filesystem;

// A 640 x 480 labels file the CLI wrote (--labels OUT.npy), and the label at (x, y) in it.
std::vector<std::uint32_t> realsense_labels(const fs::path& path) {
    const pyrseg::io::NpyArray npy = pyrseg::io::read_npy(path);
    EXPECT_EQ(npy.shape, (std::vector<std::size_t>{480, 640}));
    std::vector<std::uint32_t> labels(std::size_t{640} * 480);
    std::memcpy(labels.data(), npy.bytes.data(), std::min(labels.size() * 4, npy.bytes.size()));
    return labels;
}

std::uint32_t label_at(const std::vector<std::uint32_t>& labels, int x, int y) {
    return labels[std::size_t(y) * 640 + std::size_t(x)];
}

// The pixels carrying `label` inside the box x0..x1, y0..y1 (inclusive) and outside it.
struct BoxCount {
    std::size_t inside = 0;
    std::size_t outside = 0;
};
BoxCount count_in_box(const std::vector<std::uint32_t>& labels, std::uint32_t label, int x0, int y0, int x1, int y1) {
    BoxCount n;
    for (std::size_t i = 0; i < labels.size(); ++i) {
        if (labels[i] != label) continue;
        const int x = int(i % 640), y = int(i / 640);
        (x >= x0 && x <= x1 && y >= y0 && y <= y1 ? n.inside : n.outside) += 1;
    }
    return n;
}

using pyrseg::cli_test::CliRun;
using pyrseg::cli_test::run;
using pyrseg::cli_test::run_with_env;

fs::path temp_dir() {
    fs::path dir = fs::temp_directory_path() / ("pyrseg_cli_test_" + std::to_string(::getpid()));
    fs::create_directories(dir);
    return dir;
}

fs::path mug_scan() {
    return fs::path(PYRSEG_SHARED_DATA_DIR) / "table_scene_mug_stereo_textured.pcd";
}

TEST(Cli, EveryCommandExplainsItselfWithHelp) {
    for (const char* command :
         {"--help", "segment --help", "demo --help", "backends --help", "eval --help", "bench-report --help"}) {
        const CliRun r = run(command);
        EXPECT_EQ(r.status, 0) << command << "\n" << r.output;
        EXPECT_NE(r.output.find("Usage"), std::string::npos) << command << "\n" << r.output;
    }
    const std::string help = run("segment --help").output;
    for (const char* option : {"--unit-mm U", "--metres-per-unit M", "--depth-scale S", "--pcd OUT.pcd",
                               "Units:", "With no output option it writes nothing"}) {
        EXPECT_NE(help.find(option), std::string::npos) << option;
    }
}

// The defaults --help states are the library's (the normal radius once read 1 after the default became 2).
TEST(Cli, HelpStatesTheLibrarysDefaults) {
    const std::string help = run("segment --help").output;
    EXPECT_NE(help.find("estimated normals (default " + std::to_string(pyrseg::kDefaultNormalRadius) + ")"),
              std::string::npos)
        << help;
}

TEST(Cli, UsageErrorsExitWithTwoAndSayWhat) {
    CliRun r = run("");
    EXPECT_EQ(r.status, 2);
    r = run("frobnicate");
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.output.find("unknown command 'frobnicate'"), std::string::npos) << r.output;
    r = run("segment");
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.output.find("INPUT"), std::string::npos) << r.output;
    r = run("segment x.pcd --dt banana --labels o.npy");
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.output.find("--dt expects a number"), std::string::npos) << r.output;
    r = run("segment x.pcd --bogus");
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.output.find("unknown option --bogus"), std::string::npos) << r.output;
    // Without an output option the input is still read (and only summarized): a missing one is a file error.
    r = run("segment x.pcd");
    EXPECT_EQ(r.status, 1);
    EXPECT_NE(r.output.find("x.pcd: cannot open"), std::string::npos) << r.output;
}

TEST(Cli, FileAndParameterErrorsNameTheProblem) {
    const fs::path dir = temp_dir();
    CliRun r = run("segment " + (dir / "missing.pcd").string() + " --labels " + (dir / "o.npy").string());
    EXPECT_EQ(r.status, 1);
    EXPECT_NE(r.output.find("missing.pcd"), std::string::npos) << r.output;
    const fs::path garbage = dir / "garbage.pcd";
    FILE* f = std::fopen(garbage.c_str(), "w");
    ASSERT_NE(f, nullptr);
    std::fputs("VERSION 0.7\nFIELDS x y\n", f);
    std::fclose(f);
    r = run("segment " + garbage.string() + " --labels " + (dir / "o.npy").string());
    EXPECT_EQ(r.status, 1);
    EXPECT_NE(r.output.find("garbage.pcd"), std::string::npos) << r.output;
    r = run("segment " + (dir / "scan.xyz").string() + " --labels o.npy");
    EXPECT_EQ(r.status, 1);
    EXPECT_NE(r.output.find("unsupported input format"), std::string::npos) << r.output;
    if (fs::exists(mug_scan())) {
        r = run("segment " + mug_scan().string() + " --ct -1 --labels " + (dir / "o.npy").string());
        EXPECT_EQ(r.status, 1);
        EXPECT_NE(r.output.find("ct"), std::string::npos) << r.output;
        r = run("segment " + mug_scan().string() + " --backend nope --labels " + (dir / "o.npy").string());
        EXPECT_EQ(r.status, 1);
        EXPECT_NE(r.output.find("unknown backend 'nope'"), std::string::npos) << r.output;
    }
    fs::remove_all(dir);
}

TEST(Cli, BackendsListsEveryBackendAndWhyNot) {
    const CliRun r = run("backends");
    EXPECT_EQ(r.status, 0);
    EXPECT_NE(r.output.find("cpu     available"), std::string::npos) << r.output;
    for (const std::string& name : pyrseg::backend_names())
        EXPECT_NE(r.output.find(name + " "), std::string::npos) << name;
}

// With no OpenCL driver (the ICD loader pointed at an empty vendor folder), `pyrseg backends` says why and
// choosing the backend is a clear error.
TEST(Cli, NoOpenclPlatformIsExplainedAndAnError) {
    const std::string listing = run("backends").output;
    const std::size_t entry = listing.find("opencl  ");
    ASSERT_NE(entry, std::string::npos) << listing;
    const std::string opencl = listing.substr(entry, listing.find('\n', listing.find('\n', entry) + 1) - entry);
    if (opencl.find("not built") != std::string::npos || opencl.find("disabled") != std::string::npos) {
        GTEST_SKIP() << "this build has no OpenCL backend: " << opencl;
    }
    const fs::path dir = temp_dir();
    const std::string no_icd = "OCL_ICD_VENDORS=" + (dir / "no-vendors").string() + " ";
    CliRun r = run_with_env(no_icd, "backends");
    EXPECT_EQ(r.status, 0) << r.output;
    EXPECT_NE(r.output.find("no OpenCL platform found"), std::string::npos) << r.output;
    if (fs::exists(mug_scan())) {
        r = run_with_env(no_icd, "segment " + mug_scan().string() + " --unit-mm 1000 --backend opencl --labels " +
                                     (dir / "o.npy").string());
        EXPECT_EQ(r.status, 1) << r.output;
        EXPECT_NE(r.output.find("backend 'opencl' (requested) is unavailable: no OpenCL platform found"),
                  std::string::npos)
            << r.output;
    }
    fs::remove_all(dir);
}

// With no Vulkan driver (the loader pointed at a driver manifest that does not exist), `pyrseg backends` says why
// and choosing the backend is a clear error.
TEST(Cli, NoVulkanDriverIsExplainedAndAnError) {
    const std::string listing = run("backends").output;
    const std::size_t entry = listing.find("vulkan  ");
    ASSERT_NE(entry, std::string::npos) << listing;
    const std::string vulkan = listing.substr(entry, listing.find('\n', listing.find('\n', entry) + 1) - entry);
    if (vulkan.find("not built") != std::string::npos || vulkan.find("disabled") != std::string::npos) {
        GTEST_SKIP() << "this build has no Vulkan backend: " << vulkan;
    }
    const fs::path dir = temp_dir();
    const std::string manifest = (dir / "no-driver.json").string();
    const std::string no_driver = "VK_ICD_FILENAMES=" + manifest + " VK_DRIVER_FILES=" + manifest + " ";
    CliRun r = run_with_env(no_driver, "backends");
    EXPECT_EQ(r.status, 0) << r.output;
    EXPECT_NE(r.output.find("no Vulkan driver found"), std::string::npos) << r.output;
    if (fs::exists(mug_scan())) {
        r = run_with_env(no_driver, "segment " + mug_scan().string() + " --unit-mm 1000 --backend vulkan --labels " +
                                        (dir / "o.npy").string());
        EXPECT_EQ(r.status, 1) << r.output;
        EXPECT_NE(r.output.find("backend 'vulkan' (requested) is unavailable: no Vulkan driver found"),
                  std::string::npos)
            << r.output;
    }
    fs::remove_all(dir);
}

// A depth image with its calibration: back-projected and segmented; without intrinsics a clear error; a point
// cloud's unit option on a depth image is a usage error.
TEST(Cli, DepthImagesNeedIntrinsicsAndSegment) {
    const fs::path data(PYRSEG_SHARED_DATA_DIR);
    const fs::path depth = data / "cape_depth_0.png";
    if (!fs::exists(depth)) GTEST_SKIP() << "sample depth image not present: " << depth.string();
    const fs::path dir = temp_dir();
    const std::string out = " --labels " + (dir / "d.npy").string();
    CliRun r = run("segment " + depth.string() + " --calib " + (data / "cape_calib_params.xml").string() +
                   ":IR_intrinsic_params" + out);
    EXPECT_EQ(r.status, 0) << r.output;
    EXPECT_NE(r.output.find("depth image, 640 x 480"), std::string::npos) << r.output;
    const pyrseg::io::NpyArray npy = pyrseg::io::read_npy(dir / "d.npy");
    ASSERT_EQ(npy.shape, (std::vector<std::size_t>{480, 640}));
    r = run("segment " + depth.string() + " --intrinsics 575.93,576.41,315.15,230.59 --metres-per-unit 0.001" + out);
    EXPECT_EQ(r.status, 0) << r.output;
    r = run("segment " + depth.string() + out);
    EXPECT_EQ(r.status, 1) << r.output;
    EXPECT_NE(r.output.find("cape_depth_0.png: a depth image needs the camera's intrinsics"), std::string::npos)
        << r.output;
    r = run("segment " + depth.string() + " --calib " + (data / "cape_calib_params.xml").string() + out);
    EXPECT_EQ(r.status, 1) << r.output;
    EXPECT_NE(r.output.find("name one, as FILE:NODE"), std::string::npos) << r.output;
    r = run("segment " + depth.string() + " --intrinsics 1,2,3,4 --unit-mm 1000" + out);
    EXPECT_EQ(r.status, 2) << r.output;
    fs::remove_all(dir);
}

// A NumPy cloud with normals (H x W x 6), as a Python pipeline would save it.
TEST(Cli, NumpyCloudsWithNormalsAreSegmented) {
    pyrseg::synthetic::SceneOptions o;
    o.width = 64;
    o.height = 48;
    const pyrseg::synthetic::Scene scene = pyrseg::synthetic::generate(o);
    std::vector<float> six(std::size_t(o.width) * std::size_t(o.height) * 6);
    for (std::size_t i = 0; i < six.size() / 6; ++i) {
        for (std::size_t c = 0; c < 3; ++c) {
            six[6 * i + c] = scene.points[3 * i + c];
            six[6 * i + 3 + c] = scene.normals[3 * i + c];
        }
    }
    const fs::path dir = temp_dir();
    pyrseg::io::write_npy(dir / "cloud.npy", six.data(), o.height, o.width, 6);
    const CliRun r = run("segment " + (dir / "cloud.npy").string() + " --labels " + (dir / "l.npy").string());
    EXPECT_EQ(r.status, 0) << r.output;
    EXPECT_NE(r.output.find("NumPy cloud, 64 x 48, normals from file"), std::string::npos) << r.output;
    // The same labels as a 16-bit PNG.
    ASSERT_EQ(run("segment " + (dir / "cloud.npy").string() + " --labels " + (dir / "l.png").string()).status, 0);
    const pyrseg::io::NpyArray npy = pyrseg::io::read_npy(dir / "l.npy");
    const pyrseg::io::Image png = pyrseg::io::read_png(dir / "l.png");
    ASSERT_EQ(png.bit_depth, 16);
    ASSERT_EQ(png.channels, 1);
    ASSERT_EQ(npy.bytes.size(), 2 * png.data.size());
    for (std::size_t i = 0; i < png.data.size() / 2; ++i) {
        std::uint32_t a = 0;
        std::uint16_t b = 0;
        std::memcpy(&a, npy.bytes.data() + 4 * i, 4);
        std::memcpy(&b, png.data.data() + 2 * i, 2);
        ASSERT_EQ(a, b) << "pixel " << i;
    }
    fs::remove_all(dir);
}

// A batch of 50 frames from a folder plus one broken file: every good frame is segmented and written, the broken one
// is reported by name without stopping the batch, and a summary ends it; then the same frames by glob pattern with
// the progress bar.
TEST(Cli, BatchOfFiftyFramesReportsProgressFailuresAndASummary) {
    const fs::path dir = temp_dir();
    const fs::path in = dir / "frames";
    fs::create_directories(in);
    for (int i = 0; i < 50; ++i) {
        const pyrseg::io::PointCloud cloud = pyrseg::cli_test::scene_cloud(96, 72, std::uint64_t(i) + 1, 4);
        char name[32];
        std::snprintf(name, sizeof name, "frame_%02d.pcd", i);
        pyrseg::io::write_pcd(in / name, cloud, pyrseg::io::PcdEncoding::binary);
    }
    {
        std::FILE* f = std::fopen((in / "frame_99.pcd").c_str(), "w");
        ASSERT_NE(f, nullptr);
        std::fputs("VERSION 0.7\nFIELDS x y z\n", f);  // cut short
        std::fclose(f);
    }
    const fs::path out = dir / "out";
    CliRun r = run("segment " + in.string() + " --out-dir " + out.string() + " --progress lines --backend cpu");
    EXPECT_EQ(r.status, 1) << r.output;
    EXPECT_NE(r.output.find("[1/51] "), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("[51/51] failed: "), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("batch: 51 frames, 50 segmented, 1 failed"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("frame_99.pcd"), std::string::npos) << r.output;
    for (int i = 0; i < 50; ++i) {
        char name[32];
        std::snprintf(name, sizeof name, "frame_%02d", i);
        EXPECT_TRUE(fs::exists(out / (std::string(name) + ".labels.npy"))) << name;
        EXPECT_TRUE(fs::exists(out / (std::string(name) + ".png"))) << name;
    }
    r = run("segment '" + (in / "frame_[0-4]?.pcd").string() + "' --out-dir " + out.string() +
            " --write labels,figure --progress bar --backend cpu");
    EXPECT_EQ(r.status, 0) << r.output;
    EXPECT_NE(r.output.find("] 50/50 frames"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("fps  ETA"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("batch: 50 frames, 50 segmented, 0 failed"), std::string::npos) << r.output;
    EXPECT_TRUE(fs::exists(out / "frame_49.figure.png"));
    r = run("segment " + in.string() + " --labels x.npy --out-dir " + out.string());
    EXPECT_EQ(r.status, 2) << r.output;
    fs::remove_all(dir);
}

// The acceptance case: the PCL mug scan, in metres, with default parameters.
TEST(Cli, MugScanTableIsOneSegmentAndTheMugAnother) {
    if (!fs::exists(mug_scan())) GTEST_SKIP() << "sample scan not present: " << mug_scan().string();
    const fs::path dir = temp_dir();
    const fs::path labels_path = dir / "mug.npy";
    const fs::path png_path = dir / "mug.png";
    const CliRun r = run("segment " + mug_scan().string() + " --unit-mm 1000 --labels " + labels_path.string() +
                         " --png " + png_path.string());
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_TRUE(fs::exists(png_path));
    const pyrseg::io::NpyArray npy = pyrseg::io::read_npy(labels_path);
    ASSERT_EQ(npy.dtype, "<u4");
    ASSERT_EQ(npy.shape, (std::vector<std::size_t>{480, 640}));
    std::vector<std::uint32_t> labels(std::size_t{640} * 480);
    std::memcpy(labels.data(), npy.bytes.data(), labels.size() * 4);
    const auto at = [&](int x, int y) { return labels[std::size_t(y) * 640 + std::size_t(x)]; };
    std::map<std::uint32_t, std::size_t> sizes;
    for (std::uint32_t l : labels) ++sizes[l];

    // Table top: points spread over it, around the mug, all in one large segment.
    const std::uint32_t table = at(200, 420);
    ASSERT_NE(table, 0u);
    for (const auto& [x, y] : {std::pair{160, 200}, {600, 200}, {600, 450}, {300, 350}, {520, 260}, {250, 250}}) {
        EXPECT_EQ(at(x, y), table) << "table point (" << x << ", " << y << ")";
    }
    EXPECT_GT(sizes[table], 100000u);
    // The mug: a different segment of its own, where the mug is.
    const std::uint32_t mug = at(392, 262);
    EXPECT_NE(mug, 0u);
    EXPECT_NE(mug, table);
    EXPECT_GT(sizes[mug], 2000u);
    EXPECT_LT(sizes[mug], 20000u);
    for (std::size_t i = 0; i < labels.size(); ++i) {
        if (labels[i] != mug) continue;
        const int x = int(i % 640);
        const int y = int(i / 640);
        EXPECT_TRUE(x > 300 && x < 500 && y > 200 && y < 340) << "mug pixel far from the mug at " << x << "," << y;
    }
    fs::remove_all(dir);
}

// Consumer depth scans with the preset of their kind of camera (issue: real sensors): the floor or table is one
// segment, and every object is a segment of its own where the object is.
struct ExpectedScene {
    std::vector<std::pair<int, int>> surface;        // pixels of the floor / table: one segment
    std::vector<std::array<int, 4>> objects;         // x0, y0, x1, y1: one distinct segment inside each
    std::vector<std::pair<int, int>> object_pixels;  // a pixel of each object
};

void expect_scene_segmented(const fs::path& scan, const std::string& options, const ExpectedScene& e) {
    if (!fs::exists(scan)) GTEST_SKIP() << "sample scan not present: " << scan.string();
    const fs::path dir = temp_dir();
    const fs::path labels_path = dir / "labels.npy";
    const CliRun r = run("segment " + scan.string() + " " + options + " --labels " + labels_path.string());
    ASSERT_EQ(r.status, 0) << r.output;
    const std::vector<std::uint32_t> labels = realsense_labels(labels_path);
    const auto at = [&](int x, int y) { return label_at(labels, x, y); };
    const std::uint32_t surface = at(e.surface[0].first, e.surface[0].second);
    ASSERT_NE(surface, 0u);
    for (const auto& [x, y] : e.surface) EXPECT_EQ(at(x, y), surface) << "surface point (" << x << ", " << y << ")";
    std::set<std::uint32_t> seen{surface};
    for (std::size_t k = 0; k < e.objects.size(); ++k) {
        const auto [px, py] = e.object_pixels[k];
        const std::uint32_t object = at(px, py);
        EXPECT_NE(object, 0u) << "object " << k << " unlabelled at (" << px << ", " << py << ")";
        EXPECT_TRUE(seen.insert(object).second) << "object " << k << " shares segment " << object;
        const auto [x0, y0, x1, y1] = e.objects[k];
        std::size_t outside = 0, inside = 0;
        for (std::size_t i = 0; i < labels.size(); ++i) {
            if (labels[i] != object) continue;
            const int x = int(i % 640), y = int(i / 640);
            // The presets' edge rounds label up to about 10 pixels of edge band around an object.
            const int m = 10;
            (x >= x0 - m && x <= x1 + m && y >= y0 - m && y <= y1 + m ? inside : outside) += 1;
        }
        EXPECT_EQ(outside, 0u) << "object " << k << "'s segment reaches outside the object (" << inside << " inside)";
        EXPECT_GT(inside, 1000u) << "object " << k;
    }
    fs::remove_all(dir);
}

TEST(Cli, MilkScanWithKinectPresetFloorIsOneSegmentAndEachObjectItsOwn) {
    // Floor around and between the three objects; the bottle (right), the carton (middle; either face), the jug
    // (left).
    expect_scene_segmented(fs::path(PYRSEG_SHARED_DATA_DIR) / "milk_cartoon_all_small_clorox.pcd",
                           "--unit-mm 1000 --sensor kinect-v1",
                           {{{320, 400}, {60, 100}, {560, 100}, {350, 300}, {560, 400}, {200, 380}, {380, 60}},
                            {{395, 90, 505, 270}, {220, 70, 335, 235}, {85, 175, 200, 300}},
                            {{450, 180}, {300, 150}, {136, 253}}});
}

TEST(Cli, MugScanWithStereoPresetTableIsOneSegmentAndTheMugItsOwn) {
    expect_scene_segmented(fs::path(PYRSEG_SHARED_DATA_DIR) / "table_scene_mug_stereo_textured.pcd",
                           "--unit-mm 1000 --sensor realsense-d435",
                           {{{200, 420}, {160, 200}, {600, 200}, {600, 450}, {300, 420}, {520, 260}},
                            {{330, 225, 445, 395}},
                            {{390, 340}}});
}

// The real RealSense tabletop frames (shared/data/realsense): --sensor auto chooses realsense-d435 once for the
// batch, says why, and every frame runs with it; without --sensor the hint names that preset.
TEST(Cli, RealSenseFramesAutoChoosesTheStereoPresetOncePerBatch) {
    const fs::path data = fs::path(PYRSEG_SHARED_DATA_DIR) / "realsense";
    if (!fs::exists(data / "wood_table_1_depth.png")) GTEST_SKIP() << "RealSense frames not present: " << data;
    const fs::path dir = temp_dir();
    const std::string calib = " --calib " + (data / "camera.yml").string();
    CliRun r = run("segment \"" + (data / "*_depth.png").string() + "\"" + calib + " --sensor auto --out-dir " +
                   (dir / "out").string());
    ASSERT_EQ(r.status, 0) << r.output;
    std::size_t chosen = 0;
    for (std::size_t at = r.output.find("sensor auto: realsense-d435 for this run"); at != std::string::npos;
         at = r.output.find("sensor auto: realsense-d435 for this run", at + 1)) {
        ++chosen;
    }
    EXPECT_EQ(chosen, 1u) << r.output;
    EXPECT_NE(r.output.find("stereo shadows"), std::string::npos) << r.output;
    std::size_t frames = 0;
    for (std::size_t at = r.output.find(", sensor auto: realsense-d435\n"); at != std::string::npos;
         at = r.output.find(", sensor auto: realsense-d435\n", at + 1)) {
        ++frames;
    }
    EXPECT_EQ(frames, 4u) << r.output;
    EXPECT_EQ(r.output.find("structured-light"), std::string::npos) << r.output;
    r = run("segment " + (data / "wood_table_3_depth.png").string() + calib);
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_NE(r.output.find("Try --sensor realsense-d435"), std::string::npos) << r.output;
    fs::remove_all(dir);
}

// The white bowl of wood_table_3 makes no depth step and only a weak crease at its rim: from depth alone it shares
// the table's segment; with the colour image (--color: the preset's colour edges) it is a segment of its own, within
// the bowl's outline and apart from the table.
TEST(Cli, RealSenseColourSeparatesTheWhiteBowlFromTheTable) {
    const fs::path data = fs::path(PYRSEG_SHARED_DATA_DIR) / "realsense";
    if (!fs::exists(data / "wood_table_3_color.png")) GTEST_SKIP() << "RealSense frames not present: " << data;
    const fs::path dir = temp_dir();
    const std::string frame = (data / "wood_table_3_depth.png").string() + " --calib " +
                              (data / "camera.yml").string() + " --sensor realsense-d435 --labels ";
    CliRun r = run("segment " + frame + (dir / "depth.npy").string());
    ASSERT_EQ(r.status, 0) << r.output;
    const std::vector<std::uint32_t> depth_only = realsense_labels(dir / "depth.npy");
    EXPECT_EQ(label_at(depth_only, 460, 290), label_at(depth_only, 200, 400))
        << "without colour the bowl is the table's";
    // The preset's colour term, as the README tells a RealSense user to run it.
    r = run("segment " + frame + (dir / "color.npy").string() + " --color " +
            (data / "wood_table_3_color.png").string());
    ASSERT_EQ(r.status, 0) << r.output;
    const std::vector<std::uint32_t> labels = realsense_labels(dir / "color.npy");
    const std::uint32_t bowl = label_at(labels, 460, 290);
    ASSERT_NE(bowl, 0u);
    EXPECT_EQ(label_at(labels, 440, 300), bowl);
    const std::uint32_t table = label_at(labels, 200, 400);
    EXPECT_NE(table, 0u);
    EXPECT_NE(table, bowl);
    EXPECT_EQ(label_at(labels, 600, 450), table);
    const auto [inside, outside] = count_in_box(labels, bowl, 390, 205, 535, 325);
    EXPECT_GT(inside, 5000u);
    EXPECT_EQ(outside, 0u);
    // A colour image of another size, or a depth image given as the colour, is refused with the reason.
    r = run("segment " + frame + (dir / "bad.npy").string() + " --color " + (data / "wood_table_1_depth.png").string());
    EXPECT_NE(r.status, 0);
    EXPECT_NE(r.output.find("8-bit RGB"), std::string::npos) << r.output;
    EXPECT_FALSE(fs::exists(dir / "bad.npy"));
    fs::remove_all(dir);
}

// office_table_7's yellow toy brick: its foot is rounded into the table by the stereo matcher, so with the depth alone
// it is the table's segment; with the colour image the preset's gated colour edges cut it out whole.
TEST(Cli, RealSenseColourSeparatesTheToyBrickFromTheTable) {
    const fs::path data = fs::path(PYRSEG_SHARED_DATA_DIR) / "realsense";
    if (!fs::exists(data / "office_table_7_color.png")) GTEST_SKIP() << "RealSense frames not present: " << data;
    const fs::path dir = temp_dir();
    const std::string frame = (data / "office_table_7_depth.png").string() + " --calib " +
                              (data / "camera.yml").string() + " --sensor realsense-d435 --labels ";
    CliRun r = run("segment " + frame + (dir / "depth.npy").string());
    ASSERT_EQ(r.status, 0) << r.output;
    const std::vector<std::uint32_t> depth_only = realsense_labels(dir / "depth.npy");
    EXPECT_EQ(label_at(depth_only, 97, 259), label_at(depth_only, 300, 400))
        << "without colour the brick is the table's";
    r = run("segment " + frame + (dir / "color.npy").string() + " --color " +
            (data / "office_table_7_color.png").string());
    ASSERT_EQ(r.status, 0) << r.output;
    const std::vector<std::uint32_t> labels = realsense_labels(dir / "color.npy");
    const std::uint32_t brick = label_at(labels, 97, 259);
    const std::uint32_t table = label_at(labels, 300, 400);
    ASSERT_NE(brick, 0u);
    EXPECT_NE(table, 0u);
    EXPECT_NE(brick, table);
    EXPECT_EQ(label_at(labels, 500, 300), table);
    const auto [inside, outside] = count_in_box(labels, brick, 5, 195, 190, 330);
    EXPECT_GT(inside, 6000u);
    EXPECT_EQ(outside, 0u);
    fs::remove_all(dir);
}

// The scene of wood_table_1 (docs/algorithm.md section 10c) as the README's RealSense command writes it: the table is
// the largest support, and the cracker box (about 21 cm tall, upright) stands on it in a box that holds it.
TEST(Cli, RealSenseSceneHasTheTableAndTheCrackerBoxStandingOnIt) {
    const fs::path data = fs::path(PYRSEG_SHARED_DATA_DIR) / "realsense";
    if (!fs::exists(data / "wood_table_1_color.png")) GTEST_SKIP() << "RealSense frames not present: " << data;
    const fs::path dir = temp_dir();
    const std::string frame = "segment " + (data / "wood_table_1_depth.png").string() + " --calib " +
                              (data / "camera.yml").string() + " --sensor realsense-d435 --color " +
                              (data / "wood_table_1_color.png").string() + " --labels " + (dir / "labels.npy").string();
    CliRun r = run(frame + " --scene " + (dir / "scene.json").string());
    ASSERT_EQ(r.status, 0) << r.output;
    const std::vector<std::uint32_t> labels = realsense_labels(dir / "labels.npy");
    std::ifstream in(dir / "scene.json");
    const nlohmann::json scene = nlohmann::json::parse(in);
    ASSERT_FALSE(scene["supports"].empty());
    const nlohmann::json& table = scene["supports"][0];
    EXPECT_EQ(table["label"].get<std::uint32_t>(), label_at(labels, 600, 300));
    EXPECT_TRUE(table["level"].get<bool>());
    const std::uint32_t box = label_at(labels, 490, 330);
    const auto object = std::find_if(scene["objects"].begin(), scene["objects"].end(),
                                     [&](const nlohmann::json& o) { return o["label"].get<std::uint32_t>() == box; });
    ASSERT_NE(object, scene["objects"].end()) << "the cracker box is no object of the scene";
    EXPECT_EQ((*object)["support"].get<int>(), 0);
    const double height = (*object)["height"].get<double>();
    EXPECT_GT(height, 180.0);
    EXPECT_LT(height, 250.0);
    // The same scene as a mesh: 12 triangles per object, 2 per support.
    r = run(frame + " --scene " + (dir / "scene.ply").string());
    ASSERT_EQ(r.status, 0) << r.output;
    std::ifstream ply(dir / "scene.ply");
    const std::string text((std::istreambuf_iterator<char>(ply)), std::istreambuf_iterator<char>());
    const std::size_t faces = 12 * scene["objects"].size() + 2 * scene["supports"].size();
    EXPECT_NE(text.find("element face " + std::to_string(faces) + "\n"), std::string::npos);
    EXPECT_EQ(text.rfind("ply\nformat ascii 1.0\n", 0), 0u);
    // --scene names JSON or PLY, nothing else.
    r = run(frame + " --scene " + (dir / "scene.txt").string());
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.output.find("--scene"), std::string::npos) << r.output;
    fs::remove_all(dir);
}

// --figure with --scene adds a fourth panel, the scene's boxes over the segments, projected through the pinhole the
// cloud file's points were made with (fitted to them); a cloud that is no camera's gets the plain figure and a note.
TEST(Cli, FigureWithSceneDrawsTheBoxes) {
    const fs::path dir = temp_dir();
    const pyrseg::io::PointCloud cloud = pyrseg::cli_test::scene_cloud(160, 120, 1, 4);
    pyrseg::io::write_pcd(dir / "scene.pcd", cloud, pyrseg::io::PcdEncoding::binary);
    const std::string frame = "segment " + (dir / "scene.pcd").string();
    ASSERT_EQ(run(frame + " --figure " + (dir / "plain.png").string()).status, 0);
    CliRun r = run(frame + " --figure " + (dir / "scene.png").string() + " --scene " + (dir / "s.json").string());
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_EQ(r.output.find("no scene panel"), std::string::npos) << r.output;
    const pyrseg::io::Image plain = pyrseg::io::read_png(dir / "plain.png");
    const pyrseg::io::Image with_scene = pyrseg::io::read_png(dir / "scene.png");
    EXPECT_EQ(with_scene.height, plain.height);
    EXPECT_GT(with_scene.width, plain.width + 160) << "a fourth panel";
    // The same points, their columns shuffled: no pinhole maps them to their pixels.
    pyrseg::io::PointCloud shuffled = cloud;
    for (int y = 0; y < shuffled.height; ++y) {
        for (int x = 0; x < shuffled.width / 2; ++x) {
            float* a = shuffled.points.data() + 3 * (std::size_t(y) * 160 + std::size_t(x));
            float* b = shuffled.points.data() + 3 * (std::size_t(y) * 160 + std::size_t(159 - x));
            std::swap_ranges(a, a + 3, b);
        }
    }
    pyrseg::io::write_pcd(dir / "mirrored.pcd", shuffled, pyrseg::io::PcdEncoding::binary);
    r = run("segment " + (dir / "mirrored.pcd").string() + " --figure " + (dir / "m.png").string() + " --scene " +
            (dir / "m.json").string());
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_NE(r.output.find("no scene panel"), std::string::npos) << r.output;
    EXPECT_EQ(pyrseg::io::read_png(dir / "m.png").width, plain.width);
    fs::remove_all(dir);
}

// The cracker box of wood_table_1 with the realsense-d435 preset, with and without the colour image: its front and
// top faces are one segment (the merge joins them across their convex edge), which stays within the box and apart
// from the table. With colour, the print on the box cuts nothing: the preset's colour edges need a crease.
class CliRealSenseBox : public ::testing::TestWithParam<bool> {};

TEST_P(CliRealSenseBox, IsOneSegmentApartFromTheTable) {
    const fs::path data = fs::path(PYRSEG_SHARED_DATA_DIR) / "realsense";
    if (!fs::exists(data / "wood_table_1_depth.png")) GTEST_SKIP() << "RealSense frames not present: " << data;
    const fs::path dir = temp_dir();
    const fs::path labels_path = dir / "labels.npy";
    const std::string color = GetParam() ? " --color " + (data / "wood_table_1_color.png").string() : "";
    const CliRun r =
        run("segment " + (data / "wood_table_1_depth.png").string() + " --calib " + (data / "camera.yml").string() +
            " --sensor realsense-d435 --labels " + labels_path.string() + color);
    ASSERT_EQ(r.status, 0) << r.output;
    const std::vector<std::uint32_t> labels = realsense_labels(labels_path);
    const auto at = [&](int x, int y) { return label_at(labels, x, y); };
    const std::uint32_t box = at(490, 330);  // the front face
    ASSERT_NE(box, 0u);
    EXPECT_EQ(at(470, 240), box) << "the top face";
    EXPECT_EQ(at(400, 350), box);
    const std::uint32_t table = at(540, 400);
    EXPECT_NE(table, 0u);
    EXPECT_NE(table, box);
    EXPECT_EQ(at(600, 300), table);
    const auto [inside, outside] = count_in_box(labels, box, 375, 215, 580, 420);
    EXPECT_EQ(outside, 0u) << inside << " inside";
    EXPECT_GT(inside, 20000u);
    fs::remove_all(dir);
}

INSTANTIATE_TEST_SUITE_P(Cli, CliRealSenseBox, ::testing::Bool(), [](const ::testing::TestParamInfo<bool>& param_info) {
    return param_info.param ? std::string("WithColour") : std::string("DepthOnly");
});

TEST(Cli, CapeDepthImageWithKinectPresetEachWallIsOneSegment) {
    // A corner: the near wall on the left, the far wall on the right of the diagonal crease.
    const fs::path data(PYRSEG_SHARED_DATA_DIR);
    expect_scene_segmented(
        data / "cape_depth_0.png",
        "--calib " + (data / "cape_calib_params.xml").string() + ":IR_intrinsic_params --sensor kinect-v1",
        {{{100, 100}, {100, 400}, {250, 250}, {380, 60}}, {{300, 150, 639, 479}}, {{500, 400}}});
}

// Without --sensor the defaults apply, and a frame noisier than they suit gets a hint naming a preset; --sensor auto
// picks that preset; a scanner-like frame gets neither; unknown names are refused with the list.
TEST(Cli, SensorHintAutoAndUnknownNames) {
    const fs::path dir = temp_dir();
    pyrseg::io::write_pcd(dir / "scanner.pcd", pyrseg::cli_test::scene_cloud(160, 120, 1),
                          pyrseg::io::PcdEncoding::binary);
    CliRun r = run("segment " + (dir / "scanner.pcd").string() + " --labels " + (dir / "a.npy").string());
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_EQ(r.output.find("hint:"), std::string::npos) << r.output;
    r = run("segment " + (dir / "scanner.pcd").string() + " --sensor auto --labels " + (dir / "a.npy").string());
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_NE(r.output.find("sensor auto: structured-light"), std::string::npos) << r.output;
    r = run("segment " + (dir / "scanner.pcd").string() + " --sensor kinect --labels " + (dir / "a.npy").string());
    EXPECT_EQ(r.status, 1) << r.output;  // like the other bad parameter values (--ct -1, --backend nope)
    EXPECT_NE(r.output.find("known: structured-light, kinect-v1, realsense-d435, azure-kinect, auto"),
              std::string::npos)
        << r.output;
    r = run("segment --help");
    EXPECT_NE(r.output.find("--sensor NAME"), std::string::npos);
    EXPECT_NE(r.output.find("--edge-rounds E"), std::string::npos);
    if (fs::exists(mug_scan())) {
        r = run("segment " + mug_scan().string() + " --unit-mm 1000 --labels " + (dir / "m.npy").string());
        ASSERT_EQ(r.status, 0) << r.output;
        EXPECT_NE(r.output.find("hint:"), std::string::npos) << r.output;
        // A stereo scan: its holes lie on the left of near surfaces.
        EXPECT_NE(r.output.find("Try --sensor realsense-d435"), std::string::npos) << r.output;
        r = run("segment " + mug_scan().string() + " --unit-mm 1000 --sensor auto --labels " +
                (dir / "m.npy").string());
        ASSERT_EQ(r.status, 0) << r.output;
        EXPECT_NE(r.output.find("sensor auto: realsense-d435"), std::string::npos) << r.output;
        EXPECT_EQ(r.output.find("hint:"), std::string::npos) << r.output;
    }
    fs::remove_all(dir);
}

// --pcl-png draws PCL's segmentation of the same frame when pyrseg is built with PCL, and says why not otherwise.
TEST(Cli, PclPngComparesWithThePeer) {
    const fs::path dir = temp_dir();
    pyrseg::io::write_pcd(dir / "scene.pcd", pyrseg::cli_test::scene_cloud(160, 120, 3),
                          pyrseg::io::PcdEncoding::binary);
    const CliRun r =
        run("segment " + (dir / "scene.pcd").string() + " --sensor kinect-v1 --pcl-png " + (dir / "pcl.png").string());
#ifdef PYRSEG_TEST_PCL_PEER
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_TRUE(fs::exists(dir / "pcl.png"));
    EXPECT_NE(r.output.find("PCL regions"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("tuned for kinect-v1"), std::string::npos) << r.output;
#else
    EXPECT_EQ(r.status, 1) << r.output;
    EXPECT_NE(r.output.find("no PCL peer"), std::string::npos) << r.output;
    EXPECT_FALSE(fs::exists(dir / "pcl.png"));
#endif
    fs::remove_all(dir);
}

// A NumPy depth map (H x W float32, metres) segments like the same samples in a float TIFF: both go through DepthView.
TEST(Cli, NumpyDepthMapsSegmentLikeDepthImages) {
    const fs::path dir = temp_dir();
    pyrseg::synthetic::SceneOptions o;
    o.width = 160;
    o.height = 120;
    const pyrseg::synthetic::Scene scene = pyrseg::synthetic::generate(o);
    std::vector<float> metres(std::size_t(o.width) * std::size_t(o.height));
    for (std::size_t i = 0; i < metres.size(); ++i) metres[i] = scene.points[3 * i + 2] / 1000.0f;  // NaN: no data
    pyrseg::io::write_npy(dir / "depth.npy", metres.data(), o.height, o.width, 1);
    pyrseg::io::write_tiff_float(dir / "depth.tif", metres.data(), o.width, o.height);
    const std::string k = " --intrinsics " + std::to_string(scene.fx) + "," + std::to_string(scene.fy) + "," +
                          std::to_string(scene.cx) + "," + std::to_string(scene.cy);
    CliRun r = run("segment " + (dir / "depth.npy").string() + k + " --labels " + (dir / "a.npy").string());
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_NE(r.output.find("NumPy depth map"), std::string::npos) << r.output;
    r = run("segment " + (dir / "depth.tif").string() + k + " --labels " + (dir / "b.npy").string());
    ASSERT_EQ(r.status, 0) << r.output;
    const pyrseg::io::NpyArray a = pyrseg::io::read_npy(dir / "a.npy");
    const pyrseg::io::NpyArray b = pyrseg::io::read_npy(dir / "b.npy");
    EXPECT_EQ(a.bytes, b.bytes);
    std::set<std::uint32_t> labels;
    for (std::size_t i = 0; i + 4 <= a.bytes.size(); i += 4) {
        std::uint32_t l = 0;
        std::memcpy(&l, a.bytes.data() + i, 4);
        labels.insert(l);
    }
    EXPECT_GT(labels.size(), 5u);
    r = run("segment " + (dir / "depth.npy").string() + " --labels " + (dir / "c.npy").string());
    EXPECT_NE(r.status, 0);
    EXPECT_NE(r.output.find("intrinsics"), std::string::npos) << r.output;
    std::vector<std::uint32_t> ints(metres.size(), 1000);
    pyrseg::io::write_npy(dir / "ints.npy", ints.data(), o.height, o.width);
    r = run("segment " + (dir / "ints.npy").string() + k + " --labels " + (dir / "c.npy").string());
    EXPECT_NE(r.status, 0);
    EXPECT_NE(r.output.find("uint16 or float32"), std::string::npos) << r.output;
    fs::remove_all(dir);
}

TEST(Cli, DemoRunsOnASmallSceneAndWritesPictures) {
    const fs::path dir = temp_dir();
    const CliRun r = run("demo --size 160x120 --runs 1 --data " + (dir / "none").string() + " --out " + dir.string());
    EXPECT_EQ(r.status, 0) << r.output;
    // With one backend there is nothing to compare, and the demo must not claim it compared anything.
    EXPECT_TRUE(r.output.find("agree byte for byte") != std::string::npos ||
                r.output.find("nothing to cross-check") != std::string::npos)
        << r.output;
    EXPECT_EQ(r.output.find("DISAGREE"), std::string::npos) << r.output;
    EXPECT_TRUE(fs::exists(dir / "synthetic_figure.png"));
    EXPECT_TRUE(fs::exists(dir / "synthetic_segments.png"));
    EXPECT_TRUE(fs::exists(dir / "synthetic_truth.png"));
    fs::remove_all(dir);
}

}  // namespace

// --stats writes what the library's statistics pass computed, as JSON or CSV; the pixel counts add up to the
// labelled pixels of the --labels output of the same run.
TEST(Cli, StatsAreWrittenAsJsonOrCsv) {
    const fs::path dir = temp_dir();
    const pyrseg::io::PointCloud cloud = pyrseg::cli_test::scene_cloud(160, 120, 1);
    pyrseg::io::write_pcd(dir / "scene.pcd", cloud, pyrseg::io::PcdEncoding::binary);
    const CliRun r = run("segment " + (dir / "scene.pcd").string() + " --labels " + (dir / "l.npy").string() +
                         " --stats " + (dir / "s.json").string());
    ASSERT_EQ(r.status, 0) << r.output;
    const pyrseg::io::NpyArray labels = pyrseg::io::read_npy(dir / "l.npy");
    std::size_t labelled = 0;
    std::uint32_t largest = 0;
    for (std::size_t i = 0; i < labels.bytes.size() / 4; ++i) {
        std::uint32_t l = 0;
        std::memcpy(&l, labels.bytes.data() + 4 * i, 4);
        labelled += l != 0 ? 1 : 0;
        largest = std::max(largest, l);
    }
    std::ifstream json_file(dir / "s.json");
    const nlohmann::json doc = nlohmann::json::parse(json_file);
    EXPECT_EQ(doc["width"], 160);
    EXPECT_EQ(doc["segment_count"], largest);
    std::size_t counted = 0;
    for (const nlohmann::json& s : doc["segments"]) counted += s["pixel_count"].get<std::size_t>();
    EXPECT_EQ(counted, labelled);
    EXPECT_GT(doc["segments"][0]["centroid"][2].get<double>(), 500.0) << "millimetres, about 1.2 m away";
    // The largest segment (the scene's back plane or floor) is planar, its plane facing the camera.
    const auto largest_segment = std::max_element(
        doc["segments"].begin(), doc["segments"].end(),
        [](const nlohmann::json& a, const nlohmann::json& b) { return a["pixel_count"] < b["pixel_count"]; });
    const nlohmann::json& plane = (*largest_segment)["plane"];
    EXPECT_TRUE(plane["planar"].get<bool>()) << plane.dump();
    EXPECT_LT(plane["rms"].get<double>(), 2.0);
    EXPECT_LT(plane["normal"][2].get<double>(), 0.0) << "towards the camera";
    EXPECT_EQ((*largest_segment)["box"]["extents"].size(), 3u);
    ASSERT_EQ(run("segment " + (dir / "scene.pcd").string() + " --planar-tolerance 0 --stats " +
                  (dir / "strict.json").string())
                  .status,
              0);
    std::ifstream strict_file(dir / "strict.json");
    const nlohmann::json strict = nlohmann::json::parse(strict_file);
    for (const nlohmann::json& s : strict["segments"]) {
        EXPECT_EQ(s["plane"]["planar"].get<bool>(), s["plane"]["rms"].get<double>() == 0.0) << s.dump();
    }

    ASSERT_EQ(run("segment " + (dir / "scene.pcd").string() + " --stats " + (dir / "s.csv").string()).status, 0);
    std::ifstream csv(dir / "s.csv");
    std::string line;
    std::size_t lines = 0;
    while (std::getline(csv, line)) ++lines;
    EXPECT_EQ(lines, std::size_t(largest) + 1) << "a header and one line per segment";
    // In a batch: NAME.stats.json.
    const CliRun batch = run("segment " + (dir / "scene.pcd").string() + " --out-dir " + (dir / "out").string() +
                             " --write stats --progress none");
    EXPECT_EQ(batch.status, 0) << batch.output;
    EXPECT_TRUE(fs::exists(dir / "out" / "scene.stats.json"));
    fs::remove_all(dir);
}

// --graph writes the segment graph as JSON or CSV: its lengths add up to the crossings between the --labels output's
// segments, and each edge's kinds to its length.
TEST(Cli, GraphIsWrittenAsJsonOrCsv) {
    const fs::path dir = temp_dir();
    const pyrseg::io::PointCloud cloud = pyrseg::cli_test::scene_cloud(160, 120, 1);
    pyrseg::io::write_pcd(dir / "scene.pcd", cloud, pyrseg::io::PcdEncoding::binary);
    const std::string frame = "segment " + (dir / "scene.pcd").string() + " --edge-rounds 4";
    const CliRun r = run(frame + " --labels " + (dir / "l.npy").string() + " --graph " + (dir / "g.json").string());
    ASSERT_EQ(r.status, 0) << r.output;
    const pyrseg::io::NpyArray labels = pyrseg::io::read_npy(dir / "l.npy");
    const auto label = [&](std::size_t x, std::size_t y) {
        std::uint32_t l = 0;
        std::memcpy(&l, labels.bytes.data() + 4 * (y * 160 + x), 4);
        return l;
    };
    std::size_t crossings = 0;
    for (std::size_t y = 0; y < 120; ++y) {
        for (std::size_t x = 0; x < 160; ++x) {
            const std::uint32_t a = label(x, y);
            if (x + 1 < 160 && a != 0 && label(x + 1, y) != 0 && label(x + 1, y) != a) ++crossings;
            if (y + 1 < 120 && a != 0 && label(x, y + 1) != 0 && label(x, y + 1) != a) ++crossings;
        }
    }
    std::ifstream json_file(dir / "g.json");
    const nlohmann::json doc = nlohmann::json::parse(json_file);
    ASSERT_GT(doc["edge_count"].get<std::size_t>(), 0u) << doc.dump();
    std::size_t counted = 0;
    for (const nlohmann::json& e : doc["edges"]) {
        EXPECT_LT(e["a"].get<std::uint32_t>(), e["b"].get<std::uint32_t>());
        EXPECT_EQ(e["flat"].get<std::uint32_t>() + e["convex"].get<std::uint32_t>() +
                      e["concave"].get<std::uint32_t>() + e["step"].get<std::uint32_t>(),
                  e["length"].get<std::uint32_t>());
        counted += e["length"].get<std::size_t>();
    }
    EXPECT_EQ(counted, crossings);
    ASSERT_EQ(run(frame + " --graph " + (dir / "g.csv").string()).status, 0);
    std::ifstream csv(dir / "g.csv");
    std::string line;
    std::size_t lines = 0;
    while (std::getline(csv, line)) ++lines;
    EXPECT_EQ(lines, doc["edge_count"].get<std::size_t>() + 1) << "a header and one line per edge";
    const CliRun batch = run(frame + " --out-dir " + (dir / "out").string() + " --write graph --progress none");
    EXPECT_EQ(batch.status, 0) << batch.output;
    EXPECT_TRUE(fs::exists(dir / "out" / "scene.graph.json"));
    const CliRun wrong = run(frame + " --graph " + (dir / "g.txt").string());
    EXPECT_NE(wrong.status, 0);
    EXPECT_NE(wrong.output.find("--graph"), std::string::npos) << wrong.output;
    fs::remove_all(dir);
}

// bench-report turns Google Benchmark JSON into ratio tables: a made-up run with known times gives known ratios,
// and a file that is not such JSON is an error naming it.
TEST(Cli, BenchReportWritesRatiosAndPlots) {
    const fs::path dir = temp_dir();
    const auto entry = [](const std::string& name, double ms) {
        return nlohmann::json{{"name", name + "/real_time"}, {"real_time", ms}, {"time_unit", "ms"}};
    };
    nlohmann::json doc;
    doc["context"] = {{"host_name", "testhost"}, {"num_cpus", 2}, {"backend cpu", "available"}};
    doc["benchmarks"] = {entry("memcpy/640x480/estimated_normals", 0.1),
                         entry("memcpy/640x480/given_normals", 0.2),
                         entry("memcpy/640x480/mask", 0.01),
                         entry("pipeline/cpu/640x480/estimated_normals", 10.0),
                         entry("pipeline/cpu/640x480/given_normals", 5.0),
                         entry("pcl/organized_edge_aware/640x480/estimated_normals", 150.0),
                         entry("pcl/organized_edge_aware/640x480/given_normals", 8.0),
                         entry("stage/cpu/640x480", 3.0),
                         entry("opencv/sauf_4/640x480", 0.5)};
    doc["benchmarks"].push_back({{"name", "pipeline/vulkan/640x480/estimated_normals/real_time"},
                                 {"error_occurred", true},
                                 {"error_message", "too large for this device"}});
    std::ofstream(dir / "bench.json") << doc.dump();
    const CliRun r = run("bench-report " + (dir / "bench.json").string());
    ASSERT_EQ(r.status, 0) << r.output;
    std::ifstream md_file(dir / "performance.md");
    const std::string md((std::istreambuf_iterator<char>(md_file)), std::istreambuf_iterator<char>());
    EXPECT_NE(md.find("testhost"), std::string::npos);
    EXPECT_NE(md.find("| 640x480 | 0.100 ms | 10.0 ms (100×) |"), std::string::npos) << md;
    EXPECT_NE(md.find("15.0×"), std::string::npos) << "PCL 150 ms / cpu 10 ms\n" << md;
    EXPECT_NE(md.find("30.0×"), std::string::npos) << "PCL 150 ms / cpu with given normals 5 ms\n" << md;
    EXPECT_NE(md.find("1.60×"), std::string::npos) << "PCL's labelling 8 ms / cpu with given normals 5 ms\n" << md;
    EXPECT_NE(md.find("6.00×"), std::string::npos) << "stage 3 ms / OpenCV 0.5 ms\n" << md;
    EXPECT_NE(md.find("too large for this device"), std::string::npos) << "skips keep their reason\n" << md;
    EXPECT_TRUE(fs::exists(dir / "bench_vs_pcl.png"));
    EXPECT_TRUE(fs::exists(dir / "bench_vs_opencv.png"));

    std::ofstream(dir / "not.json") << "{ nope";
    const CliRun bad = run("bench-report " + (dir / "not.json").string());
    EXPECT_EQ(bad.status, 1);
    EXPECT_NE(bad.output.find("not.json"), std::string::npos) << bad.output;
    fs::remove_all(dir);
}

namespace {

nlohmann::json bench_entry(const std::string& name, double ms) {
    return nlohmann::json{{"name", name + "/real_time"}, {"real_time", ms}, {"time_unit", "ms"}};
}

std::string read_file(const fs::path& path) {
    std::ifstream in(path);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

}  // namespace

// Every backend the rows name gets its columns, a name bench-report has never heard of too (it once knew four and
// dropped the rows of any other without a word).
TEST(Cli, BenchReportFollowsTheBackendsTheRowsName) {
    const fs::path dir = temp_dir();
    nlohmann::json doc;
    doc["context"] = {{"host_name", "testhost"}, {"backend metal", "available"}};
    doc["benchmarks"] = {bench_entry("memcpy/640x480/estimated_normals", 0.1),
                         bench_entry("memcpy/640x480/mask", 0.01),
                         bench_entry("pipeline/cpu/640x480/estimated_normals", 10.0),
                         bench_entry("pipeline/metal/640x480/estimated_normals", 4.0),
                         bench_entry("pcl/organized_edge_aware/640x480/estimated_normals", 150.0),
                         bench_entry("stage/metal/640x480", 0.25),
                         bench_entry("opencv/sauf_4/640x480", 0.5),
                         bench_entry("fills/maze/metal/640x480", 7.0)};
    std::ofstream(dir / "bench.json") << doc.dump();
    const CliRun r = run("bench-report " + (dir / "bench.json").string());
    ASSERT_EQ(r.status, 0) << r.output;
    const std::string md = read_file(dir / "performance.md");
    EXPECT_NE(md.find("| frame | memcpy | cpu | metal | fill rounds | PCL | PCL ÷ cpu | PCL ÷ metal |"),
              std::string::npos)
        << md;
    EXPECT_NE(md.find("| 640x480 | 0.100 ms | 10.0 ms (100×) | 4.00 ms (40.0×) |"), std::string::npos) << md;
    EXPECT_NE(md.find("37.5×"), std::string::npos) << "PCL 150 ms / metal 4 ms\n" << md;
    EXPECT_NE(md.find("0.500×"), std::string::npos) << "metal's stage 0.25 ms / OpenCV 0.5 ms\n" << md;
    EXPECT_NE(md.find("| maze | 640x480 | metal | 7.00 ms |"), std::string::npos) << md;
    fs::remove_all(dir);
}

// --update rewrites only the section between a document's markers, --check fails once that section differs from
// what the JSON gives (docs/performance.md is checked so by the ctest docs_performance_tables).
TEST(Cli, BenchReportUpdatesAndChecksADocumentsSection) {
    const fs::path dir = temp_dir();
    nlohmann::json doc;
    doc["context"] = {{"host_name", "testhost"}, {"load_avg", {1.5, 1.0, 0.5}}};
    doc["benchmarks"] = {bench_entry("memcpy/640x480/estimated_normals", 0.1), bench_entry("memcpy/640x480/mask", 0.01),
                         bench_entry("pipeline/cpu/640x480/estimated_normals", 10.0)};
    fs::create_directories(dir / "data");
    std::ofstream(dir / "data" / "bench.json") << doc.dump();
    const fs::path md = dir / "doc.md";
    std::ofstream(md) << "# Doc\n\nBefore.\n\n<!-- bench-report:begin (generated) -->\nold tables\n"
                         "<!-- bench-report:end -->\n\nAfter.\n";
    const std::string json = (dir / "data" / "bench.json").string();
    EXPECT_EQ(run("bench-report " + json + " --check " + md.string()).status, 1) << "stale before the update";
    const CliRun up = run("bench-report " + json + " --update " + md.string());
    ASSERT_EQ(up.status, 0) << up.output;
    const std::string text = read_file(md);
    EXPECT_EQ(text.rfind("# Doc\n\nBefore.\n\n<!-- bench-report:begin (generated) -->\n", 0), 0u) << text;
    EXPECT_NE(text.find("<!-- bench-report:end -->\n\nAfter.\n"), std::string::npos) << text;
    EXPECT_EQ(text.find("old tables"), std::string::npos) << text;
    EXPECT_EQ(text.find("# pyrseg benchmark report"), std::string::npos) << "no title of its own\n" << text;
    EXPECT_NE(text.find("### Whole pipeline"), std::string::npos) << "headings one level down\n" << text;
    EXPECT_NE(text.find("[data/bench.json](data/bench.json)"), std::string::npos) << text;
    EXPECT_NE(text.find("The machine was not idle"), std::string::npos) << "load 1.5 at the start\n" << text;
    // A quiet start is idle, whatever the load the bench itself makes by its end.
    nlohmann::json quiet = doc;
    quiet["context"]["load_avg"] = {0.1, 0.2, 0.3};
    quiet["context"]["load_avg_after"] = {1.8, 1.1, 0.6};
    std::ofstream(dir / "data" / "quiet.json") << quiet.dump();
    const fs::path quiet_md = dir / "quiet.md";
    std::ofstream(quiet_md) << "<!-- bench-report:begin (generated) -->\n<!-- bench-report:end -->\n";
    ASSERT_EQ(run("bench-report " + (dir / "data" / "quiet.json").string() + " --update " + quiet_md.string()).status,
              0);
    const std::string quiet_text = read_file(quiet_md);
    EXPECT_EQ(quiet_text.find("not idle"), std::string::npos) << quiet_text;
    EXPECT_NE(quiet_text.find("at the end: 1.80, 1.10, 0.60 (the bench's own threads count in it)"), std::string::npos)
        << quiet_text;
    EXPECT_NE(text.find("(images/bench_vs_pcl.png)"), std::string::npos) << text;
    EXPECT_TRUE(fs::exists(dir / "images" / "bench_vs_pcl.png"));
    EXPECT_EQ(run("bench-report " + json + " --update " + md.string()).status, 0);
    EXPECT_EQ(read_file(md), text) << "a second update changes nothing";

    const CliRun same = run("bench-report " + json + " --check " + md.string());
    EXPECT_EQ(same.status, 0) << same.output;
    std::string edited = text;
    edited.replace(edited.find("10.0 ms"), 7, "9.00 ms");
    std::ofstream(md) << edited;
    const CliRun stale = run("bench-report " + json + " --check " + md.string());
    EXPECT_EQ(stale.status, 1) << stale.output;
    EXPECT_NE(stale.output.find("--update"), std::string::npos) << "says how to regenerate it\n" << stale.output;
    EXPECT_EQ(read_file(md), edited) << "--check writes nothing";

    std::ofstream(md) << "# No markers\n";
    const CliRun none = run("bench-report " + json + " --update " + md.string());
    EXPECT_EQ(none.status, 1) << none.output;
    EXPECT_NE(none.output.find("bench-report:begin"), std::string::npos) << none.output;
    fs::remove_all(dir);
}

// Issue 17: what a new user trips over, each fixed and kept fixed.
namespace {

std::vector<std::uint32_t> read_labels(const fs::path& path) {
    const pyrseg::io::NpyArray npy = pyrseg::io::read_npy(path);
    std::vector<std::uint32_t> labels(npy.bytes.size() / 4);
    std::memcpy(labels.data(), npy.bytes.data(), npy.bytes.size());
    return labels;
}

std::size_t files_in(const fs::path& dir) {
    return std::size_t(std::distance(fs::directory_iterator(dir), fs::directory_iterator()));
}

// A cloud in metres without --unit-mm is read as metres, saying so (once per run), and segments like the same
// cloud in millimetres; an explicit --unit-mm always wins, with a warning when it makes the depths implausible.
TEST(Cli, CloudInMetresIsReadAsMetresAndSaysSo) {
    const fs::path dir = temp_dir();
    const pyrseg::io::PointCloud mm = pyrseg::cli_test::scene_cloud(160, 120, 5);
    pyrseg::io::PointCloud metres = mm;
    for (float& v : metres.points) v /= 1000.0f;
    pyrseg::io::write_pcd(dir / "mm.pcd", mm, pyrseg::io::PcdEncoding::binary);
    pyrseg::io::write_pcd(dir / "m.pcd", metres, pyrseg::io::PcdEncoding::binary);
    CliRun r = run("segment " + (dir / "mm.pcd").string() + " --backend cpu --labels " + (dir / "mm.npy").string());
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_EQ(r.output.find("metres"), std::string::npos) << r.output;
    r = run("segment " + (dir / "m.pcd").string() + " --backend cpu --labels " + (dir / "m.npy").string());
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_NE(r.output.find("so the cloud is read as metres (--unit-mm 1000); pass --unit-mm 1 if it is in "
                            "millimetres"),
              std::string::npos)
        << r.output;
    EXPECT_NE(r.output.find("m.pcd: PCD in metres, 160 x 120"), std::string::npos) << r.output;
    const std::vector<std::uint32_t> from_mm = read_labels(dir / "mm.npy");
    const std::vector<std::uint32_t> from_metres = read_labels(dir / "m.npy");
    ASSERT_EQ(from_mm.size(), from_metres.size());
    std::size_t differ = 0;
    for (std::size_t i = 0; i < from_mm.size(); ++i) differ += from_mm[i] != from_metres[i] ? 1 : 0;
    EXPECT_LT(differ, from_mm.size() / 100) << "metres read as metres segment like millimetres";
    EXPECT_GT(*std::max_element(from_metres.begin(), from_metres.end()), 3u);

    // --unit-mm wins, in both directions; an implausible one is segmented as asked, with a warning.
    r = run("segment " + (dir / "m.pcd").string() + " --backend cpu --unit-mm 1000 --labels " +
            (dir / "m2.npy").string());
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_EQ(r.output.find("note:"), std::string::npos) << r.output;
    EXPECT_EQ(r.output.find("warning:"), std::string::npos) << r.output;
    EXPECT_EQ(read_labels(dir / "m2.npy"), from_metres);
    r = run("segment " + (dir / "m.pcd").string() + " --backend cpu --unit-mm 1 --labels " + (dir / "m3.npy").string());
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_EQ(r.output.find("read as metres"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("warning: " + (dir / "m.pcd").string() + ": with --unit-mm 1 the median depth is"),
              std::string::npos)
        << r.output;
    EXPECT_NE(r.output.find("is --unit-mm right?"), std::string::npos) << r.output;
    EXPECT_NE(read_labels(dir / "m3.npy"), from_metres) << "metres read as millimetres segment differently";

    // A batch of clouds in metres: each read as metres, the note given once.
    fs::create_directories(dir / "frames");
    for (const char* name : {"a.pcd", "b.pcd", "c.pcd"}) {
        pyrseg::io::write_pcd(dir / "frames" / name, metres, pyrseg::io::PcdEncoding::binary);
    }
    r = run("segment " + (dir / "frames").string() + " --out-dir " + (dir / "out").string() +
            " --write labels --progress lines --backend cpu");
    ASSERT_EQ(r.status, 0) << r.output;
    std::size_t notes = 0;
    for (std::size_t at = r.output.find("read as metres"); at != std::string::npos;
         at = r.output.find("read as metres", at + 1)) {
        ++notes;
    }
    EXPECT_EQ(notes, 1u) << r.output;
    EXPECT_EQ(read_labels(dir / "out" / "c.labels.npy"), from_metres);
    fs::remove_all(dir);
}

// The depth unit is stated as SDKs state it (--metres-per-unit: RealSense's depth scale); the old --depth-scale
// (its inverse) still works with a warning saying what to pass; a unit that puts the frame at an implausible
// distance is refused with the unit that fits, and writes nothing.
TEST(Cli, DepthUnitIsMetresPerUnitAndImplausibleUnitsAreRefused) {
    const fs::path dir = temp_dir();
    pyrseg::synthetic::SceneOptions o;
    o.width = 160;
    o.height = 120;
    const pyrseg::synthetic::Scene scene = pyrseg::synthetic::generate(o);
    std::vector<std::uint16_t> mm(std::size_t(o.width) * std::size_t(o.height));
    std::vector<float> float_mm(mm.size());
    for (std::size_t i = 0; i < mm.size(); ++i) {
        const float z = scene.points[3 * i + 2];
        mm[i] = std::isfinite(z) ? std::uint16_t(std::lround(z)) : std::uint16_t(0);
        float_mm[i] = float(mm[i]);  // the same samples as floats: the same segments
    }
    pyrseg::io::write_png_gray16(dir / "depth.png", mm.data(), o.width, o.height);
    pyrseg::io::write_tiff_float(dir / "depth_mm.tif", float_mm.data(), o.width, o.height);
    const std::string k = " --backend cpu --intrinsics " + std::to_string(scene.fx) + "," + std::to_string(scene.fy) +
                          "," + std::to_string(scene.cx) + "," + std::to_string(scene.cy);
    const std::string png = "segment " + (dir / "depth.png").string() + k;

    CliRun r = run(png + " --labels " + (dir / "default.npy").string());
    ASSERT_EQ(r.status, 0) << r.output;
    r = run(png + " --metres-per-unit 0.001 --labels " + (dir / "mpu.npy").string());
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_EQ(read_labels(dir / "mpu.npy"), read_labels(dir / "default.npy"));
    EXPECT_GT(r.output.find(" segments"), 0u);
    // The old flag, as it was meant: the same result, and a warning naming the new one.
    r = run(png + " --depth-scale 1000 --labels " + (dir / "old.npy").string());
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_NE(r.output.find("--depth-scale is deprecated"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("--depth-scale 1000 is --metres-per-unit 0.001"), std::string::npos) << r.output;
    EXPECT_EQ(read_labels(dir / "old.npy"), read_labels(dir / "default.npy"));
    // A RealSense user's depth scale given to the old flag: refused (it once gave 0 segments), saying what to pass.
    r = run(png + " --depth-scale 0.001 --labels " + (dir / "rs.npy").string());
    EXPECT_EQ(r.status, 1) << r.output;
    EXPECT_NE(r.output.find("depth.png: with --depth-scale 0.001 (depth units per metre: 1000 m per unit), the depth "
                            "image's median depth is"),
              std::string::npos)
        << r.output;
    EXPECT_NE(r.output.find("outside any depth sensor's range"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("; metres_per_unit 0.001 makes it"), std::string::npos) << r.output;
    EXPECT_FALSE(fs::exists(dir / "rs.npy"));
    // The same mistake the other way round, and float samples in millimetres read as the default metres.
    r = run(png + " --metres-per-unit 1000 --labels " + (dir / "rs.npy").string());
    EXPECT_EQ(r.status, 1) << r.output;
    EXPECT_NE(r.output.find("metres_per_unit 0.001 makes"), std::string::npos) << r.output;
    r = run("segment " + (dir / "depth_mm.tif").string() + k + " --labels " + (dir / "rs.npy").string());
    EXPECT_EQ(r.status, 1) << r.output;
    EXPECT_NE(r.output.find("with float samples read as metres (the default), the depth image's median depth is"),
              std::string::npos)
        << r.output;
    EXPECT_NE(r.output.find("metres_per_unit 0.001 makes"), std::string::npos) << r.output;
    EXPECT_FALSE(fs::exists(dir / "rs.npy"));
    r = run("segment " + (dir / "depth_mm.tif").string() + k + " --metres-per-unit 0.001 --labels " +
            (dir / "tif.npy").string());
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_EQ(read_labels(dir / "tif.npy"), read_labels(dir / "default.npy"));
    // Nonsense and contradictions are usage errors.
    r = run(png + " --metres-per-unit 0 --labels " + (dir / "x.npy").string());
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_NE(r.output.find("--metres-per-unit must be a number > 0"), std::string::npos) << r.output;
    r = run(png + " --metres-per-unit 0.001 --depth-scale 1000 --labels " + (dir / "x.npy").string());
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_FALSE(fs::exists(dir / "x.npy"));
    // Intrinsics in the order cx, cy, fx, fy (they were accepted, and segmented a skewed cloud): refused, saying the
    // order; the library's own words (pyrseg::check_depth_camera), as in C++ and Python.
    const std::string swapped = " --backend cpu --intrinsics " + std::to_string(scene.cx) + "," +
                                std::to_string(scene.cy) + "," + std::to_string(scene.fx) + "," +
                                std::to_string(scene.fy);
    r = run("segment " + (dir / "depth.png").string() + swapped + " --labels " + (dir / "x.npy").string());
    EXPECT_EQ(r.status, 1) << r.output;
    EXPECT_NE(r.output.find("the order is fx, fy, cx, cy"), std::string::npos) << r.output;
    EXPECT_FALSE(fs::exists(dir / "x.npy"));
    // A D405's depth scale on millimetre samples: possible (a frame 10 times closer), so a warning, not an error.
    r = run(png + " --metres-per-unit 0.0001 --labels " + (dir / "d405.npy").string());
    EXPECT_EQ(r.status, 0) << r.output;
    EXPECT_NE(r.output.find("warning: " + (dir / "depth.png").string() + ": the median depth is"), std::string::npos)
        << r.output;
    EXPECT_NE(r.output.find("(the depth scale: --metres-per-unit 0.0001)"), std::string::npos) << r.output;
    fs::remove_all(dir);
}

// Output names must say the format written: a wrong extension is a usage error naming the accepted ones, checked
// before anything is read or written; the extension's case does not matter.
TEST(Cli, OutputExtensionsAreCheckedBeforeAnythingIsWritten) {
    const fs::path dir = temp_dir();
    pyrseg::io::write_pcd(dir / "scene.pcd", pyrseg::cli_test::scene_cloud(96, 72, 2), pyrseg::io::PcdEncoding::binary);
    const std::string segment = "segment " + (dir / "scene.pcd").string() + " --backend cpu ";
    const struct {
        std::string options, message;
    } refused[] = {
        {"--png " + (dir / "out.jpg").string(), "out.jpg: the name must end in .png (the segments in colour, as PNG)"},
        {"--labels " + (dir / "out.txt").string(), "out.txt: the name must end in .npy or .png"},
        {"--labels " + (dir / "out.pcd").string(), "for a cloud with a label field, give --pcd OUT.pcd"},
        {"--mask-png " + (dir / "mask").string(), "--mask-png " + (dir / "mask").string() + ": the name must end in"},
        {"--figure " + (dir / "f.tif").string(), "must end in .png"},
        {"--ply " + (dir / "c.pcd").string(), "must end in .ply"},
        {"--pcd " + (dir / "c.ply").string(), "must end in .pcd"},
        {"--stats " + (dir / "s.txt").string(), "must end in .json or .csv"},
        {"--pcl-png " + (dir / "p.jpg").string(), "must end in .png"},
        // One bad name among good ones: nothing at all is written.
        {"--labels " + (dir / "ok.npy").string() + " --png " + (dir / "ok.png").string() + " --stats " +
             (dir / "s.yaml").string(),
         "s.yaml: the name must end in .json or .csv"},
    };
    for (const auto& c : refused) {
        const CliRun r = run(segment + c.options);
        EXPECT_EQ(r.status, 2) << c.options << "\n" << r.output;
        EXPECT_NE(r.output.find(c.message), std::string::npos) << c.options << "\n" << r.output;
        EXPECT_EQ(files_in(dir), 1u) << c.options;
    }
    const CliRun r = run(segment + "--png " + (dir / "OUT.PNG").string() + " --stats " + (dir / "S.Json").string());
    EXPECT_EQ(r.status, 0) << r.output;
    EXPECT_EQ(pyrseg::io::read_png(dir / "OUT.PNG").channels, 3);
    EXPECT_TRUE(fs::exists(dir / "S.Json"));
    fs::remove_all(dir);
}

// With no output option, segment prints what it found (count, time, sizes) and writes nothing.
TEST(Cli, NoOutputPrintsASummaryAndWritesNothing) {
    const fs::path dir = temp_dir();
    pyrseg::io::write_pcd(dir / "scene.pcd", pyrseg::cli_test::scene_cloud(160, 120, 4),
                          pyrseg::io::PcdEncoding::binary);
    const CliRun r = run("segment " + (dir / "scene.pcd").string() + " --backend cpu");
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_EQ(files_in(dir), 1u);
    EXPECT_NE(r.output.find("scene.pcd: PCD, 160 x 120, normals estimated, "), std::string::npos) << r.output;
    EXPECT_NE(r.output.find(" ms on cpu"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("nothing written"), std::string::npos) << r.output;
    ASSERT_EQ(
        run("segment " + (dir / "scene.pcd").string() + " --backend cpu --labels " + (dir / "l.npy").string()).status,
        0);
    const std::vector<std::uint32_t> labels = read_labels(dir / "l.npy");
    std::map<std::uint32_t, std::size_t> sizes;
    std::size_t labelled = 0;
    for (const std::uint32_t l : labels) {
        if (l == 0) continue;
        ++sizes[l];
        ++labelled;
    }
    std::size_t largest = 0;
    for (const auto& [label, size] : sizes) largest = std::max(largest, size);
    EXPECT_NE(r.output.find(", " + std::to_string(sizes.size()) + " segments, "), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("segment sizes in pixels, largest first: " + std::to_string(largest) + ", "),
              std::string::npos)
        << r.output;
    EXPECT_NE(r.output.find("labelled: " + std::to_string(labelled) + " of 19200 pixels"), std::string::npos)
        << r.output;
    fs::remove_all(dir);
}

// Labelled PCD for PCL users: x y z label (PointXYZL), binary, organized, the labels those of --labels, the points
// those of the input; in a batch NAME.labels.pcd. (tests/io reads it with PCL's own loadPCDFile.)
TEST(Cli, LabelledPcdIsPointXYZLWithTheSameLabels) {
    const fs::path dir = temp_dir();
    const pyrseg::io::PointCloud cloud = pyrseg::cli_test::scene_cloud(96, 72, 6);
    pyrseg::io::write_pcd(dir / "scene.pcd", cloud, pyrseg::io::PcdEncoding::binary_compressed);
    const CliRun r = run("segment " + (dir / "scene.pcd").string() + " --backend cpu --pcd " +
                         (dir / "out.pcd").string() + " --labels " + (dir / "l.npy").string());
    ASSERT_EQ(r.status, 0) << r.output;
    std::ifstream file(dir / "out.pcd", std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
    for (const char* line :
         {"\nFIELDS x y z label\n", "\nSIZE 4 4 4 4\n", "\nTYPE F F F U\n", "\nWIDTH 96\n", "\nHEIGHT 72\n"}) {
        EXPECT_NE(bytes.find(line), std::string::npos) << line;
    }
    const std::string data = "\nDATA binary\n";
    const std::size_t body = bytes.find(data);
    ASSERT_NE(body, std::string::npos);
    const std::size_t n = std::size_t{96} * 72;
    ASSERT_EQ(bytes.size(), body + data.size() + 16 * n);
    const std::vector<std::uint32_t> labels = read_labels(dir / "l.npy");
    for (std::size_t i = 0; i < n; ++i) {
        std::uint32_t label = 0;
        std::memcpy(&label, bytes.data() + body + data.size() + 16 * i + 12, 4);
        ASSERT_EQ(label, labels[i]) << "point " << i;
    }
    const pyrseg::io::PointCloud back = pyrseg::io::read_pcd(dir / "out.pcd");
    ASSERT_EQ(back.points.size(), cloud.points.size());
    EXPECT_EQ(std::memcmp(back.points.data(), cloud.points.data(), cloud.points.size() * sizeof(float)), 0);
    const CliRun batch = run("segment " + (dir / "scene.pcd").string() + " --out-dir " + (dir / "out").string() +
                             " --write pcd --progress none --backend cpu");
    ASSERT_EQ(batch.status, 0) << batch.output;
    EXPECT_EQ(pyrseg::io::read_pcd(dir / "out" / "scene.labels.pcd").width, 96);
    fs::remove_all(dir);
}

// --- Tracks (pyrseg segment --track; docs/algorithm.md section 11) ---------------------------------------------------

// Three frames of a camera panning over a synthetic scene, kTrackShift pixels a frame, as binary PCDs in
// DIR/frames: frame_N.pcd is the scene's columns N * kTrackShift .. N * kTrackShift + kTrackWidth - 1.
constexpr int kTrackWidth = 320;
constexpr int kTrackHeight = 240;
constexpr int kTrackShift = 2;
constexpr int kTrackFrames = 3;

void write_pan(const fs::path& folder) {
    fs::create_directories(folder);
    pyrseg::synthetic::SceneOptions o;
    o.width = kTrackWidth + kTrackShift * (kTrackFrames - 1);
    o.height = kTrackHeight;
    o.seed = 5;
    o.object_count = 10;
    o.hole_fraction = 0.0;
    const pyrseg::synthetic::Scene wide = pyrseg::synthetic::generate(o);
    for (int f = 0; f < kTrackFrames; ++f) {
        pyrseg::io::PointCloud cloud;
        cloud.width = kTrackWidth;
        cloud.height = kTrackHeight;
        cloud.points.resize(3 * std::size_t(kTrackWidth) * kTrackHeight);
        for (int y = 0; y < kTrackHeight; ++y) {
            std::copy_n(wide.points.data() + 3 * (std::size_t(y) * std::size_t(o.width) + std::size_t(f * kTrackShift)),
                        3 * std::size_t(kTrackWidth), cloud.points.data() + 3 * std::size_t(y) * kTrackWidth);
        }
        pyrseg::io::write_pcd(folder / ("frame_" + std::to_string(f) + ".pcd"), cloud, pyrseg::io::PcdEncoding::binary);
    }
}

// A frame's pixel (x, y) is the pixel (x + kTrackShift * (b - a), y) of an earlier frame a of the pan: calls
// `both(i_a, i_b)` for the pixels the two frames share.
template <class Both>
void shared_pixels(int a, int b, const Both& both) {
    const int shift = kTrackShift * (b - a);
    for (int y = 0; y < kTrackHeight; ++y) {
        for (int x = 0; x + shift < kTrackWidth; ++x) {
            both(std::size_t(y) * kTrackWidth + std::size_t(x + shift), std::size_t(y) * kTrackWidth + std::size_t(x));
        }
    }
}

// A batch with --track is one stream: the same surface has the same track id in every frame (the labels 1..K are
// renumbered as the camera pans), the tracks file agrees with the id image, and the colour pictures colour each
// pixel by its id, so that a pixel that keeps its id keeps its colour.
TEST(CliTracks, ABatchIsOneStreamWhoseIdsAndColoursCarryOver) {
    const fs::path dir = temp_dir() / "tracks_batch";
    fs::remove_all(dir);
    write_pan(dir / "frames");
    const CliRun r = run("segment " + (dir / "frames").string() + " --out-dir " + (dir / "out").string() +
                         " --track --write labels,png,track_ids,tracks --progress none --backend cpu");
    ASSERT_EQ(r.status, 0) << r.output;
    std::vector<std::vector<std::uint32_t>> labels, ids;
    std::vector<pyrseg::io::Image> pictures;
    for (int f = 0; f < kTrackFrames; ++f) {
        const fs::path stem = dir / "out" / ("frame_" + std::to_string(f));
        labels.push_back(read_labels(stem.string() + ".labels.npy"));
        ids.push_back(read_labels(stem.string() + ".track_ids.npy"));
        pictures.push_back(pyrseg::io::read_png(stem.string() + ".png"));
        ASSERT_EQ(ids.back().size(), std::size_t(kTrackWidth) * kTrackHeight);
        ASSERT_EQ(labels.back().size(), ids.back().size());
        ASSERT_EQ(pictures.back().channels, 3);
        std::ifstream file(stem.string() + ".tracks.json");
        const nlohmann::json doc = nlohmann::json::parse(file);
        EXPECT_EQ(doc["stream_frame"].get<int>(), f);
        const nlohmann::json& tracks = doc["tracks"];
        const std::uint32_t k = *std::max_element(labels.back().begin(), labels.back().end());
        ASSERT_EQ(tracks.size(), k);
        ASSERT_EQ(doc["track_count"].get<std::size_t>(), k);
        for (std::uint32_t l = 1; l <= k; ++l) {
            EXPECT_EQ(tracks[l - 1]["label"].get<std::uint32_t>(), l);
            if (f == 0) {
                EXPECT_EQ(tracks[l - 1]["how"].get<std::string>(), "new_track");
            }
        }
        for (std::size_t i = 0; i < ids.back().size(); ++i) {
            const std::uint32_t l = labels.back()[i];
            ASSERT_EQ(ids.back()[i], l == 0 ? 0u : tracks[l - 1]["id"].get<std::uint32_t>()) << "pixel " << i;
        }
    }
    for (int a = 0; a < kTrackFrames; ++a) {
        for (int b = a + 1; b < kTrackFrames; ++b) {
            std::size_t both = 0, same_id = 0, same_label = 0, relabelled = 0, recoloured = 0;
            std::string first_recoloured;
            shared_pixels(a, b, [&](std::size_t in_a, std::size_t in_b) {
                const std::uint32_t id = ids[std::size_t(a)][in_a];
                if (id == 0 || ids[std::size_t(b)][in_b] == 0) return;
                ++both;
                same_label += labels[std::size_t(a)][in_a] == labels[std::size_t(b)][in_b] ? 1 : 0;
                if (ids[std::size_t(b)][in_b] != id) return;
                ++same_id;
                relabelled += labels[std::size_t(a)][in_a] != labels[std::size_t(b)][in_b] ? 1 : 0;
                const std::uint8_t* ca = pictures[std::size_t(a)].data.data() + 3 * in_a;
                const std::uint8_t* cb = pictures[std::size_t(b)].data.data() + 3 * in_b;
                if (!std::equal(ca, ca + 3, cb) && recoloured++ == 0) {
                    first_recoloured = "pixel " + std::to_string(in_b) + " keeps track id " + std::to_string(id);
                }
            });
            ASSERT_GT(both, 0u);
            EXPECT_EQ(recoloured, 0u) << "frames " << a << " and " << b << ": " << first_recoloured
                                      << " but changes colour";
            EXPECT_GE(double(same_id) / double(both), 0.99) << "frames " << a << " and " << b;
            // The scene must be one whose labels change in the pan, else the colours would say nothing.
            EXPECT_LT(same_label, same_id) << "frames " << a << " and " << b;
            EXPECT_GT(relabelled, 1000u) << "frames " << a << " and " << b;
        }
    }
    fs::remove_all(dir);
}

// The tracks' single-frame outputs, their formats, and what --track refuses.
TEST(CliTracks, OutputsParametersAndRefusals) {
    const fs::path dir = temp_dir() / "tracks_outputs";
    fs::remove_all(dir);
    write_pan(dir / "frames");
    const std::string frame = "segment " + (dir / "frames" / "frame_0.pcd").string() + " --backend cpu";
    CliRun r =
        run(frame + " --track --labels " + (dir / "l.npy").string() + " --track-ids " + (dir / "t.png").string() +
            " --tracks " + (dir / "t.csv").string() + " --track-hold 3" + " --track-max-distance 20");
    ASSERT_EQ(r.status, 0) << r.output;
    const pyrseg::io::Image ids = pyrseg::io::read_png(dir / "t.png");
    EXPECT_EQ(ids.bit_depth, 16);
    EXPECT_EQ(ids.channels, 1);
    const std::vector<std::uint32_t> labels = read_labels(dir / "l.npy");
    const std::uint32_t k = *std::max_element(labels.begin(), labels.end());
    std::ifstream csv(dir / "t.csv");
    std::string line;
    std::getline(csv, line);
    EXPECT_EQ(line, "label,id,first_frame,age,hidden_frames,how");
    std::uint32_t rows = 0;
    while (std::getline(csv, line)) {
        ++rows;
        // One frame is a stream of one: every segment is new, its id its label.
        EXPECT_EQ(line, std::to_string(rows) + "," + std::to_string(rows) + ",0,1,0,new_track");
    }
    EXPECT_EQ(rows, k);
    // Everything about tracks needs --track.
    for (const std::string& without :
         {frame + " --tracks " + (dir / "x.json").string(), frame + " --track-ids " + (dir / "x.npy").string(),
          frame + " --track-hold 3", frame + " --track-max-distance 5",
          "segment " + (dir / "frames").string() + " --out-dir " + (dir / "o").string() + " --write labels,tracks"}) {
        r = run(without);
        EXPECT_EQ(r.status, 2) << without << "\n" << r.output;
        EXPECT_NE(r.output.find("needs --track"), std::string::npos) << r.output;
    }
    EXPECT_FALSE(fs::exists(dir / "o"));
    r = run(frame + " --track --raw");
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_NE(r.output.find("leave out --raw"), std::string::npos) << r.output;
    // The library checks the parameters, and the CLI prints its error.
    r = run(frame + " --track --track-hold 1001");
    EXPECT_EQ(r.status, 1) << r.output;
    EXPECT_NE(r.output.find("track_hold_frames must be in 0..1000"), std::string::npos) << r.output;
    r = run(frame + " --track --track-max-distance -1");
    EXPECT_EQ(r.status, 1) << r.output;
    EXPECT_NE(r.output.find("track_max_distance_mm"), std::string::npos) << r.output;
    r = run(frame + " --track --tracks " + (dir / "t.txt").string());
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_NE(r.output.find("--tracks"), std::string::npos) << r.output;
    // A batch with --track writes the id images by default.
    r = run("segment " + (dir / "frames").string() + " --out-dir " + (dir / "out").string() +
            " --track --progress none --backend cpu");
    ASSERT_EQ(r.status, 0) << r.output;
    for (const char* name : {"frame_2.labels.npy", "frame_2.png", "frame_2.track_ids.npy"}) {
        EXPECT_TRUE(fs::exists(dir / "out" / name)) << name;
    }
    // A frame of another size starts the stream over, and says so.
    pyrseg::io::write_pcd(dir / "frames" / "frame_3.pcd", pyrseg::cli_test::scene_cloud(160, 120, 5),
                          pyrseg::io::PcdEncoding::binary);
    r = run("segment " + (dir / "frames").string() + " --out-dir " + (dir / "restart").string() +
            " --track --write tracks --progress none --backend cpu");
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_NE(r.output.find("frame_3.pcd: the tracks restart at this frame"), std::string::npos) << r.output;
    for (const auto& [name, stream_frame] : {std::pair{"frame_2.tracks.json", 2}, {"frame_3.tracks.json", 0}}) {
        std::ifstream file(dir / "restart" / name);
        EXPECT_EQ(nlohmann::json::parse(file)["stream_frame"].get<int>(), stream_frame) << name;
    }
    const std::string help = run("segment --help").output;
    for (const char* option : {"--track ", "--track-ids OUT.npy", "--tracks OUT.json", "--track-max-distance MM",
                               "--track-hold FRAMES", "Tracks: with --track"}) {
        EXPECT_NE(help.find(option), std::string::npos) << option;
    }
    fs::remove_all(dir);
}

// A backend without tracks refuses --track with the library's error (ErrorCode::backend_unavailable); one with them
// gives the cpu backend's ids (the same on every backend).
TEST(CliTracks, OtherBackendsRefuseOrAgree) {
    const fs::path dir = temp_dir() / "tracks_backends";
    fs::remove_all(dir);
    write_pan(dir / "frames");
    const std::string frames = "segment " + (dir / "frames").string() + " --track --progress none --write track_ids";
    ASSERT_EQ(run(frames + " --backend cpu --out-dir " + (dir / "cpu").string()).status, 0);
    for (const pyrseg::BackendInfo& b : pyrseg::list_backends()) {
        if (b.name == "cpu" || !b.available) continue;
        const CliRun single = run("segment " + (dir / "frames" / "frame_0.pcd").string() + " --track --backend " +
                                  b.name + " --track-ids " + (dir / (b.name + ".npy")).string());
        if (single.status != 0) {
            EXPECT_EQ(single.status, 1) << single.output;
            EXPECT_NE(single.output.find("tracks"), std::string::npos) << single.output;
            continue;
        }
        const CliRun batch = run(frames + " --backend " + b.name + " --out-dir " + (dir / b.name).string());
        ASSERT_EQ(batch.status, 0) << batch.output;
        for (int f = 0; f < kTrackFrames; ++f) {
            const std::string name = "frame_" + std::to_string(f) + ".track_ids.npy";
            EXPECT_EQ(read_labels(dir / b.name / name), read_labels(dir / "cpu" / name)) << b.name << " " << name;
        }
    }
    fs::remove_all(dir);
}

}  // namespace

// --threads N: the CPU backend with N threads of its own, the same labels as the shared arena's; out of range, or
// beside another backend, a usage error that names it.
TEST(Cli, ThreadsGiveTheCpuBackendItsOwnThreadsAndTheSameLabels) {
    const fs::path dir = temp_dir();
    pyrseg::io::write_pcd(dir / "s.pcd", pyrseg::cli_test::scene_cloud(160, 120, 7), pyrseg::io::PcdEncoding::binary);
    CliRun r = run("segment " + (dir / "s.pcd").string() + " --backend cpu --labels " + (dir / "shared.npy").string());
    ASSERT_EQ(r.status, 0) << r.output;
    for (const char* threads : {"1", "3"}) {
        const fs::path own = dir / (std::string("own") + threads + ".npy");
        r = run("segment " + (dir / "s.pcd").string() + " --threads " + threads + " --labels " + own.string());
        ASSERT_EQ(r.status, 0) << r.output;
        EXPECT_NE(r.output.find(std::string("backend cpu (--threads ") + threads), std::string::npos) << r.output;
        EXPECT_EQ(read_labels(own), read_labels(dir / "shared.npy")) << "--threads " << threads;
    }
    for (const char* bad : {"0", "1025", "-2"}) {
        r = run("segment " + (dir / "s.pcd").string() + " --threads " + bad + " --labels " + (dir / "x.npy").string());
        EXPECT_EQ(r.status, 2) << r.output;
        EXPECT_NE(r.output.find("--threads must be in 1..1024"), std::string::npos) << r.output;
    }
    r = run("segment " + (dir / "s.pcd").string() + " --threads 2 --backend vulkan --labels " +
            (dir / "x.npy").string());
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_NE(r.output.find("--threads sets the CPU backend's threads"), std::string::npos) << r.output;
    EXPECT_FALSE(fs::exists(dir / "x.npy"));
}

// The labelled PCD with --scene: beside 'label', 'object' and 'support' name the scene JSON's objects[k] and
// supports[k] as k + 1 (0: none), so a PCL user finds each point's object without the labels' image.
TEST(Cli, LabelledPcdNamesEachPointsSceneObjectAndSupport) {
    const fs::path dir = temp_dir();
    pyrseg::io::write_pcd(dir / "s.pcd", pyrseg::cli_test::scene_cloud(160, 120, 3), pyrseg::io::PcdEncoding::binary);
    CliRun r = run("segment " + (dir / "s.pcd").string() + " --backend cpu --scene " + (dir / "scene.json").string() +
                   " --pcd " + (dir / "out.pcd").string());
    ASSERT_EQ(r.status, 0) << r.output;
    std::ifstream in(dir / "scene.json");
    const nlohmann::json scene = nlohmann::json::parse(in);
    ASSERT_FALSE(scene["objects"].empty());
    ASSERT_FALSE(scene["supports"].empty());
    std::ifstream pcd_in(dir / "out.pcd", std::ios::binary);
    const std::string pcd((std::istreambuf_iterator<char>(pcd_in)), std::istreambuf_iterator<char>());
    const std::size_t fields_at = pcd.find("FIELDS ");
    const std::string fields = pcd.substr(fields_at + 7, pcd.find('\n', fields_at) - fields_at - 7);
    EXPECT_TRUE(fields == "x y z label object support" ||
                fields == "x y z normal_x normal_y normal_z label object support")
        << fields;
    const std::size_t floats = fields.starts_with("x y z normal_x") ? 6 : 3;
    const std::size_t step = 4 * (floats + 3);
    const std::size_t data = pcd.find("DATA binary\n") + 12;
    ASSERT_EQ(pcd.size() - data, std::size_t{160} * 120 * step);
    std::size_t object_points = 0;
    std::size_t support_points = 0;
    for (std::size_t i = 0; i < std::size_t{160} * 120; ++i) {
        std::uint32_t v[3];
        std::memcpy(v, pcd.data() + data + i * step + 4 * floats, sizeof v);
        const auto [label, object, support] = std::tuple{v[0], v[1], v[2]};
        ASSERT_FALSE(object != 0 && support != 0) << "a segment is an object or a support, not both: " << i;
        if (object != 0) {
            ASSERT_LE(object, scene["objects"].size());
            ASSERT_EQ(scene["objects"][object - 1]["label"].get<std::uint32_t>(), label) << i;
            ++object_points;
        }
        if (support != 0) {
            ASSERT_LE(support, scene["supports"].size());
            ASSERT_EQ(scene["supports"][support - 1]["label"].get<std::uint32_t>(), label) << i;
            ++support_points;
        }
        if (label != 0 && object == 0 && support == 0) {
            for (const nlohmann::json& o : scene["objects"]) ASSERT_NE(o["label"].get<std::uint32_t>(), label) << i;
        }
    }
    EXPECT_GT(object_points, 0u);
    EXPECT_GT(support_points, 0u);
    // Without --scene the PCD is PointXYZL's: the label alone.
    r = run("segment " + (dir / "s.pcd").string() + " --backend cpu --pcd " + (dir / "plain.pcd").string());
    ASSERT_EQ(r.status, 0) << r.output;
    std::ifstream plain_in(dir / "plain.pcd", std::ios::binary);
    const std::string plain((std::istreambuf_iterator<char>(plain_in)), std::istreambuf_iterator<char>());
    EXPECT_NE(plain.find("label\nSIZE"), std::string::npos);
    // With --track the track ids follow (a lone frame's tracks are new: ids 1..K, as its labels).
    r = run("segment " + (dir / "s.pcd").string() + " --backend cpu --track --pcd " + (dir / "tracked.pcd").string());
    ASSERT_EQ(r.status, 0) << r.output;
    std::ifstream tracked_in(dir / "tracked.pcd", std::ios::binary);
    const std::string tracked((std::istreambuf_iterator<char>(tracked_in)), std::istreambuf_iterator<char>());
    EXPECT_NE(tracked.find(" label track\nSIZE"), std::string::npos);
    fs::remove_all(dir);
}
