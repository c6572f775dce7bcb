// Peer: OpenCV's connected-components labelling of the same fillable mask pyrseg's segmentation stage labels
// (stage/* in bench_segment.cpp). SAUF and Spaghetti, 4- and 8-connectivity, with OpenCV's own threading.
#include <benchmark/benchmark.h>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <string>

#include "bench/bench_scenes.hpp"

namespace pyrseg::bench {
namespace {

void opencv_labelling(benchmark::State& state, int width, int height, int connectivity, int algorithm) {
    const SceneMask& m = scene_mask(width, height);
    // OpenCV reads the mask in place (no copy): the same bytes pyrseg's stage reads.
    const cv::Mat mask(height, width, CV_8U, const_cast<std::uint8_t*>(m.fillable.data()));
    cv::Mat labels;
    int count = 0;
    for (auto _ : state) {
        count = cv::connectedComponents(mask, labels, connectivity, CV_32S, algorithm);
        benchmark::DoNotOptimize(labels.data);
    }
    state.counters["segments"] = count - 1;  // label 0 is the background
    state.counters["Mpix/s"] =
        benchmark::Counter(double(width) * height * 1e-6, benchmark::Counter::kIsIterationInvariantRate);
    state.SetBytesProcessed(std::int64_t(state.iterations()) * std::int64_t(width) * height);
}

int register_all() {
    const struct {
        const char* name;
        int algorithm;
    } algorithms[] = {{"sauf", cv::CCL_SAUF}, {"spaghetti", cv::CCL_SPAGHETTI}};
    for (const auto& size : kSizes) {
        const int w = size[0];
        const int h = size[1];
        for (const auto& a : algorithms) {
            for (const int connectivity : {4, 8}) {
                const std::string name =
                    std::string("opencv/") + a.name + "_" + std::to_string(connectivity) + "/" + size_name(w, h);
                const int algorithm = a.algorithm;
                register_timed(name.c_str(),
                               [=](benchmark::State& st) { opencv_labelling(st, w, h, connectivity, algorithm); });
            }
        }
    }
    benchmark::AddCustomContext("opencv",
                                std::string(CV_VERSION) + ", " + std::to_string(cv::getNumThreads()) + " threads");
    return 0;
}

const int kRegistered = register_all();

}  // namespace
}  // namespace pyrseg::bench
