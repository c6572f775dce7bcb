// The segment graph (docs/algorithm.md section 10d): its pairs and lengths against the labels the frame gave, and
// the kind of boundary on surfaces whose creases and steps are known. Bit-exactness against the reference is the
// conformance suite's job.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <functional>
#include <map>
#include <utility>
#include <vector>

#include "pyrseg/segmenter.hpp"
#include "pyrseg/synthetic.hpp"

namespace pyrseg {
namespace {

Outputs graph_only() {
    Outputs o;
    o.segment_graph = true;
    return o;
}

// A w x h grid, 2 mm apart in x and y, at depth z(x, y) millimetres.
std::vector<float> surface(int w, int h, const std::function<double(double, double)>& z) {
    std::vector<float> p(3 * std::size_t(w) * std::size_t(h));
    for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) {
            const double px = 2.0 * (x - w / 2);
            const double py = 2.0 * (y - h / 2);
            float* at = p.data() + 3 * (std::size_t(y) * std::size_t(w) + std::size_t(x));
            at[0] = float(px);
            at[1] = float(py);
            at[2] = float(z(px, py));
        }
    }
    return p;
}

// The pairs of 4-neighbours with different non-zero labels, counted per pair (a < b), from the labels alone.
std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> crossings(const Result& r) {
    std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> pairs;
    for (int y = 0; y < r.height; ++y) {
        for (int x = 0; x < r.width; ++x) {
            const std::uint32_t a = r.labels[std::size_t(y) * std::size_t(r.width) + std::size_t(x)];
            for (const auto& [dx, dy] : {std::pair{1, 0}, std::pair{0, 1}}) {
                if (x + dx >= r.width || y + dy >= r.height) continue;
                const std::uint32_t b = r.labels[std::size_t(y + dy) * std::size_t(r.width) + std::size_t(x + dx)];
                if (a == 0 || b == 0 || a == b) continue;
                ++pairs[{std::min(a, b), std::max(a, b)}];
            }
        }
    }
    return pairs;
}

void expect_graph_of_labels(const Result& r, bool with_kinds) {
    const auto expected = crossings(r);
    ASSERT_EQ(r.graph.size(), expected.size());
    auto it = expected.begin();
    for (const SegmentEdge& e : r.graph) {
        EXPECT_EQ(e.a, it->first.first);
        EXPECT_EQ(e.b, it->first.second);
        EXPECT_EQ(e.length, it->second) << "edge " << e.a << "-" << e.b;
        EXPECT_EQ(e.flat + e.convex + e.concave + e.step, with_kinds ? e.length : 0u);
        ++it;
    }
}

// The largest edge of the frame's graph: the boundary between the two main surfaces.
SegmentEdge longest(const Result& r) {
    SegmentEdge best;
    for (const SegmentEdge& e : r.graph) best = e.length > best.length ? e : best;
    return best;
}

TEST(SegmentGraph, PairsAndLengthsAreThoseOfTheLabels) {
    for (const std::uint64_t seed : {1u, 2u, 3u}) {
        synthetic::SceneOptions o;
        o.width = 320;
        o.height = 240;
        o.seed = seed;
        const synthetic::Scene s = synthetic::generate(o);
        for (const bool compact : {true, false}) {
            Params p;
            p.compact = compact;
            p.edge_rounds = 4;  // edge bands closed: segments touch
            Segmenter segmenter(o.width, o.height, p, "cpu", graph_only());
            const Result r = segmenter.segment(CloudView{s.points.data(), nullptr, o.width, o.height});
            ASSERT_GT(r.graph.size(), 2u);
            SCOPED_TRACE("seed " + std::to_string(seed) + (compact ? ", compacted" : ", raw labels"));
            expect_graph_of_labels(r, true);
        }
    }
}

TEST(SegmentGraph, AMaskHasLengthsWithoutKinds) {
    const synthetic::Scene s = synthetic::generate(synthetic::SceneOptions{});
    Segmenter segmenter(s.width, s.height, Params{}, "cpu", graph_only());
    Outputs with_mask = graph_only();
    with_mask.fillable_mask = true;
    Segmenter from_cloud(s.width, s.height, Params{}, "cpu", with_mask);
    const Result cloud = from_cloud.segment(CloudView{s.points.data(), nullptr, s.width, s.height});
    Result r;
    segmenter.segment_mask(MaskView{cloud.fillable_mask.data(), nullptr, s.width, s.height}, r);
    ASSERT_FALSE(r.graph.empty());
    expect_graph_of_labels(r, false);
}

TEST(SegmentGraph, NotAskedForIsEmpty) {
    const synthetic::Scene s = synthetic::generate(synthetic::SceneOptions{});
    Segmenter segmenter(s.width, s.height, Params{}, "cpu");
    EXPECT_TRUE(segmenter.segment(CloudView{s.points.data(), nullptr, s.width, s.height}).graph.empty());
}

// A ridge towards the camera is a convex crease, a valley a concave one, a raised block's rim a depth step.
TEST(SegmentGraph, KindsOfKnownBoundaries) {
    const int w = 96;
    const int h = 64;
    struct Case {
        const char* name;
        std::function<double(double, double)> z;
        std::uint32_t SegmentEdge::*kind;
    };
    const std::vector<Case> cases = {
        // The ridge's crest is its nearest line, the valley's its farthest.
        {"ridge", [](double x, double) { return 1000.0 + std::abs(x); }, &SegmentEdge::convex},
        {"valley", [](double x, double) { return 1000.0 - std::abs(x); }, &SegmentEdge::concave},
        {"block", [](double x, double y) { return std::abs(x) < 30 && std::abs(y) < 20 ? 900.0 : 1000.0; },
         &SegmentEdge::step},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(c.name);
        const std::vector<float> points = surface(w, h, c.z);
        Params p;
        p.edge_rounds = 4;  // the crease's edge band closed: the two sides touch
        Segmenter segmenter(w, h, p, "cpu", graph_only());
        const Result r = segmenter.segment(CloudView{points.data(), nullptr, w, h});
        ASSERT_GE(r.segment_count, 2u);
        const SegmentEdge e = longest(r);
        ASSERT_GT(e.length, 20u);
        EXPECT_GE(double(e.*c.kind), 0.9 * e.length)
            << "flat " << e.flat << ", convex " << e.convex << ", concave " << e.concave << ", step " << e.step;
    }
}

}  // namespace
}  // namespace pyrseg
