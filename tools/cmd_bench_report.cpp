// pyrseg bench-report: turns pyrseg_bench's JSON (Google Benchmark) into one markdown report of ratios — pyrseg per
// backend against a memcpy of the same bytes and against each peer measured in the same run — and PNG plots.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "pyrseg/error.hpp"
#include "tools/commands.hpp"
#include "tools/output_files.hpp"
#include "tools/plot.hpp"

namespace pyrseg::cli {
namespace {

namespace fs = std::filesystem;

constexpr const char* kUsage =
    "Usage: pyrseg bench-report BENCH.json [--out-dir DIR | --update DOC.md | --check DOC.md]\n"
    "\n"
    "Reads the JSON that `pyrseg_bench --benchmark_format=json --benchmark_out=BENCH.json` writes and writes\n"
    "DIR/performance.md (default DIR: the JSON's folder) with, per frame size:\n"
    "  - in short, per backend, the range of its ratios to PCL and to OpenCV over the frame sizes;\n"
    "  - the whole pipeline (points to labels) per backend, in ms and in multiples of a memcpy of the input bytes,\n"
    "    and PCL's organized segmentation (its own integral-image normals) divided by pyrseg's time;\n"
    "  - the segmentation stage (fillable mask to compacted labels) per backend, and OpenCV's connectedComponents\n"
    "    (SAUF, Spaghetti; 4- and 8-connected) of the same mask: pyrseg's time divided by OpenCV's;\n"
    "  - depth images, the robust metric, the fills' worst cases and the per-pass times of the full-size frame;\n"
    "and two plots, DIR/bench_vs_pcl.png and DIR/bench_vs_opencv.png. Every backend the JSON's rows name gets its\n"
    "columns. Ratios come from one run on one machine; the report starts with that machine's description and its\n"
    "load.\n"
    "\n"
    "  --update DOC.md  the same report as a section of DOC.md: replaces what lies between its lines\n"
    "                   <!-- bench-report:begin ... --> and <!-- bench-report:end -->, links BENCH.json relative to\n"
    "                   DOC.md and writes the plots to DOC.md's images/ folder (docs/performance.md: the ctest\n"
    "                   docs_performance_tables checks it with --check)\n"
    "  --check DOC.md   writes nothing; fails (status 1) when DOC.md's section is not what --update would write\n"
    "The whole run is scripts/bench.sh.\n";

struct Entry {
    double ms = std::numeric_limits<double>::quiet_NaN();
    std::string error;  // skipped, with the reason
    std::map<std::string, double> counters;
};

using Entries = std::map<std::string, Entry>;

double to_ms(double value, const std::string& unit) {
    if (unit == "ns") return value * 1e-6;
    if (unit == "us") return value * 1e-3;
    if (unit == "s") return value * 1e3;
    return value;
}

Entries read_entries(const nlohmann::json& doc) {
    Entries out;
    for (const nlohmann::json& b : doc.at("benchmarks")) {
        std::string name = b.at("name").get<std::string>();
        if (const auto slash = name.rfind("/real_time"); slash != std::string::npos) name.erase(slash);
        Entry e;
        if (b.value("error_occurred", false)) {
            e.error = b.value("error_message", std::string("skipped"));
        } else {
            e.ms = to_ms(b.at("real_time").get<double>(), b.value("time_unit", std::string("ns")));
        }
        for (const auto& [key, value] : b.items()) {
            if (value.is_number() && key != "real_time" && key != "cpu_time" && key != "iterations")
                e.counters[key] = value.get<double>();
        }
        out[name] = e;
    }
    return out;
}

const Entry* find(const Entries& entries, const std::string& name) {
    const auto it = entries.find(name);
    return it == entries.end() ? nullptr : &it->second;
}

std::string fixed(double v, int digits) {
    char text[64];
    std::snprintf(text, sizeof text, "%.*f", digits, v);
    return text;
}

// Three significant digits, the way timings deserve.
std::string sig3(double v) {
    if (!std::isfinite(v)) return "—";
    const double a = std::fabs(v);
    return fixed(v, a >= 100 ? 0 : a >= 10 ? 1 : a >= 1 ? 2 : 3);
}

std::string ms_cell(const Entry* e) {
    if (e == nullptr) return "—";
    if (!e->error.empty()) return "skipped";
    return sig3(e->ms) + " ms";
}

double ratio(const Entry* num, const Entry* den) {
    if (num == nullptr || den == nullptr || !num->error.empty() || !den->error.empty()) {
        return std::numeric_limits<double>::quiet_NaN();
    }
    return num->ms / den->ms;
}

// A pass's time from a benchmark's counters ("normals_ms", ...), or a dash.
std::string pass_cell(const Entry* e, const char* pass) {
    if (e == nullptr) return "—";
    const auto it = e->counters.find(pass);
    if (it == e->counters.end()) return "—";
    char text[32];
    std::snprintf(text, sizeof text, "%.2f ms", it->second);
    return text;
}

// A benchmark's counter ("stats_ms", ...), NaN when the benchmark or the counter is missing.
double counter(const Entry* e, const char* name) {
    if (e == nullptr) return std::numeric_limits<double>::quiet_NaN();
    const auto it = e->counters.find(name);
    return it == e->counters.end() ? std::numeric_limits<double>::quiet_NaN() : it->second;
}

// Milliseconds as a share of a frame's time, or a dash when either is unknown.
std::string percent_of_frame(double ms, const Entry* frame) {
    if (!std::isfinite(ms) || frame == nullptr || !frame->error.empty() || !(frame->ms > 0)) return "—";
    char text[32];
    std::snprintf(text, sizeof text, "%.1f%%", 100.0 * ms / frame->ms);
    return text;
}

// A pass's time as a share of a frame's, or a dash.
std::string share_cell(const Entry* e, const char* pass, const Entry* frame) {
    return percent_of_frame(counter(e, pass), frame);
}

// Points to fillable mask: normals (when estimated), quantize and metric, or the one pass that fuses them where a
// backend does (points_to_mask), so that fused and separate passes compare.
std::string front_end_cell(const Entry* e) {
    if (e == nullptr) return "—";
    double ms = 0;
    bool any = false;
    for (const char* pass : {"points_to_mask_ms", "normals_ms", "quantize_ms", "metric_ms"}) {
        const auto it = e->counters.find(pass);
        if (it == e->counters.end()) continue;
        ms += it->second;
        any = true;
    }
    if (!any) return "—";
    char text[32];
    std::snprintf(text, sizeof text, "%.2f ms", ms);
    return text;
}

std::string ratio_cell(double r) {
    return std::isfinite(r) ? sig3(r) + "×" : "—";
}

struct Size {
    std::string name;  // "2064x1544"
    double megapixels = 0;
};

std::vector<Size> frame_sizes(const Entries& entries) {
    std::vector<Size> sizes;
    for (const auto& [name, e] : entries) {
        if (name.rfind("memcpy/", 0) != 0 || name.size() < 12 || name.substr(name.size() - 5) != "/mask") continue;
        const std::string size = name.substr(7, name.size() - 12);
        int w = 0;
        int h = 0;
        if (std::sscanf(size.c_str(), "%dx%d", &w, &h) == 2) sizes.push_back({size, double(w) * h * 1e-6});
    }
    std::sort(sizes.begin(), sizes.end(), [](const Size& a, const Size& b) { return a.megapixels < b.megapixels; });
    return sizes;
}

// The backend a benchmark name is about: pipeline*/<backend>/..., stage/<backend>/..., fills/<case>/<backend>/...;
// empty for the peers and memcpy.
std::string backend_of(const std::string& name) {
    std::vector<std::string> parts;
    std::stringstream in(name);
    for (std::string part; std::getline(in, part, '/');) parts.push_back(part);
    if (parts.size() >= 3 && (parts[0].rfind("pipeline", 0) == 0 || parts[0] == "stage")) return parts[1];
    if (parts.size() >= 4 && parts[0] == "fills") return parts[2];
    return {};
}

// Every backend that ran a row (one that only skipped, for want of its device, is in the list of skips): the known
// ones in the order of the tables so far (the CPU, the native backend, first), then any other in alphabetical order,
// so that a new backend gets its columns without a change here.
std::vector<std::string> backends_in(const Entries& entries) {
    std::set<std::string> named;
    for (const auto& [name, e] : entries) {
        if (std::string b = backend_of(name); !b.empty() && e.error.empty()) named.insert(b);
    }
    std::vector<std::string> out;
    for (const char* b : {"cpu", "cuda", "opencl", "vulkan"}) {
        if (named.erase(b) != 0) out.emplace_back(b);
    }
    out.insert(out.end(), named.begin(), named.end());
    return out;
}

std::string pipeline_name(const std::string& backend, const std::string& size, const std::string& kind) {
    std::string name = "pipeline/";
    name += backend;
    name += '/';
    name += size;
    name += '/';
    name += kind;
    return name;
}

std::string table_row(const std::vector<std::string>& cells) {
    std::string row = "|";
    for (const std::string& c : cells) row += " " + c + " |";
    return row + "\n";
}

std::string header(const std::vector<std::string>& cells) {
    std::string row = table_row(cells) + "|";
    for (std::size_t i = 0; i < cells.size(); ++i) row += i == 0 ? "---|" : "---:|";
    return row + "\n";
}

// What the outputs beyond the labels cost on the robust frames with the merge (pipeline_robust_merge*/): the
// statistics (the segments' exact moments), the segment graph, the scene on the host (supports, objects and their
// boxes fitted to the points), the colour edge term. Shares of the robust frame with the merge, from the passes' own
// times (frame differences are as noisy as the frames).
std::string outputs_cost_section(const Entries& entries, const std::vector<Size>& sizes,
                                 const std::vector<std::string>& backends) {
    std::string md =
        "## What statistics, the segment graph, the scene and colour cost\n\nThe robust frames with the merge "
        "(pipeline_robust_merge/, kinect-v1 preset, normals estimated) and the same frames with Outputs::segment_stats "
        "(_stats: the statistics pass, docs/algorithm.md section 10), Outputs::segment_graph (_graph: the graph pass, "
        "section 10d), the scene (_scene: the statistics, the fillable mask downloaded, then on the host "
        "`describe_scene` and `fit_object_boxes`, section 10c) and a colour image with the colour edge term (_color: "
        "the colour pass, step 0c; the colour changes the segments, so that frame differs by more than the pass). "
        "Shares: each pass's time in the robust frame with the merge (the targets on the CPU: statistics, graph "
        "and fits together at most 10%; the merge and the colour term at most 15%).\n\n";
    std::string rows;
    for (const Size& s : sizes) {
        for (const std::string& b : backends) {
            const std::string tail = "/" + b + "/" + s.name + "/estimated_normals";
            const Entry* frame = find(entries, "pipeline_robust_merge" + tail);
            const Entry* stats = find(entries, "pipeline_robust_merge_stats" + tail);
            const Entry* graph = find(entries, "pipeline_robust_merge_graph" + tail);
            const Entry* scene = find(entries, "pipeline_robust_merge_scene" + tail);
            const Entry* color = find(entries, "pipeline_robust_merge_color" + tail);
            if (frame == nullptr || (stats == nullptr && graph == nullptr && scene == nullptr && color == nullptr))
                continue;
            const double together =
                counter(stats, "stats_ms") + counter(graph, "graph_ms") + counter(scene, "scene_ms");
            rows += table_row({s.name, b, ms_cell(frame), pass_cell(stats, "stats_ms"),
                               share_cell(stats, "stats_ms", frame), pass_cell(graph, "graph_ms"),
                               share_cell(graph, "graph_ms", frame), pass_cell(scene, "scene_ms"),
                               percent_of_frame(together, frame), ms_cell(color), pass_cell(color, "color_ms"),
                               share_cell(color, "color_ms", frame)});
        }
    }
    if (rows.empty()) return md + "No pipeline_robust_merge_stats/, _graph/, _scene/ or _color/ rows in this run.\n\n";
    return md +
           header({"frame", "backend", "robust + merge", "statistics pass", "share", "graph pass", "share",
                   "scene on the host", "statistics + graph + scene", "with colour", "colour pass", "share"}) +
           rows + "\n";
}

std::string machine(const nlohmann::json& doc) {
    const nlohmann::json& c = doc.value("context", nlohmann::json::object());
    std::ostringstream s;
    s << "Machine: " << c.value("host_name", std::string("?")) << ", " << c.value("num_cpus", 0) << " CPUs at "
      << c.value("mhz_per_cpu", 0) << " MHz, run " << c.value("date", std::string("?"))
      << " (Google Benchmark's own library is a " << c.value("library_build_type", std::string("?"))
      << " build: Debian's package).\n\n";
    // Google Benchmark's load averages when the run started; scripts/bench.sh adds them at its end. Only the start's
    // says whether other work ran: at the end the load counts the bench's own threads and the processes its cpu_load
    // rows spin.
    const auto load = [&](const char* key) -> std::string {
        const nlohmann::json& l = c.value(key, nlohmann::json::array());
        if (!l.is_array() || l.empty() || !l[0].is_number()) return {};
        std::string text;
        for (const nlohmann::json& v : l) text += (text.empty() ? "" : ", ") + fixed(v.get<double>(), 2);
        return text;
    };
    const std::string before = load("load_avg");
    const std::string after = load("load_avg_after");
    const nlohmann::json& start = c.value("load_avg", nlohmann::json::array());
    const bool busy = !before.empty() && start[0].get<double>() >= 0.5;
    if (!before.empty()) {
        s << "Load average (1, 5, 15 min) at the start: " << before;
        if (!after.empty()) s << "; at the end: " << after << " (the bench's own threads count in it)";
        s << (busy ? ". **The machine was not idle** (load 0.5 or more at the start): times are longer than a quiet "
                     "machine's and vary more, and so do the ratios of rows measured at different moments.\n\n"
                   : ".\n\n");
    }
    for (const auto& [key, value] : c.items()) {
        if (key.rfind("backend ", 0) == 0 || key == "opencv" || key == "pcl" || key == "peers not built")
            s << "- " << key << ": " << (value.is_string() ? value.get<std::string>() : value.dump()) << "\n";
    }
    return s.str() + "\n";
}

struct Report {
    std::string markdown;
    LineChart vs_pcl;
    LineChart vs_opencv;
};

LineSeries series(const std::string& name, std::size_t index, bool hollow = false) {
    static const std::array<std::array<std::uint8_t, 3>, 6> colors = {
        {{31, 119, 180}, {214, 39, 40}, {44, 160, 44}, {148, 103, 189}, {255, 127, 14}, {23, 190, 207}}};
    LineSeries s;
    s.name = name;
    s.color = colors[index % colors.size()];
    s.hollow = hollow;
    return s;
}

void fit_y(LineChart& chart) {
    double top = 0;
    for (const LinePanel& p : chart.panels) {
        for (const LineSeries& s : p.series) {
            for (const double v : s.y) {
                if (std::isfinite(v)) top = std::max(top, v);
            }
        }
    }
    const double step = top <= 2 ? 0.5 : top <= 5 ? 1 : top <= 10 ? 2 : top <= 25 ? 5 : top <= 50 ? 10 : 20;
    chart.y_min = 0;
    chart.y_max = std::max(step, std::ceil(top / step) * step);
    chart.y_ticks.clear();
    for (double t = 0; t <= chart.y_max + 1e-9; t += step) chart.y_ticks.push_back(t);
}

// source: how the report names the JSON (markdown); images: the plots' folder as the report links them.
Report build_report(const nlohmann::json& doc, const std::string& source, const std::string& images) {
    const Entries entries = read_entries(doc);
    const std::vector<Size> sizes = frame_sizes(entries);
    const std::vector<std::string> backends = backends_in(entries);
    if (sizes.empty() || backends.empty()) {
        throw Error(ErrorCode::format, source + ": no pyrseg_bench results (pipeline/*, memcpy/*/mask) in it");
    }
    Report r;
    std::string& md = r.markdown;
    md += "# pyrseg benchmark report\n\nFrom " + source + ". " + machine(doc);

    // In short: each ratio's range over the frame sizes, per backend.
    const auto range = [&](const std::function<double(const Size&)>& of) {
        double lo = std::numeric_limits<double>::infinity();
        double hi = -lo;
        for (const Size& s : sizes) {
            const double v = of(s);
            if (!std::isfinite(v)) continue;
            lo = std::min(lo, v);
            hi = std::max(hi, v);
        }
        if (!std::isfinite(lo)) return std::string("—");
        return lo == hi ? ratio_cell(lo) : ratio_cell(lo) + " to " + ratio_cell(hi);
    };
    md += "## In short\n\nEach ratio's range over the frame sizes below (" + sizes.front().name + " to " +
          sizes.back().name +
          "). PCL ÷ pyrseg: above 1, pyrseg is faster; pyrseg ÷ OpenCV: below 1, pyrseg is faster.\n\n";
    md += header({"backend", "PCL ÷ pyrseg, each estimating its normals", "PCL's labelling ÷ pyrseg, the same normals",
                  "pyrseg's stage ÷ OpenCV SAUF-4, the same mask"});
    for (const std::string& b : backends) {
        md += table_row({b, range([&](const Size& s) {
                             return ratio(find(entries, "pcl/organized_edge_aware/" + s.name + "/estimated_normals"),
                                          find(entries, pipeline_name(b, s.name, "estimated_normals")));
                         }),
                         range([&](const Size& s) {
                             return ratio(find(entries, "pcl/organized_edge_aware/" + s.name + "/given_normals"),
                                          find(entries, pipeline_name(b, s.name, "given_normals")));
                         }),
                         range([&](const Size& s) {
                             return ratio(find(entries, "stage/" + b + "/" + s.name),
                                          find(entries, "opencv/sauf_4/" + s.name));
                         })});
    }
    md += "\n";

    // Whole pipeline, per normals source. PCL's pipeline estimates its own normals (integral images); with the
    // scene's normals it runs only its labelling, which compares with pyrseg given the same normals.
    for (const bool given : {false, true}) {
        const std::string kind = given ? "given_normals" : "estimated_normals";
        md += given ? "## Whole pipeline, points and normals to labels\n\n"
                    : "## Whole pipeline, points to labels (normals estimated)\n\n";
        md +=
            "Milliseconds per frame; in brackets, multiples of a memcpy of the same input bytes; fill rounds: the "
            "sweep rounds of the CPU's PYRSEG_CPU_FILL=sweeps (0 for the union-find fills). PCL: "
            "OrganizedConnectedComponentSegmentation with "
            "EdgeAwarePlaneComparator, ";
        md += given ? "once with its integral-image normals (its whole pipeline) and once with the scene's normals "
                      "(its labelling alone).\n\n"
                    : "with its integral-image normals.\n\n";
        std::vector<std::pair<std::string, std::string>> peers = {{"PCL", "estimated_normals"}};
        if (given) peers = {{"PCL, its normals", "estimated_normals"}, {"PCL, these normals", "given_normals"}};
        const auto peer_entry = [&](const std::string& peer_kind, const Size& s) {
            return find(entries, "pcl/organized_edge_aware/" + s.name + "/" + peer_kind);
        };
        std::vector<std::string> head = {"frame", "memcpy"};
        for (const std::string& b : backends) head.push_back(b);
        head.emplace_back("fill rounds");
        for (const auto& p : peers) head.push_back(p.first);
        for (const auto& p : peers) {
            for (const std::string& b : backends) head.push_back(p.first + " ÷ " + b);
        }
        md += header(head);
        for (const Size& s : sizes) {
            const Entry* copy = find(entries, "memcpy/" + s.name + "/" + kind);
            std::vector<std::string> row = {s.name, copy != nullptr ? sig3(copy->ms) + " ms" : "—"};
            std::string rounds = "—";
            for (const std::string& b : backends) {
                const Entry* e = find(entries, pipeline_name(b, s.name, kind));
                std::string cell = ms_cell(e);
                if (e != nullptr && e->error.empty() && copy != nullptr)
                    cell += " (" + ratio_cell(ratio(e, copy)) + ")";
                row.push_back(cell);
                const auto rounds_it =
                    e != nullptr ? e->counters.find("fill_rounds") : std::map<std::string, double>::const_iterator{};
                if (e != nullptr && rounds_it != e->counters.end() && rounds_it->second > 0)
                    rounds = fixed(rounds_it->second, 0);
            }
            row.push_back(rounds);
            for (const auto& p : peers) row.push_back(ms_cell(peer_entry(p.second, s)));
            for (const auto& p : peers) {
                for (const std::string& b : backends) {
                    row.push_back(
                        ratio_cell(ratio(peer_entry(p.second, s), find(entries, pipeline_name(b, s.name, kind)))));
                }
            }
            md += table_row(row);
        }
        md += "\n";
    }
    // Skips, with their reasons, once.
    std::set<std::string> reasons;
    for (const auto& [name, e] : entries) {
        if (!e.error.empty()) reasons.insert(name + ": " + e.error);
    }
    if (!reasons.empty()) {
        md += "Skipped in this run:\n\n";
        for (const std::string& why : reasons) md += "- " + why + "\n";
        md += "\n";
    }

    // The segmentation stage against OpenCV.
    const std::vector<std::pair<std::string, std::string>> peers = {{"sauf_4", "SAUF 4-conn"},
                                                                    {"sauf_8", "SAUF 8-conn"},
                                                                    {"spaghetti_4", "Spaghetti 4-conn"},
                                                                    {"spaghetti_8", "Spaghetti 8-conn"}};
    md +=
        "## Segmentation stage: fillable mask to compacted labels\n\n"
        "pyrseg's pyramid passes on the mask its metric produced for the scene, and OpenCV's connectedComponents "
        "of the same mask (plain labelling, which merges what bridges join). Ratios: pyrseg ÷ OpenCV SAUF "
        "4-connected (below 1: pyrseg faster).\n\n";
    std::vector<std::string> head = {"frame", "memcpy"};
    for (const std::string& b : backends) head.push_back(b);
    for (const auto& p : peers) head.push_back("OpenCV " + p.second);
    for (const std::string& b : backends) head.push_back(b + " ÷ SAUF-4");
    md += header(head);
    for (const Size& s : sizes) {
        const Entry* sauf4 = find(entries, "opencv/sauf_4/" + s.name);
        std::vector<std::string> row = {s.name, ms_cell(find(entries, "memcpy/" + s.name + "/mask"))};
        for (const std::string& b : backends) row.push_back(ms_cell(find(entries, "stage/" + b + "/" + s.name)));
        for (const auto& p : peers) row.push_back(ms_cell(find(entries, "opencv/" + p.first + "/" + s.name)));
        for (const std::string& b : backends)
            row.push_back(ratio_cell(ratio(find(entries, "stage/" + b + "/" + s.name), sauf4)));
        md += table_row(row);
    }
    md += "\n";

    // Depth frames: the same scenes as uint16 depth images (2 bytes a pixel uploaded, back-projected on the device)
    // beside the float clouds (12 bytes a pixel).
    md +=
        "## Depth images (DepthView)\n\nThe same scenes as uint16 depth images in millimetres "
        "(pipeline_depth/: 2 bytes a pixel uploaded, back-projected on the device by the depth pass) beside the float "
        "clouds (pipeline/, 12 bytes a pixel), normals estimated. Ratio: depth ÷ cloud. The device-resident columns "
        "(pipeline_device/, pipeline_depth_device/) are the same frames already in the application's GPU buffers, "
        "labels left there (pyrseg/opencl.hpp, ...), each frame waited for once: no host transfer.\n\n";
    md += header({"frame", "backend", "cloud", "depth image", "depth ÷ cloud", "upload: cloud", "upload: depth",
                  "depth pass", "cloud, device-resident", "depth image, device-resident"});
    for (const Size& s : sizes) {
        for (const std::string& b : backends) {
            const Entry* cloud = find(entries, "pipeline/" + b + "/" + s.name + "/estimated_normals");
            const Entry* depth = find(entries, "pipeline_depth/" + b + "/" + s.name + "/u16");
            if (depth == nullptr) continue;
            md += table_row({s.name, b, ms_cell(cloud), ms_cell(depth), ratio_cell(ratio(depth, cloud)),
                             pass_cell(cloud, "upload_ms"), pass_cell(depth, "upload_ms"), pass_cell(depth, "depth_ms"),
                             ms_cell(find(entries, "pipeline_device/" + b + "/" + s.name + "/estimated_normals")),
                             ms_cell(find(entries, "pipeline_depth_device/" + b + "/" + s.name + "/u16"))});
        }
    }
    md += "\n";

    // What the robust metric costs: the same frames with the kinect-v1 preset, pass by pass.
    md +=
        "## The robust metric's cost\n\nThe same frames, normals estimated, with the paper's metric (pipeline/) and "
        "with the robust metric of the kinect-v1 preset, its merge off (pipeline_robust/: window normals R = 3, "
        "curvature "
        "stride 6). "
        "Ratio: robust ÷ paper (above 1: the robust metric is slower). Points to mask: normals, quantize and metric "
        "(the CPU runs them fused into one pass with the paper metric; separately with the robust one).\n\n";
    md += header({"frame", "backend", "paper", "robust", "robust ÷ paper", "points to mask: paper",
                  "points to mask: robust", "normals: robust", "metric: robust"});
    for (const Size& s : sizes) {
        for (const std::string& b : backends) {
            const Entry* paper = find(entries, "pipeline/" + b + "/" + s.name + "/estimated_normals");
            const Entry* robust = find(entries, "pipeline_robust/" + b + "/" + s.name + "/estimated_normals");
            if (robust == nullptr) continue;
            md += table_row({s.name, b, ms_cell(paper), ms_cell(robust), ratio_cell(ratio(robust, paper)),
                             front_end_cell(paper), front_end_cell(robust), pass_cell(robust, "normals_ms"),
                             pass_cell(robust, "metric_ms")});
        }
    }
    md += "\n";

    // What the merge (step 6d) costs on those robust frames.
    md +=
        "## The merge's cost\n\nThe robust frames above with the preset's merge on (pipeline_robust_merge/; "
        "docs/algorithm.md section 5b). Share: the merge pass's time in the robust frame without it (the target is "
        "at most 15% on the CPU).\n\n";
    std::string merge_rows;
    for (const Size& s : sizes) {
        for (const std::string& b : backends) {
            const Entry* robust = find(entries, "pipeline_robust/" + b + "/" + s.name + "/estimated_normals");
            const Entry* merged = find(entries, "pipeline_robust_merge/" + b + "/" + s.name + "/estimated_normals");
            if (merged == nullptr) continue;
            merge_rows += table_row({s.name, b, ms_cell(robust), ms_cell(merged), pass_cell(merged, "merge_ms"),
                                     share_cell(merged, "merge_ms", robust)});
        }
    }
    if (merge_rows.empty()) {
        md += "No pipeline_robust_merge/ rows in this run (runs before the merge had none).\n\n";
    } else {
        md += header({"frame", "backend", "robust", "robust + merge", "merge pass", "merge pass ÷ robust"}) +
              merge_rows + "\n";
    }

    md += outputs_cost_section(entries, sizes, backends);

    // The fills' worst cases.
    md +=
        "## The fills' worst cases\n\nOne winding region of 8-pixel corridors. Every backend fills by union-find, "
        "whatever the region's shape; sweep rounds are counted only by the CPU's PYRSEG_CPU_FILL=sweeps. A GPU "
        "backend's dispatches and host waits per frame are the same as for any other frame of that size.\n\n";
    md += header({"case", "frame", "backend", "frame time", "fill time", "sweep rounds", "dispatches", "host waits"});
    for (const auto& named : entries) {
        const std::string& name = named.first;
        const Entry& e =
            named.second;  // a plain reference: lambdas below capture it (clang 14 cannot capture bindings)
        if (name.rfind("fills/", 0) != 0) continue;
        std::vector<std::string> parts;
        std::stringstream in(name);
        for (std::string part; std::getline(in, part, '/');) parts.push_back(part);
        if (parts.size() != 4) continue;
        const auto counter = [&](const char* key) {
            const auto it = e.counters.find(key);
            return it == e.counters.end() ? std::string("—") : sig3(it->second);
        };
        const auto rounds = e.counters.find("fill_rounds");
        const auto whole = [&](const char* key) {
            const auto it = e.counters.find(key);
            return it == e.counters.end() ? std::string("—") : fixed(it->second, 0);
        };
        md += table_row({parts[1], parts[3], parts[2], ms_cell(&e), counter("fill_ms") + " ms",
                         rounds == e.counters.end() ? "—" : fixed(rounds->second, 0), whole("dispatches"),
                         whole("host_syncs")});
    }
    md += "\n";

    // Where a full frame's time goes.
    const Size& largest_with_all = [&]() -> const Size& {
        for (const Size& s : sizes) {
            if (s.name == "2064x1544") return s;
        }
        return sizes.back();
    }();
    md += "## Per pass, " + largest_with_all.name + ", estimated normals (ms per frame)\n\n";
    std::set<std::string> passes;
    for (const std::string& b : backends) {
        if (const Entry* e = find(entries, "pipeline/" + b + "/" + largest_with_all.name + "/estimated_normals")) {
            for (const auto& [key, v] : e->counters) {
                if (key.size() > 3 && key.substr(key.size() - 3) == "_ms") passes.insert(key);
            }
        }
    }
    head = {"pass"};
    for (const std::string& b : backends) head.push_back(b);
    md += header(head);
    for (const std::string& pass : passes) {
        std::vector<std::string> row = {pass.substr(0, pass.size() - 3)};
        for (const std::string& b : backends) {
            const Entry* e = find(entries, "pipeline/" + b + "/" + largest_with_all.name + "/estimated_normals");
            const auto it = e != nullptr ? e->counters.find(pass) : std::map<std::string, double>::const_iterator{};
            row.push_back(e != nullptr && it != e->counters.end() ? sig3(it->second) : "—");
        }
        md += table_row(row);
    }
    md += "\n";

    // Plots: x = megapixels.
    r.vs_pcl.title = "PCL time / pyrseg time, same normals (higher: pyrseg faster)";
    r.vs_pcl.x_label = "frame, megapixels";
    r.vs_opencv.title = "pyrseg / OpenCV SAUF-4 (lower: pyrseg faster)";
    r.vs_opencv.x_label = "frame, megapixels";
    LinePanel pcl_panel;
    pcl_panel.title = "whole pipeline";
    LinePanel cv_panel;
    cv_panel.title = "mask to labels";
    // Frame sizes evenly spaced (they grow by factors of about 4), labelled with their megapixels.
    for (const Size& s : sizes) {
        for (LinePanel* panel : {&pcl_panel, &cv_panel}) {
            panel->x.push_back(double(panel->x.size()));
            panel->x_labels.push_back(sig3(s.megapixels));
        }
    }
    for (std::size_t k = 0; k < backends.size(); ++k) {
        for (const bool given : {false, true}) {
            LineSeries line = series(backends[k] + (given ? " given n." : " est. n."), k, given);
            for (const Size& s : sizes) {
                // Like for like: both sides estimate their normals, or both are given the scene's.
                const std::string kind = given ? "given_normals" : "estimated_normals";
                line.y.push_back(ratio(find(entries, "pcl/organized_edge_aware/" + s.name + "/" + kind),
                                       find(entries, "pipeline/" + backends[k] + "/" + s.name + "/" + kind)));
            }
            pcl_panel.series.push_back(line);
        }
        LineSeries line = series(backends[k], k);
        for (const Size& s : sizes)
            line.y.push_back(
                ratio(find(entries, "stage/" + backends[k] + "/" + s.name), find(entries, "opencv/sauf_4/" + s.name)));
        cv_panel.series.push_back(line);
    }
    r.vs_pcl.panels.push_back(pcl_panel);
    r.vs_opencv.panels.push_back(cv_panel);
    fit_y(r.vs_pcl);
    fit_y(r.vs_opencv);
    md += "![PCL / pyrseg](" + images + "bench_vs_pcl.png)\n\n![pyrseg / OpenCV](" + images + "bench_vs_opencv.png)\n";
    return r;
}

constexpr const char* kBegin = "<!-- bench-report:begin";
constexpr const char* kEnd = "<!-- bench-report:end -->";

// The report as a section of another document: its headings one level down and no title of its own.
std::string as_section(const std::string& report) {
    std::string out;
    std::stringstream in(report);
    for (std::string line; std::getline(in, line);) {
        if (line.rfind("# ", 0) == 0) {
            std::getline(in, line);  // the title and the empty line after it
            continue;
        }
        if (line.rfind("## ", 0) == 0) line.insert(0, "#");
        out += line + "\n";
    }
    return out;
}

// DOC's text with the section between the markers replaced; throws when the markers are not there once each.
std::string replaced(const std::string& doc, const fs::path& path, const std::string& section) {
    const auto begin = doc.find(kBegin);
    const auto end = doc.find(kEnd);
    if (begin == std::string::npos || end == std::string::npos || end < begin ||
        doc.find(kBegin, begin + 1) != std::string::npos || doc.find(kEnd, end + 1) != std::string::npos) {
        throw Error(ErrorCode::format, path.string() + ": needs one line " + kBegin + " ... --> and one line " + kEnd +
                                           " after it, around the section bench-report writes");
    }
    const auto body = doc.find('\n', begin);
    return doc.substr(0, body + 1) + "\n" + section + "\n" + doc.substr(end);
}

std::string read_text(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw Error(ErrorCode::io, path.string() + ": cannot open");
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

}  // namespace

int cmd_bench_report(const std::vector<std::string>& argv) {
    const Args args(argv, {"out-dir", "update", "check"}, {"help"});
    if (args.flag("help")) {
        std::fputs(kUsage, stdout);
        return 0;
    }
    if (args.positional().size() != 1) throw UsageError{"expects one BENCH.json"};
    const std::optional<std::string> update = args.value("update");
    const std::optional<std::string> check = args.value("check");
    if (int(update.has_value()) + int(check.has_value()) + int(args.value("out-dir").has_value()) > 1)
        throw UsageError{"--update, --check and --out-dir exclude each other"};
    const fs::path input = args.positional()[0];
    std::ifstream in(input);
    if (!in) throw Error(ErrorCode::io, input.string() + ": cannot open");
    nlohmann::json doc;
    try {
        doc = nlohmann::json::parse(in);
    } catch (const nlohmann::json::exception& e) {
        throw Error(ErrorCode::format, input.string() + ": not JSON: " + e.what());
    }
    const std::optional<fs::path> target = update ? update : check;
    // In a document, the JSON is a link relative to it and the plots are in its images/ folder.
    std::string source = "`" + input.filename().string() + "`";
    if (target) {
        const fs::path rel = fs::relative(input, fs::absolute(*target).parent_path());
        source = "[" + rel.generic_string() + "](" + rel.generic_string() + ")";
    }
    Report report;
    try {
        report = build_report(doc, source, target ? "images/" : "");
    } catch (const nlohmann::json::exception& e) {
        throw Error(ErrorCode::format, input.string() + ": not Google Benchmark JSON: " + e.what());
    }
    if (target) {
        const std::string old_text = read_text(*target);
        const std::string new_text = replaced(old_text, *target, as_section(report.markdown));
        if (check) {
            if (new_text == old_text) {
                std::printf("%s: its bench-report section is what %s gives\n", target->string().c_str(),
                            input.string().c_str());
                return 0;
            }
            std::fprintf(stderr,
                         "%s: its bench-report section differs from what %s gives (edited by hand, or the report "
                         "changed); regenerate it: pyrseg bench-report %s --update %s\n",
                         target->string().c_str(), input.string().c_str(), input.string().c_str(),
                         target->string().c_str());
            return 1;
        }
        write_text_file(*target, new_text);
        const fs::path images = target->parent_path() / "images";
        std::error_code ec;
        fs::create_directories(images, ec);
        write_png((images / "bench_vs_pcl.png").string(), render_line_chart(report.vs_pcl));
        write_png((images / "bench_vs_opencv.png").string(), render_line_chart(report.vs_opencv));
        std::printf("updated %s's bench-report section, %s and bench_vs_opencv.png\n", target->string().c_str(),
                    (images / "bench_vs_pcl.png").string().c_str());
        return 0;
    }
    const fs::path out_dir =
        args.value("out-dir").value_or(input.parent_path().empty() ? fs::path(".") : input.parent_path());
    std::error_code ec;
    fs::create_directories(out_dir, ec);
    const fs::path md = out_dir / "performance.md";
    write_text_file(md, report.markdown);
    write_png((out_dir / "bench_vs_pcl.png").string(), render_line_chart(report.vs_pcl));
    write_png((out_dir / "bench_vs_opencv.png").string(), render_line_chart(report.vs_opencv));
    std::printf("wrote %s, bench_vs_pcl.png, bench_vs_opencv.png\n", md.string().c_str());
    return 0;
}

}  // namespace pyrseg::cli
