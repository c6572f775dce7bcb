// The fills' worst cases: one long winding region, a square spiral and a maze (synthetic::spiral_mask, maze_mask),
// whose labels must travel the whole corridor. The union-find fills of every backend do not care; the CPU's sweep
// scheme (PYRSEG_CPU_FILL=sweeps) needs a round per turn or so, and reports how many (fill_rounds).
#include <benchmark/benchmark.h>

#include <map>
#include <memory>
#include <string>
#include <utility>

#include "bench/bench_scenes.hpp"
#include "pyrseg/backend.hpp"

namespace pyrseg::bench {
namespace {

const synthetic::FillMask& worst_case(const std::string& kind, int width, int height) {
    static std::map<std::string, std::unique_ptr<synthetic::FillMask>> cache;
    auto& slot = cache[kind + size_name(width, height)];
    if (!slot) {
        slot = std::make_unique<synthetic::FillMask>(kind == "spiral" ? synthetic::spiral_mask(width, height)
                                                                      : synthetic::maze_mask(width, height));
    }
    return *slot;
}

void fill_worst_case(benchmark::State& state, const std::string& backend, const std::string& kind, int width,
                     int height) {
    const synthetic::FillMask& m = worst_case(kind, width, height);
    const MaskView view{m.fillable.data(), nullptr, width, height};
    time_frames(state, backend, width, height, std::size_t(width) * std::size_t(height),
                [&](Segmenter& segmenter, Result& result) { segmenter.segment_mask(view, result); });
}

int register_all() {
    for (const auto& size : {std::pair{640, 480}, std::pair{2064, 1544}}) {
        for (const std::string kind : {"spiral", "maze"}) {
            for (const BackendInfo& b : list_backends()) {
                if (!b.available) continue;
                const std::string name = "fills/" + kind + "/" + b.name + "/" + size_name(size.first, size.second);
                register_timed(name.c_str(), [=](benchmark::State& st) {
                    fill_worst_case(st, b.name, kind, size.first, size.second);
                });
            }
        }
    }
    return 0;
}

const int kRegistered = register_all();

}  // namespace
}  // namespace pyrseg::bench
