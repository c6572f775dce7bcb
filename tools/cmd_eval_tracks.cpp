// `pyrseg eval --tracks`: segment ids that carry over from frame to frame (Outputs::segment_tracks) against the
// ground truth's objects on synthetic sequences from a moving camera, beside plain per-frame labels and the host-side
// matcher a user would write (tools/eval/tracks.hpp; docs/quality.md).
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "pyrseg/error.hpp"
#include "pyrseg/presets.hpp"
#include "pyrseg/segmenter.hpp"
#include "pyrseg/synthetic.hpp"
#include "tools/args.hpp"
#include "tools/commands.hpp"
#include "tools/eval/tracks.hpp"
#include "tools/eval_sensors.hpp"
#include "tools/figures.hpp"
#include "tools/output_files.hpp"
#include "tools/printable.hpp"
#include "tools/progress.hpp"

namespace pyrseg::cli {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

constexpr const char* kTracksUsage =
    "Usage: pyrseg eval --tracks [--sensors NAME,...] [--frames N] [--seeds N] [--size WxH]\n"
    "                   [--scenarios camera,objects] [--max-step MM] [--max-turn DEG] [--match-iou X,...]\n"
    "                   [--min-pixels N] [--params preset|default] [--out-dir DIR] [--progress auto|bar|lines|none]\n"
    "                   [--quick] [parameters]\n"
    "\n"
    "Measures how well segment ids carry over from frame to frame (Outputs::segment_tracks, docs/algorithm.md\n"
    "section 11) on synthetic sequences with ground truth: the seeded bin-picking scene (synthetic::sequence) seen\n"
    "from a camera on a smooth random walk of up to --max-step mm (default 20) and --max-turn degrees (default 2)\n"
    "a frame, through each sensor model (structured-light, kinect-v1, realsense-d435, azure-kinect; pyrseg with\n"
    "that sensor's preset, CPU backend; --params default: the defaults), every frame with its own noise. Scenarios:\n"
    "  camera    the camera moves, the objects stay\n"
    "  objects   the camera moves, and objects slide along the floor, are hidden for 2..8 frames (occluded) and\n"
    "            come back, leave for good, or appear later\n"
    "Methods, over the same frames and the same labels:\n"
    "  pyrseg             the track ids (Result::track_ids)\n"
    "  per-frame labels   the labels as ids (each frame numbers its segments afresh)\n"
    "  Hungarian IoU>=X   a host-side matcher as a user would write it: each frame's segments matched to the\n"
    "                     previous frame's ids by the assignment that maximizes shared pixels (Kuhn-Munkres),\n"
    "                     pairs with IoU >= X only, new ids for the rest (--match-iou, default 0.1,0.3)\n"
    "\n"
    "Scored on the ground truth's objects (not the floor or the bin) in view: at least --min-pixels pixels\n"
    "(default 300 at 640x480, scaled with the image's area, at least 20). Per frame an object is matched to the id\n"
    "covering most of its pixels among those with IoU >= 0.5, or missed. Per method, as multi-object tracking\n"
    "scores them:\n"
    "  ID switches       a matched frame whose id differs from the object's previous matched frame's (CLEAR MOT);\n"
    "                    per object per 100 frames in view, counting only switches while the object stayed in\n"
    "                    view (not across frames it was out of view or hidden); the worst object's rate (objects\n"
    "                    in view >= 100 frames); and every switch\n"
    "  IDF1              2 IDTP / (2 IDTP + IDFP + IDFN) over the objects' frames in view and the predicted\n"
    "                    detections (matched ids, and ids of >= --min-pixels pixels lying mostly on objects),\n"
    "                    IDTP from the one-to-one assignment of objects to ids over the sequence with the most\n"
    "                    frames matched (Ristani et al. 2016)\n"
    "  IDTP / matched    of the frames an object was matched in, the share under the id IDF1's assignment gave\n"
    "                    it: identity alone, without the misses that bound IDF1\n"
    "  fragmentations    the times an object matched in one frame is missed in its next frame in view, between\n"
    "                    its first and last match (the same for the three: they label the same segments)\n"
    "  frames/s          segmentation (with tracks for pyrseg), plus the matcher for the host-side matchers\n"
    "\n"
    "  --sensors NAME,...  sensor models (default: all)\n"
    "  --frames N          frames per sequence (default 300)\n"
    "  --seeds N           sequences per sensor model and scenario, scene seeds 1..N (default 2)\n"
    "  --size WxH          frame size (default 640x480)\n"
    "  --scenarios LIST    camera, objects, or both (default camera,objects)\n"
    "  --quick             a short run: 320x240, 30 frames, 1 seed, structured-light and kinect-v1; the other\n"
    "                      options override it\n"
    "Writes DIR/tracks.md (--out-dir, default pyrseg-eval-tracks): a table per scenario, the acceptance checks of\n"
    "docs/quality.md (camera motion: at most 1 in-view ID switch per object per 100 frames, IDF1 >= 0.9, no worse\n"
    "than every host-side matcher on any sequence) and every sequence's scores. Progress goes to stderr.\n";

constexpr double kMaxSwitchesPer100 = 1.0;
constexpr double kMinIdf1 = 0.9;

template <class... Values>
std::string printed(const char* fmt, Values... values) {
    char buffer[256];
    std::snprintf(buffer, sizeof buffer, fmt, values...);
    return buffer;
}

std::string fixed(const char* fmt, double v) {
    return std::isnan(v) ? "n/a" : printed(fmt, v);
}

enum class Scenario : std::uint8_t { camera, objects };

const char* scenario_name(Scenario s) {
    return s == Scenario::camera ? "camera" : "objects";
}

struct Method {
    std::string name;
    std::optional<double> match_iou;  // the host-side matcher's threshold; none: pyrseg's ids or the labels
    bool labels = false;              // per-frame labels
};

// One sequence's scores, per method.
struct SequenceScores {
    synthetic::Sensor sensor{};
    Scenario scenario{};
    int seed = 0;
    std::vector<eval::TrackScores> scores;
    std::vector<double> seconds;  // per method
    // pyrseg's in-view switches by how the segment got the id it switched to (TrackMatch: new, overlap, position).
    std::array<std::uint64_t, 3> switch_causes{};
};

struct Options {
    std::vector<synthetic::Sensor> sensors;
    std::vector<Scenario> scenarios;
    int frames = 300;
    int seeds = 2;
    int width = 640, height = 480;
    double max_step = 20, max_turn = 2;
    std::uint32_t min_pixels = 300;
    bool preset = true;
};

// Whether pyrseg's ids (method 0) are no worse than every host-side matcher's on this sequence: IDF1 at least
// theirs and no more in-view switches.
bool no_worse_than_hosts(const SequenceScores& s, const std::vector<Method>& methods) {
    for (std::size_t m = 0; m < methods.size(); ++m) {
        if (!methods[m].match_iou) continue;
        if (s.scores[0].idf1() < s.scores[m].idf1()) return false;
        if (s.scores[0].switches_in_view > s.scores[m].switches_in_view) return false;
    }
    return true;
}

// The frames a sequence's picture shows: a row of per-frame labels over a row of track ids, so that the colours
// that change under the labels and stay under the ids are side by side.
constexpr std::size_t kPictureFrames[] = {0, 4, 8, 12};

// Rows of panels (each row side_by_side) one under the other.
RgbImage stacked(const std::vector<RgbImage>& rows) {
    RgbImage out;
    for (const RgbImage& row : rows) out.width = std::max(out.width, row.width);
    for (const RgbImage& row : rows) out.height += row.height;
    out.rgb.assign(3 * std::size_t(out.width) * std::size_t(out.height), 0);
    int y0 = 0;
    for (const RgbImage& row : rows) {
        for (int y = 0; y < row.height; ++y) {
            std::copy_n(row.rgb.begin() + 3 * std::ptrdiff_t(y) * row.width, 3 * std::ptrdiff_t(row.width),
                        out.rgb.begin() + 3 * std::ptrdiff_t(y0 + y) * out.width);
        }
        y0 += row.height;
    }
    return out;
}

SequenceScores run_sequence(const Options& o, synthetic::Sensor sensor, Scenario scenario, int seed,
                            const Params& params, const std::vector<Method>& methods, Progress& progress,
                            std::uint64_t& label_mismatches, const fs::path& picture) {
    synthetic::SequenceOptions so;
    so.scene.width = o.width;
    so.scene.height = o.height;
    so.scene.seed = std::uint64_t(seed);
    so.scene.sensor = sensor;
    so.frames = o.frames;
    so.max_step_mm = o.max_step;
    so.max_turn_deg = o.max_turn;
    so.object_motion = scenario == Scenario::objects;
    const std::vector<synthetic::SceneOptions> frames = synthetic::sequence(so);

    Outputs tracked_outputs;
    tracked_outputs.segment_tracks = true;
    tracked_outputs.track_ids = true;
    Segmenter tracked(o.width, o.height, params, "cpu", tracked_outputs);
    Segmenter plain(o.width, o.height, params, "cpu", Outputs{});
    std::vector<eval::OverlapMatcher> matchers;
    matchers.reserve(methods.size());
    for (const Method& m : methods) matchers.emplace_back(m.match_iou.value_or(0.0));

    SequenceScores out;
    out.sensor = sensor;
    out.scenario = scenario;
    out.seed = seed;
    out.seconds.assign(methods.size(), 0.0);
    std::vector<std::vector<eval::FrameMatches>> matches(methods.size());
    Result with_tracks, labels;
    std::vector<std::vector<SegmentTrack>> tracks(frames.size());  // pyrseg's, per frame
    std::vector<std::uint32_t> ids;
    std::vector<Panel> label_panels, id_panels;
    const std::string name =
        std::string(synthetic::sensor_name(sensor)) + ", " + scenario_name(scenario) + ", seed " + std::to_string(seed);
    for (std::size_t f = 0; f < frames.size(); ++f) {
        const synthetic::Scene scene = synthetic::generate(frames[f]);
        CloudView view;
        view.points = scene.points.data();
        view.width = scene.width;
        view.height = scene.height;
        const auto t0 = Clock::now();
        tracked.segment(view, with_tracks);
        const auto t1 = Clock::now();
        plain.segment(view, labels);
        const auto t2 = Clock::now();
        const double tracked_s = std::chrono::duration<double>(t1 - t0).count();
        const double plain_s = std::chrono::duration<double>(t2 - t1).count();
        if (with_tracks.labels != labels.labels) ++label_mismatches;
        if (!picture.empty() &&
            std::find(std::begin(kPictureFrames), std::end(kPictureFrames), f) != std::end(kPictureFrames)) {
            const std::string frame = "frame " + std::to_string(f);
            label_panels.push_back({frame + ": labels", colorize(labels.labels, o.width, o.height)});
            id_panels.push_back({frame + ": track ids", colorize(with_tracks.track_ids, o.width, o.height)});
        }
        tracks[f] = with_tracks.tracks;
        for (std::size_t m = 0; m < methods.size(); ++m) {
            const std::vector<std::uint32_t>* scored = &labels.labels;
            if (m == 0) {
                scored = &with_tracks.track_ids;
                out.seconds[m] += tracked_s;
            } else if (methods[m].labels) {
                out.seconds[m] += plain_s;
            } else {
                const auto m0 = Clock::now();
                matchers[m].track(labels.labels, ids);
                out.seconds[m] += plain_s + std::chrono::duration<double>(Clock::now() - m0).count();
                scored = &ids;
            }
            matches[m].push_back(eval::match_frame(scene.object_id, *scored, synthetic::kFirstObjectId, o.min_pixels));
        }
        progress.frame_done(name + ": frame " + std::to_string(f + 1) + "/" + std::to_string(frames.size()), false);
    }
    if (!label_panels.empty())
        write_png(picture.string(), stacked({side_by_side(label_panels), side_by_side(id_panels)}));
    std::vector<eval::SwitchEvent> switches;
    for (std::size_t m = 0; m < methods.size(); ++m) {
        out.scores.push_back(eval::score_tracks(matches[m], m == 0 ? &switches : nullptr));
    }
    for (const eval::SwitchEvent& e : switches) {
        for (const SegmentTrack& t : tracks[e.frame]) {
            if (t.id == e.id) ++out.switch_causes[static_cast<std::size_t>(t.how)];
        }
    }
    return out;
}

std::string table(const std::vector<SequenceScores>& runs, const Options& o, Scenario scenario,
                  const std::vector<Method>& methods) {
    std::ostringstream md;
    md << "| sensor | method | objects | object frames | matched | ID switches per object per 100 frames in view "
          "| worst object | ID switches, all | IDF1 | IDTP / matched | fragmentations | frames/s |\n"
          "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
    for (const synthetic::Sensor sensor : o.sensors) {
        for (std::size_t m = 0; m < methods.size(); ++m) {
            eval::TrackScores total;
            double seconds = 0;
            for (const SequenceScores& r : runs) {
                if (r.sensor != sensor || r.scenario != scenario) continue;
                total.add(r.scores[m]);
                seconds += r.seconds[m];
            }
            if (total.sequences == 0) continue;
            const bool ours = m == 0;
            const auto bold = [&](const std::string& cell) { return ours ? "**" + cell + "**" : cell; };
            md << "| " << synthetic::sensor_name(sensor) << " | " << methods[m].name << " | " << total.objects << " | "
               << total.object_frames << " | " << fixed("%.1f%%", 100 * total.matched_share()) << " | "
               << bold(fixed("%.2f", total.switches_per_100())) << " | " << fixed("%.1f", total.worst_object_rate)
               << " | " << total.switches << " | " << bold(fixed("%.3f", total.idf1())) << " | "
               << fixed("%.3f", total.identity_share()) << " | " << total.fragmentations << " | "
               << fixed("%.1f", seconds > 0 ? double(total.frames) / seconds : std::nan("")) << " |\n";
        }
    }
    md << "\npyrseg's in-view ID switches by how the segment got its new id (docs/algorithm.md section 11): ";
    std::string sep;
    for (const synthetic::Sensor sensor : o.sensors) {
        std::array<std::uint64_t, 3> causes{};
        for (const SequenceScores& r : runs) {
            if (r.sensor != sensor || r.scenario != scenario) continue;
            for (std::size_t c = 0; c < 3; ++c) causes[c] += r.switch_causes[c];
        }
        md << sep << synthetic::sensor_name(sensor) << " " << causes[0] << " new, " << causes[1] << " by overlap, "
           << causes[2] << " by position";
        sep = "; ";
    }
    md << ".\n";
    return md.str();
}

std::string acceptance(const std::vector<SequenceScores>& runs, const Options& o, const std::vector<Method>& methods) {
    std::ostringstream md;
    md << "| sensor | in-view ID switches per object per 100 frames <= 1 | IDF1 >= 0.9 | no worse than every "
          "host-side matcher on every sequence (IDF1, in-view switches) |\n|---|---|---|---|\n";
    for (const synthetic::Sensor sensor : o.sensors) {
        eval::TrackScores total;
        int sequences = 0, no_worse = 0;
        for (const SequenceScores& r : runs) {
            if (r.sensor != sensor || r.scenario != Scenario::camera) continue;
            total.add(r.scores[0]);
            ++sequences;
            no_worse += no_worse_than_hosts(r, methods) ? 1 : 0;
        }
        if (sequences == 0) continue;
        const double rate = total.switches_per_100(), idf1 = total.idf1();
        md << "| " << synthetic::sensor_name(sensor) << " | " << fixed("%.2f", rate) << " (worst object "
           << fixed("%.1f", total.worst_object_rate) << "): " << (rate <= kMaxSwitchesPer100 ? "met" : "**missed**")
           << " | " << fixed("%.3f", idf1) << ": " << (idf1 >= kMinIdf1 ? "met" : "**missed**") << " | " << no_worse
           << " of " << sequences << ": " << (no_worse == sequences ? "met" : "**missed**") << " |\n";
    }
    return md.str();
}

std::string per_sequence(const std::vector<SequenceScores>& runs, const std::vector<Method>& methods) {
    std::ostringstream md;
    md << "In-view ID switches per object per 100 frames / IDF1, per method.\n\n| sensor | scenario | seed | objects |";
    for (const Method& m : methods) md << " " << m.name << " |";
    md << " pyrseg no worse |\n|---|---|---:|---:|";
    for (std::size_t m = 0; m < methods.size(); ++m) md << "---:|";
    md << "---|\n";
    for (const SequenceScores& r : runs) {
        md << "| " << synthetic::sensor_name(r.sensor) << " | " << scenario_name(r.scenario) << " | " << r.seed << " | "
           << r.scores[0].objects << " |";
        for (const eval::TrackScores& s : r.scores) {
            md << " " << fixed("%.2f", s.switches_per_100()) << " / " << fixed("%.3f", s.idf1()) << " |";
        }
        md << " " << (no_worse_than_hosts(r, methods) ? "yes" : "**no**") << " |\n";
    }
    return md.str();
}

}  // namespace

