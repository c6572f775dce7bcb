#include <glob.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "pyrseg/backend.hpp"
#include "pyrseg/cpu.hpp"
#include "pyrseg/error.hpp"
#include "pyrseg/io.hpp"
#include "pyrseg/scene.hpp"
#include "pyrseg/segmenter.hpp"
#include "tools/batch_plan.hpp"
#include "tools/cloud_stats.hpp"
#include "tools/commands.hpp"
#include "tools/figures.hpp"
#include "tools/output_checks.hpp"
#include "tools/output_files.hpp"
#include "tools/pcl_peer.hpp"
#include "tools/printable.hpp"
#include "tools/progress.hpp"
#include "tools/scene_picture.hpp"
#include "tools/track_table.hpp"

namespace pyrseg::cli {
namespace {

namespace fs = std::filesystem;

constexpr const char* kSegmentUsage =
    "Usage: pyrseg segment INPUT [outputs] [--backend NAME] [--threads N] [input options] [parameters]\n"
    "       pyrseg segment INPUT... --out-dir DIR [--write labels,png,mask,figure,ply,pcd,stats,graph,scene,\n"
    "                      track_ids,tracks] [--track] [--progress auto|bar|lines|none] [--backend NAME]\n"
    "                      [input options] [parameters]\n"
    "\n"
    "Segments one organized point cloud or depth image (see Inputs below) and prints a line with the segment count\n"
    "and the time (the first frame's includes the warm-up: kernel builds, first-touch allocation).\n"
    "With no output option it writes nothing and also prints the segment sizes. Outputs (each name must end in the\n"
    "extension shown, and no two may name the same file, else nothing is done; a frame's files are written all or\n"
    "none: when one cannot be written whole (a full disk), none of them is left and the exit status is 1; Ctrl-C\n"
    "or a SIGTERM leaves no temporary file; a FIFO needs a reader, else it is an error, not a wait):\n"
    "  --labels OUT.npy      labels as a NumPy uint32 array, H x W (0 = no segment, 1..K segments);\n"
    "  --labels OUT.png      or as a 16-bit grayscale PNG, when every label fits in 16 bits\n"
    "  --png OUT.png         the segments in colour\n"
    "  --mask-png OUT.png    the fillable mask (white) the pyramid labels\n"
    "  --figure OUT.png      mask | plain connected components | pyramid, side by side; with --scene also the\n"
    "                        scene's boxes and support outlines over the frame (its colour image, else the\n"
    "                        segments), projected through the pinhole the cloud was made with\n"
    "  --ply OUT.ply         the cloud coloured by segment (gray: no segment), binary PLY, organized (obj_info\n"
    "                        num_cols/num_rows and a range_grid), for CloudCompare, MeshLab or PCL\n"
    "  --pcd OUT.pcd         the cloud with each point's segment in a 'label' field (0: none), binary PCD in PCL's\n"
    "                        PointXYZL layout: pcl::io::loadPCDFile reads it into pcl::PointCloud<pcl::PointXYZL>.\n"
    "                        Organized, invalid points NaN, in the input's unit (millimetres for depth images).\n"
    "                        With --scene also 'object' and 'support' (the scene object or support the point's\n"
    "                        segment is: 1 + its index in the scene's JSON, 0: none), with --track 'track' (the\n"
    "                        track id); PCL reads them by name from a pcl::PCLPointCloud2\n"
    "  --stats OUT.json      per segment: label, pixel count, bounding box, 3D centroid (the cloud's units), mean\n"
    "  --stats OUT.csv       normal, depth range, plane (normal towards the camera, offset, RMS distance, curvature,\n"
    "                        planar or not) and oriented box (axes, side lengths), from exact sums the backend\n"
    "                        computes over the segment's fillable pixels (fillable_count; not its edge pixels);\n"
    "                        JSON or CSV, as the extension says\n"
    "  --graph OUT.json      which segments touch which: per pair, its boundary's length in pixel sides and how many\n"
    "  --graph OUT.csv       of them are flat, a convex crease, a concave crease or a depth step (docs/algorithm.md\n"
    "                        10d), counted exactly by the backend; JSON or CSV, as the extension says\n"
    "  --track-ids OUT.npy   with --track (below): each pixel's track id, as --labels writes labels (0 = no\n"
    "  --track-ids OUT.png   segment; a 16-bit PNG when every id fits in 16 bits)\n"
    "  --tracks OUT.json     with --track: per segment, its label, its track id, the frame of the stream it was first\n"
    "  --tracks OUT.csv      seen in, its age (the frames it was seen in), the frames it was hidden just before this\n"
    "                        one and how it was matched (new_track, overlap, position); JSON or CSV\n"
    "  --scene OUT.json      the scene: the support surfaces (large flat segments: floor, table, wall; plane and\n"
    "                        outline) and the objects resting on them, each with its support, its height above it\n"
    "                        and a box standing on it that holds the object's points (docs/algorithm.md 10c)\n"
    "  --scene OUT.ply       or the objects' boxes and the supports' outlines as a mesh, coloured as --png colours\n"
    "                        the segments, to open beside --ply OUT.ply in CloudCompare or MeshLab\n"
    "  --pcl-png OUT.png     PCL's organized segmentation of the same frame in colour, to compare (builds with\n"
    "                        PCL): with the settings pyrseg eval tuned for the --sensor named or chosen, else\n"
    "                        PCL's defaults\n"
    "  --backend NAME        @BACKENDS@ or auto (default: $PYRSEG_BACKEND, else auto)\n"
    "  --threads N           the CPU backend with an arena of N threads of its own (1..1024; implies --backend\n"
    "                        cpu). Without it the CPU backend shares the process's oneTBB threads, or takes\n"
    "                        $PYRSEG_THREADS of its own; the labels never depend on the threads.\n"
    "  --quiet, -q           nothing on stderr but warnings and errors (no backend line, notes, hints or progress\n"
    "                        unless --progress is given); stdout still has the results: the frame's line, a batch's\n"
    "                        summary (redirect it to drop them)\n"
    "  --verbose, -v         the full reason for the backend auto chose (by default one short line)\n"
    "  --track               follow the segments from frame to frame (docs/algorithm.md section 11): each segment\n"
    "                        gets a track id that carries over from the previous frame (see Tracks below)\n"
    "\n"
    "Units: cloud files do not say theirs. Without --unit-mm, a cloud whose median depth is under 20 units is read\n"
    "as metres (pyrseg says so), any other as millimetres; --unit-mm always wins. Depth images and depth maps take\n"
    "the unit of their samples from --metres-per-unit (below).\n"
    "\n"
    "Batches: several INPUTs, folders (their .pcd/.ply/.npy/.png/.tif/.tiff files, by name) or quoted glob\n"
    "patterns, with --out-dir. Each frame writes DIR/NAME.labels.npy, NAME.png, NAME.mask.png, NAME.figure.png,\n"
    "NAME.ply, NAME.labels.pcd, NAME.stats.json, NAME.graph.json, NAME.scene.json, NAME.track_ids.npy,\n"
    "NAME.tracks.json as --write asks (default labels,png; with --track labels,png,track_ids); NAME_2, NAME_3 ...\n"
    "when another frame's output has that name already. An output that would be one of the batch's inputs is refused\n"
    "before anything is read. A frame that fails (also one an input option does not apply to: --intrinsics on a\n"
    "cloud, --unit-mm on a depth image) is reported and skipped (none of its outputs is left); the exit status is 1\n"
    "if any failed.\n"
    "Progress is a bar on a terminal and a line per frame otherwise (--progress); a summary ends the batch, with the\n"
    "first frame's time (its warm-up) apart from the others'.\n"
    "\n"
    "Tracks: with --track the batch's frames are one stream, in the order the batch takes them: the INPUTs in the\n"
    "order given, a folder's files and a pattern's matches by name (number the frames with leading zeros:\n"
    "frame_0009 before frame_0010). One Segmenter segments them all, and each segment keeps its track id while the\n"
    "camera moves (an object hidden for up to --track-hold frames gets its id back); a frame that fails is left out\n"
    "of the stream, and one of another size (or other parameters: --sensor auto) restarts it, with a warning. The\n"
    "labels outputs stay the frame's labels 1..K; the pictures (--png, --figure, --ply, --scene OUT.ply) are\n"
    "coloured by track id, so that a segment keeps its colour and a video of them does not flicker. A backend\n"
    "without tracks refuses --track with the library's error.\n"
    "\n";

struct OutputPaths {
    std::optional<fs::path> labels, png, mask, figure, ply, pcd, stats, graph, scene, pcl_png, track_ids, tracks;
    [[nodiscard]] bool any() const {
        return labels || png || mask || figure || ply || pcd || stats || graph || scene || pcl_png || track_ids ||
               tracks;
    }
};

// The output options, the extensions their files may have, and what they write (for the message refusing another
// extension: a name is never silently given a format it does not say).
struct OutputOption {
    const char* name;
    std::optional<fs::path> OutputPaths::*path;
    std::vector<std::string> extensions;
    const char* writes;
};
const std::vector<OutputOption>& output_options() {
    static const std::vector<OutputOption> options = {
        {"labels",
         &OutputPaths::labels,
         {".npy", ".png"},
         "labels as a NumPy uint32 array or a 16-bit PNG; for a cloud with a label field, give --pcd OUT.pcd"},
        {"png", &OutputPaths::png, {".png"}, "the segments in colour, as PNG"},
        {"mask-png", &OutputPaths::mask, {".png"}, "the mask, as PNG"},
        {"figure", &OutputPaths::figure, {".png"}, "the figure, as PNG"},
        {"ply", &OutputPaths::ply, {".ply"}, "the coloured cloud, as PLY"},
        {"pcd", &OutputPaths::pcd, {".pcd"}, "the cloud with a label field, as PCD"},
        {"stats", &OutputPaths::stats, {".json", ".csv"}, "the statistics, as JSON or CSV"},
        {"graph", &OutputPaths::graph, {".json", ".csv"}, "the segment graph, as JSON or CSV"},
        {"scene", &OutputPaths::scene, {".json", ".ply"}, "the scene, as JSON or a PLY mesh of its boxes"},
        {"pcl-png", &OutputPaths::pcl_png, {".png"}, "PCL's segmentation in colour, as PNG"},
        {"track-ids", &OutputPaths::track_ids, {".npy", ".png"}, "track ids as a NumPy uint32 array or a 16-bit PNG"},
        {"tracks", &OutputPaths::tracks, {".json", ".csv"}, "the tracks, as JSON or CSV"},
    };
    return options;
}

std::string lower_extension(const fs::path& path) {
    std::string ext = path.extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    return ext;
}

OutputPaths output_paths(const Args& args) {
    OutputPaths out;
    for (const OutputOption& o : output_options()) {
        const std::optional<std::string> name = args.value(o.name);
        if (!name) continue;
        const std::string ext = lower_extension(*name);
        if (std::find(o.extensions.begin(), o.extensions.end(), ext) == o.extensions.end()) {
            std::string accepted;
            for (const std::string& e : o.extensions) {
                if (!accepted.empty()) accepted += " or ";
                accepted += e;
            }
            throw UsageError{"--" + std::string(o.name) + " " + *name + ": the name must end in " + accepted + " (" +
                             o.writes + ")"};
        }
        out.*o.path = *name;
    }
    return out;
}

// The outputs as check_outputs sees them: each with its option's name.
std::vector<NamedOutput> named_outputs(const OutputPaths& out) {
    std::vector<NamedOutput> named;
    for (const OutputOption& o : output_options()) {
        if (const std::optional<fs::path>& path = out.*o.path) named.push_back({"--" + std::string(o.name), *path});
    }
    return named;
}

struct FrameReport {
    std::string line;
    std::uint32_t segments = 0;
    double milliseconds = 0;
    bool warm_up = false;  // the frame ran on a new Segmenter: its time includes building it for the backend
};

// What the run says: --quiet leaves stderr to warnings and errors, and a batch of clouds in metres needs one note,
// not one per frame.
struct RunNotes {
    bool quiet = false;
    bool metres_read = false;
    // --sensor auto chooses once, on the first frame with enough depth to judge, and keeps it for the batch (one
    // camera's frames do not change sensor; a batch that switched presets frame by frame would not compare).
    std::optional<SensorKind> auto_sensor;
    bool hinted = false;             // the hint to name a preset is given once per run
    bool track = false;              // --track: the frames are one stream, their segments' ids carry over
    std::uint32_t stream_frame = 0;  // with --track, the next frame's number in the stream (0 after a restart)
};

// Labels or track ids (`what`: "label", "track id"): .npy (uint32) or, when every value fits, a 16-bit PNG that
// image viewers and OpenCV read directly.
void write_id_image(const fs::path& path, const std::vector<std::uint32_t>& values, int width, int height,
                    const char* what) {
    if (lower_extension(path) != ".png") {
        io::write_npy(path, values.data(), height, width);
        return;
    }
    const std::uint32_t largest = values.empty() ? 0u : *std::max_element(values.begin(), values.end());
    if (largest > 65535u) {
        throw Error(ErrorCode::invalid_argument, path.string() + ": " + what + " " + std::to_string(largest) +
                                                     " does not fit a 16-bit PNG; write .npy instead");
    }
    std::vector<std::uint16_t> gray(values.begin(), values.end());
    io::write_png_gray16(path, gray.data(), width, height);
}

// Per pixel, 1 + the index of the scene object (support) that its segment is, 0 for none: the labelled PCD's object
// and support fields, whose numbers are the scene JSON's objects[k] and supports[k] plus one.
void scene_index_images(const Scene& scene, const std::vector<std::uint32_t>& labels,
                        std::vector<std::uint32_t>& object, std::vector<std::uint32_t>& support) {
    const std::uint32_t largest = labels.empty() ? 0u : *std::max_element(labels.begin(), labels.end());
    std::vector<std::uint32_t> object_of(std::size_t(largest) + 1, 0);
    std::vector<std::uint32_t> support_of(object_of.size(), 0);
    for (std::size_t k = 0; k < scene.objects.size(); ++k) {
        if (scene.objects[k].label <= largest) object_of[scene.objects[k].label] = std::uint32_t(k + 1);
    }
    for (std::size_t k = 0; k < scene.supports.size(); ++k) {
        if (scene.supports[k].label <= largest) support_of[scene.supports[k].label] = std::uint32_t(k + 1);
    }
    object.resize(labels.size());
    support.resize(labels.size());
    for (std::size_t i = 0; i < labels.size(); ++i) {
        object[i] = object_of[labels[i]];
        support[i] = support_of[labels[i]];
    }
}

// The scene as its pictures show it (--scene OUT.ply, the figure's scene panel): with tracks, each support and
// object under its segment's track id, so that its colour is the one --png gives the segment.
Scene coloured_as_segments(const Scene& scene, const Result& result) {
    if (result.tracks.empty()) return scene;
    Scene coloured = scene;
    const auto id = [&](std::uint32_t label) {
        return label >= 1 && label <= result.tracks.size() ? result.tracks[label - 1].id : label;
    };
    for (SceneSupport& s : coloured.supports) s.label = id(s.label);
    for (SceneObject& o : coloured.objects) o.label = id(o.label);
    return coloured;
}

// One frame: read, segment (reusing the Segmenter while the size stays the same), write what was asked.
// The parameters a Segmenter was made with decide its plan; --sensor auto may change them from frame to frame.
bool same_params(const Params& a, const Params& b) {
    return a.ct == b.ct && a.dt == b.dt && a.unit_mm == b.unit_mm && a.bridge_levels == b.bridge_levels &&
           a.unjoinable_gap == b.unjoinable_gap && a.label_edges == b.label_edges && a.compact == b.compact &&
           a.normal_radius == b.normal_radius && a.metric == b.metric && a.normal_window == b.normal_window &&
           a.curvature_stride == b.curvature_stride && a.dt_per_m2 == b.dt_per_m2 &&
           a.ct_growth_per_m2 == b.ct_growth_per_m2;
}

// The cloud's unit in millimetres: --unit-mm when given (which always wins, with a warning when it puts the median
// depth out of every sensor's range), else the one its median depth says (detected_unit_mm), telling when that is
// metres so that nobody is surprised by it.
double cloud_unit_mm(const fs::path& input, const io::PointCloud& cloud, const Args& args, double given_unit_mm,
                     RunNotes& notes) {
    const double median = median_depth(cloud.points);
    if (args.value("unit-mm")) {
        const double metres = median * given_unit_mm / 1000.0;
        if (median > 0 && !plausible_median_metres(metres)) {
            std::fprintf(stderr,
                         "pyrseg: warning: %s: with --unit-mm %s the median depth is %.4g m, outside any depth "
                         "sensor's range (%g to %g m): is --unit-mm right? (1 for millimetres, 1000 for metres)\n",
                         printable(input).c_str(), args.value("unit-mm")->c_str(), metres, kPlausibleMedianMetresMin,
                         kPlausibleMedianMetresMax);
        }
        return given_unit_mm;
    }
    const double unit_mm = detected_unit_mm(median);
    if (unit_mm == 1000.0 && !notes.metres_read && !notes.quiet) {
        std::fprintf(stderr,
                     "pyrseg: note: %s: median depth %.3g units, so the cloud is read as metres (--unit-mm 1000); "
                     "pass --unit-mm 1 if it is in millimetres\n",
                     printable(input).c_str(), median);
        notes.metres_read = true;
    }
    return unit_mm;
}

// What a run without outputs prints under the frame's line: the segments' sizes, largest first, and how much of the
// frame they cover.
std::string size_summary(const Result& result, const io::PointCloud& cloud) {
    std::vector<std::uint32_t> labels;
    for (const std::uint32_t l : result.labels) {
        if (l != 0) labels.push_back(l);
    }
    std::sort(labels.begin(), labels.end());
    std::vector<std::size_t> sizes;
    for (std::size_t i = 0; i < labels.size();) {
        std::size_t j = i;
        while (j < labels.size() && labels[j] == labels[i]) ++j;
        sizes.push_back(j - i);
        i = j;
    }
    std::sort(sizes.begin(), sizes.end(), std::greater<>());
    std::size_t valid = 0;
    for (std::size_t i = 2; i < cloud.points.size(); i += 3) {
        if (std::isfinite(cloud.points[i]) && cloud.points[i] > 0) ++valid;
    }
    const std::size_t pixels = result.labels.size();
    std::string text = "  segment sizes in pixels, largest first:";
    constexpr std::size_t kShown = 10;
    for (std::size_t i = 0; i < sizes.size() && i < kShown; ++i) {
        text += i == 0 ? " " : ", ";
        text += std::to_string(sizes[i]);
    }
    if (sizes.empty()) text += " none";
    if (sizes.size() > kShown) {
        text +=
            ", ... (" + std::to_string(sizes.size()) + " in all, the smallest " + std::to_string(sizes.back()) + ")";
    }
    char coverage[160];
    std::snprintf(coverage, sizeof coverage, "\n  labelled: %zu of %zu pixels (%.1f%%); %zu valid points\n",
                  labels.size(), pixels, pixels > 0 ? 100.0 * double(labels.size()) / double(pixels) : 0.0, valid);
    text += coverage;
    text += "  nothing written: --labels, --png, --pcd, --ply, --stats ... write outputs (pyrseg segment --help)";
    return text;
}

FrameReport segment_frame(const fs::path& input, const Args& args, const Params& base_params, const OutputPaths& out,
                          std::unique_ptr<Segmenter>& segmenter, RunNotes& notes) {
    // NAME.png or NAME.ply in the input's own folder would be the input itself.
    for (const OutputOption& o : output_options()) {
        const std::optional<fs::path>& path = out.*o.path;
        std::error_code ec;
        if (path.has_value() && fs::equivalent(*path, input, ec)) {
            throw Error(ErrorCode::io, printable(*path) + ": is the input; refusing to overwrite it");
        }
    }
    const LoadedInput loaded = load_input(input, args);
    const io::PointCloud& cloud = loaded.cloud;
    Params frame_params = base_params;
    if (!loaded.millimetres) frame_params.unit_mm = cloud_unit_mm(input, cloud, args, base_params.unit_mm, notes);
    CloudView view;
    view.points = cloud.points.data();
    view.normals = cloud.normals.empty() ? nullptr : cloud.normals.data();
    view.width = cloud.width;
    view.height = cloud.height;
    view.color = loaded.color.empty() ? nullptr : loaded.color.data();
    const std::optional<SensorChoice> sensor = parse_sensor(args);
    std::string sensor_note;
    Params params = frame_params;
    std::optional<SensorKind> kind;  // the sensor the parameters are for, when one is named or chosen
    if (sensor && !sensor->automatic) kind = sensor->kind;
    // --sensor auto measures until it has chosen; without --sensor, a frame is measured for the hint until it has
    // been given (nothing else reads the measurement).
    std::optional<SensorKind> automatic = sensor && sensor->automatic ? notes.auto_sensor : std::nullopt;
    const bool measure = sensor ? sensor->automatic && !automatic : !notes.quiet && !notes.hinted;
    if (measure) {
        const FrameNoise noise = loaded.depth ? measure_frame_noise(loaded.depth->view(cloud.width, cloud.height))
                                              : measure_frame_noise(view, frame_params.unit_mm);
        if (sensor) {
            automatic = noise.suggested;
            if (noise.samples >= kMinFrameNoiseSamples) {
                notes.auto_sensor = noise.suggested;
                if (!notes.quiet) {
                    std::fprintf(stderr, "pyrseg: sensor auto: %s for this run, from %s: %s\n",
                                 sensor_kind_name(noise.suggested), printable(input).c_str(), noise.reason.c_str());
                }
            }
        } else if (noise.suggested != SensorKind::structured_light) {
            notes.hinted = true;
            std::fprintf(stderr,
                         "pyrseg: hint: %s: %s; the default parameters suit low-noise scanners. Try --sensor %s (or "
                         "--sensor auto, or the preset of your camera: --help lists them)\n",
                         printable(input).c_str(), noise.reason.c_str(), sensor_kind_name(noise.suggested));
        }
    }
    if (automatic) {
        kind = *automatic;
        params = parse_params(args, kind);
        params.unit_mm = frame_params.unit_mm;
        sensor_note = std::string(", sensor auto: ") + sensor_kind_name(*kind);
    }
    const bool warm_up = !segmenter || segmenter->width() != cloud.width || segmenter->height() != cloud.height ||
                         !same_params(segmenter->params(), params);
    if (warm_up) {
        Outputs outputs;
        outputs.fillable_mask = out.mask.has_value() || out.figure.has_value() || out.scene.has_value();
        outputs.segment_stats = out.stats.has_value() || out.scene.has_value();
        outputs.segment_graph = out.graph.has_value();
        // With --track the id image is always made: the pictures are coloured by it.
        outputs.segment_tracks = notes.track;
        outputs.track_ids = notes.track;
        if (notes.track && segmenter) {
            std::fprintf(stderr,
                         "pyrseg: warning: %s: the tracks restart at this frame (ids from 1 again): its size or "
                         "parameters differ from the previous frame's\n",
                         printable(input).c_str());
        }
        segmenter.reset();  // the old one's memory goes before the new one's is taken
        if (const std::optional<int> threads = args.integer("threads")) {  // checked by cmd_segment: 1..kMaxThreads
            segmenter = std::make_unique<Segmenter>(
                cpu::make_segmenter(cloud.width, cloud.height, unsigned(*threads), params, outputs));
        } else {
            segmenter = std::make_unique<Segmenter>(cloud.width, cloud.height, params,
                                                    args.value("backend").value_or(""), outputs);
        }
        notes.stream_frame = 0;
    }
    const auto start = std::chrono::steady_clock::now();
    DepthView depth_view;
    if (loaded.depth) {
        depth_view = loaded.depth->view(cloud.width, cloud.height);
        depth_view.color = view.color;
    }
    const Result result = loaded.depth ? segmenter->segment(depth_view) : segmenter->segment(view);
    const std::chrono::duration<double, std::milli> elapsed = std::chrono::steady_clock::now() - start;
    const std::uint32_t stream_frame = notes.stream_frame++;
    const io::SegmentTable table{result.width, result.height, params.unit_mm, input.string()};

    // All of the frame's outputs or none (tools/output_files.hpp).
    OutputFiles files;
    if (out.labels) {
        files.stage(*out.labels, [&](const fs::path& to) {
            write_id_image(to, result.labels, result.width, result.height, "label");
        });
    }
    if (out.track_ids) {
        files.stage(*out.track_ids, [&](const fs::path& to) {
            write_id_image(to, result.track_ids, result.width, result.height, "track id");
        });
    }
    if (out.png) files.stage(*out.png, [&](const fs::path& to) { write_png(to.string(), colorize_segments(result)); });
    if (out.mask) {
        files.stage(*out.mask, [&](const fs::path& to) {
            write_png(to.string(), mask_picture(result.fillable_mask, result.width, result.height));
        });
    }
    // The scene, for --scene and the figure's scene panel.
    Scene scene;
    if (out.scene) {
        describe_scene(result.segments, params, SceneParams{}, scene);
        fit_object_boxes(cloud.points, result.labels, result.fillable_mask, scene);
    }
    std::string scene_note;
    if (out.figure) {
        RgbImage figure;
        if (!out.scene) figure = comparison_figure(result);
        if (out.scene) {
            // With --scene, a fourth panel: the boxes and support outlines over the segments, projected through the
            // pinhole the cloud was made with (the depth image's intrinsics, or fitted to an organized cloud).
            if (const std::optional<PinholeCamera> camera = fit_pinhole(cloud)) {
                RgbImage base = colorize_segments(result);
                if (!loaded.color.empty()) base.rgb = loaded.color;
                std::vector<Panel> panels = comparison_panels(result);
                panels.push_back({"scene: " + std::to_string(scene.objects.size()) + " objects, " +
                                      std::to_string(scene.supports.size()) + " supports",
                                  scene_picture(dimmed_gray(base), coloured_as_segments(scene, result), *camera)});
                figure = side_by_side(panels);
            } else {
                figure = comparison_figure(result);
                scene_note = "; the figure has no scene panel: the cloud is not a pinhole camera's organized cloud";
            }
        }
        files.stage(*out.figure, [&](const fs::path& to) { write_png(to.string(), figure); });
    }
    if (out.ply) {
        files.stage(*out.ply, [&](const fs::path& to) { io::write_ply(to, cloud, colour_keys(result).data(), true); });
    }
    if (out.pcd) {
        // The segment's label, and with --scene the scene object and support each point's segment is (1 + its
        // index in the scene's JSON, 0: none), with --track its track id.
        std::vector<io::PcdField> fields = {{"label", result.labels.data()}};
        std::vector<std::uint32_t> object;
        std::vector<std::uint32_t> support;
        if (out.scene) {
            scene_index_images(scene, result.labels, object, support);
            fields.push_back({"object", object.data()});
            fields.push_back({"support", support.data()});
        }
        if (notes.track) fields.push_back({"track", result.track_ids.data()});
        files.stage(*out.pcd, [&](const fs::path& to) { io::write_pcd(to, cloud, fields, io::PcdEncoding::binary); });
    }
    std::string pcl_note;
    if (out.pcl_png) {
        const PclRun pcl = pcl_segment(cloud, params.unit_mm, kind);
        files.stage(*out.pcl_png, [&](const fs::path& to) {
            write_png(to.string(), colorize(pcl.labels, cloud.width, cloud.height));
        });
        pcl_note = "; " + std::to_string(pcl.regions) + " PCL regions (" + pcl.settings + ")";
    }
    if (out.stats) {
        files.stage(*out.stats, [&](const fs::path& to) { io::write_segment_stats(to, result.segments, table); });
    }
    if (out.graph) {
        files.stage(*out.graph, [&](const fs::path& to) { io::write_segment_graph(to, result.graph, table); });
    }
    if (out.tracks) {
        files.stage(*out.tracks, [&](const fs::path& to) {
            write_text_file(to, segment_tracks_text(result.tracks, table, stream_frame, lower_extension(to) == ".csv"));
        });
    }
    if (out.scene) {
        files.stage(*out.scene, [&](const fs::path& to) {
            // The mesh in the pictures' colours; the JSON names the segments by label, as --stats does.
            io::write_scene(to, lower_extension(to) == ".ply" ? coloured_as_segments(scene, result) : scene, table);
        });
    }
    files.commit();
    const std::string unit_note =
        !loaded.millimetres && !args.value("unit-mm") && params.unit_mm == 1000.0 ? " in metres" : "";
    char line[512];
    std::snprintf(line, sizeof line, "%s, %d x %d, normals %s, %u segments, %.1f ms on %s%s%s%s", unit_note.c_str(),
                  result.width, result.height, cloud.normals.empty() ? "estimated" : "from file", result.segment_count,
                  elapsed.count(), segmenter->backend_name().c_str(), warm_up ? ", including warm-up" : "",
                  sensor_note.c_str(), (pcl_note + scene_note).c_str());
    std::string report = printable(input) + ": " + loaded.kind + line;
    if (!out.any()) {
        report += '\n';
        report += size_summary(result, cloud);
    }
    return {report, result.segment_count, elapsed.count(), warm_up};
}

// Folders expand to their supported files, glob patterns to their matches (name order), other names stay. With
// --color DIR, a folder's NAME_color.png files are colour images, not frames.
std::vector<fs::path> expand_inputs(const std::vector<std::string>& names, bool color_images) {
    std::vector<fs::path> inputs;
    for (const std::string& name : names) {
        std::error_code ec;
        if (fs::is_directory(name, ec)) {
            std::vector<fs::path> found;
            for (const fs::directory_entry& e : fs::directory_iterator(name, ec)) {
                const bool color_image = color_images && e.path().filename().string().ends_with("_color.png");
                if (e.is_regular_file(ec) && is_supported_input(e.path()) && !color_image) found.push_back(e.path());
            }
            std::sort(found.begin(), found.end());
            // A warning, not a note: a name that brings no frame is likely a mistake, and --quiet keeps warnings.
            if (found.empty()) {
                std::fprintf(stderr, "pyrseg: warning: %s holds no .pcd/.ply/.npy/.png/.tif/.tiff file\n",
                             printable(name).c_str());
            }
            inputs.insert(inputs.end(), found.begin(), found.end());
        } else if (name.find_first_of("*?[") != std::string::npos && !fs::exists(name, ec)) {
            glob_t matches{};
            if (::glob(name.c_str(), 0, nullptr, &matches) == 0) {
                for (std::size_t i = 0; i < matches.gl_pathc; ++i) inputs.emplace_back(matches.gl_pathv[i]);
            } else {
                std::fprintf(stderr, "pyrseg: warning: pattern '%s' matches nothing\n", printable(name).c_str());
            }
            globfree(&matches);
        } else {
            inputs.emplace_back(name);
        }
    }
    return inputs;
}

std::set<std::string> parse_write_list(const std::string& text, bool track) {
    constexpr const char* kKinds = "labels, png, mask, figure, ply, pcd, stats, graph, scene, track_ids, tracks";
    std::set<std::string> kinds;
    std::stringstream in(text);
    std::string item;
    while (std::getline(in, item, ',')) {
        if (batch_output_suffixes().count(item) == 0) {
            throw UsageError{std::string("--write expects a list of ") + kKinds + "; got '" + item + "'"};
        }
        if ((item == "track_ids" || item == "tracks") && !track) {
            throw UsageError{"--write " + item + " needs --track (the frames as one stream whose segments keep ids)"};
        }
        kinds.insert(item);
    }
    if (kinds.empty()) throw UsageError{std::string("--write needs at least one of ") + kKinds};
    return kinds;
}

// What a batch's summary says of the segmentation times: the first frame's apart, since it includes the warm-up
// (kernel builds, first-touch allocation) and is several times a typical frame's.
struct BatchTimes {
    std::size_t frames = 0;
    double first_ms = 0;
    double others_ms = 0;         // the sum over the frames after the first
    std::size_t others_warm = 0;  // of those, frames on a new Segmenter (a new size or parameters)

