// The tracking metrics of `pyrseg eval --tracks` (tools/eval/tracks.hpp) on hand-made id sequences with known
// answers, the assignment against brute force, and the host-side overlap matcher.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>
#include <random>
#include <vector>

#include "tools/eval/tracks.hpp"

namespace {

using pyrseg::eval::FrameMatches;
using pyrseg::eval::match_frame;
using pyrseg::eval::min_cost_assignment;
using pyrseg::eval::OverlapMatcher;
using pyrseg::eval::score_tracks;
using pyrseg::eval::TrackScores;
using Ids = std::vector<std::uint32_t>;

// The least total cost over every way to assign the shorter side into the longer, by trying them all.
double brute_force_min(const std::vector<double>& cost, std::size_t rows, std::size_t cols) {
    const bool transposed = rows > cols;
    const std::size_t n = std::min(rows, cols), m = std::max(rows, cols);
    std::vector<std::size_t> columns(m);
    std::iota(columns.begin(), columns.end(), 0);
    double best = std::numeric_limits<double>::infinity();
    do {  // every permutation of the longer side; its first n entries are an injective map
        double sum = 0;
        for (std::size_t i = 0; i < n; ++i) {
            sum += transposed ? cost[columns[i] * cols + i] : cost[i * cols + columns[i]];
        }
        best = std::min(best, sum);
    } while (std::next_permutation(columns.begin(), columns.end()));
    return best;
}

// A valid assignment (each row at most one column, each column at most one row, min(rows, cols) pairs) and its cost.
double checked_cost(const std::vector<int>& assigned, const std::vector<double>& cost, std::size_t rows,
                    std::size_t cols) {
    EXPECT_EQ(assigned.size(), rows);
    std::vector<int> taken(cols, 0);
    double sum = 0;
    std::size_t pairs = 0;
    for (std::size_t r = 0; r < rows; ++r) {
        if (assigned[r] < 0) continue;
        EXPECT_LT(std::size_t(assigned[r]), cols);
        EXPECT_EQ(taken[std::size_t(assigned[r])]++, 0) << "column " << assigned[r] << " taken twice";
        sum += cost[r * cols + std::size_t(assigned[r])];
        ++pairs;
    }
    EXPECT_EQ(pairs, std::min(rows, cols));
    return sum;
}

TEST(EvalTracks, AssignmentKnownMatrix) {
    const std::vector<double> cost = {4, 1, 3, 2, 0, 5, 3, 2, 2};
    const std::vector<int> assigned = min_cost_assignment(cost, 3, 3);
    EXPECT_EQ(assigned, (std::vector<int>{1, 0, 2}));
    EXPECT_EQ(checked_cost(assigned, cost, 3, 3), 5.0);
    EXPECT_TRUE(min_cost_assignment({}, 0, 4).empty());
    EXPECT_EQ(min_cost_assignment({}, 3, 0), (std::vector<int>{-1, -1, -1}));
    EXPECT_EQ(min_cost_assignment(std::vector<double>{7}, 1, 1), (std::vector<int>{0}));
    EXPECT_THROW((void)min_cost_assignment(std::vector<double>{1, 2}, 3, 1), std::invalid_argument);
}

TEST(EvalTracks, AssignmentMatchesBruteForce) {
    std::mt19937 rng(12345);
    int cases = 0;
    for (std::size_t rows = 1; rows <= 6; ++rows) {
        for (std::size_t cols = 1; cols <= 6; ++cols) {
            for (int trial = 0; trial < 12; ++trial) {
                std::vector<double> cost(rows * cols);
                // Small integers (many ties), negatives (overlaps), and fractions.
                for (double& c : cost) {
                    const int kind = trial % 3;
                    c = kind == 0   ? double(std::uniform_int_distribution<int>(0, 4)(rng))
                        : kind == 1 ? -double(std::uniform_int_distribution<int>(0, 1000)(rng))
                                    : std::uniform_real_distribution<double>(-5, 5)(rng);
                }
                SCOPED_TRACE(std::to_string(rows) + "x" + std::to_string(cols) + " trial " + std::to_string(trial));
                const std::vector<int> assigned = min_cost_assignment(cost, rows, cols);
                EXPECT_NEAR(checked_cost(assigned, cost, rows, cols), brute_force_min(cost, rows, cols), 1e-9);
                ++cases;
            }
        }
    }
    EXPECT_EQ(cases, 432);
}

// Frames of one object each: id per frame (0: missed), or absent (out of view) where present is false.
struct Step {
    bool present;
    std::uint32_t id;
};
std::vector<FrameMatches> one_object(const std::vector<Step>& steps, std::uint32_t object = 7) {
    std::vector<FrameMatches> frames(steps.size());
    for (std::size_t f = 0; f < steps.size(); ++f) {
        if (!steps[f].present) continue;
        frames[f].objects.emplace_back(object, steps[f].id);
        if (steps[f].id != 0) frames[f].detections.push_back(steps[f].id);
    }
    return frames;
}

TEST(EvalTracks, PerfectTrackerScoresOne) {
    std::vector<FrameMatches> frames(50);
    for (std::size_t f = 0; f < frames.size(); ++f) {
        for (std::uint32_t o = 7; o < 12; ++o) frames[f].objects.emplace_back(o, o * 10);
        for (std::uint32_t o = 7; o < 12; ++o) frames[f].detections.push_back(o * 10);
    }
    const TrackScores s = score_tracks(frames);
    EXPECT_EQ(s.objects, 5u);
    EXPECT_EQ(s.object_frames, 250u);
    EXPECT_EQ(s.matched, 250u);
    EXPECT_EQ(s.switches, 0u);
    EXPECT_EQ(s.fragmentations, 0u);
    EXPECT_EQ(s.idtp, 250u);
    EXPECT_DOUBLE_EQ(s.idf1(), 1.0);
    EXPECT_DOUBLE_EQ(s.switches_per_100(), 0.0);
}

TEST(EvalTracks, ASwitchCountsOnce) {
    const TrackScores s = score_tracks(one_object({{true, 1}, {true, 1}, {true, 1}, {true, 2}, {true, 2}, {true, 2}}));
    EXPECT_EQ(s.switches, 1u);
    EXPECT_EQ(s.switches_in_view, 1u);
    EXPECT_EQ(s.idtp, 3u);
    EXPECT_DOUBLE_EQ(s.idf1(), 0.5);  // 2 * 3 / (6 truth + 6 detections)
    EXPECT_DOUBLE_EQ(s.identity_share(), 0.5);
    EXPECT_NEAR(s.switches_per_100(), 100.0 / 6, 1e-12);
    // Back to the first id is a switch again; a missed frame in between does not hide one.
    std::vector<pyrseg::eval::SwitchEvent> events;
    const TrackScores back = score_tracks(one_object({{true, 1}, {true, 2}, {true, 0}, {true, 1}}), &events);
    EXPECT_EQ(events, (std::vector<pyrseg::eval::SwitchEvent>{{1, 7, 2}, {3, 7, 1}}));
    EXPECT_EQ(back.switches, 2u);
    EXPECT_EQ(back.switches_in_view, 2u);
    EXPECT_EQ(back.fragmentations, 1u);
}

TEST(EvalTracks, SwitchesOutOfViewAreNotInViewSwitches) {
    // In view 0..2 as id 1, out of view 3..4 (hidden, or left the frame), back as id 2.
    const TrackScores s =
        score_tracks(one_object({{true, 1}, {true, 1}, {true, 1}, {false, 0}, {false, 0}, {true, 2}, {true, 2}}));
    EXPECT_EQ(s.switches, 1u);
    EXPECT_EQ(s.switches_in_view, 0u);
    std::vector<pyrseg::eval::SwitchEvent> events;
    (void)score_tracks(one_object({{true, 1}, {false, 0}, {true, 2}}), &events);
    EXPECT_TRUE(events.empty());
    EXPECT_EQ(s.object_frames, 5u);
    EXPECT_EQ(s.fragmentations, 0u) << "frames out of view are not misses";
    // Out of view and then missed while in view: the switch is still not in view.
    const TrackScores t = score_tracks(one_object({{true, 1}, {false, 0}, {true, 0}, {true, 2}}));
    EXPECT_EQ(t.switches, 1u);
    EXPECT_EQ(t.switches_in_view, 0u);
}

TEST(EvalTracks, Fragmentation) {
    // Matched, missed, matched, missed twice, matched: interrupted twice.
    EXPECT_EQ(score_tracks(one_object({{true, 1}, {true, 1}, {true, 0}, {true, 1}, {true, 0}, {true, 0}, {true, 1}}))
                  .fragmentations,
              2u);
    // Misses before the first match and after the last do not interrupt the trajectory.
    EXPECT_EQ(score_tracks(one_object({{true, 0}, {true, 1}, {true, 1}, {true, 0}})).fragmentations, 0u);
    EXPECT_EQ(score_tracks(one_object({{true, 0}, {true, 0}})).fragmentations, 0u);
    const TrackScores missed = score_tracks(one_object({{true, 0}, {true, 0}}));
    EXPECT_EQ(missed.matched, 0u);
    EXPECT_DOUBLE_EQ(missed.idf1(), 0.0);
}

TEST(EvalTracks, PerFrameIdsScoreLow) {
    std::mt19937 rng(7);
    std::vector<FrameMatches> fresh(100), permuted(100);
    std::uint32_t next = 1;
    for (std::size_t f = 0; f < 100; ++f) {
        std::vector<std::uint32_t> labels = {1, 2, 3, 4, 5};
        std::shuffle(labels.begin(), labels.end(), rng);
        for (std::uint32_t o = 0; o < 5; ++o) {
            fresh[f].objects.emplace_back(7 + o, next);
            fresh[f].detections.push_back(next++);
            permuted[f].objects.emplace_back(7 + o, labels[o]);
            permuted[f].detections.push_back(labels[o]);
        }
        std::sort(permuted[f].detections.begin(), permuted[f].detections.end());
    }
    const TrackScores a = score_tracks(fresh);
    EXPECT_EQ(a.idtp, 5u);
    EXPECT_NEAR(a.idf1(), 0.01, 1e-12);
    EXPECT_EQ(a.switches, 5u * 99u);
    const TrackScores b = score_tracks(permuted);  // labels reused in random order, as plain per-frame labels
    EXPECT_LT(b.idf1(), 0.4);
    EXPECT_GT(b.switches, 300u);
}

TEST(EvalTracks, IdF1UsesTheBestOneToOneAssignment) {
    // Object 7: id 2 in frames 0..5, id 1 in 6..10; object 8: missed in 0..5, id 2 in 6..10. Taking the largest
    // pair first (7 with 2, 6 frames) would leave 8 nothing; the best assignment is 7-1 and 8-2, 5 + 5 frames.
    std::vector<FrameMatches> frames(11);
    for (std::uint32_t f = 0; f < 11; ++f) {
        if (f < 6) {
            frames[f].objects = {{7, 2}, {8, 0}};
            frames[f].detections = {2};
        } else {
            frames[f].objects = {{7, 1}, {8, 2}};
            frames[f].detections = {1, 2};
        }
    }
    const TrackScores s = score_tracks(frames);
    EXPECT_EQ(s.idtp, 10u);
    EXPECT_EQ(s.object_frames, 22u);
    EXPECT_EQ(s.detections, 16u);
    EXPECT_DOUBLE_EQ(s.idf1(), 20.0 / 38.0);
}

TEST(EvalTracks, WorstObjectRate) {
    std::vector<Step> steps(100, {true, 1});
    for (std::size_t f = 50; f < 80; ++f) steps[f].id = 2;  // 1 -> 2 -> 1: two switches in 100 frames
    EXPECT_DOUBLE_EQ(score_tracks(one_object(steps)).worst_object_rate, 2.0);
    steps.resize(99);  // under 100 frames in view: not rated
    EXPECT_DOUBLE_EQ(score_tracks(one_object(steps)).worst_object_rate, 0.0);
}

TEST(EvalTracks, MatchFrame) {
    // Truth: 1 = floor (not an object), 7 (10 px), 8 (6 px), 9 (2 px: under min_pixels). Ids: 5 covers 8 of 7's
    // pixels and 2 more (IoU 8/12); 6 covers half of 8 and 4 floor pixels (IoU 3/10: missed); 3 lies on the floor.
    const Ids truth = {7, 7, 7, 7, 7, 7, 7, 7, 7, 7, 8, 8, 8, 8, 8, 8, 9, 9, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 0, 0};
    const Ids ids = {5, 5, 5, 5, 5, 5, 5, 5, 0, 0, 6, 6, 6, 0, 0, 0, 5, 5, 6, 6, 6, 6, 3, 3, 3, 3, 3, 3, 0, 0};
    FrameMatches m = match_frame(truth, ids, 7, 3);
    ASSERT_EQ(m.objects.size(), 2u);
    EXPECT_EQ(m.objects[0], (std::pair<std::uint32_t, std::uint32_t>{7, 5}));
    EXPECT_EQ(m.objects[1], (std::pair<std::uint32_t, std::uint32_t>{8, 0}));
    // 5 is matched; 6 (7 px) lies mostly on the floor and 3 wholly: neither is a detection.
    EXPECT_EQ(m.detections, (Ids{5}));
    // An id of enough pixels that lies mostly on objects is a detection though it matches none.
    const Ids truth2 = {7, 7, 7, 7, 7, 7, 7, 7, 8, 8, 8, 8, 8, 8, 8, 8};
    const Ids ids2 = {4, 4, 4, 4, 2, 2, 2, 2, 2, 2, 2, 2, 4, 4, 4, 4};
    m = match_frame(truth2, ids2, 7, 3);
    EXPECT_EQ(m.objects, (std::vector<std::pair<std::uint32_t, std::uint32_t>>{{7, 0}, {8, 0}}));
    EXPECT_EQ(m.detections, (Ids{2, 4}));
    EXPECT_THROW((void)match_frame(truth2, ids, 7, 3), std::invalid_argument);
}

TEST(EvalTracks, OverlapMatcherKeepsIdsThroughRelabelling) {
    OverlapMatcher matcher(0.2);
    Ids ids;
    matcher.track(Ids{1, 1, 1, 2, 2, 2, 0, 3, 3}, ids);
    EXPECT_EQ(ids, (Ids{1, 1, 1, 2, 2, 2, 0, 3, 3}));
    // Labels renumbered and shifted by one pixel: the regions keep their ids.
    matcher.track(Ids{0, 3, 3, 3, 1, 1, 1, 2, 2}, ids);
    EXPECT_EQ(ids, (Ids{0, 1, 1, 1, 2, 2, 2, 3, 3}));
    // A region that overlaps nothing enough gets a new id, never one used before.
    matcher.track(Ids{0, 0, 0, 0, 0, 0, 0, 0, 1}, ids);
    EXPECT_EQ(ids, (Ids{0, 0, 0, 0, 0, 0, 0, 0, 3}));  // IoU 1/2 with id 3
    matcher.track(Ids{1, 1, 0, 0, 0, 0, 0, 0, 0}, ids);
    EXPECT_EQ(ids, (Ids{4, 4, 0, 0, 0, 0, 0, 0, 0}));
    matcher.reset();
    matcher.track(Ids{2, 2, 0, 0, 0, 0, 0, 0, 1}, ids);
    EXPECT_EQ(ids, (Ids{2, 2, 0, 0, 0, 0, 0, 0, 1})) << "a new sequence numbers from 1 again";
    EXPECT_THROW(matcher.track(Ids{1, 2}, ids), std::invalid_argument);
}

TEST(EvalTracks, OverlapMatcherAssignsJointlyNotGreedily) {
    // Previous ids: A = 1 on pixels 0..18, B = 2 on 19..26. Now label 1 holds A's 0..9 and all of B, label 2
    // A's 10..18. Greedy (the largest overlap first) gives A to label 1 (10 pixels) and leaves B; the assignment
    // gives A to label 2 (9) and B to label 1 (8): 17 pixels kept.
    OverlapMatcher matcher(0.1);
    Ids first(27, 1), ids;
    std::fill(first.begin() + 19, first.end(), 2);
    matcher.track(first, ids);
    ASSERT_EQ(ids, first);
    Ids second(27, 1);
    std::fill(second.begin() + 10, second.begin() + 19, 2);
    matcher.track(second, ids);
    EXPECT_EQ(ids[0], 2u) << "label 1 takes B's id";
    EXPECT_EQ(ids[12], 1u) << "label 2 takes A's id";
    // With a threshold above every IoU, both are new.
    OverlapMatcher strict(0.5);
    strict.track(first, ids);
    strict.track(second, ids);
    EXPECT_EQ(ids[0], 3u);
    EXPECT_EQ(ids[12], 4u);
}

}  // namespace
