// Hand-built masks for the pyramid passes, for every backend: the behaviour the paper is about (bridges), the
// contract's anchoring rule, step 6's schedule, edge labelling, compaction and the tiny-image fallback. Each case
// checks the property it is about and compares every output with the reference byte for byte.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <map>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "pyrseg/segmenter.hpp"
#include "pyrseg/synthetic.hpp"
#include "support/oracle.hpp"

namespace pyrseg::test {
namespace {

struct Mask {
    int width;
    int height;
    std::vector<std::uint8_t> fillable;
    std::vector<std::uint8_t> valid;

    Mask(int w, int h) : width(w), height(h), fillable(std::size_t(w) * std::size_t(h), 0), valid(fillable.size(), 1) {}
    void fill_rect(int x0, int y0, int x1, int y1, std::uint8_t v = 1) {  // inclusive
        for (int y = y0; y <= y1; ++y) {
            for (int x = x0; x <= x1; ++x) fillable[std::size_t(y) * std::size_t(width) + std::size_t(x)] = v;
        }
    }
    [[nodiscard]] std::size_t at(int x, int y) const { return std::size_t(y) * std::size_t(width) + std::size_t(x); }
};

// Plain 4-connected components count, independent of pyrseg.
int plain_components(const Mask& m) {
    std::vector<int> seen(m.fillable.size(), 0);
    int count = 0;
    for (std::size_t s = 0; s < seen.size(); ++s) {
        if (!m.fillable[s] || seen[s]) continue;
        ++count;
        std::vector<std::size_t> stack{s};
        seen[s] = 1;
        while (!stack.empty()) {
            const std::size_t i = stack.back();
            stack.pop_back();
            const int x = int(i % std::size_t(m.width));
            const int y = int(i / std::size_t(m.width));
            const int nbs[4][2] = {{x - 1, y}, {x + 1, y}, {x, y - 1}, {x, y + 1}};
            for (const auto& nb : nbs) {
                if (nb[0] < 0 || nb[1] < 0 || nb[0] >= m.width || nb[1] >= m.height) continue;
                const std::size_t j = m.at(nb[0], nb[1]);
                if (m.fillable[j] && !seen[j]) {
                    seen[j] = 1;
                    stack.push_back(j);
                }
            }
        }
    }
    return count;
}

class HandCases : public ::testing::TestWithParam<std::string> {
protected:
    void SetUp() override { PYRSEG_SKIP_IF_UNAVAILABLE(GetParam()); }

    // Runs the backend on the mask, checks it against the reference, returns the backend's result.
    Result run(const Mask& m, const Params& params = {}) {
        Outputs outputs;
        outputs.raw_labels = true;
        outputs.fillable_mask = true;
        outputs.segment_stats = true;
        outputs.segment_graph = true;
        Segmenter segmenter(m.width, m.height, params, GetParam(), outputs);
        MaskView view;
        view.fillable = m.fillable.data();
        view.valid = m.valid.data();
        view.width = m.width;
        view.height = m.height;
        Result r;
        segmenter.segment_mask(view, r);
        fill_rounds_ = segmenter.last_fill_rounds();
        const pyrseg_ref::Output ref =
            pyrseg_ref::segment_mask(m.fillable.data(), m.valid.data(), m.width, m.height, to_reference(params));
        EXPECT_TRUE(ref.ok) << ref.error;
        EXPECT_TRUE(same_bytes("raw labels", r.raw_labels, ref.raw_labels, m.width));
        EXPECT_TRUE(same_bytes("labels", r.labels, ref.labels, m.width));
        EXPECT_EQ(r.segment_count, ref.segment_count);
        EXPECT_TRUE(same_segments(r.segments, ref.segments));
        EXPECT_TRUE(same_graph(r.graph, ref.graph));
        EXPECT_EQ(r.fillable_mask, m.fillable);
        return r;
    }

