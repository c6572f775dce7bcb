// The quality metrics of `pyrseg eval` (tools/eval/metrics.hpp) on hand-made label images with known answers, and
// the adjusted Rand index against a brute-force count over all pixel pairs.
#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <random>
#include <stdexcept>
#include <vector>

#include "tools/eval/metrics.hpp"

namespace {

using pyrseg::eval::adjusted_rand_index;
using pyrseg::eval::score;
using Labels = std::vector<std::uint32_t>;

// The definition, pair by pair: pixels with truth 0 are left out; predicted 0 is in no pair.
double brute_force_ari(const Labels& truth, const Labels& predicted) {
    double index = 0, same_truth = 0, same_predicted = 0, total = 0;
    for (std::size_t i = 0; i < truth.size(); ++i) {
        if (truth[i] == 0) continue;
        for (std::size_t j = i + 1; j < truth.size(); ++j) {
            if (truth[j] == 0) continue;
            const bool t = truth[i] == truth[j];
            const bool p = predicted[i] != 0 && predicted[i] == predicted[j];
            total += 1;
            same_truth += t;
            same_predicted += p;
            index += t && p;
        }
    }
    if (total == 0) return 1.0;
    const double expected = same_truth * same_predicted / total;
    const double maximum = 0.5 * (same_truth + same_predicted);
    if (maximum == expected) return 1.0;
    return (index - expected) / (maximum - expected);
}

TEST(EvalMetrics, AdjustedRandIndexKnownValues) {
    // scikit-learn's documented examples, labels shifted by one (0 means "no ground truth" / "unlabelled" here).
    EXPECT_DOUBLE_EQ(adjusted_rand_index(Labels{1, 1, 2, 2}, Labels{1, 1, 2, 2}), 1.0);
    EXPECT_DOUBLE_EQ(adjusted_rand_index(Labels{1, 1, 2, 2}, Labels{2, 2, 1, 1}), 1.0);
    EXPECT_NEAR(adjusted_rand_index(Labels{1, 1, 2, 2}, Labels{1, 1, 2, 3}), 0.5714285714285714, 1e-12);
    EXPECT_NEAR(adjusted_rand_index(Labels{1, 1, 1, 2, 2, 2}, Labels{1, 1, 2, 2, 3, 3}), 0.24242424242424243, 1e-12);
    EXPECT_NEAR(adjusted_rand_index(Labels{1, 1, 2, 2}, Labels{1, 2, 1, 2}), -0.5, 1e-12);
}

TEST(EvalMetrics, UnlabelledPixelsAreSingletons) {
    // One object, nothing labelled: every pixel is its own cluster, no agreement beyond chance.
    EXPECT_DOUBLE_EQ(adjusted_rand_index(Labels{1, 1, 1, 1}, Labels{0, 0, 0, 0}), 0.0);
    // Singletons in truth and prediction alike: identical partitions.
    EXPECT_DOUBLE_EQ(adjusted_rand_index(Labels{1, 2, 3, 4}, Labels{0, 0, 0, 0}), 1.0);
    // Unlabelled pixels are not one cluster: {0, 0} is not a pair, so this equals labels 5 and 6 on them.
    EXPECT_DOUBLE_EQ(adjusted_rand_index(Labels{1, 1, 2, 2, 3, 3}, Labels{7, 7, 8, 8, 0, 0}),
                     adjusted_rand_index(Labels{1, 1, 2, 2, 3, 3}, Labels{7, 7, 8, 8, 5, 6}));
}

TEST(EvalMetrics, PixelsWithoutGroundTruthAreIgnored) {
    const Labels truth{1, 1, 0, 2, 2, 0};
    EXPECT_DOUBLE_EQ(adjusted_rand_index(truth, Labels{3, 3, 9, 4, 4, 3}), 1.0);
    const auto s = score(truth, Labels{3, 3, 9, 4, 4, 3}, 1);
    EXPECT_EQ(s.pixels, 4u);
    EXPECT_EQ(s.labelled, 4u);
    EXPECT_EQ(s.segments, 2u);
    EXPECT_EQ(s.merged, 0u);
}

TEST(EvalMetrics, AdjustedRandIndexMatchesPairCounting) {
    std::mt19937 rng(7);
    for (int trial = 0; trial < 200; ++trial) {
        const std::size_t n = 1 + rng() % 60;
        const std::uint32_t truth_ids = 1 + rng() % 5;
        const std::uint32_t predicted_ids = 1 + rng() % 6;
        Labels truth(n), predicted(n);
        for (std::size_t i = 0; i < n; ++i) {
            truth[i] = rng() % (truth_ids + 1);                                        // 0: no ground truth
            predicted[i] = rng() % 4 == 0 ? 0u : 0xFFFFFFF0u + rng() % predicted_ids;  // large labels work too
        }
        EXPECT_NEAR(adjusted_rand_index(truth, predicted), brute_force_ari(truth, predicted), 1e-12) << trial;
        EXPECT_DOUBLE_EQ(score(truth, predicted).ari, adjusted_rand_index(truth, predicted));
    }
}

TEST(EvalMetrics, OneSegmentOverTwoObjectsMergesBoth) {
    const Labels truth{1, 1, 1, 1, 2, 2, 2, 2};
    const auto s = score(truth, Labels{5, 5, 5, 5, 5, 5, 5, 5}, 4);
    EXPECT_EQ(s.objects, 2u);
    EXPECT_EQ(s.merged, 2u);
    EXPECT_EQ(s.split, 0u);
    EXPECT_EQ(s.segments, 1u);
    EXPECT_DOUBLE_EQ(s.ari, 0.0);
}

TEST(EvalMetrics, AClaimNeedsMoreThanHalf) {
    const Labels truth{1, 1, 1, 1, 2, 2, 2, 2};
    // Segment 7 holds exactly half of object 1 (no claim) and all of object 2: nothing is merged.
    auto s = score(truth, Labels{7, 7, 8, 8, 7, 7, 7, 7}, 4);
    EXPECT_EQ(s.merged, 0u);
    EXPECT_EQ(s.split, 1u);  // object 1: largest segment 2 of 4 labelled pixels
    // Three of four: claimed, so both objects are merged.
    s = score(truth, Labels{7, 7, 7, 8, 7, 7, 7, 7}, 4);
    EXPECT_EQ(s.merged, 2u);
    EXPECT_EQ(s.split, 1u);  // 3 of 4 = 75% < 80%
}

TEST(EvalMetrics, SeparableMergesLeaveFlushGroupsAside) {
    // Objects 1, 2, 3, 4 of 2 pixels each; 1-2 and 2-3 are flush pairs (a chain), 4 is flush with none.
    const Labels truth{1, 1, 2, 2, 3, 3, 4, 4};
    const std::vector<std::array<std::uint32_t, 2>> flush{{1, 2}, {2, 3}, {7, 9}};  // 7, 9: not in the frame
    // One segment over the flush chain only: merged, but not a separable merge.
    auto s = score(truth, Labels{5, 5, 5, 5, 5, 5, 6, 6}, 2, 0.8, flush);
    EXPECT_EQ(s.merged, 3u);
    EXPECT_EQ(s.merged_separable, 0u);
    // The chain and object 4 together: every one of them is merged with an object it is not flush with.
    s = score(truth, Labels{5, 5, 5, 5, 5, 5, 5, 5}, 2, 0.8, flush);
    EXPECT_EQ(s.merged, 4u);
    EXPECT_EQ(s.merged_separable, 4u);
    // 1 with 4 (separable), 2 with 3 (flush): two separable merges.
    s = score(truth, Labels{5, 5, 6, 6, 6, 6, 5, 5}, 2, 0.8, flush);
    EXPECT_EQ(s.merged, 4u);
    EXPECT_EQ(s.merged_separable, 2u);
    // Without flush pairs the two counts are the same.
    s = score(truth, Labels{5, 5, 5, 5, 5, 5, 6, 6}, 2);
    EXPECT_EQ(s.merged_separable, s.merged);
}

TEST(EvalMetrics, SmallObjectsAreNotEvaluated) {
    // Object 2 has 2 pixels, under the minimum of 3: it is not counted, and merging with it does not count.
    const Labels truth{1, 1, 1, 1, 2, 2};
    const auto s = score(truth, Labels{4, 4, 4, 4, 4, 4}, 3);
    EXPECT_EQ(s.objects, 1u);
    EXPECT_EQ(s.merged, 0u);
    EXPECT_EQ(score(truth, Labels{4, 4, 4, 4, 4, 4}, 2).merged, 2u);
}

TEST(EvalMetrics, SplitCountsLabelledPixelsAndUnlabelledObjects) {
    const Labels truth{1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 2, 2, 2, 2, 2};
    // Object 1: half unlabelled, the rest one segment: not split (labelled: 5 of 15 pixels overall here).
    // Object 2: nothing labelled: split.
    auto s = score(truth, Labels{0, 0, 0, 0, 0, 3, 3, 3, 3, 3, 0, 0, 0, 0, 0}, 5);
    EXPECT_EQ(s.objects, 2u);
    EXPECT_EQ(s.split, 1u);
    EXPECT_EQ(s.merged, 0u);
    EXPECT_EQ(s.pixels, 15u);
    EXPECT_EQ(s.labelled, 5u);
    // Object 1 in 8 + 2 pixels (80%: not split), object 2 in 3 + 1 + 1 (60%: split).
    s = score(truth, Labels{3, 3, 3, 3, 3, 3, 3, 3, 4, 4, 5, 5, 5, 6, 7}, 5);
    EXPECT_EQ(s.split, 1u);
    EXPECT_EQ(s.segments, 5u);
}

TEST(EvalMetrics, InterleavedLabelsCountLikeRuns) {
    // The contingency table counts runs: the order of pixels must not matter.
    const Labels truth{1, 2, 1, 2, 1, 2, 1, 2, 3, 3};
    const Labels predicted{5, 6, 5, 6, 5, 5, 5, 6, 0, 6};
    Labels truth_sorted{1, 1, 1, 1, 2, 2, 2, 2, 3, 3};
    Labels predicted_sorted{5, 5, 5, 5, 6, 6, 5, 6, 0, 6};
    EXPECT_DOUBLE_EQ(adjusted_rand_index(truth, predicted), adjusted_rand_index(truth_sorted, predicted_sorted));
    const auto a = score(truth, predicted, 2);
    const auto b = score(truth_sorted, predicted_sorted, 2);
    EXPECT_EQ(a.merged, b.merged);
    EXPECT_EQ(a.split, b.split);
    // 5 claims object 1 (4 of 4), 6 claims object 2 (3 of 4); object 3 (1 of 2 in 6) is claimed by none.
    EXPECT_EQ(a.merged, 0u);
    EXPECT_EQ(a.split, 1u);  // object 2: 3 of 4 labelled pixels
}

TEST(EvalMetrics, SizeMismatchThrows) {
    EXPECT_THROW((void)score(Labels{1, 2}, Labels{1}), std::invalid_argument);
}

}  // namespace
