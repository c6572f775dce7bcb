// Peer: PCL's organized segmentation (peers/pcl_segmentation.hpp) on the same clouds as pyrseg's pipeline/*: with
// its integral-image normals next to pipeline/*/estimated_normals, and its labelling alone with the scene's exact
// normals (no edge map) next to pipeline/*/given_normals. The conversion to PCL's cloud is outside the timing.
#include <benchmark/benchmark.h>

#include <string>

#include "bench/bench_scenes.hpp"
#include "peers/pcl_segmentation.hpp"

namespace pyrseg::bench {
namespace {

void pcl_segmentation(benchmark::State& state, int width, int height, bool given_normals) {
    const synthetic::Scene& s = scene(width, height);
    peers::PclOrganizedSegmentation pcl;
    pcl.set_cloud(s.points.data(), given_normals ? s.normals.data() : nullptr, width, height);
    std::uint32_t segments = 0;
    for (auto _ : state) {
        segments = pcl.run();
        benchmark::DoNotOptimize(segments);
    }
    state.counters["segments"] = double(segments);
    state.counters["Mpix/s"] =
        benchmark::Counter(double(width) * height * 1e-6, benchmark::Counter::kIsIterationInvariantRate);
    state.SetBytesProcessed(std::int64_t(state.iterations()) * std::int64_t(width) * height * 12 *
                            (given_normals ? 2 : 1));
}

int register_all() {
    for (const auto& size : kSizes) {
        const int w = size[0];
        const int h = size[1];
        for (const bool given : {false, true}) {
            const std::string name =
                "pcl/organized_edge_aware/" + size_name(w, h) + (given ? "/given_normals" : "/estimated_normals");
            register_timed(name.c_str(), [=](benchmark::State& st) { pcl_segmentation(st, w, h, given); });
        }
    }
    benchmark::AddCustomContext("pcl", peers::pcl_version());
    return 0;
}

const int kRegistered = register_all();

}  // namespace
}  // namespace pyrseg::bench