    std::uint32_t fill_rounds_ = 0;  // of the last run
};

// Two large regions joined by a 1-pixel and a 2-pixel bridge: plain labelling merges them, the pyramid does not.
TEST_P(HandCases, BridgesDoNotMergeLargeRegions) {
    Mask m(128, 64);
    m.fill_rect(0, 0, 59, 63);
    m.fill_rect(68, 0, 127, 63);
    m.fill_rect(60, 10, 67, 10);  // 1-pixel bridge
    m.fill_rect(60, 40, 67, 41);  // 2-pixel bridge
    ASSERT_EQ(plain_components(m), 1);
    const Result r = run(m);
    const std::uint32_t left = r.labels[m.at(30, 30)];
    const std::uint32_t right = r.labels[m.at(100, 30)];
    EXPECT_NE(left, 0u);
    EXPECT_NE(right, 0u);
    EXPECT_NE(left, right) << "the bridges merged the two regions";
    EXPECT_EQ(r.segment_count, 2u);
    for (int y = 0; y < 64; ++y) {
        EXPECT_EQ(r.labels[m.at(0, y)], left);
        EXPECT_EQ(r.labels[m.at(127, y)], right);
    }
}

// A small (young) region joined by bridges to two large (old) ones joins the smaller-labelled old region, and the
// old regions stay apart (contract step 4, anchoring).
TEST_P(HandCases, YoungRegionBetweenTwoOldOnesJoinsTheSmallerLabel) {
    Mask m(128, 64);
    m.fill_rect(0, 0, 51, 63);    // old region A (contains 16x16 blocks of level U)
    m.fill_rect(76, 0, 127, 63);  // old region B
    m.fill_rect(56, 24, 71, 39);  // young region, too small for level U
    m.fill_rect(52, 30, 55, 31);  // 2-pixel bridges A - young - B
    m.fill_rect(72, 30, 75, 31);
    ASSERT_EQ(plain_components(m), 1);
    const Result r = run(m);
    const std::uint32_t a = r.raw_labels[m.at(20, 20)];
    const std::uint32_t b = r.raw_labels[m.at(100, 20)];
    const std::uint32_t young = r.raw_labels[m.at(63, 31)];
    ASSERT_NE(a, b);
    EXPECT_EQ(young, std::min(a, b));
    EXPECT_EQ(r.segment_count, 2u);
}

// Anchors are the texels whose label is old after step 3, not texels that adopt an old label during the fill:
// a corridor reached first (left to right) by the larger old label must still end with the smaller one.
TEST_P(HandCases, AnchorsAreFixedBeforeTheFillStarts) {
    Mask m(128, 64);
    m.fill_rect(0, 16, 47, 63);   // B: its first level-U texel is in the second texel row
    m.fill_rect(80, 0, 127, 47);  // A: starts in the first texel row, so its label is smaller
    m.fill_rect(48, 30, 79, 31);  // a 2-pixel corridor, visible at level N-1 only
    const Result r = run(m);
    const std::uint32_t a = r.raw_labels[m.at(100, 10)];
    const std::uint32_t b = r.raw_labels[m.at(10, 50)];
    ASSERT_LT(a, b);
    EXPECT_EQ(r.raw_labels[m.at(50, 30)], a) << "the corridor kept the larger label it met first";
    EXPECT_EQ(r.raw_labels[m.at(78, 31)], a);
}

// Step 6 is one iteration in a fixed order: rows (left-right, right-left), then columns (down, up). Thin
// full-resolution-only paths show the order: a pixel needing a column move before a row move stays unlabelled.
TEST_P(HandCases, FinalFillFollowsTheRowThenColumnSchedule) {
    Mask m(64, 64);
    m.fill_rect(0, 0, 31, 63);  // a large region on the left
    // A 1-pixel staircase leaving it: right along row 5, down column 40, right along row 20.
    m.fill_rect(32, 5, 40, 5);
    m.fill_rect(40, 6, 40, 20);
    m.fill_rect(41, 20, 50, 20);
    const Result r = run(m);
    const std::uint32_t region = r.labels[m.at(10, 10)];
    EXPECT_EQ(r.labels[m.at(40, 5)], region);   // row sweep
    EXPECT_EQ(r.labels[m.at(40, 20)], region);  // then column sweep down
    EXPECT_EQ(r.labels[m.at(45, 20)], 0u);      // a row move after a column move is not in one iteration
}

TEST_P(HandCases, EdgeLabellingTakesTheSmallestFillableNeighbourAndSkipsInvalidPixels) {
    Mask m(64, 32);
    m.fill_rect(0, 0, 29, 31);
    m.fill_rect(33, 0, 63, 31);
    for (int y = 0; y < 32; ++y) m.valid[m.at(31, y)] = 0;  // column 31 invalid; 30 and 32 valid edges
    Params with_edges;
    const Result r = run(m, with_edges);
    const std::uint32_t left = r.labels[m.at(5, 5)];
    const std::uint32_t right = r.labels[m.at(50, 5)];
    ASSERT_NE(left, right);
    for (int y = 0; y < 32; ++y) {
        EXPECT_EQ(r.labels[m.at(30, y)], left);
        EXPECT_EQ(r.labels[m.at(31, y)], 0u);
        EXPECT_EQ(r.labels[m.at(32, y)], right);
    }
    Params without;
    without.label_edges = false;
    const Result bare = run(m, without);
    for (int y = 0; y < 32; ++y) EXPECT_EQ(bare.labels[m.at(30, y)], 0u);
}

TEST_P(HandCases, EdgePixelBetweenTwoSegmentsTakesTheSmallerLabel) {
    Mask m(64, 32);
    m.fill_rect(0, 0, 30, 31);
    m.fill_rect(32, 0, 63, 31);  // column 31 is a 1-pixel valid edge between the two
    const Result r = run(m);
    const std::uint32_t left = r.raw_labels[m.at(5, 5)];
    const std::uint32_t right = r.raw_labels[m.at(50, 5)];
    ASSERT_NE(left, right);
    EXPECT_EQ(r.raw_labels[m.at(31, 7)], std::min(left, right));
}

TEST_P(HandCases, CompactionKeepsTheOrderOfRawLabels) {
    Mask m(96, 96);
    m.fill_rect(0, 0, 47, 47);
    m.fill_rect(50, 0, 95, 30);
    m.fill_rect(50, 34, 60, 44);
    m.fill_rect(0, 52, 95, 95);
    m.fill_rect(70, 40, 72, 42);
    const Result r = run(m);
    std::map<std::uint32_t, std::uint32_t> raw_to_compact;
    for (std::size_t i = 0; i < r.labels.size(); ++i) {
        if (r.raw_labels[i] == 0) {
            EXPECT_EQ(r.labels[i], 0u);
            continue;
        }
        const auto [it, inserted] = raw_to_compact.emplace(r.raw_labels[i], r.labels[i]);
        EXPECT_EQ(it->second, r.labels[i]) << "one raw label became two compact labels";
    }
    ASSERT_EQ(raw_to_compact.size(), r.segment_count);
    std::uint32_t expected = 1;
    for (const auto& [raw, compact] : raw_to_compact) EXPECT_EQ(compact, expected++) << "raw label " << raw;
}

TEST_P(HandCases, TinyImagesArePlainConnectedComponents) {
    Mask m(8, 8);
    m.fill_rect(0, 0, 2, 7);
    m.fill_rect(4, 0, 7, 1);
    m.fill_rect(7, 2, 7, 7);
    m.fill_rect(5, 5, 5, 5);
    Outputs outputs;
    const Result r = run(m);
    EXPECT_EQ(r.segment_count, 3u);
    EXPECT_EQ(r.raw_labels[m.at(1, 7)], 1u);   // 1 + index of (0, 0)
    EXPECT_EQ(r.raw_labels[m.at(7, 7)], 5u);   // 1 + index of (4, 0)
    EXPECT_EQ(r.raw_labels[m.at(5, 5)], 46u);  // 1 + index of (5, 5)
    EXPECT_EQ(r.labels[m.at(5, 5)], 3u);
    EXPECT_EQ(r.labels[m.at(3, 3)], 0u);  // no edge labelling in the fallback
    for (const auto& size : {std::pair{1, 1}, std::pair{1, 7}, std::pair{7, 1}}) {
        Mask strip(size.first, size.second);
        strip.fill_rect(0, 0, size.first - 1, size.second - 1);
        EXPECT_EQ(run(strip).segment_count, 1u);
    }
}

TEST_P(HandCases, AnEmptyMaskHasNoSegments) {
    const Mask m(33, 17);
    const Result r = run(m);
    EXPECT_EQ(r.segment_count, 0u);
    EXPECT_TRUE(std::all_of(r.labels.begin(), r.labels.end(), [](std::uint32_t l) { return l == 0; }));
}

// A staircase corridor from the top-left to the bottom-right: each round of row and column sweeps carries the
// smallest label down only one step, so a sweep scheme needs about as many rounds as there are steps (63). Every
// backend reaches the fixed point; only the CPU's sweep scheme (PYRSEG_CPU_FILL=sweeps) counts rounds, since the
// CPU's and the GPUs' union-find fills compute the fixed point directly and report 0.
TEST_P(HandCases, AFillNeedingManyRoundsReachesTheFixedPoint) {
    Mask m(512, 512);
    for (int step = 0; step < 63; ++step) {
        const int x = step * 8;
        const int y = step * 8;
        m.fill_rect(x, y, x + 11, y + 3);       // across, 4 px thick
        m.fill_rect(x + 8, y, x + 11, y + 11);  // down
    }
    ASSERT_EQ(plain_components(m), 1);
    Params params;
    params.bridge_levels = 1;  // new labels on level N - 1, where the corridor is 2 texels wide
    const Result first = run(m, params);
    EXPECT_EQ(first.labels[m.at(0, 0)], first.labels[m.at(500, 500)]) << "the corridor is one segment";
    const char* cpu_fill = std::getenv("PYRSEG_CPU_FILL");
    if (GetParam() == "cpu" && cpu_fill != nullptr && std::string(cpu_fill) == "sweeps") {
        EXPECT_GE(fill_rounds_, 63u) << "a round crosses one step of the staircase";
    } else {
        EXPECT_EQ(fill_rounds_, 0u) << "union-find fills take no rounds";
    }
}

// The fills' worst cases for any propagation scheme, at sizes that are no multiple of anything: one region winding
// through the whole frame (a spiral; mazes of three seeds), every label carried the whole way.
TEST_P(HandCases, WindingRegionsMatchTheReference) {
    for (const auto& [w, h] : {std::pair{333, 251}, std::pair{640, 480}}) {
        std::vector<synthetic::FillMask> masks = {synthetic::spiral_mask(w, h)};
        for (const std::uint32_t seed : {1u, 2u, 12345u}) masks.push_back(synthetic::maze_mask(w, h, seed));
        for (const synthetic::FillMask& f : masks) {
            Mask m(w, h);
            m.fillable = f.fillable;
            ASSERT_EQ(plain_components(m), 1);
            SCOPED_TRACE(std::to_string(w) + " x " + std::to_string(h));
            (void)run(m);
        }
    }
}

// One component over the whole frame: every texel's candidate goes to one root (atomic contention on GPUs).
TEST_P(HandCases, OneHugeComponent) {
    Mask m(1031, 772);
    m.fill_rect(0, 0, 1030, 771);
    const Result r = run(m);
    EXPECT_EQ(r.segment_count, 1u);
}

// Stripes too thin to reach level U: no label is old, so step 4 has no anchors at all.
TEST_P(HandCases, FramesWhoseLabelsAreAllYoung) {
    Mask m(256, 192);
    for (int x = 0; x + 6 <= 256; x += 8) m.fill_rect(x, 0, x + 5, 191);
    m.fill_rect(0, 100, 255, 101);  // a thin bridge across all of them
    (void)run(m);
}

// A GPU frame's cost besides its kernels does not depend on the image: the same dispatches for a maze, a spiral and
// a few boxes, and one host wait (two with segment statistics, fetched once K is known).
TEST_P(HandCases, DispatchesAndHostWaitsDoNotDependOnTheImage) {
    const int w = 640;
    const int h = 480;
    Mask boxes(w, h);
    boxes.fill_rect(10, 10, 300, 200);
    boxes.fill_rect(320, 10, 630, 470);
    boxes.fill_rect(10, 220, 200, 470);
    std::vector<std::vector<std::uint8_t>> masks = {synthetic::maze_mask(w, h).fillable,
                                                    synthetic::spiral_mask(w, h).fillable, boxes.fillable};
    for (const int asked : {0, 1, 2, 3}) {
        const bool stats = (asked & 1) != 0;
        const bool graph = (asked & 2) != 0;
        Outputs outputs;
        outputs.segment_stats = stats;
        outputs.segment_graph = graph;
        Segmenter segmenter(w, h, {}, GetParam(), outputs);
        std::set<std::uint32_t> dispatches;
        std::set<std::uint32_t> waits;
        Result r;
        for (const auto& mask : masks) {
            segmenter.segment_mask(MaskView{mask.data(), nullptr, w, h}, r);
            dispatches.insert(segmenter.last_dispatches());
            waits.insert(segmenter.last_host_syncs());
        }
        EXPECT_EQ(dispatches.size(), 1u) << "dispatches differ between images";
        EXPECT_EQ(waits.size(), 1u) << "host waits differ between images";
        if (GetParam() == "cpu") {
            EXPECT_EQ(*dispatches.begin(), 0u);
            EXPECT_EQ(*waits.begin(), 0u);
        } else {
            EXPECT_GT(*dispatches.begin(), 10u);
            EXPECT_EQ(*waits.begin(), stats || graph ? 2u : 1u);
        }
    }
}

INSTANTIATE_TEST_SUITE_P(Backends, HandCases, ::testing::ValuesIn(available_backend_names()),
                         [](const ::testing::TestParamInfo<std::string>& param_info) { return param_info.param; });

}  // namespace
}  // namespace pyrseg::test
