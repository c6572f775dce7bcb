// pyrseg/cpu.hpp: "cpu" Segmenters with a thread setting of their own.
#include "pyrseg/cpu.hpp"

#include <string>

#include "backends/cpu/cpu_backend.hpp"
#include "core/device_frame.hpp"
#include "pyrseg/error.hpp"

namespace pyrseg::cpu {

Segmenter make_segmenter(int width, int height, unsigned threads, const Params& params, const Outputs& outputs) {
    if (threads == 0) {
        throw Error(ErrorCode::invalid_parameter,
                    "a CPU Segmenter of 0 threads: give 1 or more (or make a plain Segmenter to share the caller's "
                    "oneTBB arena)");
    }
    return core::make_segmenter(width, height, params, outputs, "cpu", [&](const core::Plan& plan) {
        return make_executor(plan, ThreadSetting{threads, nullptr});
    });
}

Segmenter make_segmenter(int width, int height, tbb::task_arena& arena, const Params& params, const Outputs& outputs) {
    return core::make_segmenter(width, height, params, outputs, "cpu", [&](const core::Plan& plan) {
        return make_executor(plan, ThreadSetting{0, &arena});
    });
}

}  // namespace pyrseg::cpu
