#include "backends/cpu/thread_pool.hpp"

#include <algorithm>
#include <charconv>
#include <chrono>
#include <cstdlib>
#include <string>
#include <string_view>

#include "pyrseg/error.hpp"

namespace pyrseg::cpu {
namespace {

constexpr unsigned kMaxThreads = 1024;

// PYRSEG_THREADS, or every core when it is unset or empty. A value that is not a count is an error rather than
// silently every core: PYRSEG_THREADS=2x or =two was meant to limit the pool.
unsigned default_threads() {
    const char* env = std::getenv("PYRSEG_THREADS");
    if (env == nullptr || *env == '\0') return std::max(1u, std::thread::hardware_concurrency());
    const std::string_view text(env);
    unsigned v = 0;
    const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
    if (ec != std::errc() || end != text.data() + text.size() || v < 1 || v > kMaxThreads) {
        std::string shown(text.substr(0, 40));
        for (char& c : shown) {
            if (static_cast<unsigned char>(c) < 0x20 || static_cast<unsigned char>(c) >= 0x7f) c = '?';
        }
        throw Error(ErrorCode::invalid_parameter, "PYRSEG_THREADS='" + shown +
                                                      "' is not a number of threads from 1 to " +
                                                      std::to_string(kMaxThreads) + " (unset it to use every core)");
    }
    return v;
}

// How long a thread spins for the next loop or for the workers to finish before it sleeps.
constexpr std::chrono::microseconds kSpin{50};

// Spins until done() holds or kSpin has passed; returns done().
template <class Done>
bool spin_until(const Done& done) {
    const auto until = std::chrono::steady_clock::now() + kSpin;
    for (unsigned n = 0;; ++n) {
        if (done()) return true;
        if ((n & 63u) == 63u && std::chrono::steady_clock::now() > until) return done();
        std::this_thread::yield();
    }
}

}  // namespace

unsigned ThreadPool::default_size() {
    return default_threads();
}

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
        busy_workers_.store(static_cast<unsigned>(workers_.size()), std::memory_order_relaxed);
        generation_.fetch_add(1, std::memory_order_release);
    }
    start_cv_.notify_all();
    work_chunks();
    const auto all_done = [this] { return busy_workers_.load(std::memory_order_acquire) == 0; };
    if (spin_until(all_done)) return;
    std::unique_lock lock(mutex_);
    done_cv_.wait(lock, all_done);
}

void ThreadPool::worker_loop() {
    std::size_t seen = 0;
    for (;;) {
        // The loop's parameters were written under the mutex before the generation changed: taking the mutex
        // here (after spinning or sleeping) makes them visible.
        spin_until([&] { return generation_.load(std::memory_order_acquire) != seen; });
        {
            std::unique_lock lock(mutex_);
            start_cv_.wait(lock, [&] { return stopping_ || generation_.load(std::memory_order_relaxed) != seen; });
            if (stopping_) return;
            seen = generation_.load(std::memory_order_relaxed);
        }
        work_chunks();
        if (busy_workers_.fetch_sub(1, std::memory_order_acq_rel) == 1) {
            // The caller may be asleep: notify under the mutex, so the wake-up cannot fall between its check and
            // its wait.
            std::lock_guard lock(mutex_);
            done_cv_.notify_one();
        }
    }
}

}  // namespace pyrseg::cpu
