#include <set>
#include <string>

#include "pyrseg/error.hpp"
#include "tools/commands.hpp"

namespace pyrseg::cli {

const char* const kParameterHelp =
    "Segmentation parameters (defaults from the algorithm contract, docs/algorithm.md):\n"
    "  --sensor NAME         start from the preset for a kind of depth sensor; the options below override it:\n"
    "                          structured-light  low-noise scanners (PhoXi-like): the defaults\n"
    "                          kinect-v1         Kinect v1, Xtion, Orbbec Astra (disparity-stepped depth)\n"
    "                          realsense-d435    RealSense D4xx and other active stereo cameras\n"
    "                          azure-kinect      Azure Kinect, Kinect v2 and other time-of-flight cameras\n"
    "                          auto              choose from the first frame's depth (its noise, whole-millimetre\n"
    "                                            depth, disparity steps, stereo shadows), once for the run\n"
    "                        Without --sensor the defaults apply, and pyrseg says when a frame looks noisier than\n"
    "                        they suit. docs/quality.md has each preset's values and measurements.\n"
    "  --ct RADIANS          curvature threshold: neighbouring normals more than this angle apart (on average)\n"
    "                        make an edge. Default 0.25; >= 3.1416 disables curvature edges.\n"
    "  --dt MM               depth threshold in millimetres: a spread of neighbour depth differences above this\n"
    "                        makes an edge. Default 10.\n"
    "  --unit-mm U           millimetres per cloud unit: 1 for millimetres, 1000 for metres. Default: metres for a\n"
    "                        cloud whose median depth is under 20 units (no sensor sees that close in\n"
    "                        millimetres), else millimetres. A given value always wins.\n"
    "  --bridge-levels B     pyramid levels below full resolution at which seeds stop being created (default 2;\n"
    "                        3 for scenes with many bridges).\n"
    "  --unjoinable-gap G    levels between the seeding level and the level whose regions never merge (default 2).\n"
    "  --normal-radius R     neighbour distance in pixels for estimated normals (default 2); larger smooths noise.\n"
    "                        Scale it with pixel density: twice the pixels across the same view, twice the radius.\n"
    "  --metric NAME         paper (default: the contract's metric, for low-noise scanners) or robust (window\n"
    "                        normals, thresholds that grow with depth; for consumer depth cameras).\n"
    "  --normal-window R     robust: estimated normals sum tangents over a (2R+1)^2 window (1..7, default 3).\n"
    "  --curvature-stride S  robust: the normals S pixels before and after each pixel are compared (1..64,\n"
    "                        default 4).\n"
    "  --dt-per-m2 MM        robust: millimetres added to --dt per square metre of depth (default 0).\n"
    "  --ct-growth G         robust: 1 - cos(ct) grows by G per square metre of depth (default 0).\n"
    "  --edge-rounds E       label edge pixels up to E steps from a segment (1..63, default 1: the contract's one\n"
    "                        layer); the robust presets use more, to share out their wider edge bands.\n"
    "  --edge-max-depth-step S   rounds after the first label a pixel only from neighbours whose depth is within\n"
    "                        S times its own (0..1, default 0: no test; the robust presets use 0.02), so that a\n"
    "                        band's labels do not cross an object's outline. Needs a cloud or depth image.\n"
    "  --no-label-edges      leave edge pixels unlabelled (0) instead of joining them to a neighbouring segment.\n"
    "  --merge               after the pyramid, join segments that meet along a convex or flat boundary (an\n"
    "                        object's faces and parts), never across a concave crease or a depth step (an object\n"
    "                        and the table under it). Needs a cloud or depth image, not a mask.\n"
    "  --no-merge            leave the segments as the pyramid made them (undoes a preset's --merge).\n"
    "  --merge-reach R       measure each boundary crossing up to R pixels into both sides (1..16, default 2).\n"
    "  --merge-tolerance MM  how far each side may lie above the other's tangent plane and still count as convex\n"
    "                        or flat (default 1 mm), plus --merge-tolerance-per-m2 MM per square metre of depth.\n"
    "  --merge-min-crossings C   a boundary shorter than C crossings never joins (default 16).\n"
    "  --merge-max-bad S     the share of a boundary's crossings that may be concave or steps (0..1, default 0.05).\n"
    "  --color-edge-threshold T   with a colour image (--color), a pixel whose neighbours along its row or column\n"
    "                        differ by more than T (|dR| + |dG| + |dB|, 0..765) is an edge (default: 765, the\n"
    "                        colour unused; realsense-d435: 100, with --color-edge-curvature 0.3).\n"
    "  --color-edge-stride S those neighbours lie S pixels either side of it (1..16, default 1).\n"
    "  --color-edge-curvature G   a colour edge cuts only where the normals across the pixel turn by more than G\n"
    "                        (0..1) of the curvature limit: a crease too weak for the metric, as where a stereo\n"
    "                        camera rounds an object's foot into the table, but not print, grain or shadows on a\n"
    "                        flat or smooth surface (--metric robust; default 0: every colour edge cuts;\n"
    "                        realsense-d435: 0.3).\n"
    "  --planar-tolerance MM a segment is planar (--stats) when its points lie within MM RMS of their plane\n"
    "                        (default 2 mm), plus --planar-tolerance-per-m2 MM per square metre of depth.\n"
    "  --raw                 write raw pyramid labels instead of compacted 1..K.\n";

const char* const kTrackParameterHelp =
    "Track parameters (docs/algorithm.md section 11):\n"
    "  --track-max-distance MM   a segment that no segment of the previous frame overlaps enough takes the id of a\n"
    "                        track whose centroid, moved by the camera's motion, is at most MM millimetres from its\n"
    "                        own (default 50; 0 finds only a track exactly where it was)\n"
    "  --track-hold FRAMES   a track not seen for more than FRAMES frames is dropped; one seen again within them\n"
    "                        (an object hidden for a while) gets its id back (0..1000, default 10)\n";

const std::set<std::string> kTrackValueOptions = {"track-max-distance", "track-hold"};

const std::set<std::string> kParameterValueOptions = {"ct",
                                                      "dt",
                                                      "unit-mm",
                                                      "bridge-levels",
                                                      "unjoinable-gap",
                                                      "normal-radius",
                                                      "metric",
                                                      "sensor",
                                                      "normal-window",
                                                      "curvature-stride",
                                                      "dt-per-m2",
                                                      "ct-growth",
                                                      "edge-rounds",
                                                      "edge-max-depth-step",
                                                      "merge-reach",
                                                      "merge-tolerance",
                                                      "merge-tolerance-per-m2",
                                                      "merge-min-crossings",
                                                      "merge-max-bad",
                                                      "color-edge-threshold",
                                                      "color-edge-stride",
                                                      "color-edge-curvature",
                                                      "planar-tolerance",
                                                      "planar-tolerance-per-m2"};
const std::set<std::string> kParameterFlagOptions = {"no-label-edges", "raw", "merge", "no-merge"};

std::optional<SensorChoice> parse_sensor(const Args& args) {
    const std::optional<std::string> name = args.value("sensor");
    if (!name) return std::nullopt;
    if (*name == "auto") return SensorChoice{true, SensorKind::structured_light};
    if (auto kind = sensor_kind_from_name(*name)) return SensorChoice{false, *kind};
    std::string known;
    for (SensorKind k : sensor_kinds()) known += std::string(sensor_kind_name(k)) + ", ";
    throw Error(ErrorCode::invalid_argument, "--sensor: unknown sensor '" + *name + "'; known: " + known + "auto");
}

Params parse_params(const Args& args, std::optional<SensorKind> preset) {
    Params p;
    if (!preset) {
        if (auto choice = parse_sensor(args); choice && !choice->automatic) preset = choice->kind;
    }
    if (preset) p = sensor_preset(*preset);
    if (auto v = args.number("ct")) p.ct = *v;
    if (auto v = args.number("dt")) p.dt = *v;
    if (auto v = args.number("unit-mm")) p.unit_mm = *v;
    if (auto v = args.integer("bridge-levels")) p.bridge_levels = *v;
    if (auto v = args.integer("unjoinable-gap")) p.unjoinable_gap = *v;
    if (auto v = args.integer("normal-radius")) p.normal_radius = *v;
    if (auto v = args.value("metric")) {
        if (*v == "paper") {
            p.metric = Metric::paper;
        } else if (*v == "robust") {
            p.metric = Metric::robust;
        } else {
            throw Error(ErrorCode::invalid_argument, "--metric must be paper or robust, got '" + *v + "'");
        }
    }
    if (auto v = args.integer("normal-window")) p.normal_window = *v;
    if (auto v = args.integer("curvature-stride")) p.curvature_stride = *v;
    if (auto v = args.number("dt-per-m2")) p.dt_per_m2 = *v;
    if (auto v = args.number("ct-growth")) p.ct_growth_per_m2 = *v;
    if (auto v = args.integer("edge-rounds")) p.edge_rounds = *v;
    if (auto v = args.number("edge-max-depth-step")) p.edge_max_depth_step = *v;
    if (args.flag("merge") && args.flag("no-merge")) {
        throw Error(ErrorCode::invalid_argument, "--merge and --no-merge contradict each other");
    }
    if (args.flag("merge")) p.merge = true;
    if (args.flag("no-merge")) p.merge = false;
    if (auto v = args.integer("merge-reach")) p.merge_reach = *v;
    if (auto v = args.number("merge-tolerance")) p.merge_tolerance_mm = *v;
    if (auto v = args.number("merge-tolerance-per-m2")) p.merge_tolerance_per_m2 = *v;
    if (auto v = args.integer("merge-min-crossings")) p.merge_min_crossings = *v;
    if (auto v = args.number("merge-max-bad")) p.merge_max_bad_share = *v;
    if (auto v = args.integer("color-edge-threshold")) p.color_edge_threshold = *v;
    if (auto v = args.integer("color-edge-stride")) p.color_edge_stride = *v;
    if (auto v = args.number("color-edge-curvature")) p.color_edge_curvature_share = *v;
    if (auto v = args.number("planar-tolerance")) p.planar_tolerance_mm = *v;
    if (auto v = args.number("planar-tolerance-per-m2")) p.planar_tolerance_per_m2 = *v;
    if (auto v = args.number("track-max-distance")) p.track_max_distance_mm = *v;
    if (auto v = args.integer("track-hold")) p.track_hold_frames = *v;
    p.label_edges = !args.flag("no-label-edges");
    p.compact = !args.flag("raw");
    return p;
}

}  // namespace pyrseg::cli
