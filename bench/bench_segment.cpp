// Segmentation speed per backend and pass on synthetic bin-picking scenes, next to a memcpy of the same input
// bytes measured in the same process (so ratios, not absolute numbers, carry between machines).
//   pyrseg_bench --benchmark_filter=2064   (full PhoXi frames only)
#include <benchmark/benchmark.h>

#include <cstring>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "pyrseg/backend.hpp"
#include "pyrseg/segmenter.hpp"
#include "pyrseg/synthetic.hpp"

namespace {

const pyrseg::synthetic::Scene& scene(int width, int height) {
    static std::map<std::pair<int, int>, std::unique_ptr<pyrseg::synthetic::Scene>> cache;
    auto& slot = cache[{width, height}];
    if (!slot) {
        pyrseg::synthetic::SceneOptions o;
        o.width = width;
        o.height = height;
        slot = std::make_unique<pyrseg::synthetic::Scene>(pyrseg::synthetic::generate(o));
    }
    return *slot;
}

// Total time of a whole frame; counters are milliseconds per frame for each pass, as Segmenter::last_timings()
// reports them (host times, or the device's timestamps for backends that queue a frame, such as Vulkan).
void segment(benchmark::State& state, const std::string& backend, int width, int height, bool given_normals) {
    const pyrseg::synthetic::Scene& s = scene(width, height);
    pyrseg::Segmenter segmenter(width, height, {}, backend);
    pyrseg::CloudView view{s.points.data(), given_normals ? s.normals.data() : nullptr, width, height};
    pyrseg::Result result;
    segmenter.segment(view, result);
    std::map<std::string, double> pass_ms;
    for (auto _ : state) {
        segmenter.segment(view, result);
        for (const pyrseg::PassTiming& t : segmenter.last_timings()) pass_ms[t.pass] += t.milliseconds;
        benchmark::DoNotOptimize(result.labels.data());
    }
    for (const auto& [pass, ms] : pass_ms) {
        state.counters[pass + "_ms"] = benchmark::Counter(ms / double(state.iterations()));
    }
    state.counters["segments"] = result.segment_count;
    state.counters["Mpix/s"] =
        benchmark::Counter(double(width) * height * 1e-6, benchmark::Counter::kIsIterationInvariantRate);
}

// The floor: copying the bytes the segmentation reads (points, and normals when given).
void copy_input(benchmark::State& state, int width, int height, bool given_normals) {
    const std::size_t bytes = std::size_t(width) * std::size_t(height) * 3 * sizeof(float) * (given_normals ? 2 : 1);
    std::vector<char> src(bytes, 1), dst(bytes);
    for (auto _ : state) {
        std::memcpy(dst.data(), src.data(), bytes);
        benchmark::DoNotOptimize(dst.data());
        benchmark::ClobberMemory();
    }
    state.SetBytesProcessed(std::int64_t(state.iterations()) * std::int64_t(bytes));
}

const int kSizes[][2] = {{640, 480}, {2064, 1544}};

int register_all() {
    for (const auto& size : kSizes) {
        const int w = size[0];
        const int h = size[1];
        for (const bool given : {false, true}) {
            const std::string suffix =
                std::to_string(w) + "x" + std::to_string(h) + (given ? "/given_normals" : "/estimated_normals");
            benchmark::RegisterBenchmark(("memcpy_input/" + suffix).c_str(),
                                         [=](benchmark::State& st) { copy_input(st, w, h, given); })
                ->Unit(benchmark::kMillisecond)
                ->UseRealTime();
            for (const pyrseg::BackendInfo& b : pyrseg::list_backends()) {
                if (!b.available) continue;
                benchmark::RegisterBenchmark(("segment/" + b.name + "/" + suffix).c_str(),
                                             [=](benchmark::State& st) { segment(st, b.name, w, h, given); })
                    ->Unit(benchmark::kMillisecond)
                    ->UseRealTime();
            }
        }
    }
    return 0;
}

const int registered = register_all();

}  // namespace

BENCHMARK_MAIN();
