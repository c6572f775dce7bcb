// Bridges, plain connected components and edge labelling of `pyrseg eval` (tools/eval/bridges.hpp) on hand-made
// masks, and what a bridge does to each method.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <stdexcept>
#include <vector>

#include "pyrseg/segmenter.hpp"
#include "tools/eval/bridges.hpp"
#include "tools/eval/metrics.hpp"

namespace {

namespace ev = pyrseg::eval;
using Mask = std::vector<std::uint8_t>;
using Labels = std::vector<std::uint32_t>;

TEST(EvalBridges, DigitalPathIsFourConnectedAndStaysNearTheSegment) {
    const int w = 20;
    EXPECT_EQ(ev::digital_path(2, 3, 5, 3, w), (std::vector<std::size_t>{62, 63, 64, 65}));
    EXPECT_EQ(ev::digital_path(5, 3, 5, 1, w), (std::vector<std::size_t>{65, 45, 25}));
    // A diagonal: x first on every tie.
    EXPECT_EQ(ev::digital_path(0, 0, 2, 2, w), (std::vector<std::size_t>{0, 1, 21, 22, 42}));
    for (const auto& [x0, y0, x1, y1] : std::vector<std::array<int, 4>>{{0, 0, 19, 7}, {19, 0, 0, 9}, {3, 9, 4, 0}}) {
        const auto path = ev::digital_path(x0, y0, x1, y1, w);
        ASSERT_EQ(path.size(), std::size_t(std::abs(x1 - x0) + std::abs(y1 - y0) + 1));
        EXPECT_EQ(path.front(), std::size_t(y0 * w + x0));
        EXPECT_EQ(path.back(), std::size_t(y1 * w + x1));
        for (std::size_t k = 1; k < path.size(); ++k) {
            const int dx = std::abs(int(path[k] % w) - int(path[k - 1] % w));
            const int dy = std::abs(int(path[k] / w) - int(path[k - 1] / w));
            EXPECT_EQ(dx + dy, 1);
            // Every pixel centre is within one pixel of the straight segment.
            const int x = int(path[k] % w);
            const int y = int(path[k] / w);
            const double px = x - x0, py = y - y0;
            const double ux = x1 - x0, uy = y1 - y0;
            EXPECT_LE(std::abs(px * uy - py * ux) / std::hypot(ux, uy), 1.0);
        }
    }
}

TEST(EvalBridges, ConnectedComponentsAndEdgeLabelling) {
    // 5 x 3:   F F . F F
    //          . . . F .
    //          F . F F .
    const Mask fillable{1, 1, 0, 1, 1, 0, 0, 0, 1, 0, 1, 0, 1, 1, 0};
    std::uint32_t count = 0;
    Labels labels = ev::connected_components(fillable, 5, 3, &count);
    EXPECT_EQ(count, 3u);
    EXPECT_EQ(labels, (Labels{1, 1, 0, 2, 2, 0, 0, 0, 2, 0, 3, 0, 2, 2, 0}));
    // Step 6c: (2,0) sees 1 and 2 and takes 1; (1,2) sees 3 and 2 and takes 2; (2,1) sees only (2,2)'s 2 and
    // takes 2; (4,1) sees 2 twice; (0,1) sees 1 and 3; (1,1) sees 1 only; (4,2) is invalid and stays 0.
    Mask valid(15, 1);
    valid[14] = 0;
    ev::label_edges(labels, fillable, valid, 5, 3);
    EXPECT_EQ(labels, (Labels{1, 1, 1, 2, 2, 1, 1, 2, 2, 2, 3, 2, 2, 2, 0}));
}

TEST(EvalBridges, EdgeLabellingDoesNotSpread) {
    // F . . F: the two middle pixels each see one fillable neighbour; a pixel with none stays 0.
    const Mask fillable{1, 0, 0, 0, 1};
    Labels labels = ev::connected_components(fillable, 5, 1);
    ev::label_edges(labels, fillable, {}, 5, 1);
    EXPECT_EQ(labels, (Labels{1, 1, 0, 2, 2}));
}

// Two 30 x 32 objects side by side in a 64 x 32 frame, separated by a 3-pixel edge band (columns 29..31) with one
// notch at (29, 16) that belongs to the left object: the closest core pixels are (29, 16) and (32, 16).
struct TwoObjects {
    static constexpr int kW = 64, kH = 32;
    Labels truth = Labels(std::size_t(kW) * kH);
    Mask fillable = Mask(std::size_t(kW) * kH);
    TwoObjects() {
        for (int y = 0; y < kH; ++y) {
            for (int x = 0; x < kW; ++x) {
                const std::size_t i = std::size_t(y) * kW + std::size_t(x);
                truth[i] = x < 31 ? 1 : 2;
                fillable[i] = (x < 29 || x > 31) ? 1 : 0;
            }
        }
        fillable[16 * kW + 29] = 1;
    }
};

TEST(EvalBridges, OneSiteBetweenTheClosestCorePixels) {
    const TwoObjects s;
    const auto sites = ev::find_bridge_sites(s.truth, s.fillable, s.kW, s.kH);
    ASSERT_EQ(sites.size(), 1u);
    EXPECT_EQ(sites[0].first, 1u);
    EXPECT_EQ(sites[0].second, 2u);
    EXPECT_EQ(sites[0].x0, 29);
    EXPECT_EQ(sites[0].y0, 16);
    EXPECT_EQ(sites[0].x1, 32);
    EXPECT_EQ(sites[0].y1, 16);
    // Farther apart than max_gap: not neighbours.
    EXPECT_TRUE(ev::find_bridge_sites(s.truth, s.fillable, s.kW, s.kH, 2).empty());
}

TEST(EvalBridges, SitesAvoidPixelsWithoutData) {
    TwoObjects s;
    s.truth[16 * s.kW + 30] = 0;  // no data in the notch's row: the closest pair with a path over data wins
    s.fillable[16 * s.kW + 30] = 0;
    const auto sites = ev::find_bridge_sites(s.truth, s.fillable, s.kW, s.kH);
    ASSERT_EQ(sites.size(), 1u);
    // Every path from (29, 16) within reach crosses (30, 16) first; the next closest pairs are (28, y) and (32, y),
    // 4 pixels apart on every other row, and the tie goes to the first pixel in row-major order.
    EXPECT_EQ(sites[0].x0, 28);
    EXPECT_EQ(sites[0].y0, 0);
    EXPECT_EQ(sites[0].x1, 32);
    EXPECT_EQ(sites[0].y1, 0);
}

TEST(EvalBridges, SitesStartInTheLargestFillablePiece) {
    TwoObjects s;
    // A lone fillable pixel of object 1 right next to object 2 is not its core.
    s.fillable[3 * s.kW + 30] = 1;
    const auto sites = ev::find_bridge_sites(s.truth, s.fillable, s.kW, s.kH);
    ASSERT_EQ(sites.size(), 1u);
    EXPECT_EQ(sites[0].x0, 29);
    EXPECT_EQ(sites[0].y0, 16);
}

TEST(EvalBridges, BridgesAreWPixelsWide) {
    const TwoObjects s;
    const auto sites = ev::find_bridge_sites(s.truth, s.fillable, s.kW, s.kH);
    for (const int width : {1, 2, 3, 4, 6}) {
        Mask fillable = s.fillable;
        Mask valid(fillable.size(), 0);
        ev::draw_bridges(sites, width, s.truth, s.kW, s.kH, fillable, valid);
        // Columns 30 and 31 were edge everywhere: now fillable on exactly `width` rows, centred on row 16.
        for (const int x : {30, 31}) {
            int rows = 0, first = -1;
            for (int y = 0; y < s.kH; ++y) {
                if (fillable[std::size_t(y) * s.kW + std::size_t(x)] != 0) {
                    ++rows;
                    if (first < 0) first = y;
                }
            }
            EXPECT_EQ(rows, width) << "column " << x;
            EXPECT_EQ(first, 16 - (width - 1) / 2) << "column " << x;
        }
        // Every pixel the bridge made fillable is valid too (edge labelling may label it).
        for (std::size_t i = 0; i < fillable.size(); ++i) {
            if (fillable[i] != 0 && s.fillable[i] == 0) {
                EXPECT_EQ(valid[i], 1) << i;
            }
        }
        std::uint32_t count = 0;
        (void)ev::connected_components(fillable, s.kW, s.kH, &count);
        EXPECT_EQ(count, 1u) << "width " << width;
    }
    Mask fillable = s.fillable;
    Mask valid(fillable.size(), 0);
    EXPECT_THROW(ev::draw_bridges(sites, 0, s.truth, s.kW, s.kH, fillable, valid), std::invalid_argument);
}

// The point of the evaluation on the smallest example: a thin bridge merges the two objects for plain connected
// components but not for the pyramid; a bridge as wide as the pyramid's level-M texels merges them for both.
TEST(EvalBridges, ThinBridgeMergesConnectedComponentsNotThePyramid) {
    const TwoObjects s;
    const auto sites = ev::find_bridge_sites(s.truth, s.fillable, s.kW, s.kH);
    pyrseg::Segmenter segmenter(s.kW, s.kH, pyrseg::Params{}, "cpu");
    for (const int width : {1, 8}) {
        Mask fillable = s.fillable;
        Mask valid(fillable.size(), 1);
        ev::draw_bridges(sites, width, s.truth, s.kW, s.kH, fillable, valid);
        pyrseg::MaskView view;
        view.fillable = fillable.data();
        view.valid = valid.data();
        view.width = s.kW;
        view.height = s.kH;
        pyrseg::Result pyramid;
        segmenter.segment_mask(view, pyramid);
        Labels cc = ev::connected_components(fillable, s.kW, s.kH);
        ev::label_edges(cc, fillable, valid, s.kW, s.kH);
        const auto ps = ev::score(s.truth, pyramid.labels);
        const auto cs = ev::score(s.truth, cc);
        EXPECT_EQ(ps.objects, 2u);
        EXPECT_EQ(cs.merged, 2u) << "width " << width;
        EXPECT_EQ(ps.merged, width == 1 ? 0u : 2u) << "width " << width;
        if (width == 1) {
            EXPECT_EQ(pyramid.segment_count, 2u);
            EXPECT_EQ(ps.split, 0u);
            EXPECT_GT(ps.ari, 0.9);
        }
    }
}

}  // namespace
