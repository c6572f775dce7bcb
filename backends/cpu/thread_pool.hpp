#pragma once
// The CPU backend's parallel loops, on oneTBB. A loop's chunks are tasks that idle threads take (work stealing): a
// thread the OS takes away delays only the chunk it holds, and nothing waits for a thread that took none. The
// threads are oneTBB's: by default those of the arena the caller runs in (the process's, shared with every library
// that uses oneTBB), or an arena of the Segmenter's own (a thread count), or the application's. A loop allocates
// nothing of its own (the body is passed by address; oneTBB recycles its task objects).
#include <oneapi/tbb/task_arena.h>

#include <cstddef>
#include <memory>

#include "pyrseg/cpu.hpp"

namespace pyrseg::cpu {

// Where a Segmenter's loops run.
struct ThreadSetting {
    // 0: $PYRSEG_THREADS when it is set, else the arena of the thread that calls segment(). 1: the calling thread
    // alone. n: an arena of n threads of the Segmenter's own (the caller and n - 1 of oneTBB's workers).
    unsigned count = 0;
    // The application's arena (count must be 0): every loop runs inside it, beside the application's own work.
    tbb::task_arena* arena = nullptr;
};

class ThreadPool {
public:
    // Throws pyrseg::Error for a $PYRSEG_THREADS that is not a count, or a count over kMaxThreads (pyrseg/cpu.hpp).
    explicit ThreadPool(const ThreadSetting& setting = {});
    ~ThreadPool();
    ThreadPool(const ThreadPool&) = delete;
    ThreadPool& operator=(const ThreadPool&) = delete;

    // The threads a loop started now may use (the arena's concurrency: it can change with the caller's arena).
    [[nodiscard]] unsigned size() const;
    // How many pieces to cut a loop into when its pieces cost about the same: several per thread, so that when the
    // system takes a thread away, the others take over the pieces it has not started.
    [[nodiscard]] std::size_t pieces() const { return std::size_t(size()) * kPiecesPerThread; }
    static constexpr unsigned kPiecesPerThread = 8;

    // Calls body(begin, end) on disjoint chunks of [0, count) of at most `grain` items, in parallel, and returns
    // when all are done. The body must not throw (the pass bodies neither allocate nor throw). The loop is isolated:
    // a thread waiting in it runs only its chunks, never the application's tasks, so a body is never re-entered.
    template <class Body>
    void parallel_for(std::size_t count, std::size_t grain, const Body& body) {
        if (count == 0) return;
        if (count <= grain || serial_) {
            body(std::size_t{0}, count);
            return;
        }
        run(
            count, grain, [](const void* ctx, std::size_t b, std::size_t e) { (*static_cast<const Body*>(ctx))(b, e); },
            &body);
    }

private:
    using Invoke = void (*)(const void*, std::size_t, std::size_t);
    void run(std::size_t count, std::size_t grain, Invoke invoke, const void* ctx);

    std::unique_ptr<tbb::task_arena> own_;  // the arena of a thread count
    tbb::task_arena* arena_ = nullptr;      // where loops run; null: the caller's arena
    unsigned threads_without_tbb_ = 0;      // ThreadSanitizer builds: the threads of a loop
    bool serial_ = false;
};

}  // namespace pyrseg::cpu
