#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "pyrseg/backend.hpp"
#include "pyrseg/error.hpp"
#include "pyrseg/io.hpp"
#include "pyrseg/segmenter.hpp"
#include "pyrseg/synthetic.hpp"
#include "tools/cloud_stats.hpp"
#include "tools/commands.hpp"
#include "tools/figures.hpp"

namespace pyrseg::cli {
namespace {

namespace fs = std::filesystem;

constexpr const char* kDemoUsage =
    "Usage: pyrseg demo [--out DIR] [--size WxH] [--seed N] [--noise MM] [--runs N] [--data DIR] [parameters]\n"
    "\n"
    "Generates a synthetic bin-picking scene (boxes, cylinders, spheres touching each other in a bin, with\n"
    "structured-light noise and holes), segments it from its points alone (normals estimated) with every\n"
    "available backend, checks that all backends give the same labels byte for byte, prints a timing table,\n"
    "and writes pictures. The shared sample scans (*.pcd in --data, default ../shared/data) are segmented too\n"
    "when present, each with the preset of the kind of sensor its depth noise looks like (as --sensor auto).\n"
    "--sensor NAME (see the parameters) renders the synthetic scene as that sensor model sees it instead\n"
    "(docs/sensors.md) and segments it, and the scans, with that sensor's preset.\n"
    "  --out DIR     where the pictures go (default pyrseg-demo)\n"
    "  --size WxH    scene size (default 2064x1544, a Photoneo PhoXi frame)\n"
    "  --seed N      scene seed (default 1)\n"
    "  --noise MM    structured-light noise of the scene, sigma along the viewing ray (default 0.1 mm,\n"
    "                PhoXi-like; the other sensor models have their own)\n"
    "  --runs N      timed runs per backend after one warm-up (default 5)\n"
    "  --data DIR    folder of sample .pcd scans (default ../shared/data)\n"
    "\n";

struct Timed {
    std::string backend;
    Result result;
    std::vector<double> totals_ms;
    std::vector<PassTiming> passes;  // of the fastest run
};

double ms_since(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

Timed run_backend(const std::string& backend, const CloudView& view, const Params& params, int runs) {
    Outputs outputs;
    outputs.fillable_mask = true;
    Segmenter segmenter(view.width, view.height, params, backend, outputs);
    Timed t{backend, {}, {}, {}};
    segmenter.segment(view, t.result);  // warm-up: sizes the result and touches every buffer
    double best = 1e300;
    for (int r = 0; r < runs; ++r) {
        const auto start = std::chrono::steady_clock::now();
        segmenter.segment(view, t.result);
        const double ms = ms_since(start);
        t.totals_ms.push_back(ms);
        if (ms < best) {
            best = ms;
            t.passes = segmenter.last_timings();
        }
    }
    return t;
}

void print_timing_table(const std::vector<Timed>& all) {
    std::vector<std::string> passes;
    for (const Timed& t : all) {
        for (const PassTiming& p : t.passes) {
            if (std::find(passes.begin(), passes.end(), p.pass) == passes.end()) passes.emplace_back(p.pass);
        }
    }
    std::printf("\n%-8s %9s %9s", "backend", "median", "best");
    for (const std::string& p : passes) std::printf(" %10s", p.c_str());
    std::printf("   (milliseconds; passes of the best run)\n");
    for (const Timed& t : all) {
        std::vector<double> sorted = t.totals_ms;
        std::sort(sorted.begin(), sorted.end());
        std::printf("%-8s %9.2f %9.2f", t.backend.c_str(), sorted[sorted.size() / 2], sorted.front());
        for (const std::string& p : passes) {
            double ms = 0;
            for (const PassTiming& pt : t.passes) {
                if (p == pt.pass) ms = pt.milliseconds;
            }
            std::printf(" %10.2f", ms);
        }
        std::printf("\n");
    }
}

// Segments the scene with every available backend; returns false when they disagree.
bool segment_everywhere(const std::string& name, const CloudView& view, const Params& params, int runs,
                        const fs::path& out_dir, std::vector<fs::path>& written) {
    std::vector<Timed> all;
    for (const BackendInfo& b : list_backends()) {
        if (b.available) all.push_back(run_backend(b.name, view, params, runs));
    }
    bool agree = true;
    for (const Timed& t : all) {
        if (t.result.labels != all.front().result.labels) {
            std::printf("MISMATCH: %s labels differ from %s on %s\n", t.backend.c_str(), all.front().backend.c_str(),
                        name.c_str());
            agree = false;
        }
    }
    const Result& r = all.front().result;
    if (all.size() == 1) {
        std::printf("%s: %d x %d, %u segments; only %s is available here, so there is nothing to cross-check\n",
                    name.c_str(), r.width, r.height, r.segment_count, all.front().backend.c_str());
    } else {
        std::printf("%s: %d x %d, %u segments; %zu backends %s\n", name.c_str(), r.width, r.height, r.segment_count,
                    all.size(), agree ? "agree byte for byte" : "DISAGREE");
    }
    print_timing_table(all);
    const fs::path figure = out_dir / (name + "_figure.png");
    const fs::path segments = out_dir / (name + "_segments.png");
    write_png(figure.string(), comparison_figure(r));
    write_png(segments.string(), colorize(r.labels, r.width, r.height));
    written.push_back(figure);
    written.push_back(segments);
    return agree;
}

}  // namespace

int cmd_demo(const std::vector<std::string>& argv) {
    std::set<std::string> values = kParameterValueOptions;
    values.insert({"out", "size", "seed", "noise", "runs", "data"});
    std::set<std::string> flags = kParameterFlagOptions;
    flags.insert("help");
    const Args args(argv, values, flags);
    if (args.flag("help")) {
        std::printf("%s%s", kDemoUsage, kParameterHelp);
        return 0;
    }
    if (!args.positional().empty()) throw UsageError{"takes no positional arguments"};
    synthetic::SceneOptions scene_options;
    scene_options.width = 2064;
    scene_options.height = 1544;
    if (const auto size = args.value("size")) {
        if (std::sscanf(size->c_str(), "%dx%d", &scene_options.width, &scene_options.height) != 2 ||
            scene_options.width < 1 || scene_options.height < 1) {
            throw UsageError{"--size expects WxH, e.g. 640x480, got '" + *size + "'"};
        }
    }
    if (const auto seed = args.integer("seed")) scene_options.seed = std::uint64_t(*seed);
    scene_options.noise_mm = args.number("noise").value_or(0.1);
    if (scene_options.noise_mm < 0) throw UsageError{"--noise must be >= 0"};
    const int runs = args.integer("runs").value_or(5);
    if (runs < 1) throw UsageError{"--runs must be >= 1"};
    const fs::path out_dir = args.value("out").value_or("pyrseg-demo");
    fs::create_directories(out_dir);
    const Params params = parse_params(args);
    // --sensor NAME also renders the synthetic scene as that sensor model sees it (docs/sensors.md).
    const std::optional<SensorChoice> sensor = parse_sensor(args);
    if (sensor && !sensor->automatic) {
        const auto model = synthetic::sensor_from_name(sensor_kind_name(sensor->kind));
        if (model) scene_options.sensor = *model;
    }

    auto start = std::chrono::steady_clock::now();
    const synthetic::Scene scene = synthetic::generate(scene_options);
    std::printf("synthetic scene %d x %d (seed %llu, %s) generated in %.0f ms\n", scene.width, scene.height,
                static_cast<unsigned long long>(scene_options.seed), synthetic::sensor_name(scene_options.sensor),
                ms_since(start));
    std::vector<fs::path> written;
    CloudView view;
    view.points = scene.points.data();
    view.width = scene.width;
    view.height = scene.height;
    bool agree = segment_everywhere("synthetic", view, params, runs, out_dir, written);
    const fs::path truth = out_dir / "synthetic_truth.png";
    write_png(truth.string(), colorize(scene.object_id, scene.width, scene.height));
    written.push_back(truth);

    const fs::path data_dir = args.value("data").value_or("../shared/data");
    if (fs::is_directory(data_dir)) {
        std::vector<fs::path> scans;
        for (const auto& entry : fs::directory_iterator(data_dir)) {
            if (entry.path().extension() == ".pcd") scans.push_back(entry.path());
        }
        std::sort(scans.begin(), scans.end());
        for (const fs::path& scan : scans) {
            const io::PointCloud cloud = io::read_pcd(scan);
            Params scan_params = params;
            // The shared scans are in metres: the unit comes from the median depth, as in pyrseg segment.
            if (!args.value("unit-mm")) scan_params.unit_mm = detected_unit_mm(median_depth(cloud.points));
            CloudView scan_view;
            scan_view.points = cloud.points.data();
            scan_view.normals = cloud.normals.empty() ? nullptr : cloud.normals.data();
            scan_view.width = cloud.width;
            scan_view.height = cloud.height;
            // Each scan gets the preset of the kind of sensor its noise looks like, unless --sensor names one.
            std::string chosen = "parameters as given";
            if (!sensor || sensor->automatic) {
                const FrameNoise noise = measure_frame_noise(scan_view, scan_params.unit_mm);
                const double unit_mm = scan_params.unit_mm;
                scan_params = parse_params(args, noise.suggested);
                scan_params.unit_mm = unit_mm;
                chosen = std::string("sensor auto: ") + sensor_kind_name(noise.suggested) + ", " + noise.reason;
            }
            std::printf("\n%s (unit %g mm; %s)\n", scan.filename().string().c_str(), scan_params.unit_mm,
                        chosen.c_str());
            agree = segment_everywhere(scan.stem().string(), scan_view, scan_params, runs, out_dir, written) && agree;
        }
    } else {
        std::printf("\n(no sample scans: %s is not a folder)\n", data_dir.string().c_str());
    }
    std::printf("\nwrote:\n");
    for (const fs::path& p : written) std::printf("  %s\n", p.string().c_str());
    return agree ? 0 : 1;
}

}  // namespace pyrseg::cli
