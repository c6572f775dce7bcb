#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "pyrseg/error.hpp"
#include "pyrseg/io.hpp"
#include "pyrseg/segmenter.hpp"
#include "tools/cloud_stats.hpp"
#include "tools/commands.hpp"
#include "tools/figures.hpp"

namespace pyrseg::cli {
namespace {

constexpr const char* kSegmentUsage =
    "Usage: pyrseg segment INPUT [--labels OUT.npy] [--png OUT.png] [--mask-png OUT.png] [--figure OUT.png]\n"
    "                      [--backend NAME] [parameters]\n"
    "\n"
    "Segments one organized point cloud or depth image (see Inputs below). At least one output:\n"
    "  --labels OUT.npy      labels as a NumPy uint32 array, H x W (0 = no segment, 1..K segments)\n"
    "  --png OUT.png         the segments in colour\n"
    "  --mask-png OUT.png    the fillable mask (white) the pyramid labels\n"
    "  --figure OUT.png      mask | plain connected components | pyramid, side by side\n"
    "  --backend NAME        cpu, cuda, vulkan, opencl or auto (default: $PYRSEG_BACKEND, else auto)\n"
    "\n";

}  // namespace

int cmd_segment(const std::vector<std::string>& argv) {
    std::set<std::string> values = kParameterValueOptions;
    values.insert(kInputValueOptions.begin(), kInputValueOptions.end());
    values.insert({"labels", "png", "mask-png", "figure", "backend"});
    std::set<std::string> flags = kParameterFlagOptions;
    flags.insert("help");
    const Args args(argv, values, flags);
    if (args.flag("help")) {
        std::printf("%s%s%s", kSegmentUsage, kInputHelp, kParameterHelp);
        return 0;
    }
    if (args.positional().size() != 1) throw UsageError{"expects exactly one INPUT file"};
    const auto labels_path = args.value("labels");
    const auto png_path = args.value("png");
    const auto mask_path = args.value("mask-png");
    const auto figure_path = args.value("figure");
    if (!labels_path && !png_path && !mask_path && !figure_path) {
        throw UsageError{"nothing to write: give --labels, --png, --mask-png or --figure"};
    }
    const Params params = parse_params(args);
    const std::filesystem::path input = args.positional()[0];
    const LoadedInput loaded = load_input(input, args);
    const io::PointCloud& cloud = loaded.cloud;
    const double median_z = median_depth(cloud.points);
    if (!loaded.millimetres && params.unit_mm == 1.0 && median_z > 0 && median_z < 20.0) {
        std::fprintf(stderr,
                     "pyrseg: note: %s: median depth is %.3g units; if the cloud is in metres, pass --unit-mm 1000\n",
                     input.string().c_str(), median_z);
    }

    Outputs outputs;
    outputs.fillable_mask = mask_path.has_value() || figure_path.has_value();
    Segmenter segmenter(cloud.width, cloud.height, params, args.value("backend").value_or(""), outputs);
    CloudView view;
    view.points = cloud.points.data();
    view.normals = cloud.normals.empty() ? nullptr : cloud.normals.data();
    view.width = cloud.width;
    view.height = cloud.height;
    const auto start = std::chrono::steady_clock::now();
    const Result result = segmenter.segment(view);
    const std::chrono::duration<double, std::milli> elapsed = std::chrono::steady_clock::now() - start;

    if (labels_path) io::write_npy(*labels_path, result.labels.data(), result.height, result.width);
    if (png_path) write_png(*png_path, colorize(result.labels, result.width, result.height));
    if (mask_path) write_png(*mask_path, mask_picture(result.fillable_mask, result.width, result.height));
    if (figure_path) write_png(*figure_path, comparison_figure(result));
    std::printf("%s: %s, %d x %d, normals %s, %u segments, %.1f ms on %s\n", input.string().c_str(),
                loaded.kind.c_str(), result.width, result.height, cloud.normals.empty() ? "estimated" : "from file",
                result.segment_count, elapsed.count(), segmenter.backend_name().c_str());
    return 0;
}

}  // namespace pyrseg::cli
