#pragma once
// A fixed pool of worker threads for data-parallel loops. The calling thread takes part; a loop allocates
// nothing (the body is passed by address), so a frame can run many loops without touching the heap.
#include <atomic>
#include <condition_variable>
#include <cstddef>
#include <mutex>
#include <thread>
#include <vector>

namespace pyrseg::cpu {

class ThreadPool {
public:
    // threads: total including the caller; 0 means $PYRSEG_THREADS, else the hardware's count.
    explicit ThreadPool(unsigned threads = 0);
    ~ThreadPool();
    ThreadPool(const ThreadPool&) = delete;
    ThreadPool& operator=(const ThreadPool&) = delete;

    [[nodiscard]] unsigned size() const noexcept { return static_cast<unsigned>(workers_.size()) + 1; }
    // The size of a ThreadPool made with threads = 0.
    [[nodiscard]] static unsigned default_size();

    // Calls body(begin, end) on disjoint chunks of [0, count) of at most `grain` items, in parallel, and returns
    // when all are done. The body must not throw: workers may still be running chunks of it while an exception
    // would unwind the caller (the pass bodies neither allocate nor throw).
    template <class Body>
    void parallel_for(std::size_t count, std::size_t grain, const Body& body) {
        if (count == 0) return;
        if (workers_.empty() || count <= grain) {
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
    void work_chunks();
    void worker_loop();

    std::vector<std::thread> workers_;
    std::mutex mutex_;
    std::condition_variable start_cv_;
    std::condition_variable done_cv_;
    // A frame runs dozens of short loops: waking a sleeping thread costs tens of microseconds on a virtual machine,
    // so workers and the caller first spin briefly on these before they sleep on the condition variables.
    std::atomic<std::size_t> generation_{0};
    std::atomic<unsigned> busy_workers_{0};
    bool stopping_ = false;
    // The loop being run.
    Invoke invoke_ = nullptr;
    const void* ctx_ = nullptr;
    std::size_t count_ = 0;
    std::size_t grain_ = 1;
    std::atomic<std::size_t> next_{0};
};

}  // namespace pyrseg::cpu
