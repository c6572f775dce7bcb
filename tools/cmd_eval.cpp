// pyrseg eval: segmentation quality against ground truth on seeded synthetic scenes (docs/quality.md). The pyramid
// against plain connected components on the same fillable mask, and against PCL's organized segmentation, across
// depth sensor models x camera distances x widths of added bridges (or, the earlier sweep, noise levels x widths).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <optional>
#include <set>
#include <span>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "pyrseg/error.hpp"
#include "pyrseg/presets.hpp"
#include "pyrseg/segmenter.hpp"
#include "pyrseg/synthetic.hpp"
#include "tools/commands.hpp"
#include "tools/eval/bridges.hpp"
#include "tools/eval/metrics.hpp"
#include "tools/eval/summary.hpp"
#include "tools/eval_sensors.hpp"
#include "tools/figures.hpp"
#include "tools/output_files.hpp"
#include "tools/plot.hpp"
#ifdef PYRSEG_HAVE_PCL_PEER
#include "peers/pcl_segmentation.hpp"
#endif

namespace pyrseg::cli {
namespace {

namespace fs = std::filesystem;
using eval::Cell;
using eval::rate;

constexpr const char* kEvalUsage =
    "Usage: pyrseg eval [--sensors NAME,...] [--distances MM,...] [--params preset|default] [--sizes WxH,...]\n"
    "                   [--seeds N] [--bridges W,...] [--noise MM] [--tune-seeds N] [--out-dir DIR] [--quick]\n"
    "       pyrseg eval --noise MM,... [--sizes WxH,...] [--seeds N] [--bridges W,...] [--out-dir DIR] [--quick]\n"
    "       pyrseg eval --tabletop DIR [--presets NAME,...] [--out-dir DIR]   (real RGB-D frames: --tabletop --help)\n"
    "       pyrseg eval --tabletop-synthetic [--sensors NAME,...] [--seeds N] [--out-dir DIR]  (the same on synthetic\n"
    "                   tabletops through the sensor models)\n"
    "       pyrseg eval --tracks [--sensors NAME,...] [--frames N] [--seeds N] [--out-dir DIR]  (track ids over\n"
    "                   synthetic sequences from a moving camera: --tracks --help)\n"
    "\n"
    "Measures segmentation quality against ground truth on seeded synthetic bin-picking scenes (boxes, cylinders\n"
    "and spheres touching each other in a bin; seeds 1..N), comparing three labellings:\n"
    "  pyramid   pyrseg's pyramid (CPU backend) through Segmenter::segment_mask on pyrseg's fillable mask\n"
    "  CC        plain 4-connected components of the SAME mask, with the same edge labelling (contract step 6c)\n"
    "  PCL       at bridge width 0 only (it makes its own edges from the cloud, so bridges cannot be added to its\n"
    "            input): PCL's organized segmentation of the same cloud, OrganizedConnectedComponentSegmentation\n"
    "            with EdgeAwarePlaneComparator on integral-image normals (when pyrseg is built with PCL)\n"
    "The mask is the one pyrseg computes from the scene's points (normals estimated). Bridge width 0 evaluates it\n"
    "as it is (the pyramid's labels are then exactly `pyrseg segment`'s); a width W >= 1 first adds one bridge per\n"
    "pair of neighbouring ground-truth objects: a W-pixel-wide strip of fillable pixels across the edge band\n"
    "between the closest pixels of the two objects' main fillable bodies (at most 10 px apart).\n"
    "\n"
    "The sensor sweep (the default): sensor models x camera distances x bridge widths. The sensor models are the\n"
    "synthetic generator's (docs/sensors.md): structured-light (PhoXi-like; its depth noise is --noise),\n"
    "kinect-v1 (structured light, disparity steps), realsense-d435 (active stereo), azure-kinect (time of\n"
    "flight). The camera distance is from the camera to the floor point it looks at; only the camera moves.\n"
    "  pyrseg's parameters: with --params preset (the default) the preset pyrseg recommends for that kind of sensor\n"
    "            (sensor_preset, as `pyrseg segment --sensor NAME` uses it); with --params default the defaults\n"
    "            (Params{}) on every model, which shows what the presets are for. The parameter options of\n"
    "            `pyrseg segment` (--ct, --dt, --metric, --normal-window, --edge-rounds, ...) override either, which\n"
    "            is how the presets were tuned (docs/quality.md).\n"
    "  PCL's settings are tuned per sensor model as a PCL user would tune them: a grid search over integral-image\n"
    "            normal smoothing 10,20,30,45 x max depth change 0.02,0.05,0.1 x comparator angle 0.08,0.15,0.25,\n"
    "            0.4 rad x distance 10,20,40,80 mm (192 settings; covariance normals, regions of >= 100 points),\n"
    "            scored by the mean ARI on TUNING seeds disjoint from the evaluation seeds (--tune-seeds, seeds\n"
    "            from 1001) at the middle camera distance; the best setting is then evaluated on seeds 1..N at\n"
    "            every distance.\n"
    "            The report lists the setting chosen per model next to PCL's defaults' tuning score.\n"
    "The report has one table per sensor model (distance x bridge width), and a summary per model pooled over\n"
    "the distances with its acceptance checks: pyramid ARI >= PCL ARI (width 0); pyramid merged <= 1/5 of CC\n"
    "merged at bridge widths 1 and 2, counting all merges and counting separable ones; pyramid labels >= 90%\n"
    "of the ground-truth pixels (width 0).\n"
    "\n"
    "The noise sweep (the earlier one; when --noise is given without --sensors and --distances): the\n"
    "structured-light model at 1200 mm, noise levels x bridge widths, pyrseg's defaults, PCL's default settings.\n"
    "\n"
    "Metrics, over the pixels with ground truth; an object is a ground-truth id (floor, bin bottom, each wall,\n"
    "each object) with at least 100 pixels, and a segment claims an object when it holds more than half of its\n"
    "pixels:\n"
    "  merged    objects whose claiming segment also claims another object (under-segmentation; lower is better)\n"
    "  separable merged, counting only the other objects it is not flush with: upright boxes whose tops lie in\n"
    "            one plane and touch along a side (identical parts packed side by side) meet with no depth step\n"
    "            and no crease, so no segmentation from depth alone can separate them\n"
    "  split     objects whose largest segment holds less than 80% of their labelled pixels, or that have none\n"
    "            labelled (over-segmentation; lower is better)\n"
    "  ARI       adjusted Rand index of ground truth vs segments, each unlabelled pixel a singleton (1 is perfect)\n"
    "  labelled  the share of ground-truth pixels given a segment\n"
    "  segments  distinct segments on ground-truth pixels, mean per frame\n"
    "\n"
    "  --sensors NAME,...  sensor models: structured-light, kinect-v1, realsense-d435, azure-kinect (default: all)\n"
    "  --distances MM,...  camera distances, 300..6000 mm (default 800,1200,2000)\n"
    "  --params P          preset (default): pyrseg's preset per sensor model; default: Params{} for every model\n"
    "  --sizes WxH,...     scene sizes (default 640x480)\n"
    "  --seeds N           scenes per cell, seeds 1..N (default 10; 20 in the noise sweep)\n"
    "  --noise MM[,...]    depth noise sigma along the viewing ray, mm. Sensor sweep: one value, the\n"
    "                      structured-light model's (default 0.1, PhoXi-like). Alone: the noise sweep over the\n"
    "                      levels given (its default levels were 0,0.1,0.5,1,2)\n"
    "  --bridges W,...     bridge widths in pixels, 0 = the mask as it is (default 0,1,2,3,4,6,8)\n"
    "  --tune-seeds N      scenes per PCL setting in the tuning (default 4; seeds from max(1000, N) + 1)\n"
    "  --out-dir DIR       where quality.md and the plots go (default pyrseg-eval)\n"
    "  --quick             a seconds-long smoke run: 320x240, 2 seeds, sensors structured-light,kinect-v1,\n"
    "                      distance 1200, bridges 0,1,2, PCL tuned on 1 seed over 4 settings (noise sweep: noise\n"
    "                      0,0.5, bridges 0,1,2,4); the other options override it\n"
    "Writes DIR/quality.md (the tables) and the plots: sensor sweep DIR/{merge_rate,split_rate,ari}_SENSOR_WxH.png\n"
    "(one panel per distance, one line per method) and DIR/ari_summary_WxH.png (ARI at width 0 against the\n"
    "distance, one panel per sensor model); noise sweep DIR/{merge_rate,split_rate,ari}_WxH.png (one panel per\n"
    "noise level).\n";

struct Size {
    int width = 0, height = 0;
};

std::vector<Size> parse_sizes(const std::string& text) {
    std::vector<Size> sizes;
    for (const std::string& item : split_list(text)) {
        Size s;
        char tail = 0;
        if (std::sscanf(item.c_str(), "%dx%d%c", &s.width, &s.height, &tail) != 2 || s.width < 16 || s.height < 16 ||
            s.width > synthetic::kMaxImageSide || s.height > synthetic::kMaxImageSide) {
            throw UsageError{"--sizes expects WxH[,WxH...] with sides 16.." + std::to_string(synthetic::kMaxImageSide) +
                             ", got '" + text + "'"};
        }
        sizes.push_back(s);
    }
    if (sizes.empty()) throw UsageError{"--sizes is empty"};
    return sizes;
}

std::vector<double> parse_numbers(const std::string& name, const std::string& text, bool integers) {
    std::vector<double> values;
    for (const std::string& item : split_list(text)) {
        char* end = nullptr;
        const double v = std::strtod(item.c_str(), &end);
        if (item.empty() || end != item.c_str() + item.size() || !std::isfinite(v) || v < 0 ||
            (integers && (v != std::floor(v) || v > 64))) {
            std::string message = "--" + name + " expects a comma-separated list of ";
            message += integers ? "integers 0..64" : "numbers >= 0";
            message += ", got '" + text + "'";
            throw UsageError{message};
        }
        values.push_back(v);
    }
    if (values.empty()) throw UsageError{"--" + name + " is empty"};
    std::sort(values.begin(), values.end());
    values.erase(std::unique(values.begin(), values.end()), values.end());
    return values;
}

std::string format(const char* fmt, double v) {
    char buf[64];
    std::snprintf(buf, sizeof buf, fmt, v);
    return buf;
}

std::string count_and_rate(std::uint64_t n, std::uint64_t of) {
    if (of == 0) return std::to_string(n) + " (n/a)";
    return std::to_string(n) + " (" + format("%.1f%%", 100.0 * rate(n, of)) + ")";
}

std::string percent(double share) {
    return std::isnan(share) ? "n/a" : format("%.1f%%", 100.0 * share);
}

std::string fixed3(double v) {
    return std::isnan(v) ? "n/a" : format("%.3f", v);
}

std::string size_name(const Size& s) {
    return std::to_string(s.width) + "x" + std::to_string(s.height);
}

std::string describe_params(const Params& p) {
    char text[256];
    if (p.metric == Metric::paper) {
        std::snprintf(text, sizeof text, "paper metric, ct %g rad, dt %g mm, normal radius %d", p.ct, p.dt,
                      p.normal_radius);
    } else {
        std::snprintf(text, sizeof text,
                      "robust metric, ct %g rad (1 - cos grows %g per m^2), dt %g mm + %g mm per m^2, normal radius "
                      "%d, window %d, curvature stride %d",
                      p.ct, p.ct_growth_per_m2, p.dt, p.dt_per_m2, p.normal_radius, p.normal_window,
                      p.curvature_stride);
    }
    return text;
}

// Pixels the contract calls valid: point-valid and a non-zero finite normal (the normals the metric used).
std::vector<std::uint8_t> valid_pixels(const synthetic::Scene& scene, const std::vector<float>& normals) {
    const std::size_t n = scene.object_id.size();
    std::vector<std::uint8_t> valid(n, 0);
    for (std::size_t i = 0; i < n; ++i) {
        const float* p = &scene.points[3 * i];
        const float* q = &normals[3 * i];
        const bool point = std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]) && p[2] > 0;
        const bool normal =
            std::isfinite(q[0]) && std::isfinite(q[1]) && std::isfinite(q[2]) && (q[0] != 0 || q[1] != 0 || q[2] != 0);
        valid[i] = point && normal ? 1 : 0;
    }
    return valid;
}

