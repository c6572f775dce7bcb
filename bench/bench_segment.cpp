// pyrseg per backend: the whole pipeline (and, as pipeline_depth, from a uint16 depth image back-projected on the
// device) (with the paper's metric, and as pipeline_robust with the robust metric of
// the kinect-v1 preset without its merge on the same frames, so that its cost shows per pass, and as
// pipeline_robust_merge with the preset's merge, as pipeline_robust_merge_stats with the segment statistics, and as
// pipeline_robust_merge_color with a colour image and the colour edge term as well, pipeline_robust_merge_color_gated
// with its curvature gate, pipeline_robust_merge_graph with the segment graph of section 10d,
// pipeline_robust_merge_scene with the statistics and the scene summary of section 10c, pipeline_robust_merge_tracks
// with the tracks of section 11)
// (points, with estimated or given
// normals, to compacted labels) and the segmentation stage alone (a fillable mask to compacted labels), at every frame
// size, next to a memcpy of the same input bytes measured in the same process, so that ratios, not absolute numbers,
// carry between machines.
//   pyrseg_bench --benchmark_filter=2064          full PhoXi frames only
//   pyrseg_bench --benchmark_format=json > b.json && pyrseg_bench_summary b.json   ratio tables and a plot
#include <benchmark/benchmark.h>

#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "bench/bench_scenes.hpp"
#include "pyrseg/backend.hpp"
#include "pyrseg/presets.hpp"
#include "pyrseg/scene.hpp"

