// `pyrseg eval --tabletop DIR`, run as a user runs it: on the shared real RealSense frames (skipped when absent) it
// writes its tables and a picture per frame, the truth finds objects on every frame, and bad input is a usage error.
#include <gtest/gtest.h>

#include <unistd.h>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "cli/cli_runner.hpp"

namespace {

namespace fs = std::filesystem;

using pyrseg::cli_test::CliRun;
using pyrseg::cli_test::run;

const fs::path kRealsense = fs::path(PYRSEG_SHARED_DATA_DIR) / "realsense";

TEST(CliEvalTabletop, HelpSaysHowTheTruthIsMadeAndScored) {
    const CliRun r = run("eval --tabletop x --help");
    EXPECT_EQ(r.status, 0) << r.output;
    for (const char* word :
         {"Usage", "NAME_depth.png", "camera.yml", "RANSAC", "convex hull", "300 pixels", "found whole", "in parts",
          "merged with the table", "IoU", "--presets", "--pcl-sensor", "--lccp", "--out-dir"}) {
        EXPECT_NE(r.output.find(word), std::string::npos) << word << "\n" << r.output;
    }
    EXPECT_NE(run("eval --help").output.find("--tabletop"), std::string::npos);
}

TEST(CliEvalTabletop, BadInputIsAUsageError) {
    CliRun r = run("eval --tabletop /nonexistent/pyrseg");
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_NE(r.output.find("--tabletop"), std::string::npos) << r.output;
    const fs::path empty = fs::temp_directory_path() / ("pyrseg_tabletop_empty_" + std::to_string(::getpid()));
    fs::create_directories(empty);
    r = run("eval --tabletop " + empty.string());
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_NE(r.output.find("no NAME_depth.png"), std::string::npos) << r.output;
    fs::remove_all(empty);
    if (!fs::exists(kRealsense)) GTEST_SKIP() << "the shared RealSense frames are not in " << kRealsense;
    r = run("eval --tabletop " + kRealsense.string() + " --presets realsense-d435,nonesuch");
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_NE(r.output.find("nonesuch"), std::string::npos) << r.output;
    r = run("eval --tabletop " + kRealsense.string() + " --pcl-sensor nonesuch");
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_NE(r.output.find("--pcl-sensor"), std::string::npos) << r.output;
    r = run("eval --tabletop " + kRealsense.string() + " --lccp nonesuch");
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_NE(r.output.find("--lccp"), std::string::npos) << r.output;
    r = run("eval --tabletop " + kRealsense.string() + " --depth-scale 0");
    EXPECT_EQ(r.status, 2) << r.output;
}

TEST(CliEvalTabletop, TheSharedRealsenseFramesGetTablesAndPictures) {
    if (!fs::exists(kRealsense)) GTEST_SKIP() << "the shared RealSense frames are not in " << kRealsense;
    const fs::path out = fs::temp_directory_path() / ("pyrseg_tabletop_" + std::to_string(::getpid()));
    const CliRun r =
        run("eval --tabletop " + kRealsense.string() + " --presets realsense-d435,default --out-dir " + out.string());
    ASSERT_EQ(r.status, 0) << r.output;
    std::ifstream in(out / "tabletop.md");
    std::stringstream md;
    md << in.rdbuf();
    for (const char* name : {"wood_table_1", "wood_table_3", "low_table_5", "office_table_7"}) {
        EXPECT_TRUE(fs::exists(out / (std::string("tabletop_") + name + ".png"))) << name;
        EXPECT_NE(md.str().find(std::string("### ") + name), std::string::npos) << name;
        // Every frame's truth has a table and at least one object on it.
        const std::string line = r.output.substr(r.output.find(name));
        EXPECT_EQ(line.find(": 640 x 480, 0 objects"), std::string::npos) << line.substr(0, 80);
        EXPECT_EQ(line.substr(0, 100).find("no support plane"), std::string::npos) << line.substr(0, 80);
    }
    EXPECT_NE(md.str().find("| `realsense-d435` |"), std::string::npos) << md.str();
    EXPECT_NE(md.str().find("| `default` |"), std::string::npos) << md.str();
    // A table per frame names each object and each method's verdict on it (whole, in N parts or not found, with its
    // best IoU): one row per object in the truth, one verdict per method column.
    const auto count = [](const std::string& text, const std::string& what) {
        std::size_t n = 0;
        for (std::size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
        return n;
    };
    std::size_t tables = 0, rows = 0;
    for (std::size_t at = md.str().find("| object | pixels | centre (x, y) | `realsense-d435` | `default` |");
         at != std::string::npos; at = md.str().find("| object | pixels |", at + 1)) {
        ++tables;
        std::istringstream lines(md.str().substr(at));
        std::string head, line;
        std::getline(lines, head);
        const std::size_t methods = count(head, "`") / 2;
        std::getline(lines, line);  // the rule
        while (std::getline(lines, line) && !line.empty()) {
            ++rows;
            EXPECT_EQ(count(line, "(IoU "), methods) << line;
            EXPECT_EQ(count(line, "whole") + count(line, " parts ") + count(line, "not found"), methods) << line;
        }
    }
    EXPECT_EQ(tables, 4u) << md.str();
    std::size_t objects = 0;  // from each frame's line "NAME: 640 x 480, N objects in the ground truth"
    for (std::size_t at = r.output.find(": 640 x 480, "); at != std::string::npos;
         at = r.output.find(": 640 x 480, ", at + 1)) {
        objects += std::stoul(r.output.substr(at + std::string(": 640 x 480, ").size()));
    }
    EXPECT_GE(objects, 4u) << r.output;
    EXPECT_EQ(rows, objects) << md.str();
    // PCL's peers beside pyrseg, or the reason they are left out.
    if (r.output.find("PCL left out") == std::string::npos) {
        EXPECT_NE(md.str().find("| `PCL organized (realsense-d435 settings)` |"), std::string::npos) << md.str();
        EXPECT_NE(md.str().find("| `PCL supervoxels + LCCP (tuned: "), std::string::npos) << md.str();
        EXPECT_NE(r.output.find("LCCP tuning 8/8"), std::string::npos) << r.output;
    } else {
        EXPECT_NE(r.output.find("LCCP left out"), std::string::npos) << r.output;
    }
    fs::remove_all(out);
}

// The same evaluation on synthetic tabletops through a sensor model, against the generator's own truth.
TEST(CliEvalTabletop, SyntheticTabletopsThroughASensorModel) {
    const fs::path out = fs::temp_directory_path() / ("pyrseg_tabletop_synthetic_" + std::to_string(::getpid()));
    const CliRun r = run("eval --tabletop-synthetic --sensors realsense-d435 --seeds 1 --out-dir " + out.string());
    ASSERT_EQ(r.status, 0) << r.output;
    std::ifstream in(out / "tabletop_synthetic.md");
    std::stringstream md;
    md << in.rdbuf();
    EXPECT_NE(md.str().find("| realsense-d435: `realsense-d435` |"), std::string::npos) << md.str();
    EXPECT_NE(md.str().find("| realsense-d435: `realsense-d435+nomerge` |"), std::string::npos) << md.str();
    EXPECT_TRUE(fs::exists(out / "tabletop_realsense-d435_800mm_seed1.png"));
    EXPECT_EQ(run("eval --tabletop-synthetic --sensors nonesuch").status, 2);
    EXPECT_EQ(run("eval --tabletop-synthetic --tabletop " + out.string()).status, 2);
    fs::remove_all(out);
}

}  // namespace
