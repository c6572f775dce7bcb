#pragma once
// The CPU backend's threads, for applications that run their own parallel work. The CPU backend's loops are oneTBB
// tasks (work stealing: a thread the system takes away for another process delays only the small piece of work it
// holds). By default a Segmenter on "cpu" runs them in the oneTBB arena of the thread that calls segment(): the
// process's, shared with OpenCV and every other library in the process that uses oneTBB, so they do not
// oversubscribe the cores, and a Segmenter called from inside the application's own tbb::parallel_for runs beside
// it. $PYRSEG_THREADS=n gives every such Segmenter an arena of n threads of its own instead.
//
// These make a "cpu" Segmenter with a setting of its own. Either way, the labels do not depend on the threads.
#include <oneapi/tbb/task_arena.h>

#include "pyrseg/export.hpp"
#include "pyrseg/params.hpp"
#include "pyrseg/result.hpp"
#include "pyrseg/segmenter.hpp"

namespace pyrseg::cpu {

// The most threads a CPU Segmenter takes (make_segmenter below, $PYRSEG_THREADS, Python's threads=).
inline constexpr unsigned kMaxThreads = 1024;

// An arena of `threads` threads of the Segmenter's own (the calling thread and threads - 1 of oneTBB's workers);
// 1 runs every pass on the calling thread alone. Throws pyrseg::Error for 0 or more than kMaxThreads threads.
[[nodiscard]] PYRSEG_EXPORT Segmenter make_segmenter(int width, int height, unsigned threads, const Params& params = {},
                                                     const Outputs& outputs = {});

// The application's arena: every pass runs inside it (tbb::task_arena::execute) beside the application's own
// tasks, on at most its max_concurrency() threads. The application keeps the arena alive longer than the Segmenter.
// A thread waiting for pyrseg's work inside the arena runs only pyrseg's tasks (tbb::this_task_arena::isolate).
[[nodiscard]] PYRSEG_EXPORT Segmenter make_segmenter(int width, int height, tbb::task_arena& arena,
                                                     const Params& params = {}, const Outputs& outputs = {});

}  // namespace pyrseg::cpu