// PCL's organized segmentation of the scene's cloud, when pyrseg is built with it; null otherwise.
struct PclPeer {
#ifdef PYRSEG_HAVE_PCL_PEER
    peers::PclOrganizedSegmentation segmentation;
    std::vector<std::uint32_t> labels;
    const std::vector<std::uint32_t>* run(const synthetic::Scene& scene) {
        segmentation.set_cloud(scene.points.data(), nullptr, scene.width, scene.height);
        segmentation.run(&labels);
        return &labels;
    }
#else
    const std::vector<std::uint32_t>* run(const synthetic::Scene& /*scene*/) {
        return nullptr;
    }
#endif
};

// One scene, evaluated at every bridge width; cells[b] is the cell of bridges[b].
void evaluate_scene(const synthetic::SceneOptions& options, const std::vector<double>& bridges, Segmenter& segmenter,
                    PclPeer& pcl, std::span<Cell> cells) {
    const synthetic::Scene scene = synthetic::generate(options);
    const std::vector<std::array<std::uint32_t, 2>> flush = synthetic::flush_pairs(scene);
    CloudView view;
    view.points = scene.points.data();
    view.width = scene.width;
    view.height = scene.height;
    Result from_cloud;
    segmenter.segment(view, from_cloud);
    const std::vector<std::uint8_t> valid = valid_pixels(scene, from_cloud.normals);
    const std::vector<eval::BridgeSite> sites =
        eval::find_bridge_sites(scene.object_id, from_cloud.fillable_mask, scene.width, scene.height);
    Result pyramid;
    // Bridges are drawn into the mask, and a mask frame has no points for the merge or the edge rounds' depth test:
    // with either on, the bridged masks are labelled without them (the bridges' test is the pyramid's, which the
    // merge only follows, and the bridges are fillable, so the rounds do not cross them), and bridge width 0 takes
    // the cloud's own labels, both included.
    const bool merge = segmenter.params().merge || uses_edge_depth_step(segmenter.params());
    std::optional<Segmenter> unmerged;
    if (merge) {
        Params p = segmenter.params();
        p.merge = false;
        p.edge_max_depth_step = 0.0;
        unmerged.emplace(scene.width, scene.height, p, "cpu");
    }
    for (std::size_t b = 0; b < bridges.size(); ++b) {
        const int width = int(bridges[b]);
        std::vector<std::uint8_t> mask = from_cloud.fillable_mask;
        std::vector<std::uint8_t> mask_valid = valid;
        if (width > 0) eval::draw_bridges(sites, width, scene.object_id, scene.width, scene.height, mask, mask_valid);
        MaskView mask_view;
        mask_view.fillable = mask.data();
        mask_view.valid = mask_valid.data();
        mask_view.width = scene.width;
        mask_view.height = scene.height;
        if (merge) {
            if (width == 0) {
                pyramid.labels = from_cloud.labels;
            } else {
                unmerged->segment_mask(mask_view, pyramid);
            }
        } else {
            segmenter.segment_mask(mask_view, pyramid);
        }
        if (!merge && width == 0 && pyramid.labels != from_cloud.labels) {
            throw Error(ErrorCode::internal,
                        "eval: the pyramid on the cloud's own mask differs from segmenting the "
                        "cloud (seed " +
                            std::to_string(options.seed) + ")");
        }
        std::vector<std::uint32_t> cc = eval::connected_components(mask, scene.width, scene.height);
        eval::label_edges(cc, mask, mask_valid, scene.width, scene.height);
        const eval::Scores ps =
            eval::score(scene.object_id, pyramid.labels, eval::kMinObjectPixels, eval::kSplitShare, flush);
        const eval::Scores cs = eval::score(scene.object_id, cc, eval::kMinObjectPixels, eval::kSplitShare, flush);
        Cell& cell = cells[b];
        cell.objects += ps.objects;
        if (width > 0) cell.sites += sites.size();
        cell.pyramid.add(ps);
        cell.cc.add(cs);
        if (width != 0) continue;
        if (const std::vector<std::uint32_t>* labels = pcl.run(scene))
            cell.pcl.add(eval::score(scene.object_id, *labels, eval::kMinObjectPixels, eval::kSplitShare, flush));
    }
}

