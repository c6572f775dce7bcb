// pyrseg eval: segmentation quality against ground truth on seeded synthetic scenes, pyramid vs plain connected
// components on the same fillable mask, across noise levels and widths of added bridges (docs/quality.md).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "pyrseg/error.hpp"
#include "pyrseg/segmenter.hpp"
#include "pyrseg/synthetic.hpp"
#include "tools/commands.hpp"
#include "tools/eval/bridges.hpp"
#include "tools/eval/metrics.hpp"
#include "tools/figures.hpp"
#include "tools/plot.hpp"
#ifdef PYRSEG_HAVE_PCL_PEER
#include "peers/pcl_segmentation.hpp"
#endif

namespace pyrseg::cli {
namespace {

namespace fs = std::filesystem;

constexpr const char* kEvalUsage =
    "Usage: pyrseg eval [--sizes WxH[,WxH...]] [--seeds N] [--noise MM,...] [--bridges W,...] [--out-dir DIR]\n"
    "                   [--quick]\n"
    "\n"
    "Measures segmentation quality against ground truth on seeded synthetic bin-picking scenes (boxes, cylinders\n"
    "and spheres touching each other in a bin; seeds 1..N), comparing two labellings of the SAME fillable mask:\n"
    "  pyramid   pyrseg's pyramid (CPU backend, default parameters) through Segmenter::segment_mask\n"
    "  CC        plain 4-connected components of the mask, with the same edge labelling (contract step 6c)\n"
    "  PCL       at bridge width 0 only (it makes its own edges from the cloud, so bridges cannot be added to its\n"
    "            input): PCL's organized segmentation of the same cloud, OrganizedConnectedComponentSegmentation\n"
    "            with EdgeAwarePlaneComparator on integral-image normals (when pyrseg is built with PCL)\n"
    "The mask is the one pyrseg computes from the scene's points (normals estimated). Bridge width 0 evaluates it\n"
    "as it is (the pyramid's labels are then exactly `pyrseg segment`'s); a width W >= 1 first adds one bridge per\n"
    "pair of neighbouring ground-truth objects: a W-pixel-wide strip of fillable pixels across the edge band\n"
    "between the closest pixels of the two objects' main fillable bodies (at most 10 px apart).\n"
    "\n"
    "Metrics, over the pixels with ground truth; an object is a ground-truth id (floor, bin bottom, each wall,\n"
    "each object) with at least 100 pixels, and a segment claims an object when it holds more than half of its\n"
    "pixels:\n"
    "  merged    objects whose claiming segment also claims another object (under-segmentation; lower is better)\n"
    "  split     objects whose largest segment holds less than 80% of their labelled pixels, or that have none\n"
    "            labelled (over-segmentation; lower is better)\n"
    "  ARI       adjusted Rand index of ground truth vs segments, each unlabelled pixel a singleton (1 is perfect)\n"
    "  labelled  the share of ground-truth pixels given a segment\n"
    "  segments  distinct segments on ground-truth pixels, mean per frame\n"
    "\n"
    "  --sizes WxH,...   scene sizes (default 640x480)\n"
    "  --seeds N         scenes per cell, seeds 1..N (default 20)\n"
    "  --noise MM,...    depth noise sigmas along the viewing ray, mm (default 0,0.1,0.5,1,2; 0.1 is PhoXi-like)\n"
    "  --bridges W,...   bridge widths in pixels, 0 = the mask as it is (default 0,1,2,3,4,6,8)\n"
    "  --out-dir DIR     where quality.md and the plots go (default pyrseg-eval)\n"
    "  --quick           a seconds-long smoke run: 320x240, 2 seeds, noise 0,0.5, bridges 0,1,2,4 (the other\n"
    "                    options override it)\n"
    "Writes DIR/quality.md (the table) and DIR/{merge_rate,split_rate,ari}_WxH.png (one panel per noise level,\n"
    "one line per method).\n";

struct Size {
    int width = 0, height = 0;
};

std::vector<std::string> split_list(const std::string& text) {
    std::vector<std::string> items;
    std::stringstream in(text);
    std::string item;
    while (std::getline(in, item, ',')) items.push_back(item);
    return items;
}

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

struct MethodTotals {
    std::uint64_t merged = 0, split = 0, labelled = 0, pixels = 0, segments = 0;
    double ari_sum = 0;
    void add(const eval::Scores& s) {
        merged += s.merged;
        split += s.split;
        labelled += s.labelled;
        pixels += s.pixels;
        segments += s.segments;
        ari_sum += s.ari;
    }
};

struct Cell {
    double noise = 0;
    int bridge = 0;
    int frames = 0;
    std::uint64_t objects = 0;
    std::uint64_t sites = 0;        // bridges drawn (0 for width 0)
    MethodTotals pyramid, cc, pcl;  // pcl: bridge width 0 only
    int pcl_frames = 0;
};

double rate(std::uint64_t n, std::uint64_t of) {
    return of == 0 ? std::nan("") : double(n) / double(of);
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

std::string size_name(const Size& s) {
    return std::to_string(s.width) + "x" + std::to_string(s.height);
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

// One scene at one noise level, evaluated at every bridge width; cells[b] is the cell of bridges[b].
// PCL's organized segmentation of the scene's cloud, when pyrseg is built with it; null otherwise.
struct PclPeer {
#ifdef PYRSEG_HAVE_PCL_PEER
    peers::PclOrganizedSegmentation segmentation;
    std::vector<std::uint32_t> labels;
    const std::vector<std::uint32_t>* run(const synthetic::Scene& scene) {
        segmentation.set_cloud(scene.points.data(), nullptr, scene.width, scene.height);
        // Regions of at least 100 points, as PCL's organized plane segmentation keeps them: the rest of its
        // output is single points and slivers its comparator did not join.
        segmentation.run(&labels, 100);
        return &labels;
    }
#else
    const std::vector<std::uint32_t>* run(const synthetic::Scene& /*scene*/) {
        return nullptr;
    }
#endif
};

void evaluate_scene(const Size& size, std::uint64_t seed, double noise, const std::vector<double>& bridges,
                    Segmenter& segmenter, PclPeer& pcl, std::vector<Cell>& cells) {
    synthetic::SceneOptions options;
    options.width = size.width;
    options.height = size.height;
    options.seed = seed;
    options.noise_mm = noise;
    const synthetic::Scene scene = synthetic::generate(options);
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
        segmenter.segment_mask(mask_view, pyramid);
        if (width == 0 && pyramid.labels != from_cloud.labels) {
            throw Error(ErrorCode::internal,
                        "eval: the pyramid on the cloud's own mask differs from segmenting the "
                        "cloud (seed " +
                            std::to_string(seed) + ")");
        }
        std::vector<std::uint32_t> cc = eval::connected_components(mask, scene.width, scene.height);
        eval::label_edges(cc, mask, mask_valid, scene.width, scene.height);
        const eval::Scores ps = eval::score(scene.object_id, pyramid.labels);
        const eval::Scores cs = eval::score(scene.object_id, cc);
        Cell& cell = cells[b];
        ++cell.frames;
        cell.objects += ps.objects;
        if (width > 0) cell.sites += sites.size();
        cell.pyramid.add(ps);
        cell.cc.add(cs);
        if (width != 0) continue;
        if (const std::vector<std::uint32_t>* labels = pcl.run(scene)) {
            cell.pcl.add(eval::score(scene.object_id, *labels));
            ++cell.pcl_frames;
        }
    }
}

std::string table(const std::vector<Cell>& cells) {
    // PCL's columns only when it was scored (pyrseg built with it).
    const bool with_pcl = std::any_of(cells.begin(), cells.end(), [](const Cell& c) { return c.pcl_frames > 0; });
    std::ostringstream out;
    out << "| noise (mm) | bridge (px) | bridges | objects | merged: pyramid | merged: CC | split: pyramid | "
           "split: CC | ARI: pyramid | ARI: CC | labelled: pyramid | labelled: CC | segments: pyramid | "
           "segments: CC |";
    out << (with_pcl ? " merged: PCL | split: PCL | ARI: PCL | segments: PCL |\n" : "\n");
    out << "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|" << (with_pcl ? "---|---|---|---|\n" : "\n");
    for (const Cell& c : cells) {
        const double frames = std::max(1, c.frames);
        out << "| " << format("%g", c.noise) << " | " << c.bridge << " | " << c.sites << " | " << c.objects << " | "
            << count_and_rate(c.pyramid.merged, c.objects) << " | " << count_and_rate(c.cc.merged, c.objects) << " | "
            << count_and_rate(c.pyramid.split, c.objects) << " | " << count_and_rate(c.cc.split, c.objects) << " | "
            << format("%.3f", c.pyramid.ari_sum / frames) << " | " << format("%.3f", c.cc.ari_sum / frames) << " | "
            << format("%.1f%%", 100.0 * rate(c.pyramid.labelled, c.pyramid.pixels)) << " | "
            << format("%.1f%%", 100.0 * rate(c.cc.labelled, c.cc.pixels)) << " | "
            << format("%.1f", double(c.pyramid.segments) / frames) << " | "
            << format("%.1f", double(c.cc.segments) / frames) << " |";
        if (!with_pcl) {
            out << "\n";
        } else if (c.pcl_frames == 0) {
            out << " — | — | — | — |\n";
        } else {
            out << " " << count_and_rate(c.pcl.merged, c.objects) << " | " << count_and_rate(c.pcl.split, c.objects)
                << " | " << format("%.3f", c.pcl.ari_sum / c.pcl_frames) << " | "
                << format("%.1f", double(c.pcl.segments) / c.pcl_frames) << " |\n";
        }
    }
    return out.str();
}

enum class Plotted { merged, split, ari };

LineChart chart_of(const std::vector<Cell>& cells, const std::vector<double>& noises,
                   const std::vector<double>& bridges, Plotted what, const std::string& title) {
    LineChart chart;
    chart.title = title;
    chart.x_label = "bridge width (px)";
    chart.y_ticks = {0, 0.25, 0.5, 0.75, 1};
    chart.percent = what != Plotted::ari;
    chart.y_min = 0;
    chart.y_max = 1;
    for (std::size_t n = 0; n < noises.size(); ++n) {
        LinePanel panel;
        panel.title = "noise " + format("%g", noises[n]) + " mm";
        panel.x = bridges;
        LineSeries pyr{"pyramid", {230, 97, 1}, false, {}};
        LineSeries cc{"connected components", {33, 102, 172}, true, {}};
        LineSeries pcl{"PCL (no bridges added)", {40, 160, 60}, false, {}};
        for (std::size_t b = 0; b < bridges.size(); ++b) {
            const Cell& c = cells[n * bridges.size() + b];
            const double frames = std::max(1, c.frames);
            const double pcl_frames = c.pcl_frames;
            const double none = std::nan("");
            switch (what) {
                case Plotted::merged:
                    pyr.y.push_back(rate(c.pyramid.merged, c.objects));
                    cc.y.push_back(rate(c.cc.merged, c.objects));
                    pcl.y.push_back(c.pcl_frames > 0 ? rate(c.pcl.merged, c.objects) : none);
                    break;
                case Plotted::split:
                    pyr.y.push_back(rate(c.pyramid.split, c.objects));
                    cc.y.push_back(rate(c.cc.split, c.objects));
                    pcl.y.push_back(c.pcl_frames > 0 ? rate(c.pcl.split, c.objects) : none);
                    break;
                case Plotted::ari:
                    pyr.y.push_back(c.pyramid.ari_sum / frames);
                    cc.y.push_back(c.cc.ari_sum / frames);
                    pcl.y.push_back(c.pcl_frames > 0 ? c.pcl.ari_sum / pcl_frames : none);
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

double seconds_since(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

int cmd_eval(const std::vector<std::string>& argv) {
    const Args args(argv, {"sizes", "seeds", "noise", "bridges", "out-dir"}, {"help", "quick"});
    if (args.flag("help")) {
        std::fputs(kEvalUsage, stdout);
        return 0;
    }
    if (!args.positional().empty()) throw UsageError{"takes no positional arguments"};
    const bool quick = args.flag("quick");
    const std::vector<Size> sizes = parse_sizes(args.value("sizes").value_or(quick ? "320x240" : "640x480"));
    const int seeds = args.integer("seeds").value_or(quick ? 2 : 20);
    if (seeds < 1 || seeds > 100000) throw UsageError{"--seeds must be 1..100000"};
    const std::vector<double> noises =
        parse_numbers("noise", args.value("noise").value_or(quick ? "0,0.5" : "0,0.1,0.5,1,2"), false);
    const std::vector<double> bridges =
        parse_numbers("bridges", args.value("bridges").value_or(quick ? "0,1,2,4" : "0,1,2,3,4,6,8"), true);
    const fs::path out_dir = args.value("out-dir").value_or("pyrseg-eval");
    fs::create_directories(out_dir);

    std::string command = "pyrseg eval";
    for (const std::string& a : argv) command += " " + a;
    std::ostringstream md;
    md << "# pyrseg eval: pyramid vs plain connected components on the same mask\n\n"
       << "`" << command << "`: " << seeds << " seeded scene" << (seeds == 1 ? "" : "s") << " per cell (seeds 1.."
       << seeds << "), CPU backend, default parameters, " << std::thread::hardware_concurrency()
       << " hardware threads.\n\n"
       << "Objects: ground-truth ids with >= " << eval::kMinObjectPixels
       << " pixels (floor, bin bottom, walls, objects), summed over the seeds. *merged*: objects whose claiming "
          "segment (the one holding more than half of the object) claims another object too. *split*: objects "
          "whose largest segment holds less than "
       << int(eval::kSplitShare * 100)
       << "% of their labelled pixels, or that have none labelled. *ARI*: adjusted Rand index on ground-truth "
          "pixels, each unlabelled pixel a singleton, mean over the seeds. *labelled*: share of ground-truth pixels "
          "with a segment. *segments*: distinct segments on ground-truth pixels, mean per frame. *bridges*: bridges "
          "drawn, summed over the seeds (one per pair of neighbouring objects; none at width 0).\n";

    const auto start = std::chrono::steady_clock::now();
    for (const Size& size : sizes) {
        Outputs outputs;
        outputs.fillable_mask = true;
        outputs.normals = true;
        Segmenter segmenter(size.width, size.height, Params{}, "cpu", outputs);
        PclPeer pcl;
        std::vector<Cell> cells;
        for (const double noise : noises) {
            std::vector<Cell> row(bridges.size());
            for (std::size_t b = 0; b < bridges.size(); ++b) {
                row[b].noise = noise;
                row[b].bridge = int(bridges[b]);
            }
            const auto cell_start = std::chrono::steady_clock::now();
            for (int seed = 1; seed <= seeds; ++seed) {
                evaluate_scene(size, std::uint64_t(seed), noise, bridges, segmenter, pcl, row);
            }
            std::printf("%s, noise %g mm: %d scenes in %.1f s\n", size_name(size).c_str(), noise, seeds,
                        seconds_since(cell_start));
            for (const Cell& c : row) {
                std::printf(
                    "  bridge %d px: %llu objects, %llu bridges | merged: pyramid %.1f%%, CC %.1f%% | split: "
                    "pyramid %.1f%%, CC %.1f%% | ARI: pyramid %.3f, CC %.3f\n",
                    c.bridge, static_cast<unsigned long long>(c.objects), static_cast<unsigned long long>(c.sites),
                    100 * rate(c.pyramid.merged, c.objects), 100 * rate(c.cc.merged, c.objects),
                    100 * rate(c.pyramid.split, c.objects), 100 * rate(c.cc.split, c.objects),
                    c.pyramid.ari_sum / std::max(1, c.frames), c.cc.ari_sum / std::max(1, c.frames));
            }
            std::fflush(stdout);
            cells.insert(cells.end(), row.begin(), row.end());
        }
        const std::string name = size_name(size);
        const std::string seeds_text = std::to_string(seeds) + (seeds == 1 ? " seed" : " seeds");
        const std::vector<std::pair<Plotted, std::string>> plots = {
            {Plotted::merged, "merge_rate"}, {Plotted::split, "split_rate"}, {Plotted::ari, "ari"}};
        std::string subtitle = " vs bridge width, " + name;
        subtitle += ", " + seeds_text;
        const std::vector<std::string> titles = {"merged objects (%)" + subtitle, "split objects (%)" + subtitle,
                                                 "adjusted rand index" + subtitle};
        md << "\n## " << name << "\n\n" << table(cells) << "\n";
        for (std::size_t p = 0; p < plots.size(); ++p) {
            const std::string file = plots[p].second + "_" + name + ".png";
            write_png((out_dir / file).string(),
                      render_line_chart(chart_of(cells, noises, bridges, plots[p].first, titles[p])));
            md << "![" << plots[p].second << "](" << file << ")\n\n";
        }
    }
    const double total = seconds_since(start);
    md << "Run time: " << format("%.1f", total) << " s.\n";
    const fs::path report = out_dir / "quality.md";
    std::ofstream file(report);
    file << md.str();
    file.close();
    if (!file) throw Error(ErrorCode::io, report.string() + ": cannot write");
    std::printf("done in %.1f s; wrote %s and the plots\n", total, report.string().c_str());
    return 0;
}

}  // namespace pyrseg::cli
