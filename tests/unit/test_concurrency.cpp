// The CPU backend under concurrency, the suite ThreadSanitizer runs (scripts/test.sh --tsan): Segmenters in several
// threads at once, and one Segmenter's thread pool at several sizes, give the labels of one thread. Frames are
// chosen to reach every parallel pass: fragmented masks (noise), anchored fills, several edge rounds and the robust
// metric's windows (a sensor preset), estimated and given normals, depth images.
#include <gtest/gtest.h>

#include <cstdint>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "pyrseg/cpu.hpp"
#include "pyrseg/presets.hpp"
#include "pyrseg/segmenter.hpp"
#include "pyrseg/synthetic.hpp"
#include "support/cpu_targets.hpp"
#include "support/test_frame.hpp"
#include "support/thread_frames.hpp"

namespace pyrseg::test {
namespace {

TEST(Concurrency, ThreadPoolsOfEverySizeGiveTheLabelsOfOneThread) {
    const std::vector<TestFrame> all = thread_test_frames();
    const std::vector<Result> expected = alone(all);
    for (const char* threads : {"2", "3", "4", "7"}) {
        const ScopedEnv env("PYRSEG_THREADS", threads);
        for (std::size_t i = 0; i < all.size(); ++i) {
            SCOPED_TRACE(all[i].name + " threads=" + threads);
            Segmenter s(all[i].w, all[i].h, all[i].params, "cpu");
            for (int repeat = 0; repeat < 2; ++repeat) {
                const Result r = segment_frame(s, all[i]);
                ASSERT_EQ(r.labels, expected[i].labels);
                ASSERT_EQ(r.segment_count, expected[i].segment_count);
            }
        }
    }
    std::uint32_t segments = 0;
    for (const Result& r : expected) segments += r.segment_count;
    EXPECT_GT(segments, 30u) << "the frames must have segments for the labels to say much";
}

// Four threads, each with its own Segmenter (pools of 2), over every frame in a different order, at the same time.
// Segmenters with a thread count of their own (pyrseg/cpu.hpp).
TEST(Concurrency, ThreadCountsGiveTheLabelsOfOneThread) {
    const std::vector<TestFrame> all = thread_test_frames();
    const std::vector<Result> expected = alone(all);
    for (const unsigned threads : {1u, 2u, 5u}) {
        for (std::size_t i = 0; i < all.size(); ++i) {
            SCOPED_TRACE(all[i].name + " threads=" + std::to_string(threads));
            Segmenter s = cpu::make_segmenter(all[i].w, all[i].h, threads, all[i].params);
            ASSERT_EQ(segment_frame(s, all[i]).labels, expected[i].labels);
        }
    }
}

TEST(Concurrency, SegmentersInSeveralThreadsGiveTheLabelsOfOneThread) {
    const std::vector<TestFrame> all = thread_test_frames();
    const std::vector<Result> expected = alone(all);
    const ScopedEnv env("PYRSEG_THREADS", "2");
    constexpr int kThreads = 4;
    std::vector<std::string> failures(kThreads);
    std::vector<std::thread> threads;
    for (int t = 0; t < kThreads; ++t) {
        threads.emplace_back([&, t] {
            for (std::size_t k = 0; k < 2 * all.size(); ++k) {
                const std::size_t i = (k * 3 + std::size_t(t)) % all.size();
                Segmenter s(all[i].w, all[i].h, all[i].params, "cpu");
                const Result r = segment_frame(s, all[i]);
                if (r.labels != expected[i].labels && failures[std::size_t(t)].empty())
                    failures[std::size_t(t)] = all[i].name;
            }
        });
    }
    for (std::thread& t : threads) t.join();
    for (int t = 0; t < kThreads; ++t) EXPECT_EQ(failures[std::size_t(t)], "") << "thread " << t << ": labels differ";
}

// One Segmenter handed from thread to thread (one at a time, as a pipeline's stages would): the same labels.
TEST(Concurrency, ASegmenterMovesBetweenThreads) {
    const std::vector<TestFrame> all = thread_test_frames();
    const std::vector<Result> expected = alone(all);
    const TestFrame& f = all.back();
    Segmenter s(f.w, f.h, f.params, "cpu");
    for (int t = 0; t < 4; ++t) {
        Result r;
        std::thread([&] { r = segment_frame(s, f); }).join();
        EXPECT_EQ(r.labels, expected.back().labels) << "in thread " << t;
    }
}

}  // namespace
}  // namespace pyrseg::test