enum class Sweep { noise, sensors };

std::string table(const std::vector<Cell>& cells, Sweep sweep) {
    // PCL's columns only when it was scored (pyrseg built with it).
    const bool with_pcl = std::any_of(cells.begin(), cells.end(), [](const Cell& c) { return c.pcl.frames > 0; });
    std::ostringstream out;
    out << (sweep == Sweep::noise ? "| noise (mm) |" : "| distance (mm) |")
        << " bridge (px) | bridges | objects | merged: pyramid | merged: CC | split: pyramid | "
           "split: CC | ARI: pyramid | ARI: CC | labelled: pyramid | labelled: CC | segments: pyramid | "
           "segments: CC |";
    out << (with_pcl ? " merged: PCL | split: PCL | ARI: PCL | segments: PCL |\n" : "\n");
    out << "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|" << (with_pcl ? "---|---|---|---|\n" : "\n");
    for (const Cell& c : cells) {
        const double frames = std::max(1, c.pyramid.frames);
        out << "| " << format("%g", sweep == Sweep::noise ? c.noise_mm : c.distance_mm) << " | " << c.bridge << " | "
            << c.sites << " | " << c.objects << " | " << count_and_rate(c.pyramid.merged, c.objects) << " | "
            << count_and_rate(c.cc.merged, c.objects) << " | " << count_and_rate(c.pyramid.split, c.objects) << " | "
            << count_and_rate(c.cc.split, c.objects) << " | " << format("%.3f", c.pyramid.ari_sum / frames) << " | "
            << format("%.3f", c.cc.ari_sum / frames) << " | "
            << format("%.1f%%", 100.0 * rate(c.pyramid.labelled, c.pyramid.pixels)) << " | "
            << format("%.1f%%", 100.0 * rate(c.cc.labelled, c.cc.pixels)) << " | "
            << format("%.1f", double(c.pyramid.segments) / frames) << " | "
            << format("%.1f", double(c.cc.segments) / frames) << " |";
        if (!with_pcl) {
            out << "\n";
        } else if (c.pcl.frames == 0) {
            out << " — | — | — | — |\n";
        } else {
            out << " " << count_and_rate(c.pcl.merged, c.objects) << " | " << count_and_rate(c.pcl.split, c.objects)
                << " | " << format("%.3f", c.pcl.ari()) << " | "
                << format("%.1f", double(c.pcl.segments) / c.pcl.frames) << " |\n";
        }
    }
    return out.str();
}

enum class Plotted { merged, split, ari };

const LineSeries kPyramidSeries{"pyramid", {230, 97, 1}, false, {}};
const LineSeries kCcSeries{"connected components", {33, 102, 172}, true, {}};
const LineSeries kPclSeries{"PCL (no bridges added)", {40, 160, 60}, false, {}};

