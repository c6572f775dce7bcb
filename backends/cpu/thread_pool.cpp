#include "backends/cpu/thread_pool.hpp"

#include <algorithm>
#include <cstdlib>
#include <string>

namespace pyrseg::cpu {
namespace {

unsigned default_threads() {
    if (const char* env = std::getenv("PYRSEG_THREADS")) {
        try {
            const long v = std::stol(env);
            if (v >= 1 && v <= 1024) return static_cast<unsigned>(v);
        } catch (...) {  // an unreadable value falls back to the hardware's count
        }
    }
    return std::max(1u, std::thread::hardware_concurrency());
}

}  // namespace

ThreadPool::ThreadPool(unsigned threads) {
    const unsigned total = threads == 0 ? default_threads() : threads;
    workers_.reserve(total - 1);
    for (unsigned i = 1; i < total; ++i) workers_.emplace_back([this] { worker_loop(); });
}

ThreadPool::~ThreadPool() {
    {
        std::lock_guard lock(mutex_);
        stopping_ = true;
    }
    start_cv_.notify_all();
    for (std::thread& t : workers_) t.join();
}

void ThreadPool::work_chunks() {
    for (;;) {
        const std::size_t begin = next_.fetch_add(grain_, std::memory_order_relaxed);
        if (begin >= count_) return;
        invoke_(ctx_, begin, std::min(count_, begin + grain_));
    }
}

void ThreadPool::run(std::size_t count, std::size_t grain, Invoke invoke, const void* ctx) {
    {
        std::lock_guard lock(mutex_);
        invoke_ = invoke;
        ctx_ = ctx;
        count_ = count;
        grain_ = std::max<std::size_t>(grain, 1);
        next_.store(0, std::memory_order_relaxed);
        busy_workers_ = static_cast<unsigned>(workers_.size());
        ++generation_;
    }
    start_cv_.notify_all();
    work_chunks();
    std::unique_lock lock(mutex_);
    done_cv_.wait(lock, [this] { return busy_workers_ == 0; });
}

void ThreadPool::worker_loop() {
    std::size_t seen = 0;
    for (;;) {
        {
            std::unique_lock lock(mutex_);
            start_cv_.wait(lock, [&] { return stopping_ || generation_ != seen; });
            if (stopping_) return;
            seen = generation_;
        }
        work_chunks();
        {
            std::lock_guard lock(mutex_);
            --busy_workers_;
        }
        done_cv_.notify_one();
    }
}

}  // namespace pyrseg::cpu
