// The CPU backend inside an application that runs its own parallel work (pyrseg/cpu.hpp): on the application's oneTBB
// arena, called from inside its tbb::parallel_for, from an OpenMP region; the labels are those of one thread. Not in
// the ThreadSanitizer suite: these tests run the application's side on Debian's libtbb and libgomp, which it cannot
// see into.
#include <gtest/gtest.h>
#include <oneapi/tbb/enumerable_thread_specific.h>
#include <oneapi/tbb/parallel_for.h>
#include <oneapi/tbb/task_arena.h>

#include <atomic>
#include <optional>
#include <string>
#include <vector>

#include "pyrseg/cpu.hpp"
#include "pyrseg/error.hpp"
#include "support/thread_frames.hpp"

namespace pyrseg::test {
namespace {

TEST(CpuThreads, TheApplicationsArenaGivesTheLabelsOfOneThread) {
    const std::vector<TestFrame> all = thread_test_frames();
    const std::vector<Result> expected = alone(all);
    for (const int concurrency : {1, 2, 3}) {
        tbb::task_arena arena(concurrency);
        for (std::size_t i = 0; i < all.size(); ++i) {
            SCOPED_TRACE(all[i].name + " arena of " + std::to_string(concurrency));
            Segmenter s = cpu::make_segmenter(all[i].w, all[i].h, arena, all[i].params);
            ASSERT_EQ(segment_frame(s, all[i]).labels, expected[i].labels);
        }
    }
}

// Every iteration of the application's loop segments a frame with its thread's Segmenter, while the loop's other
// iterations run on the other threads: the Segmenters' loops nest inside it (isolated, so a Segmenter is never
// re-entered by a thread that waits in it).
TEST(CpuThreads, SegmentersInsideTheApplicationsParallelForGiveTheLabelsOfOneThread) {
    std::vector<TestFrame> all = thread_test_frames();
    // A frame large enough that every pass splits into many pieces (the small ones run some passes whole).
    synthetic::SceneOptions o;
    o.width = 640;
    o.height = 480;
    o.threads = 1;
    TestFrame large;
    large.w = o.width;
    large.h = o.height;
    large.points = synthetic::generate(o).points;
    large.name = "640x480";
    all.push_back(std::move(large));
    const std::vector<Result> expected = alone(all);
    for (std::size_t i = 0; i < all.size(); ++i) {
        SCOPED_TRACE(all[i].name);
        const TestFrame& f = all[i];
        tbb::enumerable_thread_specific<std::optional<Segmenter>> segmenters;
        std::atomic<int> wrong{0};
        tbb::parallel_for(0, 24, [&](int) {
            std::optional<Segmenter>& s = segmenters.local();
            if (!s) s.emplace(f.w, f.h, f.params, "cpu");
            if (segment_frame(*s, f).labels != expected[i].labels) wrong.fetch_add(1);
        });
        EXPECT_EQ(wrong.load(), 0);
    }
}

// One Segmenter called from inside the application's arena (arena.execute), the default setting: its loops run
// in the caller's arena.
TEST(CpuThreads, APlainSegmenterRunsInTheCallersArena) {
    const std::vector<TestFrame> all = thread_test_frames();
    const std::vector<Result> expected = alone(all);
    tbb::task_arena arena(2);
    for (std::size_t i = 0; i < all.size(); ++i) {
        SCOPED_TRACE(all[i].name);
        Segmenter s(all[i].w, all[i].h, all[i].params, "cpu");
        Result r;
        arena.execute([&] { r = segment_frame(s, all[i]); });
        ASSERT_EQ(r.labels, expected[i].labels);
    }
}

#if PYRSEG_TEST_OPENMP
TEST(CpuThreads, SegmentersInAnOpenMpRegionGiveTheLabelsOfOneThread) {
    const std::vector<TestFrame> all = thread_test_frames();
    const std::vector<Result> expected = alone(all);
    const int n = int(all.size());
    std::vector<int> wrong(all.size(), 0);
#pragma omp parallel for schedule(dynamic, 1)
    for (int k = 0; k < 3 * n; ++k) {
        const TestFrame& f = all[std::size_t(k % n)];
        Segmenter s(f.w, f.h, f.params, "cpu");
        if (segment_frame(s, f).labels != expected[std::size_t(k % n)].labels) wrong[std::size_t(k % n)] = 1;
    }
    for (std::size_t i = 0; i < all.size(); ++i) EXPECT_EQ(wrong[i], 0) << all[i].name;
}
#endif

TEST(CpuThreads, BadThreadCountsAreErrorsThatSaySo) {
    const auto message = [](unsigned threads) {
        try {
            (void)cpu::make_segmenter(64, 48, threads);
        } catch (const Error& e) {
            EXPECT_EQ(e.code(), ErrorCode::invalid_parameter);
            return std::string(e.what());
        }
        return std::string("no error");
    };
    EXPECT_NE(message(0).find("0 threads"), std::string::npos) << message(0);
    EXPECT_NE(message(5000).find("5000"), std::string::npos) << message(5000);
    EXPECT_NO_THROW((void)cpu::make_segmenter(64, 48, 1024));
}

}  // namespace
}  // namespace pyrseg::test
