// `pyrseg eval`, run as a user runs it: the quick sweeps (sensor models x distances, and the noise sweep) write their
// tables and plots, and on them the pyramid merges no more ground-truth objects than plain connected components once
// bridges are added (the paper's claim); `eval --tracks` writes its tables of ids over sequences.
#include <gtest/gtest.h>

#include <unistd.h>
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
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
    for (const char* word : {"Usage", "merged", "split", "ARI", "labelled", "segments", "--quick", "--bridges",
                             "--sensors", "--distances", "--params", "--tune-seeds", "preset", "structured-light",
                             "kinect-v1", "realsense-d435", "azure-kinect", "grid search", "TUNING seeds"}) {
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

TEST(CliEval, UnknownSensorAndBadSensorOptionsAreUsageErrors) {
    CliRun r = run("eval --quick --sensors kinect-v1,kinect-v9");
    EXPECT_EQ(r.status, 2) << r.output;
    // Names the culprit and lists the models there are.
    EXPECT_NE(r.output.find("unknown sensor model 'kinect-v9'"), std::string::npos) << r.output;
    for (const char* known : {"structured-light", "kinect-v1", "realsense-d435", "azure-kinect"}) {
        EXPECT_NE(r.output.find(known), std::string::npos) << known << "\n" << r.output;
    }
    r = run("eval --quick --sensors ''");
    EXPECT_EQ(r.status, 2) << r.output;
    r = run("eval --quick --distances 100");
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_NE(r.output.find("300..6000"), std::string::npos) << r.output;
    r = run("eval --quick --params tuned");
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_NE(r.output.find("preset or default"), std::string::npos) << r.output;
    r = run("eval --quick --sensors kinect-v1 --noise 0,1");
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_NE(r.output.find("one noise level"), std::string::npos) << r.output;
    r = run("eval --quick --tune-seeds 0");
    EXPECT_EQ(r.status, 2) << r.output;
}

// The noise sweep, which --noise without --sensors and --distances still runs.
TEST(CliEval, QuickSweepWritesTableAndPlotsAndThePyramidMergesLess) {
    const fs::path dir = fs::temp_directory_path() / ("pyrseg_eval_test_" + std::to_string(::getpid()));
    fs::remove_all(dir);
    const CliRun r = run("eval --quick --noise 0,0.5 --out-dir " + dir.string());
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

// The markdown tables of a report: each table's header cells, and its rows' cells, under the heading above it.
struct Table {
    std::string heading;
    std::vector<std::string> header;
    std::vector<std::vector<std::string>> rows;
    [[nodiscard]] std::size_t column(const std::string& name) const {
        for (std::size_t c = 0; c < header.size(); ++c) {
            if (header[c] == name) return c;
        }
        ADD_FAILURE() << "no column " << name << " under " << heading;
        return 0;
    }
};

std::vector<Table> tables_of(const fs::path& report) {
    std::ifstream in(report);
    EXPECT_TRUE(in) << report;
    std::vector<Table> tables;
    std::string heading;
    bool in_table = false;
    for (std::string line; std::getline(in, line);) {
        if (line.rfind('#', 0) == 0) heading = line;
        if (line.rfind('|', 0) != 0) {
            in_table = false;
            continue;
        }
        if (!in_table) {
            tables.push_back({heading, cells_of(line), {}});
            in_table = true;
        } else if (line.rfind("|---", 0) != 0) {
            tables.back().rows.push_back(cells_of(line));
        }
    }
    return tables;
}

void expect_png(const fs::path& file) {
    ASSERT_TRUE(fs::exists(file)) << file;
    const pyrseg::io::Image image = pyrseg::io::read_png(file);
    EXPECT_GT(image.width, 300) << file;
    EXPECT_GT(image.height, 200) << file;
    EXPECT_EQ(image.channels, 3) << file;
}

// The default sweep, quick: two sensor models at one distance, bridges 0, 1 and 2, PCL tuned per model.
TEST(CliEval, QuickSensorSweepWritesTablesSummaryAndPlots) {
    const fs::path dir = fs::temp_directory_path() / ("pyrseg_eval_sensors_" + std::to_string(::getpid()));
    fs::remove_all(dir);
    const CliRun r = run("eval --quick --out-dir " + dir.string());
    ASSERT_EQ(r.status, 0) << r.output;
    // Progress: a line per sensor model and distance.
    EXPECT_NE(r.output.find("structured-light at 1200 mm"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("kinect-v1 at 1200 mm"), std::string::npos) << r.output;

    const std::vector<std::string> sensors = {"structured-light", "kinect-v1"};
    for (const std::string& sensor : sensors) {
        for (const char* plot : {"merge_rate_", "split_rate_", "ari_"}) {
            expect_png(dir / (plot + sensor + "_320x240.png"));
        }
    }
    expect_png(dir / "ari_summary_320x240.png");
    EXPECT_FALSE(fs::exists(dir / "merge_rate_320x240.png"));  // the noise sweep's plot

    const std::vector<Table> tables = tables_of(dir / "quality.md");
    const Table* summary = nullptr;
    const Table* pcl_settings = nullptr;
    std::vector<const Table*> per_sensor;
    for (const Table& t : tables) {
        if (t.header.empty()) continue;
        if (t.header[0] == "sensor" && t.header.size() > 1 && t.header[1] == "ARI: pyramid") summary = &t;
        if (t.header[0] == "sensor" && t.header.size() > 1 && t.header[1] == "PCL setting chosen") pcl_settings = &t;
        if (t.header[0] == "distance (mm)") per_sensor.push_back(&t);
    }
    ASSERT_NE(summary, nullptr) << "no summary table";
    ASSERT_EQ(summary->rows.size(), sensors.size());
    const bool with_pcl = pcl_settings != nullptr;
    for (std::size_t i = 0; i < sensors.size(); ++i) {
        const std::vector<std::string>& row = summary->rows[i];
        ASSERT_EQ(row.size(), summary->header.size()) << i;
        EXPECT_EQ(row[0], sensors[i]);
        for (const char* check : {"pyramid ARI >= PCL", "pyramid merged <= CC/5", "labelled >= 90%"}) {
            const std::string& v = row[summary->column(check)];
            EXPECT_TRUE(v == "yes" || v == "**no**" || v == "n/a") << check << ": " << v;
        }
        EXPECT_NE(row[summary->column("merged w1: pyramid")], "n/a");
        EXPECT_NE(row[summary->column("merged w2: CC")], "n/a");
        EXPECT_GT(std::stod(row[summary->column("ARI: pyramid")]), 0.0) << sensors[i];
        if (with_pcl) {
            EXPECT_GT(std::stod(row[summary->column("ARI: PCL")]), 0.0) << sensors[i];
        } else {
            EXPECT_EQ(row[summary->column("pyramid ARI >= PCL")], "n/a");
        }
    }
    if (with_pcl) {
        ASSERT_EQ(pcl_settings->rows.size(), sensors.size());
        for (std::size_t i = 0; i < sensors.size(); ++i) {
            EXPECT_EQ(pcl_settings->rows[i][0], sensors[i]);
            EXPECT_NE(pcl_settings->rows[i][1].find("smoothing"), std::string::npos) << pcl_settings->rows[i][1];
        }
    }
    // One table per sensor model: distance 1200 x bridges 0, 1, 2.
    ASSERT_EQ(per_sensor.size(), sensors.size());
    for (std::size_t i = 0; i < sensors.size(); ++i) {
        const Table& t = *per_sensor[i];
        EXPECT_EQ(t.heading, "### " + sensors[i]);
        ASSERT_TRUE(t.header.size() == 14u || t.header.size() == 18u) << t.header.size();
        ASSERT_EQ(t.rows.size(), 3u) << sensors[i];
        for (std::size_t b = 0; b < 3; ++b) {
            const std::vector<std::string>& row = t.rows[b];
            ASSERT_EQ(row.size(), t.header.size());
            EXPECT_EQ(row[0], "1200");
            EXPECT_EQ(row[1], std::to_string(b));
            EXPECT_GT(std::stoi(row[t.column("objects")]), 10);
            if (b > 0) {
                EXPECT_LE(std::stoi(row[t.column("merged: pyramid")]), std::stoi(row[t.column("merged: CC")]))
                    << sensors[i] << ", bridge " << b << " px";
            }
        }
    }
    std::ifstream in(dir / "quality.md");
    std::stringstream text;
    text << in.rdbuf();
    EXPECT_NE(text.str().find("the preset (robust metric"), std::string::npos);  // kinect-v1's preset
    fs::remove_all(dir);
}

TEST(CliEval, DefaultParamsAreScoredOnConsumerModelsToo) {
    const fs::path dir = fs::temp_directory_path() / ("pyrseg_eval_defaults_" + std::to_string(::getpid()));
    fs::remove_all(dir);
    const CliRun r = run("eval --quick --params default --sensors kinect-v1 --out-dir " + dir.string());
    ASSERT_EQ(r.status, 0) << r.output;
    std::ifstream in(dir / "quality.md");
    std::stringstream text;
    text << in.rdbuf();
    EXPECT_NE(text.str().find("the defaults for every sensor model"), std::string::npos) << text.str();
    EXPECT_NE(text.str().find("the defaults (paper metric"), std::string::npos) << text.str();
    EXPECT_EQ(text.str().find("robust metric"), std::string::npos) << text.str();
    expect_png(dir / "merge_rate_kinect-v1_320x240.png");
    fs::remove_all(dir);
}

// `pyrseg eval --tracks`: a tiny run's report has a table per scenario with every method, the acceptance checks
// and every sequence; the methods score the same segments, so they see the same objects, frames and matches.
TEST(CliEval, TracksReportHasTheTablesAndTheMethods) {
    const fs::path dir = fs::temp_directory_path() / ("pyrseg_eval_tracks_" + std::to_string(::getpid()));
    fs::remove_all(dir);
    const CliRun r =
        run("eval --tracks --frames 10 --size 160x120 --seeds 1 --sensors structured-light "
            "--progress lines --out-dir " +
            dir.string());
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_NE(r.output.find("[20/20] structured-light, objects, seed 1: frame 10/10"), std::string::npos) << r.output;
    std::ifstream in(dir / "tracks.md");
    ASSERT_TRUE(in) << "no tracks.md";
    std::string section;
    std::vector<std::string> header;
    std::map<std::string, std::vector<std::vector<std::string>>> rows;  // by section
    for (std::string line; std::getline(in, line);) {
        if (line.rfind("## ", 0) == 0) section = line.substr(3);
        if (line.rfind("| sensor | method", 0) == 0) header = cells_of(line);
        if (line.rfind("| structured-light", 0) == 0) rows[section].push_back(cells_of(line));
    }
    const std::vector<std::string> methods = {"pyrseg", "per-frame labels", "Hungarian IoU>=0.1", "Hungarian IoU>=0.3"};
    ASSERT_EQ(header.size(), 12u);
    const auto column = [&](const std::string& name) {
        const auto it = std::find(header.begin(), header.end(), name);
        EXPECT_NE(it, header.end()) << name;
        return std::size_t(it - header.begin());
    };
    for (const char* scenario : {"Camera motion", "Camera and object motion"}) {
        SCOPED_TRACE(scenario);
        const auto& table = rows[scenario];
        ASSERT_EQ(table.size(), methods.size());
        for (std::size_t m = 0; m < methods.size(); ++m) {
            ASSERT_EQ(table[m].size(), header.size());
            EXPECT_EQ(table[m][column("method")], methods[m]);
            for (const char* same : {"objects", "object frames", "matched", "fragmentations"}) {
                EXPECT_EQ(table[m][column(same)], table[0][column(same)]) << same << ", " << methods[m];
            }
            const std::string idf1 = table[m][column("IDF1")];
            const double value = std::stod(idf1[0] == '*' ? idf1.substr(2) : idf1);
            EXPECT_GE(value, 0.0);
            EXPECT_LE(value, 1.0);
        }
        EXPECT_GT(std::stoi(table[0][column("object frames")]), 30);
    }
    ASSERT_EQ(rows["Acceptance (camera motion)"].size(), 1u);
    EXPECT_EQ(rows["Acceptance (camera motion)"][0].size(), 4u);
    ASSERT_EQ(rows["Per sequence"].size(), 2u);
    EXPECT_EQ(rows["Per sequence"][0][1], "camera");
    EXPECT_EQ(rows["Per sequence"][1][1], "objects");
    EXPECT_EQ(rows["Per sequence"][0].size(), 4 + methods.size() + 1);
    fs::remove_all(dir);
}

TEST(CliEval, TracksHelpAndUsageErrors) {
    CliRun r = run("eval --tracks --help");
    EXPECT_EQ(r.status, 0) << r.output;
    for (const char* word : {"--frames", "--seeds", "--scenarios", "--match-iou", "IDF1", "ID switches",
                             "fragmentations", "Hungarian", "per-frame labels"}) {
        EXPECT_NE(r.output.find(word), std::string::npos) << word << "\n" << r.output;
    }
    EXPECT_NE(run("eval --help").output.find("--tracks"), std::string::npos);
    for (const char* bad : {"--frames 1", "--scenarios camera,walk", "--match-iou 0", "--size 10x10",
                            "--sensors kinect-v9", "--max-turn 45", "--params tuned"}) {
        r = run(std::string("eval --tracks --progress none ") + bad);
        EXPECT_EQ(r.status, 2) << bad << "\n" << r.output;
    }
}

}  // namespace