// One panel per group (noise level or distance); cells are group-major, bridges.size() per group.
LineChart chart_of(const std::vector<Cell>& cells, const std::vector<std::string>& group_titles,
                   const std::vector<double>& bridges, Plotted what, const std::string& title) {
    LineChart chart;
    chart.title = title;
    chart.x_label = "bridge width (px)";
    chart.y_ticks = {0, 0.25, 0.5, 0.75, 1};
    chart.percent = what != Plotted::ari;
    chart.y_min = 0;
    chart.y_max = 1;
    for (std::size_t n = 0; n < group_titles.size(); ++n) {
        LinePanel panel;
        panel.title = group_titles[n];
        panel.x = bridges;
        LineSeries pyr = kPyramidSeries;
        LineSeries cc = kCcSeries;
        LineSeries pcl = kPclSeries;
        for (std::size_t b = 0; b < bridges.size(); ++b) {
            const Cell& c = cells[n * bridges.size() + b];
            const double frames = std::max(1, c.pyramid.frames);
            const double none = std::nan("");
            switch (what) {
                case Plotted::merged:
                    pyr.y.push_back(rate(c.pyramid.merged, c.objects));
                    cc.y.push_back(rate(c.cc.merged, c.objects));
                    pcl.y.push_back(c.pcl.frames > 0 ? rate(c.pcl.merged, c.objects) : none);
                    break;
                case Plotted::split:
                    pyr.y.push_back(rate(c.pyramid.split, c.objects));
                    cc.y.push_back(rate(c.cc.split, c.objects));
                    pcl.y.push_back(c.pcl.frames > 0 ? rate(c.pcl.split, c.objects) : none);
                    break;
                case Plotted::ari:
                    pyr.y.push_back(c.pyramid.ari_sum / frames);
                    cc.y.push_back(c.cc.ari_sum / frames);
                    pcl.y.push_back(c.pcl.frames > 0 ? c.pcl.ari() : none);
                    break;
            }
        }
        panel.series = {pyr, cc};
        if (std::any_of(pcl.y.begin(), pcl.y.end(), [](double v) { return !std::isnan(v); }))
            panel.series.push_back(pcl);
        chart.panels.push_back(panel);
    }
    return chart;
}

// Writes the three plots of one table (merge_rate, split_rate, ari) as DIR/<what>_<suffix>.png; returns the markdown
// that shows them.
std::string write_plots(const fs::path& out_dir, const std::vector<Cell>& cells,
                        const std::vector<std::string>& group_titles, const std::vector<double>& bridges,
                        const std::string& suffix, const std::string& subtitle) {
    const std::vector<std::pair<Plotted, std::string>> plots = {
        {Plotted::merged, "merge_rate"}, {Plotted::split, "split_rate"}, {Plotted::ari, "ari"}};
    const std::vector<std::string> titles = {"merged objects (%)" + subtitle, "split objects (%)" + subtitle,
                                             "adjusted rand index" + subtitle};
    std::string md;
    for (std::size_t p = 0; p < plots.size(); ++p) {
        const std::string file = plots[p].second + "_" + suffix + ".png";
        write_png((out_dir / file).string(),
                  render_line_chart(chart_of(cells, group_titles, bridges, plots[p].first, titles[p])));
        md += "![" + plots[p].second + "](" + file + ")\n\n";
    }
    return md;
}