    void add(const FrameReport& r) {
        if (frames++ == 0) {
            first_ms = r.milliseconds;
            return;
        }
        others_ms += r.milliseconds;
        if (r.warm_up) ++others_warm;
    }
    [[nodiscard]] std::string summary() const {
        char text[256];
        if (frames == 0) return "segmentation: no frame";
        if (frames == 1) {
            std::snprintf(text, sizeof text, "segmentation: %.1f ms (one frame, including warm-up)", first_ms);
            return text;
        }
        std::snprintf(text, sizeof text,
                      "segmentation: the first frame %.1f ms (warm-up), the others %.1f ms per frame", first_ms,
                      others_ms / double(frames - 1));
        std::string said = text;
        if (others_warm > 0) {
            said +=
                " (" + std::to_string(others_warm) + " of them on a new frame size or parameters, with its warm-up)";
        }
        return said;
    }
};

int run_batch(const Args& args, const Params& params, RunNotes& notes) {
    const std::string out_dir_name = *args.value("out-dir");
    const fs::path out_dir = out_dir_name;
    const std::set<std::string> kinds = parse_write_list(
        args.value("write").value_or(notes.track ? "labels,png,track_ids" : "labels,png"), notes.track);
    const std::vector<fs::path> inputs = expand_inputs(args.positional(), args.value("color").has_value());
    if (inputs.empty()) throw Error(ErrorCode::io, "the batch has no input file");
    make_output_folder(out_dir_name);
    // Every frame's names before the first is read: none may replace an input or another frame's output.
    const std::vector<PlannedFrame> plan = plan_batch(inputs, out_dir, kinds);

    const std::optional<std::string> progress_option = args.value("progress");
    const Progress::Style style = notes.quiet && !progress_option
                                      ? Progress::Style::none
                                      : Progress::style_for(progress_option.value_or("auto"), stderr);
    Progress progress(inputs.size(), style, stderr);
    std::unique_ptr<Segmenter> segmenter;
    std::vector<std::string> failures;
    BatchTimes times;
    std::uint64_t total_segments = 0;
    for (const PlannedFrame& frame : plan) {
        OutputPaths out;
        const auto planned = [&](const char* kind) -> std::optional<fs::path> {
            const auto at = frame.outputs.find(kind);
            if (at == frame.outputs.end()) return std::nullopt;
            return at->second;
        };
        out.labels = planned("labels");
        out.png = planned("png");
        out.mask = planned("mask");
        out.figure = planned("figure");
        out.ply = planned("ply");
        out.pcd = planned("pcd");
        out.stats = planned("stats");
        out.graph = planned("graph");
        out.scene = planned("scene");
        out.track_ids = planned("track_ids");
        out.tracks = planned("tracks");
        std::string failure;
        try {
            const FrameReport r = segment_frame(frame.input, args, params, out, segmenter, notes);
            times.add(r);
            total_segments += r.segments;
            progress.frame_done(r.line, false);
            continue;
        } catch (const UsageError& e) {
            // An input option that does not apply to this kind of input (--intrinsics on a cloud in a batch of
            // depth images): this frame's failure, not the batch's end.
            failure = "pyrseg: " + printable(frame.input) + ": " + e.message +
                      " (this batch's input options fit only some of its frames: segment clouds and depth images in "
                      "separate batches)";
        } catch (const std::exception& e) {  // pyrseg::Error, or what a library still throws: the batch goes on
            failure = printable(e.what());
        }
        failures.push_back(failure);
        progress.frame_done("failed: " + failure, true);
    }
    progress.finish();
    const std::size_t ok = inputs.size() - failures.size();
    const double seconds = progress.elapsed_seconds();
    std::printf(
        "batch: %zu frames, %zu segmented, %zu failed, %.1f s (%.1f frames/s); %s, %.1f segments per frame; "
        "outputs in %s\n",
        inputs.size(), ok, failures.size(), seconds, seconds > 0 ? double(inputs.size()) / seconds : 0.0,
        times.summary().c_str(), ok > 0 ? double(total_segments) / double(ok) : 0.0, printable(out_dir).c_str());
    for (const std::string& f : failures) std::printf("  failed: %s\n", f.c_str());
    return failures.empty() ? 0 : 1;
}

}  // namespace

// Which backend the frames will run on, and why, once (the per-frame lines name it too): an explicit --backend needs
// no reason. The reason auto gives names every emulated device it passed by (hundreds of characters): one short
// line says the gist, -v the whole.
void say_backend_choice(const Args& args, const RunNotes& notes) {
    if (notes.quiet || (args.value("backend") && *args.value("backend") != "auto")) return;
    if (const std::optional<int> threads = args.integer("threads")) {
        std::fprintf(stderr, "pyrseg: backend cpu (--threads %d: an arena of %d threads of its own)\n", *threads,
                     *threads);
        return;
    }
    const BackendChoice choice = choose_backend(args.value("backend").value_or(""));
    std::string reason = choice.reason;
    if (!args.flag("verbose")) {
        if (reason.starts_with("auto: ")) reason.erase(0, 6);
        if (const std::size_t detail = reason.find(" ("); detail != std::string::npos) {
            reason = reason.substr(0, detail) + "; -v says why";
        }
    }
    std::fprintf(stderr, "pyrseg: backend %s (%s)\n", choice.name.c_str(), printable(reason).c_str());
}

int cmd_segment(const std::vector<std::string>& argv) {
    std::set<std::string> values = kParameterValueOptions;
    values.insert(kInputValueOptions.begin(), kInputValueOptions.end());
    values.insert(kTrackValueOptions.begin(), kTrackValueOptions.end());
    for (const OutputOption& o : output_options()) values.insert(o.name);
    values.insert({"backend", "out-dir", "write", "progress", "color", "threads"});
    std::set<std::string> flags = kParameterFlagOptions;
    flags.insert({"help", "quiet", "verbose", "track"});
    const Args args(argv, values, flags, {{"-q", "quiet"}, {"-v", "verbose"}});
    if (args.flag("help")) {
        std::string usage = kSegmentUsage;
        usage.replace(usage.find("@BACKENDS@"), 10, backend_names_text());
        std::printf("%s%s%s%s", usage.c_str(), kInputHelp, kParameterHelp, kTrackParameterHelp);
        return 0;
    }
    // Every option is checked before the first input is read: a mistake costs a message, not a partial run.
    const OutputPaths out = output_paths(args);
    if (args.flag("quiet") && args.flag("verbose")) throw UsageError{"give --quiet or --verbose, not both"};
    if (const std::optional<int> threads = args.integer("threads")) {
        if (*threads < 1 || *threads > int(cpu::kMaxThreads)) {
            throw UsageError{"--threads must be in 1.." + std::to_string(cpu::kMaxThreads) + ", got " +
                             std::to_string(*threads)};
        }
        const std::string backend = args.value("backend").value_or("cpu");
        if (backend != "cpu" && backend != "auto") {
            throw UsageError{"--threads sets the CPU backend's threads: --backend " + printable(backend) +
                             " has none (give --backend cpu, or leave --threads out)"};
        }
    }
    RunNotes notes;
    notes.quiet = args.flag("quiet");
    notes.track = args.flag("track");
    if (!notes.track) {
        for (const char* option : {"track-ids", "tracks", "track-max-distance", "track-hold"}) {
            if (args.value(option)) {
                throw UsageError{"--" + std::string(option) +
                                 " needs --track (the frames as one stream whose segments keep ids)"};
            }
        }
    }
    if (notes.track && args.flag("raw")) {
        throw UsageError{"--track follows the compacted labels 1..K: leave out --raw"};
    }
    check_input_options(args);
    const Params params = parse_params(args);
    if (args.value("out-dir")) {
        if (args.positional().empty()) throw UsageError{"expects at least one INPUT (file, folder or pattern)"};
        if (out.any()) throw UsageError{"in a batch (--out-dir), choose the outputs with --write, not file names"};
        if (args.value("out-dir")->empty()) throw UsageError{"--out-dir needs a folder name (\".\" for this one)"};
        if (const auto color = args.value("color"); color && !fs::is_directory(*color)) {
            throw UsageError{
                "in a batch (--out-dir), --color names the folder of the frames' NAME_color.png images, "
                "not a file: " +
                printable(*color)};
        }
        say_backend_choice(args, notes);
        return run_batch(args, params, notes);
    }
    if (args.value("write") || args.value("progress")) throw UsageError{"--write and --progress need --out-dir"};
    if (args.positional().size() != 1) {
        throw UsageError{"expects exactly one INPUT file (for a batch of several, give --out-dir)"};
    }
    if (const auto color = args.value("color"); color && fs::is_directory(*color)) {
        throw UsageError{"--color names the colour image of the one INPUT (a folder is for batches): " +
                         printable(*color)};
    }
    check_outputs(named_outputs(out));
    say_backend_choice(args, notes);
    std::unique_ptr<Segmenter> segmenter;
    std::printf("%s\n", segment_frame(args.positional()[0], args, params, out, segmenter, notes).line.c_str());
    return 0;
}

}  // namespace pyrseg::cli