int cmd_eval_tracks(const std::vector<std::string>& argv) {
    std::set<std::string> values = {"sensors",  "frames",    "seeds",      "size",   "scenarios", "max-step",
                                    "max-turn", "match-iou", "min-pixels", "params", "out-dir",   "progress"};
    values.insert(kParameterValueOptions.begin(), kParameterValueOptions.end());
    values.insert(kTrackValueOptions.begin(), kTrackValueOptions.end());
    std::set<std::string> flags = kParameterFlagOptions;
    flags.insert({"help", "tracks", "quick"});
    const Args args(argv, values, flags);
    if (args.flag("help")) {
        std::printf("%s%s", kTracksUsage, kTrackParameterHelp);
        return 0;
    }
    if (!args.positional().empty()) throw UsageError{"--tracks takes no positional arguments"};
    const bool quick = args.flag("quick");

    Options o;
    const std::string sensors = args.value("sensors").value_or(
        quick ? "structured-light,kinect-v1" : "structured-light,kinect-v1,realsense-d435,azure-kinect");
    o.sensors = parse_sensors(sensors);
    for (const std::string& item : split_list(args.value("scenarios").value_or("camera,objects"))) {
        Scenario s{};
        if (item == "camera") {
            s = Scenario::camera;
        } else if (item == "objects") {
            s = Scenario::objects;
        } else {
            throw UsageError{"--scenarios expects camera, objects or both, got '" + printable(item) + "'"};
        }
        if (std::find(o.scenarios.begin(), o.scenarios.end(), s) == o.scenarios.end()) o.scenarios.push_back(s);
    }
    if (o.scenarios.empty()) throw UsageError{"--scenarios is empty"};
    o.frames = args.integer("frames").value_or(quick ? 30 : 300);
    if (o.frames < 2 || o.frames > 100000) throw UsageError{"--frames must be 2..100000"};
    o.seeds = args.integer("seeds").value_or(quick ? 1 : 2);
    if (o.seeds < 1 || o.seeds > 10000) throw UsageError{"--seeds must be 1..10000"};
    const std::string size = args.value("size").value_or(quick ? "320x240" : "640x480");
    char tail = 0;
    if (std::sscanf(size.c_str(), "%dx%d%c", &o.width, &o.height, &tail) != 2 || o.width < 16 || o.height < 16 ||
        o.width > 4096 || o.height > 4096) {
        throw UsageError{"--size expects WxH with sides 16..4096, got '" + printable(size) + "'"};
    }
    o.max_step = args.number("max-step").value_or(20.0);
    if (!(o.max_step >= 0 && o.max_step <= 200)) throw UsageError{"--max-step must be 0..200 mm"};
    o.max_turn = args.number("max-turn").value_or(2.0);
    if (!(o.max_turn >= 0 && o.max_turn <= 30)) throw UsageError{"--max-turn must be 0..30 degrees"};
    const double area = double(o.width) * double(o.height) / (640.0 * 480.0);
    const int min_pixels = args.integer("min-pixels").value_or(std::max(20, int(std::lround(300 * area))));
    if (min_pixels < 1) throw UsageError{"--min-pixels must be >= 1"};
    o.min_pixels = std::uint32_t(min_pixels);
    const std::string params_name = args.value("params").value_or("preset");
    if (params_name != "preset" && params_name != "default") {
        throw UsageError{"--params expects preset or default, got '" + printable(params_name) + "'"};
    }
    o.preset = params_name == "preset";

    std::vector<Method> methods = {{"pyrseg", std::nullopt, false}, {"per-frame labels", std::nullopt, true}};
    for (const std::string& item : split_list(args.value("match-iou").value_or("0.1,0.3"))) {
        char* end = nullptr;
        const double x = std::strtod(item.c_str(), &end);
        if (item.empty() || end != item.c_str() + item.size() || !(x > 0 && x <= 1)) {
            throw UsageError{"--match-iou expects IoU thresholds in (0, 1], got '" + printable(item) + "'"};
        }
        methods.push_back({"Hungarian IoU>=" + printed("%g", x), x, false});
    }
    const Progress::Style style = Progress::style_for(args.value("progress").value_or("auto"), stderr);
    const fs::path out_dir = args.value("out-dir").value_or("pyrseg-eval-tracks");
    fs::create_directories(out_dir);

    std::string command = "pyrseg eval";
    for (const std::string& a : argv) command += " " + a;
    const std::size_t total_frames =
        o.sensors.size() * o.scenarios.size() * std::size_t(o.seeds) * std::size_t(o.frames);
    Progress progress(total_frames, style, stderr);
    std::vector<SequenceScores> runs;
    std::uint64_t label_mismatches = 0;
    std::ostringstream params_md;
    const auto start = Clock::now();
    for (const synthetic::Sensor sensor : o.sensors) {
        const Params params = parse_params(args, o.preset ? std::optional(kind_of(sensor)) : std::nullopt);
        params_md << "- " << synthetic::sensor_name(sensor) << ": " << (o.preset ? "its preset" : "the defaults")
                  << printed(" (ct %g, dt %g mm", params.ct, params.dt)
                  << (params.metric == Metric::robust ? ", robust metric" : ", paper metric")
                  << (params.merge ? ", merge on" : "")
                  << printed("); tracks: max distance %g mm, hold %d frames\n", params.track_max_distance_mm,
                             params.track_hold_frames);
        for (const Scenario scenario : o.scenarios) {
            for (int seed = 1; seed <= o.seeds; ++seed) {
                const auto sequence_start = Clock::now();
                // A picture of each sensor model's and scenario's first sequence.
                const fs::path picture = seed == 1
                                             ? out_dir / ("tracks_" + std::string(synthetic::sensor_name(sensor)) +
                                                          "_" + scenario_name(scenario) + ".png")
                                             : fs::path{};
                runs.push_back(
                    run_sequence(o, sensor, scenario, seed, params, methods, progress, label_mismatches, picture));
                const SequenceScores& r = runs.back();
                if (style == Progress::Style::bar) std::fputs("\r\033[K", stderr);
                std::printf("%s, %s, seed %d: %d frames in %.1f s; in-view switches per 100 / IDF1:",
                            synthetic::sensor_name(sensor), scenario_name(scenario), seed, o.frames,
                            std::chrono::duration<double>(Clock::now() - sequence_start).count());
                for (std::size_t m = 0; m < methods.size(); ++m) {
                    std::printf(" %s %.2f / %.3f;", methods[m].name.c_str(), r.scores[m].switches_per_100(),
                                r.scores[m].idf1());
                }
                std::printf("\n");
                std::fflush(stdout);
            }
        }
    }
    progress.finish();
    const double total_seconds = std::chrono::duration<double>(Clock::now() - start).count();

    std::ostringstream md;
    md << "# pyrseg eval --tracks: ids over synthetic sequences\n\n`" << command << "`: " << o.frames
       << " frames per sequence, scene seeds 1.." << o.seeds << ", " << o.width << "x" << o.height << ", CPU backend, "
       << std::thread::hardware_concurrency()
       << " hardware threads. The camera on a smooth random walk (synthetic::sequence) of up to "
       << printed("%g", o.max_step) << " mm and " << printed("%g", o.max_turn)
       << " degrees a frame; every frame its own noise. Scenarios: *camera* (the objects stay), *objects* (objects "
          "also slide along the floor, are hidden for 2..8 frames and come back, leave for good or appear later).\n\n"
       << "pyrseg's parameters:\n\n"
       << params_md.str() << "\nScored: the ground truth's objects with at least " << o.min_pixels
       << " pixels in the frame (in view); matched to the id covering most of their pixels among those with IoU >= "
          "0.5. *matched*: the share of object frames matched (the same for every method: they label the same "
          "segments). *ID switches per object per 100 frames in view*: switches while the object stayed in view, "
          "per 100 object frames; *worst object*: the largest such rate of one object in view for at least 100 "
          "frames; *ID switches, all*: CLEAR MOT's, across frames out of view too. *IDF1*: Ristani et al.'s, "
          "the predicted detections being the matched ids and the ids of at least as many pixels lying mostly on "
          "objects. *IDTP / matched*: of the frames an object was matched in, the share under the id IDF1's "
          "assignment gave it (identity alone, without the misses that bound IDF1). *fragmentations*: matched then "
          "missed in the next frame in view. *frames/s*: segmentation "
          "(pyrseg with tracks), plus the matching for the host-side matchers (`pyrseg eval --tracks --help`).\n";
    if (label_mismatches > 0) {
        md << "\n**Warning:** in " << label_mismatches
           << " frames the labels with tracks differed from those without.\n";
    }
    for (const Scenario scenario : o.scenarios) {
        md << "\n## " << (scenario == Scenario::camera ? "Camera motion" : "Camera and object motion") << "\n\n"
           << table(runs, o, scenario, methods);
    }
    if (std::find(o.scenarios.begin(), o.scenarios.end(), Scenario::camera) != o.scenarios.end()) {
        md << "\n## Acceptance (camera motion)\n\n" << acceptance(runs, o, methods);
    }
    md << "\n## Per sequence\n\n"
       << per_sequence(runs, methods) << "\nRun time: " << printed("%.1f", total_seconds) << " s.\n";
    const fs::path report = out_dir / "tracks.md";
    write_text_file(report, md.str());
    std::printf("done in %.1f s; wrote %s\n", total_seconds, report.string().c_str());
    if (label_mismatches > 0) {
        std::fprintf(stderr, "pyrseg eval: in %llu frames the labels with tracks differed from those without\n",
                     static_cast<unsigned long long>(label_mismatches));
    }
    return 0;
}

}  // namespace pyrseg::cli
