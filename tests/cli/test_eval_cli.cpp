// `pyrseg eval`, run as a user runs it: the quick sweep writes its table and plots, and on it the pyramid merges
// no more ground-truth objects than plain connected components once bridges are added (the paper's claim).
#include <gtest/gtest.h>

#include <unistd.h>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "cli/cli_runner.hpp"
#include "pyrseg/io.hpp"

namespace {

namespace fs = std::filesystem;

using pyrseg::cli_test::CliRun;
using pyrseg::cli_test::run;

std::vector<std::string> cells_of(const std::string& row) {
    std::vector<std::string> cells;
    std::stringstream in(row);
    std::string cell;
    std::getline(in, cell, '|');  // before the first bar
    while (std::getline(in, cell, '|')) {
        const auto b = cell.find_first_not_of(' ');
        const auto e = cell.find_last_not_of(' ');
        cells.push_back(b == std::string::npos ? "" : cell.substr(b, e - b + 1));
    }
    if (!cells.empty() && cells.back().empty()) cells.pop_back();
    return cells;
}

TEST(CliEval, HelpExplainsEveryMetric) {
    const CliRun r = run("eval --help");
    EXPECT_EQ(r.status, 0) << r.output;
    for (const char* word : {"Usage", "merged", "split", "ARI", "labelled", "segments", "--quick", "--bridges"}) {
        EXPECT_NE(r.output.find(word), std::string::npos) << word << "\n" << r.output;
    }
    EXPECT_NE(run("--help").output.find("eval"), std::string::npos);
}

TEST(CliEval, BadListsAreUsageErrors) {
    CliRun r = run("eval --bridges 1,x");
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.output.find("--bridges"), std::string::npos) << r.output;
    r = run("eval --noise -1");
    EXPECT_EQ(r.status, 2);
    r = run("eval --sizes 640");
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.output.find("WxH"), std::string::npos) << r.output;
}

TEST(CliEval, QuickSweepWritesTableAndPlotsAndThePyramidMergesLess) {
    const fs::path dir = fs::temp_directory_path() / ("pyrseg_eval_test_" + std::to_string(::getpid()));
    fs::remove_all(dir);
    const CliRun r = run("eval --quick --out-dir " + dir.string());
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_NE(r.output.find("bridge 4 px"), std::string::npos) << r.output;

    for (const char* plot : {"merge_rate_320x240.png", "split_rate_320x240.png", "ari_320x240.png"}) {
        ASSERT_TRUE(fs::exists(dir / plot)) << plot;
        const pyrseg::io::Image image = pyrseg::io::read_png(dir / plot);
        EXPECT_GT(image.width, 300) << plot;
        EXPECT_GT(image.height, 200) << plot;
        EXPECT_EQ(image.channels, 3) << plot;
    }
    std::ifstream in(dir / "quality.md");
    ASSERT_TRUE(in) << "no quality.md";
    std::vector<std::vector<std::string>> rows;
    std::vector<std::string> header;
    for (std::string line; std::getline(in, line);) {
        if (line.rfind("| noise", 0) == 0) header = cells_of(line);
        if (line.rfind("| ", 0) == 0 && line.rfind("| noise", 0) != 0) rows.push_back(cells_of(line));
    }
    // 14 columns, and 4 more for PCL when pyrseg is built with it.
    ASSERT_TRUE(header.size() == 14u || header.size() == 18u) << header.size();
    const auto column = [&](const std::string& name) {
        for (std::size_t c = 0; c < header.size(); ++c) {
            if (header[c] == name) return c;
        }
        ADD_FAILURE() << "no column " << name;
        return std::size_t{0};
    };
    const std::size_t pyramid_merged = column("merged: pyramid");
    const std::size_t cc_merged = column("merged: CC");
    const std::size_t objects = column("objects");
    // The quick sweep: noise 0 and 0.5 mm, bridges 0, 1, 2 and 4 px.
    const std::vector<std::pair<std::string, std::string>> expected = {
        {"0", "0"}, {"0", "1"}, {"0", "2"}, {"0", "4"}, {"0.5", "0"}, {"0.5", "1"}, {"0.5", "2"}, {"0.5", "4"}};
    ASSERT_EQ(rows.size(), expected.size());
    for (std::size_t i = 0; i < rows.size(); ++i) {
        ASSERT_EQ(rows[i].size(), header.size()) << i;
        EXPECT_EQ(rows[i][0], expected[i].first) << i;
        EXPECT_EQ(rows[i][1], expected[i].second) << i;
        EXPECT_GT(std::stoi(rows[i][objects]), 10) << i;
        // Merged counts lead their cell: "N (R%)".
        const int pyramid = std::stoi(rows[i][pyramid_merged]);
        const int cc = std::stoi(rows[i][cc_merged]);
        if (rows[i][1] != "0") {
            EXPECT_LE(pyramid, cc) << "noise " << rows[i][0] << " mm, bridge " << rows[i][1] << " px";
        }
        if (rows[i][1] == "1") {
            EXPECT_LT(pyramid, cc) << "noise " << rows[i][0] << " mm: a 1-pixel bridge should merge plain components";
        }
        // PCL segments the cloud itself, so it is scored where no bridge was added, and only there.
        if (header.size() == 18u) {
            const std::string& pcl_merged = rows[i][column("merged: PCL")];
            if (rows[i][1] == "0") {
                EXPECT_GE(std::stoi(pcl_merged), 0) << i;
                EXPECT_GT(std::stod(rows[i][column("ARI: PCL")]), 0.0) << i;
            } else {
                EXPECT_EQ(pcl_merged, "—") << i;
            }
        }
    }
    fs::remove_all(dir);
}

}  // namespace
