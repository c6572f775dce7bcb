// `pyrseg eval --tabletop DIR`: pyrseg's presets on real tabletop RGB-D frames against a ground truth made from the
// depth (tools/eval/tabletop_truth.hpp), with a picture per frame.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <map>
#include <memory>
#include <numbers>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "pyrseg/io.hpp"
#include "pyrseg/presets.hpp"
#include "pyrseg/scene.hpp"
#include "pyrseg/segmenter.hpp"
#include "pyrseg/synthetic.hpp"
#include "tools/args.hpp"
#include "tools/commands.hpp"
#include "tools/eval/tabletop_boxes.hpp"
#include "tools/eval/tabletop_scores.hpp"
#include "tools/eval/tabletop_truth.hpp"
#include "tools/figures.hpp"
#include "tools/output_files.hpp"
#include "tools/pcl_peer.hpp"
#include "tools/printable.hpp"
#include "tools/scene_picture.hpp"
#include "tools/synthetic_scene_scores.hpp"

namespace pyrseg::cli {
namespace {

namespace fs = std::filesystem;
using io::DepthImage;
using io::Image;
using io::Intrinsics;

constexpr const char* kTabletopUsage =
    "Usage: pyrseg eval --tabletop DIR [--presets NAME,...] [--pcl-sensor NAME|none] [--lccp grid|none]\n"
    "                   [--calib FILE]\n"
    "                   [--depth-scale M] [--out-dir DIR] [parameters]\n"
    "\n"
    "Measures pyrseg on real tabletop RGB-D frames: every NAME_depth.png in DIR (16-bit, registered to the colour\n"
    "camera; NAME_color.png beside it, when there is one, goes into the pictures), the camera from DIR/camera.yml\n"
    "(or --calib FILE: fx, fy, cx, cy as `pyrseg segment --calib` reads them), depth in millimetres unless\n"
    "--depth-scale says how many metres one unit is.\n"
    "\n"
    "The ground truth is made from the depth, the way the OCID dataset was annotated: the support plane (RANSAC,\n"
    "refined by least squares; 10 mm tolerance; the highest plane parallel to the first that holds a tenth of the\n"
    "valid pixels: a table, not the floor around it); the table = the plane's inliers in their largest image "
    "component;\n"
    "objects = the pixels 15-400 mm above the plane that project into the table's outline on it (the convex hull),\n"
    "split into depth-continuous components of at least 300 pixels (touching objects stay one object).\n"
    "\n"
    "Per object: found whole (one segment has IoU >= 0.5 with it), found in parts (the union of the segments lying\n"
    "at least 80% inside it has IoU >= 0.5; parts: those segments), merged with the table (at least 30% of its\n"
    "pixels carry the table's label, the segment holding most of the table), its best IoU and its unlabelled\n"
    "pixels. Per frame also the table's largest share in one segment and the time of a frame (CPU backend, the\n"
    "median of 5). --presets: the sensor presets to compare (default: every one, then the defaults as `default`);\n"
    "NAME+merge turns the merge on (docs/algorithm.md section 5b), NAME+nomerge off. The segment parameter options\n"
    "(`pyrseg segment --help`: --merge-reach, --ct, ...) override every preset's values.\n"
    "Beside them, when pyrseg is built with PCL: PCL's organized segmentation of the same frame (its cloud in mm),\n"
    "OrganizedConnectedComponentSegmentation with EdgeAwarePlaneComparator, with the settings `pyrseg eval` tuned\n"
    "for the sensor model --pcl-sensor names (default realsense-d435; none leaves PCL out), timed once; and PCL's\n"
    "supervoxels + LCCP (Stein et al. 2014) with the colour image, tuned over a small grid on these frames (seed\n"
    "20, 30 mm x concavity 10, 20 degrees x colour importance 0, 0.2; the most objects whole, then the fewest\n"
    "merged; --lccp none leaves it out).\n"
    "\n"
    "Writes DIR/tabletop.md (the tables: in sum, per frame, and per object, where each object lies and how each\n"
    "method found it: whole, in N parts or not found, merged with the table, its best IoU and unlabelled share)\n"
    "and DIR/tabletop_NAME.png (colour | ground truth | each preset) into --out-dir (default pyrseg-eval-tabletop).\n";

// printf into a string (the tables' cells and head).
template <class... Values>
std::string printed(const char* fmt, Values... values) {
    char buffer[512];
    std::snprintf(buffer, sizeof buffer, fmt, values...);
    return buffer;
}

struct Method {
    std::string name;
    Params params;
    std::optional<SensorKind> pcl;  // set: PCL's organized segmentation with the settings tuned for that model
    std::optional<peers::LccpSettings> lccp;  // set: PCL's supervoxels + LCCP with these settings
    bool color = true;                        // the frame's colour image goes to pyrseg (when it has one)
};

struct Frame {
    std::string name;
    Intrinsics camera;
    DepthImage depth;
    std::vector<float> metres;
    eval::TabletopTruth truth;
    RgbImage color;           // empty without NAME_color.png
    bool picture = true;      // a picture of it is written
    bool plane_known = true;  // truth.plane is the support's (the synthetic frames' truth has no plane)
    std::shared_ptr<const synthetic::Scene> generated;  // a synthetic frame's own scene (its primitives)
};

// Each name a preset (or `default`), NAME+merge with the merge on, NAME+nomerge with it off; the segment parameter
// options override them all.
std::vector<Method> parse_methods(const Args& args) {
    std::vector<Method> out;
    const auto add = [&](const std::string& item) {
        std::stringstream parts(item);
        std::string name;
        std::getline(parts, name, '+');
        std::optional<SensorKind> kind;
        if (name != "default") {
            kind = sensor_kind_from_name(name);
            if (!kind) throw UsageError{"--presets: no sensor preset named '" + printable(name) + "'"};
        }
        Params p = kind ? parse_params(args, kind) : parse_params(args, std::nullopt);
        bool color = true;
        for (std::string modifier; std::getline(parts, modifier, '+');) {
            if (modifier == "merge" || modifier == "nomerge") {
                p.merge = modifier == "merge";
            } else if (modifier == "nocolor") {
                color = false;
            } else {
                throw UsageError{"--presets: '" + printable(item) + "': the modifiers are +merge, +nomerge, +nocolor"};
            }
        }
        out.push_back({item, p, std::nullopt, std::nullopt, color});
    };
    const std::optional<std::string> list = args.value("presets");
    if (!list) {
        for (const SensorKind k : sensor_kinds()) add(sensor_kind_name(k));
        add("default");
        return out;
    }
    std::stringstream ss(*list);
    std::string item;
    while (std::getline(ss, item, ',')) {
        if (item.empty()) throw UsageError{"--presets has an empty name"};
        add(item);
    }
    if (out.empty()) throw UsageError{"--presets is empty"};
    return out;
}

RgbImage read_color(const fs::path& path, int width, int height) {
    if (!fs::exists(path)) return {};
    const Image png = io::read_png(path);
    if (png.width != width || png.height != height || png.bit_depth != 8 || png.channels < 3) {
        std::fprintf(stderr, "pyrseg eval: %s is not an 8-bit colour image of the depth's size; left out\n",
                     printable(path.string()).c_str());
        return {};
    }
    RgbImage out{width, height, {}};
    out.rgb.resize(std::size_t(width) * std::size_t(height) * 3);
    for (std::size_t i = 0; i < std::size_t(width) * std::size_t(height); ++i) {
        for (std::size_t c = 0; c < 3; ++c) out.rgb[3 * i + c] = png.data[std::size_t(png.channels) * i + c];
    }
    return out;
}

std::vector<fs::path> depth_files(const fs::path& dir) {
    std::vector<fs::path> depths;
    for (const fs::directory_entry& e : fs::directory_iterator(dir)) {
        const std::string name = e.path().filename().string();
        if (e.is_regular_file() && name.size() > 10 && name.ends_with("_depth.png")) depths.push_back(e.path());
    }
    std::sort(depths.begin(), depths.end());
    if (depths.empty()) throw UsageError{"--tabletop: no NAME_depth.png in " + printable(dir.string())};
    return depths;
}

std::vector<Frame> read_frames(const std::vector<fs::path>& depths, double metres_per_unit, const Intrinsics& k) {
    std::vector<Frame> frames;
    for (const fs::path& p : depths) {
        Frame f;
        const std::string file = p.filename().string();
        f.name = file.substr(0, file.size() - std::string("_depth.png").size());
        f.depth = io::read_depth_image(p);
        f.metres.resize(f.depth.depth.size());
        for (std::size_t i = 0; i < f.metres.size(); ++i) {
            const float v = f.depth.depth[i];
            f.metres[i] = v > 0 ? float(v * metres_per_unit) : 0.0f;
        }
        f.camera = k;
        f.truth = eval::make_tabletop_truth(f.depth.width, f.depth.height, f.metres, {k.fx, k.fy, k.cx, k.cy});
        f.color = read_color(p.parent_path() / (f.name + "_color.png"), f.depth.width, f.depth.height);
        frames.push_back(std::move(f));
    }
    return frames;
}

// The ground truth as a picture: the table grey, objects in the label colours, no truth black.
RgbImage truth_picture(const eval::TabletopTruth& truth, int width, int height) {
    std::vector<std::uint32_t> shown = truth.labels;
    RgbImage out = colorize(shown, width, height);
    for (std::size_t i = 0; i < shown.size(); ++i) {
        if (shown[i] == eval::kTruthTable) {
            for (std::size_t c = 0; c < 3; ++c) out.rgb[3 * i + c] = 110;
        }
    }
    return out;
}

struct Totals {
    std::uint32_t objects = 0, whole = 0, in_parts = 0, parts = 0, merged = 0;
    double iou_sum = 0, table_share_sum = 0, ms_sum = 0;
    std::uint64_t object_pixels = 0, unlabelled = 0;
    std::uint32_t frames = 0;
    void add(const eval::TabletopScores& s, double ms) {
        objects += std::uint32_t(s.objects.size());
        whole += s.whole();
        in_parts += s.in_parts();
        merged += s.merged_with_table();
        for (const eval::TabletopObjectScore& o : s.objects) {
            parts += o.parts;
            iou_sum += o.best_iou;
            object_pixels += o.pixels;
            unlabelled += o.unlabelled;
        }
        table_share_sum += s.table_share;
        ms_sum += ms;
        ++frames;
    }
};

std::string row(const std::string& first, const Totals& t) {
    const auto share = [](double a, double b) { return b == 0 ? std::string("-") : printed("%.0f%%", 100 * a / b); };
    return "| " + first + " | " + std::to_string(t.objects) + " | " + std::to_string(t.whole) + " (" +
           share(t.whole, t.objects) + ") | " + std::to_string(t.in_parts) + " (" + share(t.in_parts, t.objects) +
           ") | " + (t.objects == 0 ? std::string("-") : printed("%.1f", double(t.parts) / t.objects)) + " | " +
           std::to_string(t.merged) + " | " +
           (t.objects == 0 ? std::string("-") : printed("%.2f", t.iou_sum / t.objects)) + " | " +
           share(t.table_share_sum, t.frames) + " | " + share(double(t.unlabelled), double(t.object_pixels)) + " | " +
           (t.frames == 0 ? std::string("-") : printed("%.2f", t.ms_sum / t.frames)) + " |\n";
}

constexpr const char* kTableHead =
    "| %s | objects | whole | in parts | parts per object | merged with table | mean best IoU | table in one "
    "segment | object pixels unlabelled | ms per frame |\n|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";

// LCCP's settings from lccp_grid() that do best on the frames: the most objects whole, then the fewest merged with
// the table, then the highest mean best IoU. Prints each setting's totals.
peers::LccpSettings tune_lccp(const std::vector<Frame>& frames, double metres_per_unit) {
    const std::vector<peers::LccpSettings> grid = lccp_grid();
    std::optional<std::size_t> best;
    Totals best_totals;
    for (std::size_t g = 0; g < grid.size(); ++g) {
        Totals t;
        for (const Frame& f : frames) {
            const io::PointCloud cloud = io::depth_to_cloud(f.depth, f.camera, metres_per_unit);
            const PclRun run = lccp_segment(cloud, f.color.rgb.empty() ? nullptr : f.color.rgb.data(), grid[g]);
            t.add(eval::score_tabletop(f.truth.labels, run.labels), 0.0);
        }
        std::printf("LCCP tuning %zu/%zu: %s: %u of %u whole, %u merged with the table, mean best IoU %.2f\n", g + 1,
                    grid.size(), peers::describe(grid[g]).c_str(), t.whole, t.objects, t.merged,
                    t.objects == 0 ? 0.0 : t.iou_sum / t.objects);
        const bool better =
            !best || t.whole > best_totals.whole ||
            (t.whole == best_totals.whole &&
             (t.merged < best_totals.merged || (t.merged == best_totals.merged && t.iou_sum > best_totals.iou_sum)));
        if (better) {
            best = g;
            best_totals = t;
        }
    }
    return grid[*best];
}

double median_ms(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
}

// How far the plane of pyrseg's table segment (its statistics, docs/algorithm.md section 10b) lies from the ground
// truth's support plane: the angle between their normals and the truth plane's distance from the segment's
// centroid, which lies on the segment's plane.
struct PlaneError {
    double degrees = 0;
    double mm = 0;
    double rms_mm = 0;
    bool planar = false;
};

// The statistics are in the Segmenter's unit (unit_mm millimetres), whatever the depth image's sample unit.
PlaneError plane_error(const SegmentStats& table, const eval::SupportPlane& truth, double metres_per_unit) {
    PlaneError e;
    double cosine = 0;
    double height = truth.offset;
    for (std::size_t c = 0; c < 3; ++c) {
        cosine += table.plane_normal[c] * truth.normal[c];
        height += truth.normal[c] * table.centroid[c] * metres_per_unit;
    }
    e.degrees = std::acos(std::min(1.0, std::fabs(cosine))) * 180.0 / std::numbers::pi;
    e.mm = std::fabs(height) * 1000.0;
    e.rms_mm = table.plane_rms * metres_per_unit * 1000.0;
    e.planar = table.planar;
    return e;
}

// How one method did on one object, for the per-object table: its verdict and best IoU, and its unlabelled share when
// that is what hides it.
std::string object_verdict(const eval::TabletopObjectScore& o) {
    std::string v = o.whole ? std::string("whole") : o.in_parts ? printed("in %u parts", o.parts) : "not found";
    if (o.merged_with_table) v += ", merged with the table";
    v += printed(" (IoU %.2f", o.best_iou);
    const double unlabelled = o.pixels == 0 ? 0.0 : double(o.unlabelled) / double(o.pixels);
    if (unlabelled >= 0.2) v += printed(", %.0f%% unlabelled", 100.0 * unlabelled);
    return v + ")";
}

// A frame's objects, one row each (its truth id, size and where it lies in the image), with each method's verdict.
std::string object_table(const Frame& f, const std::vector<Method>& methods,
                         const std::vector<eval::TabletopScores>& scores) {
    const std::size_t w = std::size_t(f.depth.width);
    const std::size_t count = std::size_t(f.truth.objects) + 2;
    std::vector<double> sum_x(count, 0.0), sum_y(count, 0.0);
    for (std::size_t i = 0; i < f.truth.labels.size(); ++i) {
        const std::uint32_t id = f.truth.labels[i];
        if (id < 2 || id >= count) continue;
        const std::size_t row = i / w;  // the pixel's row: whole rows, on purpose
        sum_x[id] += double(i - row * w);
        sum_y[id] += double(row);
    }
    std::string out = "| object | pixels | centre (x, y) |";
    std::string rule = "|---:|---:|---|";
    for (const Method& m : methods) {
        out += " `" + m.name + "` |";
        rule += "---|";
    }
    out += "\n" + rule + "\n";
    for (std::size_t k = 0; k < f.truth.objects; ++k) {
        const eval::TabletopObjectScore& first = scores.front().objects[k];
        const double n = double(std::max<std::uint64_t>(first.pixels, 1));
        out += printed("| %u | %llu | (%.0f, %.0f) |", first.truth_id, static_cast<unsigned long long>(first.pixels),
                       sum_x[first.truth_id] / n, sum_y[first.truth_id] / n);
        for (const eval::TabletopScores& s : scores) {
            out += ' ';
            out += object_verdict(s.objects[k]);
            out += " |";
        }
        out += "\n";
    }
    return out + "\n";
}

// The q-quantile (nearest rank) of v; NaN when v is empty.
double quantile(std::vector<double> v, double q) {
    if (v.empty()) return std::numeric_limits<double>::quiet_NaN();
    std::sort(v.begin(), v.end());
    return v[std::min(v.size() - 1, std::size_t(q * double(v.size())))];
}

std::string scene_scores_row(const std::string& first, const SyntheticSceneScores& s) {
    const std::size_t flagged = s.planar_faces_flagged + s.cylinder_sides_flagged;
    return "| " + first + " | " + std::to_string(s.floor_largest) + " of " + std::to_string(s.frames) + " | " +
           std::to_string(s.box_iou.size()) + " | " +
           printed("%.2f (%.2f)", quantile(s.box_iou, 0.5), quantile(s.box_iou, 0.25)) + " | " +
           std::to_string(s.plane_degrees.size()) + ": " +
           printed("%.2f / %.2f", quantile(s.plane_degrees, 0.5), quantile(s.plane_degrees, 0.95)) + " | " +
           printed("%.1f / %.1f", quantile(s.plane_mm, 0.5), quantile(s.plane_mm, 0.95)) + " | " +
           (flagged == 0 ? std::string("-") : printed("%.2f", double(s.planar_faces_flagged) / double(flagged))) +
           " (" + std::to_string(s.planar_faces_flagged) + " of " + std::to_string(flagged) + ") | " +
           (s.planar_faces == 0 ? std::string("-")
                                : printed("%.2f", double(s.planar_faces_flagged) / double(s.planar_faces))) +
           " (" + std::to_string(s.planar_faces_flagged) + " of " + std::to_string(s.planar_faces) + ") |\n";
}

// One row of the scenes' table: the scene summary (docs/algorithm.md section 10c) of pyrseg's segments against the
// truth: its supports, whether the table's segment is one, the objects resting on it, and how much of each truth
// object its segment's box holds.
std::string scene_row(const Frame& f, const Method& method, const Result& statistics,
                      const eval::TabletopScores& scores, double metres_per_unit, std::vector<double>& inside_all,
                      std::vector<double>& inside_whole, Scene& scene) {
    describe_scene(statistics.segments, method.params, SceneParams{}, scene);
    int table_support = -1;
    for (std::size_t j = 0; j < scene.supports.size(); ++j) {
        if (scene.supports[j].label == scores.table_label) table_support = int(j);
    }
    // The frame's points in the statistics' unit (the Segmenter's unit_mm; depth_to_cloud gives millimetres).
    std::vector<float> points = io::depth_to_cloud(f.depth, f.camera, metres_per_unit).points;
    for (float& c : points) c = float(double(c) / method.params.unit_mm);
    fit_object_boxes(points, statistics.labels, statistics.fillable_mask, scene);
    std::size_t on_table = 0;
    std::vector<eval::OrientedBox> boxes;
    for (const SceneObject& o : scene.objects) {
        if (table_support >= 0 && o.support == table_support) ++on_table;
        boxes.push_back({o.label, o.box_centre, o.axes, o.extents});
    }
    const std::vector<eval::ObjectBoxScore> held =
        eval::score_boxes(f.truth.labels, f.truth.objects, statistics.labels, points, boxes);
    std::string shares;
    std::size_t ninety = 0;
    for (std::size_t k = 0; k < held.size(); ++k) {
        const eval::ObjectBoxScore& b = held[k];
        shares += (shares.empty() ? "" : ", ") + printed("%.0f%%", 100.0 * b.inside);
        if (scores.objects[k].whole) shares += " (whole)";
        if (b.inside >= 0.9) ++ninety;
        inside_all.push_back(b.inside);
        if (scores.objects[k].whole) inside_whole.push_back(b.inside);
    }
    return "| " + f.name + " | `" + method.name + "` | " + std::to_string(scene.supports.size()) + " | " +
           (table_support >= 0 ? "yes" : "no") + " | " + std::to_string(on_table) + " | " + std::to_string(ninety) +
           " of " + std::to_string(held.size()) + " | " + shares + " |\n";
}

// Every method on every frame: a table per frame into per_frame, a picture per frame into out_dir, the table plane's
// errors of pyrseg's methods into planes; the totals.
std::vector<Totals> evaluate_frames(const std::vector<Frame>& frames, const std::vector<Method>& methods,
                                    double metres_per_unit, const fs::path& out_dir, std::ostringstream& per_frame,
                                    std::ostringstream& planes, std::ostringstream& scenes,
                                    std::vector<SyntheticSceneScores>* synthetic_scenes = nullptr) {
    std::vector<PlaneError> worst(methods.size());
    std::vector<bool> measured(methods.size(), false);
    planes << "## The table's plane\n\nThe plane of the segment that holds most of the table (its statistics) against "
              "the ground truth's support plane: the angle between the normals, and the truth plane's distance from "
              "the segment's centroid.\n\n| frame | method | angle (degrees) | distance (mm) | RMS to its plane (mm) | "
              "planar |\n|---|---|---:|---:|---:|---|\n";
    scenes
        << "## Scenes\n\nThe scene summary of each frame (supports and the objects standing over them, from the "
           "segment statistics: docs/algorithm.md section 10c): how many supports, whether the table's segment is "
           "one, how many objects stand over it, and for each truth object the share of its points inside the box of "
           "the segment holding most of it (0% where that segment is no object).\n\n| frame | method | supports | "
           "table a support | objects on the table | boxes holding >= 90% | each truth object's share |\n"
           "|---|---|---:|---|---:|---:|---|\n";
    std::vector<double> inside_all, inside_whole;
    std::vector<Totals> totals(methods.size());
    for (const Frame& f : frames) {
        const int w = f.depth.width;
        const int h = f.depth.height;
        std::printf("%s: %d x %d, %u objects in the ground truth%s\n", f.name.c_str(), w, h, f.truth.objects,
                    f.truth.found_plane ? "" : " (no support plane found)");
        per_frame << "### " << f.name << "\n\n" << printed(kTableHead, "method");
        std::vector<Panel> panels;
        std::vector<eval::TabletopScores> frame_scores;
        bool scene_written = false;  // scene_NAME.png: the first of pyrseg's methods
        if (!f.color.rgb.empty()) panels.push_back({"colour", f.color});
        panels.push_back({"ground truth", truth_picture(f.truth, w, h)});
        for (std::size_t m = 0; m < methods.size(); ++m) {
            std::vector<std::uint32_t> labels;
            Result statistics;
            Scene scene;
            double ms = 0;
            if (methods[m].lccp) {
                const io::PointCloud cloud = io::depth_to_cloud(f.depth, f.camera, metres_per_unit);
                const auto start = std::chrono::steady_clock::now();
                labels =
                    lccp_segment(cloud, f.color.rgb.empty() ? nullptr : f.color.rgb.data(), *methods[m].lccp).labels;
                ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
            } else if (methods[m].pcl) {
                const io::PointCloud cloud = io::depth_to_cloud(f.depth, f.camera, metres_per_unit);
                const auto start = std::chrono::steady_clock::now();
                labels = pcl_segment(cloud, 1.0, methods[m].pcl).labels;
                ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
            } else {
                Segmenter segmenter(w, h, methods[m].params, "cpu");
                DepthView view = io::depth_view(f.depth, f.camera, metres_per_unit);
                if (methods[m].color && !f.color.rgb.empty()) view.color = f.color.rgb.data();
                Result result = segmenter.segment(view);
                std::vector<double> times;
                for (int run = 0; run < 5; ++run) {
                    const auto start = std::chrono::steady_clock::now();
                    result = segmenter.segment(view);
                    times.push_back(
                        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
                }
                labels = std::move(result.labels);
                ms = median_ms(times);
                Outputs stats;
                stats.segment_stats = true;
                stats.fillable_mask = true;
                Segmenter with_stats(w, h, methods[m].params, "cpu", stats);
                statistics = with_stats.segment(view);
            }
            const eval::TabletopScores s = eval::score_tabletop(f.truth.labels, labels);
            frame_scores.push_back(s);
            if (!statistics.segments.empty() && s.table_label != 0 && f.truth.found_plane && f.plane_known) {
                const PlaneError e = plane_error(statistics.segments[s.table_label - 1], f.truth.plane,
                                                 methods[m].params.unit_mm / 1000.0);
                planes << "| " << f.name << " | `" << methods[m].name << "` | " << printed("%.2f", e.degrees) << " | "
                       << printed("%.1f", e.mm) << " | " << printed("%.1f", e.rms_mm) << " | "
                       << (e.planar ? "yes" : "no") << " |\n";
                worst[m].degrees = std::max(worst[m].degrees, e.degrees);
                worst[m].mm = std::max(worst[m].mm, e.mm);
                measured[m] = true;
            }
            if (f.generated && synthetic_scenes != nullptr && !statistics.segments.empty()) {
                const std::vector<float> mm = io::depth_to_cloud(f.depth, f.camera, metres_per_unit).points;
                std::vector<float> units = mm;
                for (float& c : units) c = float(double(c) / methods[m].params.unit_mm);
                describe_scene(statistics.segments, methods[m].params, SceneParams{}, scene);
                fit_object_boxes(units, statistics.labels, statistics.fillable_mask, scene);
                score_synthetic_scene(*f.generated, mm, statistics, scene, methods[m].params.unit_mm,
                                      (*synthetic_scenes)[m]);
            }
            if (!statistics.segments.empty() && f.truth.found_plane && f.plane_known) {
                scenes << scene_row(f, methods[m], statistics, s, metres_per_unit, inside_all, inside_whole, scene);
            }
            Totals one;
            one.add(s, ms);
            totals[m].add(s, ms);
            per_frame << row("`" + methods[m].name + "`", one);
            panels.push_back({methods[m].name, colorize(labels, w, h)});
            if (!scene.supports.empty()) {
                const PinholeCamera camera{f.camera.fx, f.camera.fy, f.camera.cx, f.camera.cy};
                panels.push_back({methods[m].name + " scene",
                                  scene_picture(f.color.rgb.empty() ? panels.back().image : f.color, scene, camera)});
                if (f.picture && !scene_written && !f.color.rgb.empty()) {
                    // The scene alone, over the colour image in gray so that the boxes stand out.
                    write_png((out_dir / ("scene_" + f.name + ".png")).string(),
                              scene_picture(dimmed_gray(f.color), scene, camera));
                    scene_written = true;
                }
            }
        }
        per_frame << "\n";
        if (f.truth.objects > 0) per_frame << "Per object:\n\n" << object_table(f, methods, frame_scores);
        if (f.picture) {
            per_frame << "![" << f.name << "](tabletop_" << f.name << ".png)\n\n";
            write_png((out_dir / ("tabletop_" + f.name + ".png")).string(), side_by_side(panels));
        }
    }
    planes << "\nThe worst frame:";
    for (std::size_t m = 0; m < methods.size(); ++m) {
        if (measured[m]) {
            planes << " `" << methods[m].name << "` " << printed("%.2f", worst[m].degrees) << " degrees, "
                   << printed("%.1f", worst[m].mm) << " mm;";
        }
    }
    planes << "\n\n";
    const auto summary = [](std::vector<double> shares) {
        const auto ninety = std::count_if(shares.begin(), shares.end(), [](double v) { return v >= 0.9; });
        std::sort(shares.begin(), shares.end());
        return std::to_string(ninety) + " of " + std::to_string(shares.size()) + " boxes hold at least 90% of their " +
               "object's points, median " + printed("%.0f%%", 100.0 * shares[shares.size() / 2]);
    };
    if (!inside_all.empty()) scenes << "\nIn all: " << summary(inside_all);
    if (!inside_whole.empty()) scenes << "; of the objects found whole: " << summary(inside_whole);
    if (!inside_all.empty()) scenes << ".\n\n";
    return totals;
}

// A synthetic tabletop: objects apart on a plain floor (no bin), rendered through a sensor model, as a depth camera
// hands it over (whole millimetres); its truth is the generator's own (the floor is the table, each object of at
// least 300 pixels an object), so touching objects are not joined as in a truth made from the depth.
Frame synthetic_frame(synthetic::Sensor sensor, double distance_mm, std::uint64_t seed) {
    synthetic::SceneOptions o;
    o.seed = seed;
    o.object_count = 8;
    o.touching = false;
    o.bin = false;
    o.sensor = sensor;
    o.camera_distance_mm = distance_mm;
    const synthetic::Scene scene = synthetic::generate(o);
    Frame f;
    f.name = std::string(synthetic::sensor_name(sensor)) + "_" + std::to_string(int(distance_mm)) + "mm_seed" +
             std::to_string(seed);
    f.camera = Intrinsics{scene.fx, scene.fy, scene.cx, scene.cy};
    f.depth.width = scene.width;
    f.depth.height = scene.height;
    const std::size_t pixels = std::size_t(scene.width) * std::size_t(scene.height);
    f.depth.depth.resize(pixels);
    f.metres.resize(pixels);
    std::map<std::uint32_t, std::uint32_t> object_pixels;
    for (std::size_t i = 0; i < pixels; ++i) {
        const float z = scene.points[3 * i + 2];
        const float mm = std::isfinite(z) && z > 0 && z < 65535 ? std::nearbyint(z) : 0.0f;
        f.depth.depth[i] = mm;
        f.metres[i] = mm / 1000.0f;
        if (mm > 0 && scene.object_id[i] >= synthetic::kFirstObjectId) ++object_pixels[scene.object_id[i]];
    }
    std::map<std::uint32_t, std::uint32_t> truth_id;  // objects of at least 300 pixels, 2, 3, ... by id
    for (const auto& [id, count] : object_pixels) {
        if (count >= 300) truth_id.emplace(id, std::uint32_t(truth_id.size() + 2));
    }
    f.truth.labels.assign(pixels, eval::kTruthNone);
    for (std::size_t i = 0; i < pixels; ++i) {
        if (f.depth.depth[i] == 0) continue;
        const std::uint32_t id = scene.object_id[i];
        if (id == synthetic::kFloorId) f.truth.labels[i] = eval::kTruthTable;
        if (const auto it = truth_id.find(id); it != truth_id.end()) f.truth.labels[i] = it->second;
    }
    f.truth.objects = std::uint32_t(truth_id.size());
    f.truth.found_plane = true;
    f.plane_known = false;
    f.picture = seed == 1;
    f.generated = std::make_shared<const synthetic::Scene>(scene);
    return f;
}

int synthetic_tabletops(const Args& args, const std::vector<std::string>& argv) {
    const int seeds = args.integer("seeds").value_or(4);
    if (seeds < 1 || seeds > 1000) throw UsageError{"--seeds must be in 1..1000"};
    std::vector<SensorKind> sensors;
    std::stringstream list(args.value("sensors").value_or("kinect-v1,realsense-d435,azure-kinect"));
    for (std::string item; std::getline(list, item, ',');) {
        const std::optional<SensorKind> kind = sensor_kind_from_name(item);
        if (!kind) throw UsageError{"--sensors: no sensor model named '" + printable(item) + "'"};
        sensors.push_back(*kind);
    }
    if (sensors.empty()) throw UsageError{"--sensors is empty"};
    const fs::path out_dir = args.value("out-dir").value_or("pyrseg-eval-tabletop");
    fs::create_directories(out_dir);
    std::string command = "pyrseg eval";
    for (const std::string& a : argv) command += " " + a;
    std::ostringstream md, per_frame;
    md << "# pyrseg eval: synthetic tabletops\n\n`" << command << "`: 8 objects apart on a floor, seeds 1.." << seeds
       << " at 800 and 1200 mm per sensor model, 640 x 480 in whole millimetres, CPU backend, "
       << std::thread::hardware_concurrency() << " hardware threads. Ground truth: the generator's.\n\n## In sum\n\n"
       << printed(kTableHead, "sensor model: method");
    per_frame << "## Per frame\n\n";
    std::ostringstream scenes, matched;
    scenes << "## Scenes\n\nThe scene summary (docs/algorithm.md section 10c) against the generator's scene: the "
              "frames whose largest support is the floor; the 3D IoU of each box object's box with the generator's "
              "box (boxes found whole: one segment holding 80% of the box's pixels and lying 80% on it); the plane "
              "of each segment flagged planar that lies 80% on one flat part (a box face, the floor) against the "
              "part's plane (how many, the angle, and the part's plane's distance from the segment's centroid; for "
              "PCL's OrganizedMultiPlaneSegmentation its planes whose inliers lie 80% on one flat part); the `planar` "
              "flag on segments lying 80% "
              "on a box face (planar) against a cylinder's side (not planar).\n\n| sensor model: method | floor "
              "the largest support | boxes | box IoU median (25th percentile) | plane angle median / 95th "
              "(degrees) | plane offset median / 95th (mm) | planar precision | planar recall |\n"
              "|---|---:|---:|---:|---:|---:|---:|---:|\n";
    for (const SensorKind kind : sensors) {
        const std::string name = sensor_kind_name(kind);
        std::vector<Frame> frames;
        for (const double distance : {800.0, 1200.0}) {
            for (int seed = 1; seed <= seeds; ++seed) {
                frames.push_back(synthetic_frame(*synthetic::sensor_from_name(name), distance, std::uint64_t(seed)));
            }
        }
        std::vector<Method> methods;
        Params with = parse_params(args, kind);
        methods.push_back({name, with, std::nullopt, std::nullopt});
        Params without = with;
        without.merge = !with.merge;
        methods.push_back({name + (with.merge ? "+nomerge" : "+merge"), without, std::nullopt, std::nullopt});
        if (pcl_peer_missing().empty()) {
            methods.push_back({"PCL organized (" + name + " settings)", Params{}, kind, std::nullopt});
        }
        std::ostringstream no_planes;
        std::ostringstream no_scenes;
        std::vector<SyntheticSceneScores> scene_scores(methods.size());
        const std::vector<Totals> totals =
            evaluate_frames(frames, methods, 0.001, out_dir, per_frame, no_planes, no_scenes, &scene_scores);
        SyntheticSceneScores best_planes;
        if (pcl_peer_missing().empty()) {
            // PCL's OrganizedMultiPlaneSegmentation, its maximum curvature picked from a small grid by the median
            // plane angle over these frames (the smallest wins; the first of equals).
            SyntheticSceneScores best;
            std::string best_settings;
            for (const float curvature : {0.001f, 0.01f, 0.05f}) {
                SyntheticSceneScores peer;
                std::string settings;
                for (const Frame& f : frames) {
                    const io::PointCloud cloud = io::depth_to_cloud(f.depth, f.camera, 0.001);
                    const std::vector<peers::PclPlane> planes = pcl_planes(cloud, kind, curvature, &settings);
                    std::vector<PeerPlane> scored;
                    scored.reserve(planes.size());
                    for (const peers::PclPlane& plane : planes) scored.push_back({plane.normal, &plane.inliers});
                    score_peer_planes(*f.generated, cloud.points, scored, peer);
                }
                if (!peer.plane_degrees.empty() &&
                    (best.plane_degrees.empty() ||
                     quantile(peer.plane_degrees, 0.5) < quantile(best.plane_degrees, 0.5))) {
                    best = std::move(peer);
                    best_settings = settings;
                }
            }
            best_planes = best;
            if (!best.plane_degrees.empty()) {
                scenes << "| " << name << ": PCL OMPS (" << best_settings << ") | - | - | - | "
                       << best.plane_degrees.size() << ": "
                       << printed("%.2f / %.2f", quantile(best.plane_degrees, 0.5), quantile(best.plane_degrees, 0.95))
                       << " | " << printed("%.1f / %.1f", quantile(best.plane_mm, 0.5), quantile(best.plane_mm, 0.95))
                       << " | - | - |\n";
            }
        }
        for (std::size_t m = 0; m < methods.size(); ++m) {
            md << row(name + ": `" + methods[m].name + "`", totals[m]);
            if (scene_scores[m].frames > 0)
                scenes << scene_scores_row(name + ": `" + methods[m].name + "`", scene_scores[m]);
            if (scene_scores[m].frames > 0 && !best_planes.planes.empty()) {
                const MatchedPlanes both = match_planes(scene_scores[m], best_planes);
                matched << "| " << name << ": `" << methods[m].name << "` | " << both.a_degrees.size() << " | "
                        << printed("%.2f / %.2f", quantile(both.a_degrees, 0.5), quantile(both.a_degrees, 0.95))
                        << " | "
                        << printed("%.2f / %.2f", quantile(both.b_degrees, 0.5), quantile(both.b_degrees, 0.95))
                        << " | " << printed("%.1f / %.1f", quantile(both.a_mm, 0.5), quantile(both.a_mm, 0.95)) << " | "
                        << printed("%.1f / %.1f", quantile(both.b_mm, 0.5), quantile(both.b_mm, 0.95)) << " |\n";
            }
        }
    }
    md << "\n" << scenes.str() << "\n";
    if (!matched.str().empty()) {
        md << "The planes of the flat parts that both pyrseg (segments flagged planar) and PCL's "
              "OrganizedMultiPlaneSegmentation found in the same frame, so that both are scored on the same planes:\n\n"
              "| sensor model: method | flat parts | pyrseg angle median / 95th (degrees) | OMPS angle median / 95th "
              "(degrees) | pyrseg offset median / 95th (mm) | OMPS offset median / 95th (mm) |\n"
              "|---|---:|---:|---:|---:|---:|\n"
           << matched.str() << "\n";
    }
    md << per_frame.str();
    const fs::path report = out_dir / "tabletop_synthetic.md";
    write_text_file(report, md.str());
    std::fputs(md.str().substr(0, md.str().find("## Per frame")).c_str(), stdout);
    std::printf("wrote %s\n", report.string().c_str());
    return 0;
}

}  // namespace

int cmd_eval_tabletop(const std::vector<std::string>& argv) {
    std::set<std::string> values = kParameterValueOptions;
    values.insert({"tabletop", "presets", "pcl-sensor", "lccp", "calib", "depth-scale", "out-dir", "sensors", "seeds"});
    std::set<std::string> flags = kParameterFlagOptions;
    flags.insert({"help", "tabletop-synthetic"});
    const Args args(argv, values, flags);
    if (args.flag("help")) {
        std::fputs(kTabletopUsage, stdout);
        return 0;
    }
    if (args.flag("tabletop-synthetic")) {
        if (args.value("tabletop")) throw UsageError{"--tabletop and --tabletop-synthetic: one or the other"};
        return synthetic_tabletops(args, argv);
    }
    if (!args.positional().empty()) throw UsageError{"--tabletop takes no positional arguments"};
    const fs::path dir = args.value("tabletop").value_or("");
    if (dir.empty() || !fs::is_directory(dir)) {
        throw UsageError{"--tabletop expects a folder of NAME_depth.png frames, got '" + printable(dir.string()) + "'"};
    }
    const double metres_per_unit = args.number("depth-scale").value_or(0.001);
    if (!(metres_per_unit > 0) || metres_per_unit > 1) throw UsageError{"--depth-scale must be in (0, 1] metres"};
    const std::vector<fs::path> depths = depth_files(dir);
    const fs::path calib = args.value("calib").value_or((dir / "camera.yml").string());
    if (!args.value("calib") && !fs::exists(calib)) {
        throw UsageError{"--tabletop: no camera.yml in " + printable(dir.string()) +
                         "; give the camera with --calib FILE (fx, fy, cx, cy)"};
    }
    const Intrinsics k = io::read_intrinsics(calib);
    std::vector<Method> methods = parse_methods(args);
    const std::string pcl_sensor = args.value("pcl-sensor").value_or("realsense-d435");
    if (pcl_sensor != "none") {
        const std::optional<SensorKind> kind = sensor_kind_from_name(pcl_sensor);
        if (!kind) throw UsageError{"--pcl-sensor: no sensor model named '" + printable(pcl_sensor) + "'"};
        if (const std::string missing = pcl_peer_missing(); missing.empty()) {
            methods.push_back({"PCL organized (" + pcl_sensor + " settings)", Params{}, kind, std::nullopt});
        } else {
            std::fprintf(stderr, "pyrseg eval: PCL left out: %s\n", missing.c_str());
        }
    }
    const std::string lccp = args.value("lccp").value_or("grid");
    if (lccp != "grid" && lccp != "none")
        throw UsageError{"--lccp must be grid or none, got '" + printable(lccp) + "'"};
    const fs::path out_dir = args.value("out-dir").value_or("pyrseg-eval-tabletop");
    fs::create_directories(out_dir);

    const std::vector<Frame> frames = read_frames(depths, metres_per_unit, k);
    if (lccp == "grid") {
        if (const std::string missing = pcl_peer_missing(); missing.empty()) {
            const peers::LccpSettings chosen = tune_lccp(frames, metres_per_unit);
            methods.push_back(
                {"PCL supervoxels + LCCP (tuned: " + peers::describe(chosen) + ")", Params{}, std::nullopt, chosen});
        } else {
            std::fprintf(stderr, "pyrseg eval: LCCP left out: %s\n", missing.c_str());
        }
    }
    std::ostringstream per_frame;
    per_frame << "## Per frame\n\n";
    std::ostringstream planes;
    std::ostringstream scenes;
    const std::vector<Totals> totals =
        evaluate_frames(frames, methods, metres_per_unit, out_dir, per_frame, planes, scenes);

    std::string command = "pyrseg eval";
    for (const std::string& a : argv) command += " " + a;
    std::ostringstream md;
    md << "# pyrseg eval: real tabletop frames\n\n`" << command << "`: " << frames.size() << " frame"
       << (frames.size() == 1 ? "" : "s") << " from " << dir.string() << ", CPU backend, "
       << std::thread::hardware_concurrency() << " hardware threads. Ground truth made from the depth "
       << "(`pyrseg eval --tabletop --help`).\n\n## In sum\n\n"
       << printed(kTableHead, "method");
    for (std::size_t m = 0; m < methods.size(); ++m) md << row("`" + methods[m].name + "`", totals[m]);
    md << "\n" << planes.str() << scenes.str() << per_frame.str();
    const fs::path report = out_dir / "tabletop.md";
    write_text_file(report, md.str());
    std::fputs(md.str().substr(0, md.str().find("## Per frame")).c_str(), stdout);
    std::printf("wrote %s and %zu pictures\n", report.string().c_str(), frames.size());
    return 0;
}

}  // namespace pyrseg::cli
