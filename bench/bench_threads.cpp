// The CPU backend where a robot runs it: beside other work. Each family compares thread settings in one run, on the
// same frames (the synthetic scene of bench_scenes.hpp), at 640x480 and 2064x1544:
//   cpu_load/SIZE/METRIC/INPUT/LOAD/SETTING    a frame while LOAD cores are taken by spinning processes this bench
//       starts before the row and stops after it (quiet, busy1 .. busy<n-1>); METRIC paper (the defaults) or
//       consumer (the realsense-d435 preset: robust metric and merge); INPUT cloud (points, normals estimated) or
//       depth (uint16); SETTING shared (the default: the caller's oneTBB arena) or threads1 (the calling thread alone)
//   cpu_segmenters/SIZE/METRIC/INPUT/N/SETTING N Segmenters in N threads at once (frames/s: all of them together);
//       SETTING shared, threads1 or threads2 (an arena of 2 of its own per Segmenter)
//   cpu_inside_tbb/SIZE/METRIC/INPUT/SETTING   a frame segmented from inside the application's tbb::parallel_for
//       whose other iterations keep every other core busy until the frame is done
// Run with repetitions and random interleaving, so that the settings share the machine's moods:
//   pyrseg_bench --benchmark_filter='^cpu_' --benchmark_repetitions=7 --benchmark_enable_random_interleaving=true
#include <oneapi/tbb/parallel_for.h>
#include <oneapi/tbb/partitioner.h>
#include <oneapi/tbb/task_arena.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "bench/bench_scenes.hpp"
#include "pyrseg/cpu.hpp"
#include "pyrseg/presets.hpp"

