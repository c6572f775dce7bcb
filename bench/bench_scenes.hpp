#pragma once
// What every benchmark of pyrseg_bench shares: the frame sizes, one synthetic scene per size (generated once), and
// the fillable mask pyrseg computes for it (the common input of the labelling peers).
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "pyrseg/error.hpp"
#include "pyrseg/io.hpp"
#include "pyrseg/segmenter.hpp"
#include "pyrseg/synthetic.hpp"

namespace pyrseg::bench {

// Registers a row that reports wall time per iteration in milliseconds, as every row of pyrseg_bench does.
template <class Fn>
benchmark::internal::Benchmark* register_timed(const char* name, Fn&& fn) {
    return benchmark::RegisterBenchmark(name, std::forward<Fn>(fn))->Unit(benchmark::kMillisecond)->UseRealTime();
}

// VGA (Kinect, RealSense), SXGA-, a full PhoXi XL frame, and four times that.
inline constexpr int kSizes[][2] = {{640, 480}, {1280, 960}, {2064, 1544}, {4128, 3088}};

inline std::string size_name(int width, int height) {
    return std::to_string(width) + "x" + std::to_string(height);
}

inline const synthetic::Scene& scene(int width, int height) {
    static std::map<std::pair<int, int>, std::unique_ptr<synthetic::Scene>> cache;
    auto& slot = cache[{width, height}];
    if (!slot) {
        synthetic::SceneOptions o;
        o.width = width;
        o.height = height;
        slot = std::make_unique<synthetic::Scene>(synthetic::generate(o));
    }
    return *slot;
}

// The scene's fillable mask B (0/1 per pixel) and validity, from the CPU backend with the given normals. With
// PYRSEG_BENCH_MASKS=DIR each mask is also written as DIR/fillable_WxH.npy (uint8, H x W), so that a peer outside
// this process (scripts/gpu_check/cupy_label.py: CuPy's label on the GPU) times the very same input.
struct SceneMask {
    std::vector<std::uint8_t> fillable;
    std::vector<std::uint8_t> valid;
};

inline const SceneMask& scene_mask(int width, int height) {
    static std::map<std::pair<int, int>, std::unique_ptr<SceneMask>> cache;
    auto& slot = cache[{width, height}];
    if (!slot) {
        const synthetic::Scene& s = scene(width, height);
        Outputs o;
        o.fillable_mask = true;
        Segmenter segmenter(width, height, {}, "cpu", o);
        const Result r = segmenter.segment(CloudView{s.points.data(), s.normals.data(), width, height});
        slot = std::make_unique<SceneMask>();
        slot->fillable = r.fillable_mask;
        slot->valid.resize(r.fillable_mask.size());
        for (std::size_t i = 0; i < slot->valid.size(); ++i) slot->valid[i] = s.object_id[i] != 0 ? 1 : 0;
        if (const char* dir = std::getenv("PYRSEG_BENCH_MASKS"); dir != nullptr && *dir != '\0') {
            std::filesystem::create_directories(dir);
            io::write_npy(std::filesystem::path(dir) / ("fillable_" + size_name(width, height) + ".npy"),
                          slot->fillable.data(), height, width);
        }
    }
    return *slot;
}

// The scene as a depth camera hands it over: whole millimetres in uint16 (0: no data), with its intrinsics.
struct DepthFrame {
    std::vector<std::uint16_t> samples;
    DepthView view;
};

inline const DepthFrame& depth_frame(int width, int height) {
    static std::map<std::pair<int, int>, std::unique_ptr<DepthFrame>> cache;
    auto& slot = cache[{width, height}];
    if (!slot) {
        const synthetic::Scene& s = scene(width, height);
        slot = std::make_unique<DepthFrame>();
        slot->samples.resize(std::size_t(width) * std::size_t(height));
        for (std::size_t i = 0; i < slot->samples.size(); ++i) {
            const float z = s.points[3 * i + 2];
            slot->samples[i] = std::isfinite(z) && z > 0 && z < 65535 ? std::uint16_t(std::lround(z)) : 0;
        }
        slot->view = DepthView{slot->samples.data(), DepthFormat::u16, width, height, 0, 0.001, s.fx, s.fy, s.cx, s.cy};
    }
    return *slot;
}

// Times `frame(segmenter, result)` (one frame into result) on `segmenter`: once to size everything, then once per
// iteration. Reports per-pass counters (`<pass>_ms`, milliseconds per frame as Segmenter::last_timings() gives
// them: host times, or the device's timestamps where a backend queues the frame), the fills' sweep rounds, a GPU
// backend's dispatches and host waits per frame, the segment count, Mpix/s and input bytes/s.
template <class Frame>
void time_frames_on(benchmark::State& state, Segmenter& segmenter, int width, int height, std::size_t input_bytes,
                    const Frame& frame) {
    Result result;
    frame(segmenter, result);
    std::map<std::string, double> pass_ms;
    for (auto _ : state) {
        frame(segmenter, result);
        for (const PassTiming& t : segmenter.last_timings()) pass_ms[t.pass] += t.milliseconds;
        benchmark::DoNotOptimize(result.labels.data());
    }
    for (const auto& [pass, ms] : pass_ms) {
        state.counters[pass + "_ms"] = benchmark::Counter(ms / double(state.iterations()));
    }
    state.counters["fill_rounds"] = segmenter.last_fill_rounds();
    state.counters["dispatches"] = segmenter.last_dispatches();
    state.counters["host_syncs"] = segmenter.last_host_syncs();
    state.counters["segments"] = result.segment_count;
    state.counters["Mpix/s"] =
        benchmark::Counter(double(width) * height * 1e-6, benchmark::Counter::kIsIterationInvariantRate);
    state.SetBytesProcessed(std::int64_t(state.iterations()) * std::int64_t(input_bytes));
}

// As time_frames_on, on a Segmenter of `backend`; a backend that cannot take the frame (a device limit) is reported
// as skipped with its reason.
template <class Frame>
void time_frames(benchmark::State& state, const std::string& backend, int width, int height, std::size_t input_bytes,
                 const Frame& frame, const Params& params = {}, const Outputs& outputs = {}) {
    std::unique_ptr<Segmenter> segmenter;
    try {
        segmenter = std::make_unique<Segmenter>(width, height, params, backend, outputs);
    } catch (const Error& e) {
        state.SkipWithError(e.what());
        return;
    }
    time_frames_on(state, *segmenter, width, height, input_bytes, frame);
}

}  // namespace pyrseg::bench
