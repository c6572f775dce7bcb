// The real-frame scores (tools/eval/tabletop_scores.hpp) on hand-made label images whose answers are counted by hand.
#include <gtest/gtest.h>

#include <cstdint>
#include <stdexcept>
#include <vector>

#include "tools/eval/tabletop_scores.hpp"

namespace {

using pyrseg::eval::score_tabletop;
using Labels = std::vector<std::uint32_t>;

// Ten pixels per row; truth: the table (1) on the first row, object 2 on the second, object 3 on the third.
Labels truth_rows() {
    Labels t;
    for (std::uint32_t row : {1u, 2u, 3u}) t.insert(t.end(), 10, row);
    return t;
}

TEST(TabletopScores, ASegmentPerObjectIsWhole) {
    const Labels truth = truth_rows();
    Labels predicted = truth;
    for (std::uint32_t& l : predicted) l += 10;
    const auto s = score_tabletop(truth, predicted);
    ASSERT_EQ(s.objects.size(), 2u);
    EXPECT_EQ(s.whole(), 2u);
    EXPECT_EQ(s.in_parts(), 2u);
    EXPECT_EQ(s.merged_with_table(), 0u);
    EXPECT_DOUBLE_EQ(s.mean_best_iou(), 1.0);
    EXPECT_DOUBLE_EQ(s.table_share, 1.0);
    EXPECT_EQ(s.table_label, 11u);
    EXPECT_DOUBLE_EQ(s.unlabelled_share(), 0.0);
    EXPECT_EQ(s.objects[0].parts, 1u);
}

TEST(TabletopScores, PartsMergesAndUnlabelledPixelsAreCounted) {
    const Labels truth = truth_rows();
    Labels predicted(truth.size(), 0);
    for (int x = 0; x < 10; ++x) predicted[std::size_t(x)] = 7;  // the table: segment 7
    // Object 2: three parts of 3, 3 and 4 pixels: no single one has IoU 0.5, their union is the object.
    for (int x = 0; x < 10; ++x) predicted[10 + std::size_t(x)] = x < 3 ? 20 : x < 6 ? 21 : 22;
    // Object 3: 4 pixels carry the table's label (40% >= 30%: merged), 5 are segment 30, 1 is unlabelled.
    for (int x = 0; x < 10; ++x) predicted[20 + std::size_t(x)] = x < 4 ? 7 : x < 9 ? 30 : 0;
    const auto s = score_tabletop(truth, predicted);
    ASSERT_EQ(s.objects.size(), 2u);
    const auto& two = s.objects[0];
    EXPECT_EQ(two.truth_id, 2u);
    EXPECT_FALSE(two.whole);
    EXPECT_DOUBLE_EQ(two.best_iou, 0.4);
    EXPECT_TRUE(two.in_parts);
    EXPECT_EQ(two.parts, 3u);
    EXPECT_FALSE(two.merged_with_table);
    const auto& three = s.objects[1];
    EXPECT_TRUE(three.merged_with_table);
    EXPECT_DOUBLE_EQ(three.best_iou, 0.5);  // segment 30: 5 of 10 pixels, nothing outside
    EXPECT_TRUE(three.whole);
    EXPECT_EQ(three.unlabelled, 1u);
    EXPECT_EQ(three.parts, 1u) << "segment 7 lies mostly outside object 3";
    EXPECT_EQ(s.table_label, 7u);
    EXPECT_DOUBLE_EQ(s.table_share, 1.0);
    EXPECT_DOUBLE_EQ(s.unlabelled_share(), 1.0 / 20);
    EXPECT_DOUBLE_EQ(s.mean_best_iou(), 0.45);
}

TEST(TabletopScores, ASegmentSpillingOutsideAnObjectIsNotOneOfItsParts) {
    // Object 2 (10 pixels) and a segment covering it and 4 table pixels: IoU 10/14, but only 71% inside.
    const Labels truth = truth_rows();
    Labels predicted(truth.size(), 5);
    for (int x = 0; x < 4; ++x) predicted[std::size_t(x)] = 9;
    for (int x = 0; x < 10; ++x) predicted[10 + std::size_t(x)] = 9;
    const auto s = score_tabletop(truth, predicted);
    EXPECT_TRUE(s.objects[0].whole);
    EXPECT_NEAR(s.objects[0].best_iou, 10.0 / 14.0, 1e-12);
    EXPECT_EQ(s.objects[0].parts, 0u);
    EXPECT_FALSE(s.objects[0].in_parts);
    EXPECT_NEAR(s.table_share, 0.6, 1e-12);  // segment 5 holds 6 of the 10 table pixels
}

TEST(TabletopScores, RefusesLabelImagesOfAnotherSize) {
    EXPECT_THROW((void)score_tabletop(Labels(4, 1), Labels(5, 1)), std::invalid_argument);
}

}  // namespace