namespace pyrseg::bench {
namespace {

void pipeline(benchmark::State& state, const std::string& backend, int width, int height, bool given_normals,
              const Params& params = {}, const Outputs& outputs = {}) {
    const synthetic::Scene& s = scene(width, height);
    const CloudView view{s.points.data(), given_normals ? s.normals.data() : nullptr, width, height};
    time_frames(
        state, backend, width, height, std::size_t(width) * std::size_t(height) * 12 * (given_normals ? 2 : 1),
        [&](Segmenter& segmenter, Result& result) { segmenter.segment(view, result); }, params, outputs);
}

// The kinect-v1 preset with its merge and the statistics, then the scene of each frame (describe_scene and
// fit_object_boxes on the host, into a Scene reused frame after frame).
void scene_pipeline(benchmark::State& state, const std::string& backend, int width, int height, bool given_normals) {
    const synthetic::Scene& s = scene(width, height);
    const CloudView view{s.points.data(), given_normals ? s.normals.data() : nullptr, width, height};
    Outputs outputs;
    outputs.segment_stats = outputs.fillable_mask = true;
    const Params params = sensor_preset(SensorKind::kinect_v1);
    Scene summary;
    double scene_ms = 0;  // the host's part, summed over every frame (the warm-up too)
    int frames = 0;
    time_frames(
        state, backend, width, height, std::size_t(width) * std::size_t(height) * 12 * (given_normals ? 2 : 1),
        [&](Segmenter& segmenter, Result& result) {
            segmenter.segment(view, result);
            const auto start = std::chrono::steady_clock::now();
            describe_scene(result.segments, params, SceneParams{}, summary);
            fit_object_boxes(s.points, result.labels, result.fillable_mask, summary);
            scene_ms += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
            ++frames;
        },
        params, outputs);
    if (frames > 0) state.counters["scene_ms"] = benchmark::Counter(scene_ms / frames);
}

// A colour image for the scene: each object its own colour, stripes across every other object (colour edges inside
// surfaces as well as between them).
const std::vector<std::uint8_t>& scene_color(int width, int height) {
    static std::map<std::pair<int, int>, std::vector<std::uint8_t>> cache;
    std::vector<std::uint8_t>& rgb = cache[{width, height}];
    if (rgb.empty()) {
        const synthetic::Scene& s = scene(width, height);
        rgb.resize(3 * s.object_id.size());
        for (std::size_t i = 0; i < s.object_id.size(); ++i) {
            const bool stripe = (s.object_id[i] & 1u) != 0 && (i % std::size_t(width)) / 9 % 2 == 0;
            const std::uint32_t c = s.object_id[i] * 2654435761u + (stripe ? 0x505050u : 0u);
            for (std::size_t k = 0; k < 3; ++k) rgb[3 * i + k] = std::uint8_t(c >> (8 * k));
        }
    }
    return rgb;
}

void color_pipeline(benchmark::State& state, const std::string& backend, int width, int height, bool given_normals,
                    const Params& params) {
    const synthetic::Scene& s = scene(width, height);
    CloudView view{s.points.data(), given_normals ? s.normals.data() : nullptr, width, height};
    view.color = scene_color(width, height).data();
    time_frames(
        state, backend, width, height, std::size_t(width) * std::size_t(height) * (12 * (given_normals ? 2 : 1) + 3),
        [&](Segmenter& segmenter, Result& result) { segmenter.segment(view, result); }, params);
}

// A depth frame: 2 bytes a pixel uploaded, back-projected on the device, then as pipeline/ with estimated normals.
void depth_pipeline(benchmark::State& state, const std::string& backend, int width, int height) {
    const DepthFrame& frame = depth_frame(width, height);
    time_frames(state, backend, width, height, std::size_t(width) * std::size_t(height) * 2,
                [&](Segmenter& segmenter, Result& result) { segmenter.segment(frame.view, result); });
}

void stage(benchmark::State& state, const std::string& backend, int width, int height) {
    const SceneMask& m = scene_mask(width, height);
    const MaskView view{m.fillable.data(), m.valid.data(), width, height};
    time_frames(state, backend, width, height, std::size_t(width) * std::size_t(height),
                [&](Segmenter& segmenter, Result& result) { segmenter.segment_mask(view, result); });
}

// The floor: copying the bytes a benchmark reads.
void copy_bytes(benchmark::State& state, std::size_t bytes) {
    std::vector<char> src(bytes, 1);
    std::vector<char> dst(bytes);
    for (auto _ : state) {
        std::memcpy(dst.data(), src.data(), bytes);
        benchmark::DoNotOptimize(dst.data());
        benchmark::ClobberMemory();
    }
    state.SetBytesProcessed(std::int64_t(state.iterations()) * std::int64_t(bytes));
}

int register_all() {
    for (const auto& size : kSizes) {
        const int w = size[0];
        const int h = size[1];
        const std::string px = size_name(w, h);
        const std::size_t pixels = std::size_t(w) * std::size_t(h);
        for (const bool given : {false, true}) {
            const std::string suffix = px + (given ? "/given_normals" : "/estimated_normals");
            const std::size_t bytes = pixels * 12 * (given ? 2 : 1);
            register_timed(("memcpy/" + suffix).c_str(), [=](benchmark::State& st) { copy_bytes(st, bytes); });
            for (const BackendInfo& b : list_backends()) {
                if (!b.available) continue;
                register_timed(("pipeline/" + b.name + "/" + suffix).c_str(),
                               [=](benchmark::State& st) { pipeline(st, b.name, w, h, given); });
                // The same surface neighbourhood as the default radius on the PhoXi frame: at 4128x3088 (half the
                // pixel spacing, the same 0.1 mm noise) radius 2 sees noise that fragments the mask
                // (docs/performance-history.md, "Time per pixel"), so the frame size alone is compared on this row.
                if (const int same_footprint = int(std::lround(kDefaultNormalRadius * double(w) / 2064.0));
                    !given && same_footprint > kDefaultNormalRadius) {
                    Params wider;
                    wider.normal_radius = same_footprint;
                    register_timed(
                        ("pipeline/" + b.name + "/" + suffix + "_radius" + std::to_string(same_footprint)).c_str(),
                        [=](benchmark::State& st) { pipeline(st, b.name, w, h, false, wider); });
                }
                // The robust metric alone (the preset without its merge), then the preset as it is.
                Params robust = sensor_preset(SensorKind::kinect_v1);
                robust.merge = false;
                register_timed(("pipeline_robust/" + b.name + "/" + suffix).c_str(),
                               [=](benchmark::State& st) { pipeline(st, b.name, w, h, given, robust); });
                // The same robust frames with the merge (step 6d): the difference to pipeline_robust is its cost.
                const Params merged = sensor_preset(SensorKind::kinect_v1);
                register_timed(("pipeline_robust_merge/" + b.name + "/" + suffix).c_str(),
                               [=](benchmark::State& st) { pipeline(st, b.name, w, h, given, merged); });
                // And with the segment statistics (section 10: moments, plane and box fits): the difference to
                // pipeline_robust_merge is what they cost.
                Outputs stats;
                stats.segment_stats = true;
                register_timed(("pipeline_robust_merge_stats/" + b.name + "/" + suffix).c_str(),
                               [=](benchmark::State& st) { pipeline(st, b.name, w, h, given, merged, stats); });
                // And with the segment graph (section 10d): the difference to pipeline_robust_merge is its cost.
                Outputs graph;
                graph.segment_graph = true;
                register_timed(("pipeline_robust_merge_graph/" + b.name + "/" + suffix).c_str(),
                               [=](benchmark::State& st) { pipeline(st, b.name, w, h, given, merged, graph); });
                // And with tracks (section 11), which run the statistics too: the difference to
                // pipeline_robust_merge_stats is what following the ids costs (the same frame again and again: every
                // segment overlaps itself).
                Outputs tracks;
                tracks.segment_tracks = true;
                register_timed(("pipeline_robust_merge_tracks/" + b.name + "/" + suffix).c_str(),
                               [=](benchmark::State& st) { pipeline(st, b.name, w, h, given, merged, tracks); });
                // And the scene (section 10c) on the host from those statistics, its boxes fitted to the fillable
                // points: the difference to pipeline_robust_merge is what statistics and scene cost together.
                register_timed(("pipeline_robust_merge_scene/" + b.name + "/" + suffix).c_str(),
                               [=](benchmark::State& st) { scene_pipeline(st, b.name, w, h, given); });
                // And with a colour image and the colour edge term (step 0c): the difference to
                // pipeline_robust_merge is the colour's cost, its upload included.
                Params colored = merged;
                colored.color_edge_threshold = 120;
                register_timed(("pipeline_robust_merge_color/" + b.name + "/" + suffix).c_str(),
                               [=](benchmark::State& st) { color_pipeline(st, b.name, w, h, given, colored); });
                // And with the colour edges gated by curvature (as the realsense-d435 preset does): the difference to
                // pipeline_robust_merge_color is the gate's cost and the segmentation it changes.
                Params gated = colored;
                gated.color_edge_curvature_share = 0.3;
                register_timed(("pipeline_robust_merge_color_gated/" + b.name + "/" + suffix).c_str(),
                               [=](benchmark::State& st) { color_pipeline(st, b.name, w, h, given, gated); });
            }
        }
        register_timed(("memcpy/" + px + "/depth_u16").c_str(),
                       [=](benchmark::State& st) { copy_bytes(st, 2 * pixels); });
        for (const BackendInfo& b : list_backends()) {
            if (!b.available) continue;
            register_timed(("pipeline_depth/" + b.name + "/" + px + "/u16").c_str(),
                           [=](benchmark::State& st) { depth_pipeline(st, b.name, w, h); });
        }
        register_timed(("memcpy/" + px + "/mask").c_str(), [=](benchmark::State& st) { copy_bytes(st, pixels); });
        for (const BackendInfo& b : list_backends()) {
            if (!b.available) continue;
            register_timed(("stage/" + b.name + "/" + px).c_str(),
                           [=](benchmark::State& st) { stage(st, b.name, w, h); });
        }
    }
    for (const BackendInfo& b : list_backends()) {
        benchmark::AddCustomContext("backend " + b.name, b.available ? "available" : "unavailable: " + b.reason);
    }
#ifdef PYRSEG_BENCH_MISSING_PEERS
    benchmark::AddCustomContext("peers not built", PYRSEG_BENCH_MISSING_PEERS);
#endif
    return 0;
}

const int kRegistered = register_all();

}  // namespace
}  // namespace pyrseg::bench
