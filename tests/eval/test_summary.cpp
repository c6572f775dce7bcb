// The totals and acceptance checks `pyrseg eval` reports per sensor model (tools/eval/summary.hpp).
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "tools/eval/summary.hpp"

namespace {

using pyrseg::eval::Cell;
using pyrseg::eval::Scores;
using pyrseg::eval::summarize;

Scores scores(std::uint32_t merged, double ari, std::uint64_t labelled, std::uint64_t pixels) {
    Scores s;
    s.merged = merged;
    s.ari = ari;
    s.labelled = labelled;
    s.pixels = pixels;
    s.objects = 10;
    return s;
}

Cell cell(double distance, int bridge, std::uint32_t pyramid_merged, std::uint32_t cc_merged) {
    Cell c;
    c.distance_mm = distance;
    c.bridge = bridge;
    c.objects = 10;
    c.pyramid.add(scores(pyramid_merged, 0.9, 95, 100));
    c.cc.add(scores(cc_merged, 0.6, 99, 100));
    if (bridge == 0) c.pcl.add(scores(0, 0.7, 80, 100));
    return c;
}

TEST(EvalSummary, PoolsOverDistancesAndChecks) {
    const std::vector<Cell> cells = {cell(800, 0, 1, 1),  cell(800, 1, 0, 8),  cell(800, 2, 1, 8),
                                     cell(1200, 0, 1, 2), cell(1200, 1, 1, 7), cell(1200, 2, 1, 6)};
    const auto s = summarize(cells);
    EXPECT_EQ(s.pyramid0.frames, 2);
    EXPECT_DOUBLE_EQ(s.pyramid0.ari(), 0.9);
    EXPECT_DOUBLE_EQ(s.pcl0.ari(), 0.7);
    EXPECT_DOUBLE_EQ(s.pyramid0.labelled_share(), 0.95);
    ASSERT_TRUE(s.merge[0].present && s.merge[1].present);
    EXPECT_EQ(s.merge[0].objects, 20u);
    EXPECT_EQ(s.merge[0].pyramid, 1u);
    EXPECT_EQ(s.merge[0].cc, 15u);
    EXPECT_DOUBLE_EQ(s.merge[1].ratio(), 2.0 / 14.0);
    EXPECT_EQ(s.ari_at_least_pcl, true);
    EXPECT_EQ(s.merges_fifth_of_cc, true);  // 1 <= 15/5 and 2 <= 14/5
    EXPECT_EQ(s.labels_enough, true);
}

TEST(EvalSummary, ChecksFailAndMissingMeasurementsAreNotJudged) {
    // Width 2 merges 3 of CC's 10: more than a fifth.
    std::vector<Cell> cells = {cell(800, 0, 0, 0), cell(800, 1, 2, 10), cell(800, 2, 3, 10)};
    cells[0].pyramid = {};
    cells[0].pyramid.add(scores(0, 0.5, 80, 100));  // below PCL's 0.7, and labels 80%
    auto s = summarize(cells);
    EXPECT_EQ(s.ari_at_least_pcl, false);
    EXPECT_EQ(s.merges_fifth_of_cc, false);
    EXPECT_EQ(s.labels_enough, false);
    // No PCL and no bridged widths: nothing to judge there.
    cells = {cell(800, 0, 0, 0)};
    cells[0].pcl = {};
    s = summarize(cells);
    EXPECT_FALSE(s.ari_at_least_pcl.has_value());
    EXPECT_FALSE(s.merges_fifth_of_cc.has_value());
    EXPECT_TRUE(std::isnan(s.pcl0.ari()));
    EXPECT_TRUE(std::isnan(s.merge[0].ratio()));
    EXPECT_EQ(s.labels_enough, true);
    // The separable check judges the separable counts alone: here 2 of CC's 10 raw merges were separable and the
    // pyramid's 2 raw merges were flush pairs only.
    cells = {cell(800, 0, 0, 0), cell(800, 1, 2, 10)};
    cells[1].pyramid.merged_separable = 0;
    cells[1].cc.merged_separable = 2;
    s = summarize(cells);
    EXPECT_EQ(s.merges_fifth_of_cc, true);
    EXPECT_EQ(s.separable_merges_fifth_of_cc, true);
    EXPECT_DOUBLE_EQ(s.merge[0].separable_ratio(), 0.0);
    cells[1].pyramid.merged_separable = 1;  // 1 > 2/5
    EXPECT_EQ(summarize(cells).separable_merges_fifth_of_cc, false);
    // Bridges that merged nothing for CC do not test the pyramid.
    cells = {cell(800, 0, 0, 0), cell(800, 1, 0, 0), cell(800, 2, 0, 0)};
    EXPECT_FALSE(summarize(cells).merges_fifth_of_cc.has_value());
}

}  // namespace