double seconds_since(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

void print_cells(const std::vector<Cell>& row) {
    for (const Cell& c : row) {
        std::printf(
            "  bridge %d px: %llu objects, %llu bridges | merged: pyramid %.1f%%, CC %.1f%% | split: "
            "pyramid %.1f%%, CC %.1f%% | ARI: pyramid %.3f, CC %.3f",
            c.bridge, static_cast<unsigned long long>(c.objects), static_cast<unsigned long long>(c.sites),
            100 * rate(c.pyramid.merged, c.objects), 100 * rate(c.cc.merged, c.objects),
            100 * rate(c.pyramid.split, c.objects), 100 * rate(c.cc.split, c.objects),
            c.pyramid.ari_sum / std::max(1, c.pyramid.frames), c.cc.ari_sum / std::max(1, c.cc.frames));
        if (c.pcl.frames > 0) std::printf(", PCL %.3f", c.pcl.ari());
        std::printf("\n");
    }
    std::fflush(stdout);
}

constexpr const char* kMetricsHead =
    " pixels (floor, bin bottom, walls, objects), summed over the seeds. *merged*: objects whose claiming "
    "segment (the one holding more than half of the object) claims another object too. *split*: objects "
    "whose largest segment holds less than ";
constexpr const char* kMetricsTail =
    "% of their labelled pixels, or that have none labelled. *ARI*: adjusted Rand index on ground-truth "
    "pixels, each unlabelled pixel a singleton, mean over the seeds. *labelled*: share of ground-truth pixels "
    "with a segment. *segments*: distinct segments on ground-truth pixels, mean per frame. *bridges*: bridges "
    "drawn, summed over the seeds (one per pair of neighbouring objects; none at width 0).\n";

// ---- The noise sweep (the structured-light model at 1200 mm, noise levels x bridge widths) ----

void noise_sweep(const std::vector<Size>& sizes, int seeds, const std::vector<double>& noises,
                 const std::vector<double>& bridges, const Params& params, const fs::path& out_dir,
                 std::ostringstream& md) {
    for (const Size& size : sizes) {
        Outputs outputs;
        outputs.fillable_mask = true;
        outputs.normals = true;
        Segmenter segmenter(size.width, size.height, params, "cpu", outputs);
        PclPeer pcl;
        std::vector<Cell> cells;
        for (const double noise : noises) {
            std::vector<Cell> row(bridges.size());
            for (std::size_t b = 0; b < bridges.size(); ++b) {
                row[b].noise_mm = noise;
                row[b].bridge = int(bridges[b]);
            }
            const auto cell_start = std::chrono::steady_clock::now();
            for (int seed = 1; seed <= seeds; ++seed) {
                synthetic::SceneOptions options;
                options.width = size.width;
                options.height = size.height;
                options.seed = std::uint64_t(seed);
                options.noise_mm = noise;
                evaluate_scene(options, bridges, segmenter, pcl, row);
            }
            std::printf("%s, noise %g mm: %d scenes in %.1f s\n", size_name(size).c_str(), noise, seeds,
                        seconds_since(cell_start));
            print_cells(row);
            cells.insert(cells.end(), row.begin(), row.end());
        }
        const std::string name = size_name(size);
        std::vector<std::string> panels;
        panels.reserve(noises.size());
        for (const double noise : noises) panels.push_back("noise " + format("%g", noise) + " mm");
        const std::string seeds_text = std::to_string(seeds) + (seeds == 1 ? " seed" : " seeds");
        md << "\n## " << name << "\n\n" << table(cells, Sweep::noise) << "\n";
        md << write_plots(out_dir, cells, panels, bridges, name, " vs bridge width, " + name + (", " + seeds_text));
    }
}

// ---- The sensor sweep (sensor models x camera distances x bridge widths) ----

struct PclTuning {
    bool done = false;
    std::string chosen;  // the setting, described
    double chosen_ari = std::nan("");
    double default_ari = std::nan("");  // PCL's default settings on the same tuning scenes
    std::size_t settings = 0;
    double seconds = 0;
#ifdef PYRSEG_HAVE_PCL_PEER
    peers::PclSettings setting;
#endif
};

#ifdef PYRSEG_HAVE_PCL_PEER
// The settings a PCL user would try, normal settings outermost so that each is estimated once per scene.
std::vector<peers::PclSettings> pcl_grid(bool quick) {
    const std::vector<float> smoothing = quick ? std::vector<float>{10, 20} : std::vector<float>{10, 20, 30, 45};
    const std::vector<float> depth_change = quick ? std::vector<float>{0.02f} : std::vector<float>{0.02f, 0.05f, 0.1f};
    const std::vector<float> angle = quick ? std::vector<float>{0.25f} : std::vector<float>{0.08f, 0.15f, 0.25f, 0.4f};
    const std::vector<float> distance = quick ? std::vector<float>{10, 20} : std::vector<float>{10, 20, 40, 80};
    std::vector<peers::PclSettings> grid;
    for (const float s : smoothing) {
        for (const float d : depth_change) {
            for (const float a : angle) {
                for (const float m : distance) {
                    peers::PclSettings p;
                    p.normal_smoothing_size = s;
                    p.max_depth_change_factor = d;
                    p.angular_threshold_rad = a;
                    p.distance_threshold_mm = m;
                    grid.push_back(p);
                }
            }
        }
    }
    return grid;
}

bool same_normals(const peers::PclSettings& a, const peers::PclSettings& b) {
    return a.normal_method == b.normal_method && a.normal_smoothing_size == b.normal_smoothing_size &&
           a.max_depth_change_factor == b.max_depth_change_factor;
}
#endif

// Chooses PCL's settings for one sensor model: the grid setting with the best mean ARI over the tuning scenes
// (ties: the first in grid order). Without PCL, nothing.
PclTuning tune_pcl(const synthetic::SceneOptions& base, const std::vector<std::uint64_t>& tune_seeds, bool quick) {
    PclTuning tuning;
#ifdef PYRSEG_HAVE_PCL_PEER
    const auto start = std::chrono::steady_clock::now();
    const std::vector<peers::PclSettings> grid = pcl_grid(quick);
    std::vector<double> ari(grid.size(), 0.0);
    peers::PclOrganizedSegmentation pcl;
    std::vector<std::uint32_t> labels;
    for (const std::uint64_t seed : tune_seeds) {
        synthetic::SceneOptions options = base;
        options.seed = seed;
        const synthetic::Scene scene = synthetic::generate(options);
        pcl.set_cloud(scene.points.data(), nullptr, scene.width, scene.height);
        for (std::size_t i = 0; i < grid.size(); ++i) {
            pcl.set_settings(grid[i]);
            if (i == 0 || !same_normals(grid[i], grid[i - 1])) pcl.estimate_normals();
            pcl.segment(&labels);
            ari[i] += eval::adjusted_rand_index(scene.object_id, labels);
        }
    }
    std::size_t best = 0;
    for (std::size_t i = 1; i < grid.size(); ++i) {
        if (ari[i] > ari[best]) best = i;
    }
    const double n = double(tune_seeds.size());
    tuning.done = true;
    tuning.setting = grid[best];
    tuning.chosen = peers::describe(grid[best]);
    tuning.chosen_ari = ari[best] / n;
    for (std::size_t i = 0; i < grid.size(); ++i) {
        if (grid[i] == peers::PclSettings{}) tuning.default_ari = ari[i] / n;
    }
    tuning.settings = grid.size();
    tuning.seconds = seconds_since(start);
#else
    (void)base;
    (void)tune_seeds;
    (void)quick;
#endif
    return tuning;
}

struct SensorRun {
    synthetic::Sensor sensor = synthetic::Sensor::structured_light;
    std::string name;
    Params params;
    PclTuning tuning;
    std::vector<Cell> cells;  // distance-major, bridges.size() per distance
};

std::string yes_no(const std::optional<bool>& check) {
    return !check ? "n/a" : (*check ? "yes" : "**no**");
}

std::string summary_table(const std::vector<SensorRun>& runs) {
    std::ostringstream out;
    out << "| sensor | ARI: pyramid | ARI: PCL | ARI: CC | pyramid ARI >= PCL | merged w1: pyramid | merged w1: CC | "
           "ratio w1 | merged w2: pyramid | merged w2: CC | ratio w2 | pyramid merged <= CC/5 | labelled: pyramid | "
           "labelled >= 90% |\n"
        << "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
    for (const SensorRun& run : runs) {
        const eval::SensorSummary s = eval::summarize(run.cells);
        out << "| " << run.name << " | " << fixed3(s.pyramid0.ari()) << " | " << fixed3(s.pcl0.ari()) << " | "
            << fixed3(s.cc0.ari()) << " | " << yes_no(s.ari_at_least_pcl) << " |";
        for (const eval::MergeAtWidth& m : s.merge) {
            if (!m.present) {
                out << " n/a | n/a | n/a |";
                continue;
            }
            out << " " << count_and_rate(m.pyramid, m.objects) << " | " << count_and_rate(m.cc, m.objects) << " | "
                << (std::isnan(m.ratio()) ? "n/a" : format("%.2f", m.ratio())) << " |";
        }
        out << " " << yes_no(s.merges_fifth_of_cc) << " | " << percent(s.pyramid0.labelled_share()) << " | "
            << yes_no(s.labels_enough) << " |\n";
    }
    return out.str();
}

// The merges the bridges themselves cause: each checked width's merged objects minus those without bridges (the
// objects no labelling of the mask can separate, which both methods merge alike).
std::string added_merges_table(const std::vector<SensorRun>& runs) {
    std::ostringstream out;
    out << "| sensor | merged without bridges: pyramid | merged without bridges: CC | added by 1-px bridges: pyramid | "
           "added by 1-px bridges: CC | added by 2-px bridges: pyramid | added by 2-px bridges: CC |\n"
        << "|---|---|---|---|---|---|---|\n";
    const auto added = [](std::uint64_t at_width, std::uint64_t without) {
        return at_width >= without ? std::to_string(at_width - without) : "-" + std::to_string(without - at_width);
    };
    for (const SensorRun& run : runs) {
        const eval::SensorSummary s = eval::summarize(run.cells);
        out << "| " << run.name << " | " << s.pyramid0.merged << " | " << s.cc0.merged << " |";
        for (const eval::MergeAtWidth& m : s.merge) {
            if (!m.present) {
                out << " n/a | n/a |";
                continue;
            }
            out << " " << added(m.pyramid, s.pyramid0.merged) << " | " << added(m.cc, s.cc0.merged) << " |";
        }
        out << "\n";
    }
    return out.str();
}

// The merges a labelling of the mask can avoid: merged objects counting only objects they are not flush with
// (synthetic::flush_pairs), pooled over the distances, with the check on these counts.
std::string separable_merges_table(const std::vector<SensorRun>& runs) {
    std::ostringstream out;
    out << "| sensor | without bridges: pyramid | without bridges: CC | without bridges: PCL | w1: pyramid | w1: CC | "
           "ratio w1 | w2: pyramid | w2: CC | ratio w2 | pyramid <= CC/5 |\n"
        << "|---|---|---|---|---|---|---|---|---|---|---|\n";
    for (const SensorRun& run : runs) {
        const eval::SensorSummary s = eval::summarize(run.cells);
        const std::uint64_t objects = s.merge[0].present ? s.merge[0].objects : s.merge[1].objects;
        out << "| " << run.name << " | " << count_and_rate(s.pyramid0.merged_separable, objects) << " | "
            << count_and_rate(s.cc0.merged_separable, objects) << " | "
            << (s.pcl0.frames > 0 ? count_and_rate(s.pcl0.merged_separable, objects) : std::string("n/a")) << " |";
        for (const eval::MergeAtWidth& m : s.merge) {
            if (!m.present) {
                out << " n/a | n/a | n/a |";
                continue;
            }
            out << " " << count_and_rate(m.pyramid_separable, m.objects) << " | "
                << count_and_rate(m.cc_separable, m.objects) << " | "
                << (std::isnan(m.separable_ratio()) ? "n/a" : format("%.2f", m.separable_ratio())) << " |";
        }
        out << " " << yes_no(s.separable_merges_fifth_of_cc) << " |\n";
    }
    return out.str();
}

LineChart summary_chart(const std::vector<SensorRun>& runs, const std::vector<double>& distances,
                        const std::string& title) {
    LineChart chart;
    chart.title = title;
    chart.x_label = "camera distance (mm)";
    chart.y_ticks = {0, 0.25, 0.5, 0.75, 1};
    chart.y_min = 0;
    chart.y_max = 1;
    for (const SensorRun& run : runs) {
        const std::size_t per = run.cells.size() / std::max<std::size_t>(1, distances.size());
        LinePanel panel;
        panel.title = run.name;
        panel.x = distances;
        LineSeries pyr = kPyramidSeries;
        LineSeries cc = kCcSeries;
        LineSeries pcl = kPclSeries;
        pyr.name = "pyramid, no bridges";
        cc.name = "CC, no bridges";
        pcl.name = "PCL (tuned)";
        LineSeries pyr1{"pyramid, 1-px bridges", {250, 180, 90}, true, {}};
        LineSeries cc1{"CC, 1-px bridges", {140, 180, 230}, true, {}};
        for (std::size_t d = 0; d < distances.size(); ++d) {
            const std::span<const Cell> row(run.cells.data() + d * per, per);
            const double none = std::nan("");
            double p0 = none, c0 = none, l0 = none, p1 = none, c1 = none;
            for (const Cell& c : row) {
                if (c.bridge == 0) {
                    p0 = c.pyramid.ari();
                    c0 = c.cc.ari();
                    if (c.pcl.frames > 0) l0 = c.pcl.ari();
                }
                if (c.bridge == 1) {
                    p1 = c.pyramid.ari();
                    c1 = c.cc.ari();
                }
            }
            pyr.y.push_back(p0);
            cc.y.push_back(c0);
            pcl.y.push_back(l0);
            pyr1.y.push_back(p1);
            cc1.y.push_back(c1);
        }
        panel.series = {pyr, cc};
        if (std::any_of(pcl.y.begin(), pcl.y.end(), [](double v) { return !std::isnan(v); }))
            panel.series.push_back(pcl);
        if (std::any_of(pyr1.y.begin(), pyr1.y.end(), [](double v) { return !std::isnan(v); })) {
            panel.series.push_back(pyr1);
            panel.series.push_back(cc1);
        }
        chart.panels.push_back(panel);
    }
    return chart;
}

struct SensorSweep {
    std::vector<Size> sizes;
    int seeds = 0;
    std::vector<synthetic::Sensor> sensors;
    std::vector<double> distances;
    std::vector<double> bridges;
    double noise = 0.1;
    bool preset = true;
    int tune_seeds = 4;
    bool quick = false;
    // The parameters of a sensor's scenes: its preset (or the defaults) with the command line's parameter options
    // on top, so that a preset can be tuned with this sweep.
    std::function<Params(std::optional<SensorKind>)> params_of;
};

void sensor_sweep(const SensorSweep& sweep, const fs::path& out_dir, std::ostringstream& md) {
    const double middle = sweep.distances[(sweep.distances.size() - 1) / 2];
    std::vector<std::uint64_t> tune_seeds;
    tune_seeds.reserve(std::size_t(std::max(0, sweep.tune_seeds)));
    const std::uint64_t first_tune = std::uint64_t(std::max(1000, sweep.seeds)) + 1;
    for (int i = 0; i < sweep.tune_seeds; ++i) tune_seeds.push_back(first_tune + std::uint64_t(i));
    const std::string tune_range = std::to_string(tune_seeds.front()) +
                                   (tune_seeds.size() > 1 ? ".." + std::to_string(tune_seeds.back()) : std::string());
    for (const Size& size : sweep.sizes) {
        const std::string name = size_name(size);
        std::vector<SensorRun> runs;
        for (const synthetic::Sensor sensor : sweep.sensors) {
            SensorRun run;
            run.sensor = sensor;
            run.name = synthetic::sensor_name(sensor);
            run.params = sweep.params_of(sweep.preset ? std::optional(kind_of(sensor)) : std::nullopt);
            Outputs outputs;
            outputs.fillable_mask = true;
            outputs.normals = true;
            Segmenter segmenter(size.width, size.height, run.params, "cpu", outputs);
            synthetic::SceneOptions base;
            base.width = size.width;
            base.height = size.height;
            base.sensor = sensor;
            base.noise_mm = sweep.noise;
            base.camera_distance_mm = middle;
            run.tuning = tune_pcl(base, tune_seeds, sweep.quick);
            PclPeer pcl;
            if (run.tuning.done) {
#ifdef PYRSEG_HAVE_PCL_PEER
                pcl.segmentation.set_settings(run.tuning.setting);
#endif
                std::printf(
                    "%s, %s: PCL tuned in %.1f s over %zu settings on seeds %s at %g mm: %s (mean ARI %.3f; "
                    "PCL's defaults %.3f)\n",
                    name.c_str(), run.name.c_str(), run.tuning.seconds, run.tuning.settings, tune_range.c_str(), middle,
                    run.tuning.chosen.c_str(), run.tuning.chosen_ari, run.tuning.default_ari);
                std::fflush(stdout);
            }
            for (const double distance : sweep.distances) {
                std::vector<Cell> row(sweep.bridges.size());
                for (std::size_t b = 0; b < sweep.bridges.size(); ++b) {
                    row[b].noise_mm = sweep.noise;
                    row[b].distance_mm = distance;
                    row[b].bridge = int(sweep.bridges[b]);
                }
                const auto cell_start = std::chrono::steady_clock::now();
                for (int seed = 1; seed <= sweep.seeds; ++seed) {
                    synthetic::SceneOptions options = base;
                    options.seed = std::uint64_t(seed);
                    options.camera_distance_mm = distance;
                    evaluate_scene(options, sweep.bridges, segmenter, pcl, row);
                }
                std::printf("%s, %s at %g mm: %d scenes in %.1f s\n", name.c_str(), run.name.c_str(), distance,
                            sweep.seeds, seconds_since(cell_start));
                print_cells(row);
                run.cells.insert(run.cells.end(), row.begin(), row.end());
            }
            runs.push_back(std::move(run));
        }

        const std::string seeds_text = std::to_string(sweep.seeds) + (sweep.seeds == 1 ? " seed" : " seeds");
        md << "\n## " << name << "\n\n### Summary per sensor model (pooled over the distances)\n\n"
           << "ARI, and the pyramid's labelled share, at bridge width 0 (mean over every scene at every distance); "
              "merged objects of the pyramid and of CC with 1- and 2-pixel bridges, summed over the distances, and "
              "their ratio (pyramid / CC). The checks: the pyramid's ARI is at least PCL's; the pyramid merges at "
              "most 1/5 as many objects as CC at each of the widths 1 and 2 (n/a where CC merged none); the pyramid "
              "labels at least 90% of the "
              "ground-truth pixels.\n\n"
           << summary_table(runs) << "\n"
           << "The merges the bridges add, pooled over the distances: the merged objects at each width minus those "
              "without bridges (objects with no edge between them in the mask, which no labelling of it can "
              "separate, count in every width for both methods).\n\n"
           << added_merges_table(runs) << "\n"
           << "The merges a labelling can avoid: merged objects counting only the objects they are not *flush* with. "
              "Flush objects (`synthetic::flush_pairs`) are upright boxes whose top faces lie in one plane and touch "
              "along a side, as identical parts packed side by side: their surfaces meet with no depth step and no "
              "crease, so no segmentation from depth alone can separate them, and every method merges them. "
              "Without bridges, then with 1- and 2-pixel bridges, and the check on these counts:\n\n"
           << separable_merges_table(runs) << "\n";
        const std::string summary_file = "ari_summary_" + name + ".png";
        write_png((out_dir / summary_file).string(),
                  render_line_chart(summary_chart(
                      runs, sweep.distances, "adjusted rand index vs camera distance, " + name + (", " + seeds_text))));
        md << "![ari_summary](" << summary_file << ")\n\n";

        md << "### PCL's settings per sensor model\n\n";
        if (runs.empty() || !runs.front().tuning.done) {
            md << "PCL was not scored (pyrseg was built without PCL).\n";
        } else {
            md << "Tuned as a PCL user would tune them: for each sensor model, every setting of a grid of "
               << runs.front().tuning.settings << " ("
               << (sweep.quick ? "the quick grid: smoothing 10, 20 x depth change 0.02 x angle 0.25 rad x distance "
                                 "10, 20 mm"
                               : "integral-image normal smoothing 10, 20, 30, 45 x max depth change 0.02, 0.05, 0.1 "
                                 "x the comparator's angle 0.08, 0.15, 0.25, 0.4 rad x distance 10, 20, 40, 80 mm")
               << "; covariance normals, regions of >= 100 points) segmented " << tune_seeds.size() << " tuning scene"
               << (tune_seeds.size() == 1 ? "" : "s") << " (seeds " << tune_range
               << ", disjoint from the evaluation seeds 1.." << sweep.seeds << ") at the middle camera distance, "
               << format("%g", middle)
               << " mm, and the setting with the best mean ARI there was kept (ties: the first in grid order) for "
                  "every distance of the evaluation. *PCL defaults* is the ARI of PCL's default settings (the "
                  "benchmarks', smoothing 10, depth change 0.02, 0.25 rad, 10 mm) on the same tuning scenes.\n\n"
               << "| sensor | PCL setting chosen | tuning ARI: chosen | tuning ARI: PCL defaults |\n"
               << "|---|---|---|---|\n";
            for (const SensorRun& run : runs) {
                md << "| " << run.name << " | " << run.tuning.chosen << " | " << fixed3(run.tuning.chosen_ari) << " | "
                   << fixed3(run.tuning.default_ari) << " |\n";
            }
        }

        std::vector<std::string> panels;
        for (const double distance : sweep.distances) panels.push_back("distance " + format("%g", distance) + " mm");
        for (const SensorRun& run : runs) {
            md << "\n### " << run.name << "\n\n"
               << "pyrseg's parameters: " << (sweep.preset ? "the preset (" : "the defaults (")
               << describe_params(run.params) << ")"
               << (run.sensor == synthetic::Sensor::structured_light
                       ? "; depth noise " + format("%g", sweep.noise) + " mm"
                       : std::string())
               << ". PCL: " << (run.tuning.done ? run.tuning.chosen : std::string("not built")) << ".\n\n"
               << table(run.cells, Sweep::sensors) << "\n"
               << write_plots(out_dir, run.cells, panels, sweep.bridges, run.name + "_" + name,
                              " vs bridge width, " + run.name + (", " + name) + (", " + seeds_text));
        }
    }
}

}  // namespace

