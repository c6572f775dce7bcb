#include "backends/cpu/thread_pool.hpp"

#include <oneapi/tbb/blocked_range.h>
#include <oneapi/tbb/parallel_for.h>
#include <oneapi/tbb/partitioner.h>

#include <algorithm>
#include <charconv>
#include <cstdlib>
#include <string>
#include <string_view>

#if PYRSEG_LOOPS_WITHOUT_TBB
#include <atomic>
#include <thread>
#include <vector>
#endif

#include "pyrseg/error.hpp"

namespace pyrseg::cpu {
namespace {

// $PYRSEG_THREADS as a count, or 0 when it is unset or empty. A value that is not a count is an error rather than
// silently every core: PYRSEG_THREADS=2x or =two was meant to limit the threads.
unsigned threads_from_environment() {
    const char* env = std::getenv("PYRSEG_THREADS");
    if (env == nullptr || *env == '\0') return 0;
    const std::string_view text(env);
    unsigned v = 0;
    const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
    if (ec != std::errc() || end != text.data() + text.size() || v < 1 || v > kMaxThreads) {
        std::string shown(text.substr(0, 40));
        for (char& c : shown) {
            if (static_cast<unsigned char>(c) < 0x20 || static_cast<unsigned char>(c) >= 0x7f) c = '?';
        }
        throw Error(ErrorCode::invalid_parameter,
                    "PYRSEG_THREADS='" + shown + "' is not a number of threads from 1 to " +
                        std::to_string(kMaxThreads) + " (unset it to share the process's oneTBB threads)");
    }
    return v;
}

}  // namespace

ThreadPool::ThreadPool(const ThreadSetting& setting) {
    if (setting.arena != nullptr && setting.count != 0) {
        throw Error(ErrorCode::invalid_parameter, "give the CPU backend an arena or a thread count, not both");
    }
    if (setting.count > kMaxThreads) {
        throw Error(ErrorCode::invalid_parameter, "the CPU backend's thread count " + std::to_string(setting.count) +
                                                      " is over " + std::to_string(kMaxThreads));
    }
    const unsigned count = setting.arena != nullptr ? 0
                           : setting.count != 0     ? setting.count
                                                    : threads_from_environment();
#if PYRSEG_LOOPS_WITHOUT_TBB
    // ThreadSanitizer cannot see the synchronisation inside Debian's (uninstrumented) libtbb, so its builds run the
    // same chunks on plain threads: the passes' own races stay visible to it.
    threads_without_tbb_ = setting.arena != nullptr ? unsigned(setting.arena->max_concurrency())
                           : count != 0             ? count
                                                    : std::max(1u, std::thread::hardware_concurrency());
    serial_ = threads_without_tbb_ == 1;
#else
    serial_ = count == 1;
    if (setting.arena != nullptr) {
        arena_ = setting.arena;
    } else if (count > 1) {
        own_ = std::make_unique<tbb::task_arena>(int(count));
        arena_ = own_.get();
    }
#endif
}

ThreadPool::~ThreadPool() = default;

unsigned ThreadPool::size() const {
    if (serial_) return 1;
    if (threads_without_tbb_ != 0) return threads_without_tbb_;
    const int n = arena_ != nullptr ? arena_->max_concurrency() : tbb::this_task_arena::max_concurrency();
    return unsigned(std::max(1, n));
}

void ThreadPool::run(std::size_t count, std::size_t grain, Invoke invoke, const void* ctx) {
    grain = std::max<std::size_t>(grain, 1);
#if PYRSEG_LOOPS_WITHOUT_TBB
    std::atomic<std::size_t> next{0};
    const auto chunks = [&] {
        for (;;) {
            const std::size_t begin = next.fetch_add(grain, std::memory_order_relaxed);
            if (begin >= count) return;
            invoke(ctx, begin, std::min(count, begin + grain));
        }
    };
    std::vector<std::thread> helpers;
    for (unsigned i = 1; i < threads_without_tbb_; ++i) helpers.emplace_back(chunks);
    chunks();
    for (std::thread& t : helpers) t.join();
#else
    // The simple partitioner splits down to `grain`: the passes choose their grains for the balance they need.
    const auto loop = [&] {
        tbb::this_task_arena::isolate([&] {
            tbb::parallel_for(
                tbb::blocked_range<std::size_t>(0, count, grain),
                [&](const tbb::blocked_range<std::size_t>& r) { invoke(ctx, r.begin(), r.end()); },
                tbb::simple_partitioner());
        });
    };
    if (arena_ != nullptr) {
        arena_->execute(loop);
    } else {
        loop();
    }
#endif
}

}  // namespace pyrseg::cpu