namespace pyrseg::bench {
namespace {

// Child processes that each spin on a core while this object lives: the load of a robot's other work.
class Spinners {
public:
    explicit Spinners(unsigned count) {
        for (unsigned i = 0; i < count; ++i) {
            const pid_t pid = fork();
            if (pid == 0) {
                std::uint64_t n = 0;
                for (;;) benchmark::DoNotOptimize(++n);
            }
            if (pid > 0) pids_.push_back(pid);
        }
    }
    ~Spinners() {
        for (const pid_t pid : pids_) kill(pid, SIGKILL);
        for (const pid_t pid : pids_) waitpid(pid, nullptr, 0);
    }
    Spinners(const Spinners&) = delete;
    Spinners& operator=(const Spinners&) = delete;

private:
    std::vector<pid_t> pids_;
};

enum class Setting { shared, threads1, threads2 };

const char* setting_name(Setting s) {
    return s == Setting::shared ? "shared" : s == Setting::threads1 ? "threads1" : "threads2";
}

Segmenter make(Setting s, int w, int h, const Params& params) {
    if (s == Setting::shared) return Segmenter(w, h, params, "cpu");
    return cpu::make_segmenter(w, h, s == Setting::threads1 ? 1u : 2u, params);
}

// The scenes' caches are not for threads that start at once (cpu_segmenters): one at a time.
std::mutex scenes_mutex;

struct Frame {
    CloudView cloud{};
    const DepthView* depth = nullptr;
    std::size_t bytes = 0;
};

Frame frame_of(int w, int h, bool depth) {
    const std::lock_guard lock(scenes_mutex);
    Frame f;
    if (depth) {
        f.depth = &depth_frame(w, h).view;
        f.bytes = std::size_t(w) * std::size_t(h) * 2;
    } else {
        const synthetic::Scene& s = scene(w, h);
        f.cloud = CloudView{s.points.data(), nullptr, w, h};
        f.bytes = std::size_t(w) * std::size_t(h) * 12;
    }
    return f;
}

void segment(Segmenter& segmenter, const Frame& f, Result& out) {
    if (f.depth != nullptr) {
        segmenter.segment(*f.depth, out);
    } else {
        segmenter.segment(f.cloud, out);
    }
}

Params params_of(bool consumer) {
    return consumer ? sensor_preset(SensorKind::realsense_d435) : Params{};
}

void under_load(benchmark::State& state, int w, int h, bool consumer, bool depth, unsigned busy, Setting setting) {
    const Frame f = frame_of(w, h, depth);
    Segmenter segmenter = make(setting, w, h, params_of(consumer));
    const Spinners load(busy);
    time_frames_on(state, segmenter, w, h, f.bytes, [&](Segmenter& s, Result& r) { segment(s, f, r); });
}

// Run by every one of the row's threads (Google Benchmark's ->Threads(N)): a Segmenter each.
void segmenters(benchmark::State& state, int w, int h, bool consumer, bool depth, Setting setting) {
    const Frame f = frame_of(w, h, depth);
    Segmenter segmenter = make(setting, w, h, params_of(consumer));
    Result result;
    segment(segmenter, f, result);
    for (auto _ : state) {
        segment(segmenter, f, result);
        benchmark::DoNotOptimize(result.labels.data());
    }
    // Google Benchmark sums the threads' counters and divides by one thread's time: kAvgThreads makes this the
    // frames a second of all the Segmenters together (the row's time is already per frame of all of them).
    state.counters["frames/s"] =
        benchmark::Counter(1, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kAvgThreads);
}

void inside_tbb(benchmark::State& state, int w, int h, bool consumer, bool depth, Setting setting) {
    const Frame f = frame_of(w, h, depth);
    Segmenter segmenter = make(setting, w, h, params_of(consumer));
    const int items = tbb::this_task_arena::max_concurrency();
    Result result;
    segment(segmenter, f, result);
    for (auto _ : state) {
        std::atomic<bool> done{false};
        // Iteration 0 (which the thread that starts the loop runs first) segments; the others are the
        // application's work, which keeps its thread busy until the frame is done.
        tbb::parallel_for(
            0, items, 1,
            [&](int i) {
                if (i == 0) {
                    segment(segmenter, f, result);
                    done.store(true, std::memory_order_release);
                } else {
                    while (!done.load(std::memory_order_acquire)) {
                    }
                }
            },
            tbb::simple_partitioner());
        benchmark::DoNotOptimize(result.labels.data());
    }
}

template <class... Parts>
std::string joined(const Parts&... parts) {
    std::string out;
    (out += ... += parts);
    return out;
}

int register_all() {
    const unsigned cores = std::max(1u, std::thread::hardware_concurrency());
    for (const auto& size : {std::pair{640, 480}, std::pair{2064, 1544}}) {
        const int w = size.first;
        const int h = size.second;
        const std::string px = size_name(w, h);
        for (const bool consumer : {false, true}) {
            for (const bool depth : {false, true}) {
                const std::string kind = joined(consumer ? "/consumer" : "/paper", depth ? "/depth" : "/cloud");
                for (unsigned busy = 0; busy < cores; ++busy) {
                    for (const Setting s : {Setting::shared, Setting::threads1}) {
                        const std::string load = busy == 0 ? "/quiet" : "/busy" + std::to_string(busy);
                        const std::string name = joined("cpu_load/", px, kind, load, "/", setting_name(s));
                        register_timed(name.c_str(),
                                       [=](benchmark::State& st) { under_load(st, w, h, consumer, depth, busy, s); });
                    }
                }
                for (const int n : {1, 2, 4, 8}) {
                    for (const Setting s : {Setting::shared, Setting::threads1, Setting::threads2}) {
                        const std::string name =
                            joined("cpu_segmenters/", px, kind, "/", std::to_string(n), "/", setting_name(s));
                        register_timed(name.c_str(), [=](benchmark::State& st) {
                            segmenters(st, w, h, consumer, depth, s);
                        })->Threads(n);
                    }
                }
                for (const Setting s : {Setting::shared, Setting::threads1, Setting::threads2}) {
                    const std::string name = joined("cpu_inside_tbb/", px, kind, "/", setting_name(s));
                    register_timed(name.c_str(),
                                   [=](benchmark::State& st) { inside_tbb(st, w, h, consumer, depth, s); });
                }
            }
        }
    }
    return 0;
}

const int kRegistered = register_all();

}  // namespace
}  // namespace pyrseg::bench