int cmd_eval(const std::vector<std::string>& argv) {
    for (const std::string& a : argv) {
        if (a == "--tabletop" || a.starts_with("--tabletop=") || a == "--tabletop-synthetic") {
            return cmd_eval_tabletop(argv);
        }
        if (a == "--tracks") return cmd_eval_tracks(argv);
    }
    std::set<std::string> values = {"sizes",   "seeds",     "noise",  "bridges",   "out-dir",
                                    "sensors", "distances", "params", "tune-seeds"};
    values.insert(kParameterValueOptions.begin(), kParameterValueOptions.end());
    std::set<std::string> flags = kParameterFlagOptions;
    flags.insert({"help", "quick"});
    const Args args(argv, values, flags);
    if (args.flag("help")) {
        std::fputs(kEvalUsage, stdout);
        return 0;
    }
    if (!args.positional().empty()) throw UsageError{"takes no positional arguments"};
    const bool quick = args.flag("quick");
    // The noise sweep when --noise comes without the sensor sweep's own options; the sensor sweep otherwise.
    const Sweep mode =
        args.value("noise") && !args.value("sensors") && !args.value("distances") ? Sweep::noise : Sweep::sensors;
    const std::vector<Size> sizes = parse_sizes(args.value("sizes").value_or(quick ? "320x240" : "640x480"));
    const int seeds = args.integer("seeds").value_or(quick ? 2 : (mode == Sweep::noise ? 20 : 10));
    if (seeds < 1 || seeds > 100000) throw UsageError{"--seeds must be 1..100000"};
    const std::string default_bridges = quick ? (mode == Sweep::noise ? "0,1,2,4" : "0,1,2") : "0,1,2,3,4,6,8";
    const std::vector<double> bridges = parse_numbers("bridges", args.value("bridges").value_or(default_bridges), true);
    const std::string params_name = args.value("params").value_or("preset");
    if (params_name != "preset" && params_name != "default") {
        throw UsageError{"--params expects preset or default, got '" + params_name + "'"};
    }
    const bool preset = params_name == "preset";
    const fs::path out_dir = args.value("out-dir").value_or("pyrseg-eval");

    SensorSweep sweep;
    std::vector<double> noises;
    if (mode == Sweep::noise) {
        noises = parse_numbers("noise", *args.value("noise"), false);
    } else {
        sweep.sizes = sizes;
        sweep.seeds = seeds;
        sweep.bridges = bridges;
        sweep.preset = preset;
        sweep.quick = quick;
        sweep.params_of = [&args](std::optional<SensorKind> kind) { return parse_params(args, kind); };
        sweep.sensors =
            parse_sensors(args.value("sensors").value_or(quick ? "structured-light,kinect-v1" : known_sensors(",")));
        sweep.distances =
            parse_numbers("distances", args.value("distances").value_or(quick ? "1200" : "800,1200,2000"), false);
        for (const double d : sweep.distances) {
            if (d < 300 || d > 6000) {
                throw UsageError{"--distances: camera distances are 300..6000 mm, got " + format("%g", d)};
            }
        }
        const std::vector<double> noise = parse_numbers("noise", args.value("noise").value_or("0.1"), false);
        if (noise.size() != 1) {
            throw UsageError{
                "--noise: the sensor sweep takes one noise level (the structured-light model's); "
                "for a sweep over noise levels give --noise without --sensors and --distances"};
        }
        sweep.noise = noise.front();
        sweep.tune_seeds = args.integer("tune-seeds").value_or(quick ? 1 : 4);
        if (sweep.tune_seeds < 1 || sweep.tune_seeds > 1000) throw UsageError{"--tune-seeds must be 1..1000"};
    }
    fs::create_directories(out_dir);

    std::string command = "pyrseg eval";
    for (const std::string& a : argv) command += " " + a;
    std::ostringstream md;
    if (mode == Sweep::noise) {
        md << "# pyrseg eval: pyramid vs plain connected components on the same mask\n\n"
           << "`" << command << "`: " << seeds << " seeded scene" << (seeds == 1 ? "" : "s") << " per cell (seeds 1.."
           << seeds << "), CPU backend, default parameters, " << std::thread::hardware_concurrency()
           << " hardware threads.\n\n";
    } else {
        md << "# pyrseg eval: pyramid vs plain connected components and PCL across depth sensor models\n\n"
           << "`" << command << "`: " << seeds << " seeded scene" << (seeds == 1 ? "" : "s") << " per cell (seeds 1.."
           << seeds << "), CPU backend, pyrseg's parameters: "
           << (preset ? "the preset for each sensor model (`sensor_preset`)" : "the defaults for every sensor model")
           << ", " << std::thread::hardware_concurrency() << " hardware threads. Sensor models and camera distances "
           << "as the synthetic generator models them (docs/sensors.md).\n\n";
    }
    md << "Objects: ground-truth ids with >= " << eval::kMinObjectPixels << kMetricsHead << int(eval::kSplitShare * 100)
       << kMetricsTail;

    const auto start = std::chrono::steady_clock::now();
    if (mode == Sweep::noise) {
        noise_sweep(sizes, seeds, noises, bridges, preset ? sensor_preset(SensorKind::structured_light, 1.0) : Params{},
                    out_dir, md);
    } else {
        sensor_sweep(sweep, out_dir, md);
    }
    const double total = seconds_since(start);
    md << "\nRun time: " << format("%.1f", total) << " s.\n";
    const fs::path report = out_dir / "quality.md";
    write_text_file(report, md.str());
    std::printf("done in %.1f s; wrote %s and the plots\n", total, report.string().c_str());
    return 0;
}

}  // namespace pyrseg::cli
