// Tests of the tracks oracle (docs/algorithm.md section 11). Every frame is a hand-made label picture (12 x 8, or
// 16 x 10 where step 2 needs segments off the border) with hand-made statistics, and every expected id is written
// out by hand from the text, never computed by the oracle.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <map>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "reference/reference.hpp"
#include "reference/reference_tracks.hpp"

namespace {

using pyrseg_ref::Segment;
using pyrseg_ref::Track;
using pyrseg_ref::Tracker;
using pyrseg_ref::TrackMatch;
using pyrseg_ref::TrackParams;
using Ids = std::vector<std::uint32_t>;

struct Frame {
    int width = 0;
    int height = 0;
    std::vector<std::uint32_t> labels;
    std::vector<Segment> segments;
};

struct At {
    double x = 0, y = 0, z = 0;
};

// A frame from a picture: one string per row, '.' unlabelled, '1'..'9' the label. Each label's pixel count is counted
// from the picture, and so is its bounding box (which step 2 reads for the border). Its centroid is, by default, 10
// units per column and per row and z = 1000 (point_sum the sums of 10 x, 10 y and 1000 over its pixels, every pixel
// fillable); `at` gives it instead; labels in `no_centroid` have no fillable pixel. point_sum is the centroid times the
// count times 2^shift, so the centroid is point_sum * 2^-shift / fillable_count exactly.
Frame picture(const std::vector<std::string>& rows, const std::map<std::uint32_t, At>& at = {},
              const std::set<std::uint32_t>& no_centroid = {}, int shift = 0) {
    Frame f;
    std::uint32_t K = 0;
    for (const std::string& row : rows) {
        for (char ch : row) {
            const std::uint32_t label = ch == '.' ? 0u : static_cast<std::uint32_t>(ch - '0');
            if (ch != '.' && (ch < '1' || ch > '9')) throw std::logic_error("bad picture character");
            f.labels.push_back(label);
            if (label > K) K = label;
        }
    }
    f.segments.resize(K);
    std::vector<std::int64_t> sx(K + 1, 0), sy(K + 1, 0);
    const std::size_t width = rows.at(0).size();
    for (const std::string& row : rows) {
        if (row.size() != width) throw std::logic_error("picture rows of different lengths");
    }
    f.width = static_cast<int>(width);
    f.height = static_cast<int>(rows.size());
    for (std::size_t p = 0; p < f.labels.size(); ++p) {
        const std::uint32_t k = f.labels[p];
        if (k == 0) continue;
        Segment& s = f.segments[k - 1];
        const int x = static_cast<int>(p % width);
        const int y = static_cast<int>(p / width);
        if (s.pixel_count == 0) {
            s.x_min = s.x_max = x;
            s.y_min = s.y_max = y;
        }
        s.x_min = std::min(s.x_min, x);
        s.x_max = std::max(s.x_max, x);
        s.y_min = std::min(s.y_min, y);
        s.y_max = std::max(s.y_max, y);
        ++s.pixel_count;
        sx[k] += 10 * static_cast<std::int64_t>(p % width);
        sy[k] += 10 * static_cast<std::int64_t>(p / width);
    }
    for (std::uint32_t k = 1; k <= K; ++k) {
        Segment& s = f.segments[k - 1];
        if (s.pixel_count == 0) throw std::logic_error("a label of 1..K is missing from the picture");
        s.label = k;
        s.point_shift = shift;
        if (no_centroid.count(k) != 0) continue;
        s.fillable_count = s.pixel_count;
        const double n = static_cast<double>(s.pixel_count);
        double c[3] = {static_cast<double>(sx[k]) / n, static_cast<double>(sy[k]) / n, 1000.0};
        const auto it = at.find(k);
        if (it != at.end()) {
            c[0] = it->second.x;
            c[1] = it->second.y;
            c[2] = it->second.z;
        }
        for (int a = 0; a < 3; ++a) {
            const double sum = std::ldexp(c[a] * n, shift);
            if (sum != std::floor(sum)) throw std::logic_error("centroid * count * 2^shift is not an integer");
            s.point_sum[a] = static_cast<std::int64_t>(sum);
        }
    }
    return f;
}

const std::vector<std::string> kEmpty(8, "............");

// A 16 x 10 picture drawn as rectangles: {label, x0, y0, x1, y1}, inclusive. Nothing drawn at column 0 or 15 or row
// 0 or 9 is off the border.
struct Rect {
    char label;
    int x0, y0, x1, y1;
};
std::vector<std::string> drawn(const std::vector<Rect>& rects) {
    std::vector<std::string> rows(10, std::string(16, '.'));
    for (const Rect& r : rects) {
        for (int y = r.y0; y <= r.y1; ++y) {
            for (int x = r.x0; x <= r.x1; ++x) {
                char& at = rows.at(static_cast<std::size_t>(y)).at(static_cast<std::size_t>(x));
                if (at != '.') throw std::logic_error("rectangles overlap");
                at = r.label;
            }
        }
    }
    return rows;
}

std::vector<Track> next(Tracker& tr, const Frame& f) {
    return tr.next(f.labels, f.width, f.height, f.segments);
}

Ids ids(const std::vector<Track>& r) {
    Ids out;
    for (const Track& t : r) out.push_back(t.id);
    return out;
}

// How each segment was matched, one character each: n(ew), o(verlap), p(osition).
std::string hows(const std::vector<Track>& r) {
    std::string out;
    for (const Track& t : r) {
        out += t.how == TrackMatch::new_track ? 'n' : t.how == TrackMatch::overlap ? 'o' : 'p';
    }
    return out;
}

Ids ages(const std::vector<Track>& r) {
    Ids out;
    for (const Track& t : r) out.push_back(t.age);
    return out;
}

Ids first_frames(const std::vector<Track>& r) {
    Ids out;
    for (const Track& t : r) out.push_back(t.first_frame);
    return out;
}

Ids hidden(const std::vector<Track>& r) {
    Ids out;
    for (const Track& t : r) out.push_back(t.hidden_frames);
    return out;
}

Ids labels(const std::vector<Track>& r) {
    Ids out;
    for (const Track& t : r) out.push_back(t.label);
    return out;
}

TrackParams params(double max_distance_mm, int hold_frames = 10, double unit_mm = 1.0) {
    TrackParams p;
    p.unit_mm = unit_mm;
    p.max_distance_mm = max_distance_mm;
    p.hold_frames = hold_frames;
    return p;
}

TEST(ReferenceTracks, FirstFrameNumbersSegmentsOneToK) {
    // Label 2 lies first in raster order: new ids go by increasing k, not by position in the image.
    const Frame f0 = picture({
        "........2222",
        "111111..2222",
        "111111......",
        "333.........",
        "333.........",
        "............",
        "......444444",
        "......444444",
    });
    Tracker tr(TrackParams{});
    const std::vector<Track> r = next(tr, f0);
    EXPECT_EQ(labels(r), (Ids{1, 2, 3, 4}));
    EXPECT_EQ(ids(r), (Ids{1, 2, 3, 4}));
    EXPECT_EQ(hows(r), "nnnn");
    EXPECT_EQ(first_frames(r), (Ids{0, 0, 0, 0}));
    EXPECT_EQ(ages(r), (Ids{1, 1, 1, 1}));
    EXPECT_EQ(hidden(r), (Ids{0, 0, 0, 0}));
}

TEST(ReferenceTracks, EmptyFrameGivesNoTracks) {
    Tracker tr(TrackParams{});
    EXPECT_TRUE(next(tr, picture(kEmpty)).empty());
    // Nothing was seen: the first segment after the empty frame is frame 1's, and gets id 1.
    const std::vector<Track> r = next(tr, picture({"11..........", "11..........", "............", "............",
                                                   "............", "............", "............", "............"}));
    EXPECT_EQ(ids(r), (Ids{1}));
    EXPECT_EQ(first_frames(r), (Ids{1}));
}

TEST(ReferenceTracks, ShiftedImageKeepsIds) {
    const Frame f0 = picture({
        "111111......",
        "111111......",
        "........2222",
        "........2222",
        "333.........",
        "333.........",
        "............",
        "............",
    });
    // One pixel right and down, and the labels permuted: old 1 is 3, old 2 is 1, old 3 is 2. Overlaps: 5 of 12,
    // 3 of 6 (clipped), 2 of 6, each at least an eighth of the smaller.
    const Frame f1 = picture({
        "............",
        ".333333.....",
        ".333333.....",
        ".........111",
        ".........111",
        ".222........",
        ".222........",
        "............",
    });
    Tracker tr(TrackParams{});
    next(tr, f0);
    const std::vector<Track> r = next(tr, f1);
    EXPECT_EQ(ids(r), (Ids{2, 3, 1}));
    EXPECT_EQ(hows(r), "ooo");
    EXPECT_EQ(ages(r), (Ids{2, 2, 2}));
    EXPECT_EQ(first_frames(r), (Ids{0, 0, 0}));
    EXPECT_EQ(hidden(r), (Ids{0, 0, 0}));
}

TEST(ReferenceTracks, SplitLargerOverlapKeepsTheId) {
    const Frame f0 = picture({
        "111111111111",
        "111111111111",
        "............",
        "............",
        "............",
        "222.........",
        "222.........",
        "............",
    });
    // Segment 1 (24 pixels) splits into k = 1 (8 pixels, the left part) and k = 2 (16 pixels): k*(1) = 2.
    const Frame f1 = picture({
        "111122222222",
        "111122222222",
        "............",
        "............",
        "............",
        "333.........",
        "333.........",
        "............",
    });
    Tracker tr(TrackParams{});
    next(tr, f0);
    const std::vector<Track> r = next(tr, f1);
    EXPECT_EQ(ids(r), (Ids{3, 1, 2}));
    EXPECT_EQ(hows(r), "noo");
    EXPECT_EQ(first_frames(r), (Ids{1, 0, 0}));
    EXPECT_EQ(ages(r), (Ids{1, 2, 2}));
}

// Merges: A (1, 32 pixels) and B (2, 8 pixels) merge into M; C (3) stays. M's centroid is given as A's (35, 15, 1000),
// and C does not move (and every segment touches the border), so t = 0 throughout; B's track waits at (95, 25, 1000),
// where B comes back.
const std::vector<std::string> kApart = {
    "11111111....", "11111111....", "111111112222", "111111112222",
    "............", "............", "333.........", "333.........",
};
const std::vector<std::string> kMerged = {
    "11111111....", "11111111....", "111111111111", "111111111111",
    "............", "............", "222.........", "222.........",
};
const std::map<std::uint32_t, At> kMergedAt = {{1, {35, 15, 1000}}};

TEST(ReferenceTracks, MergeKeepsLargerOverlapAndReturnWithinHoldKeepsId) {
    Tracker tr(params(50.0, 2));
    EXPECT_EQ(ids(next(tr, picture(kApart))), (Ids{1, 2, 3}));
    std::vector<Track> r = next(tr, picture(kMerged, kMergedAt));  // frame 1: B hidden
    EXPECT_EQ(ids(r), (Ids{1, 3}));
    EXPECT_EQ(hows(r), "oo");
    r = next(tr, picture(kMerged, kMergedAt));  // frame 2: hidden 2 frames, 2 - 0 does not exceed 2
    EXPECT_EQ(ids(r), (Ids{1, 3}));
    // Frame 3: pairs (M, A) m = 32, (M, B) m = 8, (C, C) m = 6, in that order; (M, A) takes M, so (M, B) finds M
    // matched: not step 1; B found by position.
    r = next(tr, picture(kApart));
    EXPECT_EQ(ids(r), (Ids{1, 2, 3}));
    EXPECT_EQ(hows(r), "opo");
    EXPECT_EQ(hidden(r), (Ids{0, 2, 0}));
    EXPECT_EQ(ages(r), (Ids{4, 2, 4}));
    EXPECT_EQ(first_frames(r), (Ids{0, 0, 0}));
}

TEST(ReferenceTracks, HiddenLongerThanHoldGetsNewId) {
    Tracker tr(params(50.0, 2));
    next(tr, picture(kApart));
    for (int i = 0; i < 3; ++i) EXPECT_EQ(ids(next(tr, picture(kMerged, kMergedAt))), (Ids{1, 3}));
    // Frame 3 dropped B's track (3 - 0 > 2); frame 4: B is new, and id 2 is not reused.
    const std::vector<Track> r = next(tr, picture(kApart));
    EXPECT_EQ(ids(r), (Ids{1, 4, 3}));
    EXPECT_EQ(hows(r), "ono");
    EXPECT_EQ(first_frames(r), (Ids{0, 4, 0}));
    EXPECT_EQ(ages(r), (Ids{5, 1, 5}));
    EXPECT_EQ(hidden(r), (Ids{0, 0, 0}));
}

TEST(ReferenceTracks, HoldZeroDropsAtOnce) {
    Tracker tr(params(50.0, 0));
    next(tr, picture(kApart));
    next(tr, picture(kMerged, kMergedAt));  // B's track: 1 - 0 > 0, dropped
    EXPECT_EQ(ids(next(tr, picture(kApart))), (Ids{1, 4, 3}));
}

// The 1/8 threshold: 24 pixels (two rows), 25 (one more, far), 27 (three of the 24's pixels and two other rows).
// Every pair overlaps by m = 3: 8 * 3 = 24.
const std::vector<std::string> k24 = {
    "111111111111", "111111111111", "............", "............",
    "............", "............", "............", "............",
};
const std::vector<std::string> k25 = {
    "111111111111", "111111111111", "............", "............",
    "............", "............", "............", "1...........",
};
const std::vector<std::string> k27 = {
    "............", ".........111", "111111111111", "111111111111",
    "............", "............", "............", "............",
};

Track second(const std::vector<std::string>& a, const std::vector<std::string>& b, const TrackParams& p) {
    Tracker tr(p);
    next(tr, picture(a));
    const std::vector<Track> r = next(tr, picture(b));
    EXPECT_EQ(r.size(), 1u);
    return r.at(0);
}

TEST(ReferenceTracks, OverlapOfExactlyAnEighthMatches) {
    // min(n_k, n'_j) = 24 whichever of the two is the smaller.
    for (const auto& [a, b] : {std::pair{k24, k27}, std::pair{k27, k24}}) {
        const Track t = second(a, b, params(10.0));
        EXPECT_EQ(t.id, 1u);
        EXPECT_EQ(t.how, TrackMatch::overlap);
    }
}

TEST(ReferenceTracks, OverlapJustBelowAnEighthFallsToPositionOrNew) {
    // min = 25 > 24. The centroids are (52.8, 7.6, 1000) and (60, 23.33, 1000), 17.3 apart, t = 0.
    for (const auto& [a, b] : {std::pair{k25, k27}, std::pair{k27, k25}}) {
        Track t = second(a, b, params(50.0));
        EXPECT_EQ(t.id, 1u);
        EXPECT_EQ(t.how, TrackMatch::position);
        t = second(a, b, params(10.0));
        EXPECT_EQ(t.id, 2u);
        EXPECT_EQ(t.how, TrackMatch::new_track);
    }
}

// A (40 pixels, off the border) moves 2 columns right: its centroid from (55, 25, 1000) to (75, 25, 1000), m = 32,
// t = (20, 0, 0). B (4 pixels, at (15, 65, 1000)) jumps with no overlap.
const std::vector<std::string> kMotion0 = drawn({{'1', 1, 1, 10, 4}, {'2', 1, 6, 2, 7}});
std::vector<std::string> motion1(int b_column) {
    return drawn({{'1', 3, 1, 12, 4}, {'2', b_column, 6, b_column + 1, 7}});
}

TEST(ReferenceTracks, PositionFollowsTheCameraMotion) {
    // D = 20 mm / 2 mm = 10 units. B predicted at 15 + 20 = 35.
    const TrackParams p = params(20.0, 10, 2.0);
    {
        Tracker tr(p);
        next(tr, picture(kMotion0));
        const std::vector<Track> r = next(tr, picture(motion1(3)));  // at 35: d = 0 (20 without t)
        EXPECT_EQ(ids(r), (Ids{1, 2}));
        EXPECT_EQ(hows(r), "op");
        EXPECT_EQ(hidden(r), (Ids{0, 0}));
        EXPECT_EQ(ages(r), (Ids{2, 2}));
    }
    {
        Tracker tr(p);
        next(tr, picture(kMotion0));
        const std::vector<Track> r = next(tr, picture(motion1(4)));  // at 45: d^2 = 100 = D * D
        EXPECT_EQ(ids(r), (Ids{1, 2}));
        EXPECT_EQ(hows(r), "op");
    }
    {
        Tracker tr(p);
        next(tr, picture(kMotion0));
        const std::vector<Track> r = next(tr, picture(motion1(5)));  // at 55: d = 20 > 10 (though <= 20 mm)
        EXPECT_EQ(ids(r), (Ids{1, 3}));
        EXPECT_EQ(hows(r), "on");
        EXPECT_EQ(first_frames(r), (Ids{0, 1}));
    }
}

TEST(ReferenceTracks, MotionIsWeightedByOverlap) {
    // A: m = 24, moves by (40, 0, 0); C: m = 8 (two of its four rows), does not move; all off the border. t = 24 * 40
    // / 32 = 30 (the plain mean of the shifts is 20, the mean weighted by pixel counts 24). B predicted at (0 + 30,
    // 100, 1000).
    const Frame f0 = picture(drawn({{'1', 2, 1, 7, 4}, {'2', 10, 1, 13, 4}, {'3', 2, 7, 3, 8}}),
                             {{1, {0, 0, 1000}}, {2, {500, 0, 1000}}, {3, {0, 100, 1000}}});
    const Frame f1 = picture(drawn({{'1', 2, 1, 7, 4}, {'2', 10, 3, 13, 6}, {'3', 6, 7, 7, 8}}),
                             {{1, {40, 0, 1000}}, {2, {500, 0, 1000}}, {3, {30, 100, 1000}}});
    Tracker tr(params(1.0));
    next(tr, f0);
    const std::vector<Track> r = next(tr, f1);
    EXPECT_EQ(ids(r), (Ids{1, 2, 3}));
    EXPECT_EQ(hows(r), "oop");
}

TEST(ReferenceTracks, HiddenCentroidMovesByT) {
    // A (40 pixels, off the border, the same pixels throughout) moves by (20, 0, 0) a frame by its given centroids.
    Tracker tr(params(1.0));
    next(tr, picture(drawn({{'1', 2, 1, 11, 4}, {'2', 2, 7, 3, 8}}), {{1, {0, 0, 1000}}, {2, {0, 100, 1000}}}));
    // t = 20: B hidden, its centroid moves to (20, 100, 1000).
    EXPECT_EQ(ids(next(tr, picture(drawn({{'1', 2, 1, 11, 4}}), {{1, {20, 0, 1000}}}))), (Ids{1}));
    // t = 20 again: B predicted at (40, 100, 1000) (at 20 had the hidden centroid stayed).
    const std::vector<Track> r =
        next(tr, picture(drawn({{'1', 2, 1, 11, 4}, {'2', 6, 7, 7, 8}}), {{1, {40, 0, 1000}}, {2, {40, 100, 1000}}}));
    EXPECT_EQ(ids(r), (Ids{1, 2}));
    EXPECT_EQ(hows(r), "op");
    EXPECT_EQ(hidden(r), (Ids{0, 1}));
    EXPECT_EQ(ages(r), (Ids{3, 2}));
}

// Step 2's border rule. A (1: 16 pixels at columns 6..9, rows 3..6, off the border) moves by (40, 0, 0); E (2: 8
// pixels) does not move, at (500, 0, 1000); B (3: 4 pixels) jumps from (0, 100, 1000) to (40, 100, 1000) with no
// overlap. D = 1. With E's pair in t, t = 16 * 40 / (16 + m_E) < 40 and B is new; without it, t = 40 and B is found.
std::vector<Track> border_pair(const Rect& e0, const Rect& e1, const Rect& a0 = {'1', 6, 3, 9, 6}) {
    Tracker tr(params(1.0));
    next(tr,
         picture(drawn({a0, e0, {'3', 1, 1, 2, 2}}), {{1, {0, 0, 1000}}, {2, {500, 0, 1000}}, {3, {0, 100, 1000}}}));
    return next(tr, picture(drawn({{'1', 6, 3, 9, 6}, e1, {'3', 1, 7, 2, 8}}),
                            {{1, {40, 0, 1000}}, {2, {500, 0, 1000}}, {3, {40, 100, 1000}}}));
}

TEST(ReferenceTracks, MotionLeavesOutPairsOnTheBorder) {
    // E on each of the four borders, the same pixels in both frames (m = 8): left out of t (16 * 40 / 16 = 40), yet
    // still matched by overlap.
    for (const Rect& e :
         {Rect{'2', 0, 3, 1, 6}, Rect{'2', 14, 3, 15, 6}, Rect{'2', 6, 0, 9, 1}, Rect{'2', 6, 8, 9, 9}}) {
        const std::vector<Track> r = border_pair(e, e);
        EXPECT_EQ(ids(r), (Ids{1, 2, 3})) << e.x0 << "," << e.y0;
        EXPECT_EQ(hows(r), "oop") << e.x0 << "," << e.y0;
    }
    // The control: E at columns 2..3, off the border, counts: t = 16 * 40 / 24 = 26.67, B 13.3 from its prediction.
    const Rect inside{'2', 2, 3, 3, 6};
    const std::vector<Track> r = border_pair(inside, inside);
    EXPECT_EQ(ids(r), (Ids{1, 2, 4}));
    EXPECT_EQ(hows(r), "oon");
}

TEST(ReferenceTracks, MotionLeavesOutAPairOnTheBorderInEitherFrame) {
    // E at columns 14..15 (touching W - 1 = 15) in one frame and 13..14 in the other: m = 4, 8 * 4 >= 8, matched by
    // overlap; left out of t (t = 40) whichever frame touches.
    const Rect touching{'2', 14, 3, 15, 6};
    const Rect inside{'2', 13, 3, 14, 6};
    std::vector<Track> r = border_pair(touching, inside);  // the previous segment, as its track remembers
    EXPECT_EQ(ids(r), (Ids{1, 2, 3}));
    EXPECT_EQ(hows(r), "oop");
    r = border_pair(inside, touching);  // this frame's segment
    EXPECT_EQ(ids(r), (Ids{1, 2, 3}));
    EXPECT_EQ(hows(r), "oop");
    // Neither touches (columns 12..13 then 13..14, m = 4): t = 16 * 40 / 20 = 32, B 8 from its prediction: new.
    r = border_pair(Rect{'2', 12, 3, 13, 6}, inside);
    EXPECT_EQ(ids(r), (Ids{1, 2, 4}));
    EXPECT_EQ(hows(r), "oon");
}

TEST(ReferenceTracks, MotionIsZeroWhenEveryPairIsOnTheBorder) {
    // A on row 0 in the previous frame (rows 0..3; m = 4 with rows 3..6 of this one, 8 * 4 >= 16) and E on the
    // border: no pair left, t = 0, B 40 from its prediction: new.
    const std::vector<Track> r = border_pair(Rect{'2', 14, 3, 15, 6}, Rect{'2', 14, 3, 15, 6}, Rect{'1', 6, 0, 9, 3});
    EXPECT_EQ(ids(r), (Ids{1, 2, 4}));
    EXPECT_EQ(hows(r), "oon");
}

// A (40 pixels) still; B at (50, 65, 1000) in both frames, as 4, 16 or 17 pixels: 16 = 4 * 4 passes, 17 does not.
const std::vector<std::string> kSmallB = {
    "1111111111..", "1111111111..", "1111111111..", "1111111111..",
    "............", "............", "22..........", "22..........",
};
const std::vector<std::string> kB16 = {
    "1111111111..", "1111111111..", "1111111111..", "1111111111..",
    "....2222....", "....2222....", "....2222....", "....2222....",
};
const std::vector<std::string> kB17 = {
    "1111111111..", "1111111111..", "1111111111..", "1111111111..",
    "....22222...", "....2222....", "....2222....", "....2222....",
};

std::vector<Track> size_pair(const std::vector<std::string>& a, const std::vector<std::string>& b) {
    const std::map<std::uint32_t, At> at = {{2, {50, 65, 1000}}};
    Tracker tr(TrackParams{});
    next(tr, picture(a, at));
    return next(tr, picture(b, at));
}

TEST(ReferenceTracks, PositionRefusesSizeRatioAboveFour) {
    EXPECT_EQ(ids(size_pair(kSmallB, kB16)), (Ids{1, 2}));
    EXPECT_EQ(hows(size_pair(kSmallB, kB16)), "op");
    EXPECT_EQ(ids(size_pair(kB16, kSmallB)), (Ids{1, 2}));
    EXPECT_EQ(hows(size_pair(kB16, kSmallB)), "op");
    EXPECT_EQ(ids(size_pair(kSmallB, kB17)), (Ids{1, 3}));
    EXPECT_EQ(hows(size_pair(kSmallB, kB17)), "on");
    EXPECT_EQ(ids(size_pair(kB17, kSmallB)), (Ids{1, 3}));
    EXPECT_EQ(hows(size_pair(kB17, kSmallB)), "on");
}

TEST(ReferenceTracks, CentroidUsesPointShift) {
    // point_sum = c * n * 2^e. Dropping the 2^-e would put the centroids 16 times farther apart at e = 4 (30 -> 480,
    // beyond 40) and 16 times nearer at e = -4 (12 -> 0.75, within 10).
    for (int shift : {4, -2}) {
        Tracker tr(params(40.0));
        next(tr, picture({"11..........", "11..........", "............", "............", "............",
                          "............", "............", "............"},
                         {{1, {0, 0, 1000}}}, {}, shift));
        next(tr, picture(kEmpty));
        const std::vector<Track> r = next(tr, picture({"............", "............", "............", "............",
                                                       "............", "............", "..........11", "..........11"},
                                                      {{1, {30, 0, 1000}}}, {}, shift));
        EXPECT_EQ(ids(r), (Ids{1})) << "shift " << shift;
        EXPECT_EQ(hows(r), "p") << "shift " << shift;
    }
    for (int shift : {4, -4}) {
        Tracker tr(params(10.0));
        next(tr, picture({"11..........", "11..........", "............", "............", "............",
                          "............", "............", "............"},
                         {{1, {0, 0, 1000}}}, {}, shift));
        const std::vector<Track> r = next(tr, picture({"............", "............", "............", "............",
                                                       "............", "............", "..........11", "..........11"},
                                                      {{1, {12, 0, 1000}}}, {}, shift));
        EXPECT_EQ(ids(r), (Ids{2})) << "shift " << shift;
    }
}

TEST(ReferenceTracks, OverlapTieTakesTheSmallestPreviousLabel) {
    Tracker tr(TrackParams{});
    EXPECT_EQ(ids(next(tr, picture({"111111222222", "111111222222", "............", "............", "............",
                                    "............", "............", "............"}))),
              (Ids{1, 2}));
    // The labels swap: label 1 is now the right half, id 2.
    EXPECT_EQ(ids(next(tr, picture({"222222111111", "222222111111", "............", "............", "............",
                                    "............", "............", "............"}))),
              (Ids{2, 1}));
    // One segment over both, 12 pixels each: j = 1 (the right half, id 2), not the smaller id.
    const std::vector<Track> r = next(tr, picture(k24));
    EXPECT_EQ(ids(r), (Ids{2}));
    EXPECT_EQ(hows(r), "o");
}

TEST(ReferenceTracks, OverlapTieTakesTheSmallestSegment) {
    Tracker tr(TrackParams{});
    next(tr, picture(k24));
    // Split into equal halves, label 1 on the right: k*(1) = 1.
    const std::vector<Track> r = next(tr, picture({"222222111111", "222222111111", "............", "............",
                                                   "............", "............", "............", "............"}));
    EXPECT_EQ(ids(r), (Ids{1, 2}));
    EXPECT_EQ(hows(r), "on");
}

// Two 4-pixel segments in corners, then an empty frame (both tracks hidden, t = 0), then the frame under test.
const std::vector<std::string> kCorners = {
    "11..........", "11..........", "............", "............",
    "............", "............", "..........22", "..........22",
};

TEST(ReferenceTracks, PositionTieTakesTheSmallerId) {
    Tracker tr(params(60.0));
    next(tr, picture(kCorners, {{1, {0, 0, 1000}}, {2, {100, 0, 1000}}}));
    next(tr, picture(kEmpty));
    const std::vector<Track> r = next(tr, picture({"............", "............", "............", ".....11.....",
                                                   ".....11.....", "............", "............", "............"},
                                                  {{1, {50, 0, 1000}}}));
    EXPECT_EQ(ids(r), (Ids{1}));
    EXPECT_EQ(hows(r), "p");
    EXPECT_EQ(hidden(r), (Ids{1}));
}

TEST(ReferenceTracks, PositionTieTakesTheSmallerSegment) {
    Tracker tr(params(60.0));
    next(tr, picture({"11..........", "11..........", "............", "............", "............", "............",
                      "............", "............"},
                     {{1, {50, 0, 1000}}}));
    next(tr, picture(kEmpty));
    const std::vector<Track> r = next(tr, picture(kCorners, {{1, {100, 0, 1000}}, {2, {0, 0, 1000}}}));
    EXPECT_EQ(ids(r), (Ids{1, 2}));
    EXPECT_EQ(hows(r), "pn");
}

TEST(ReferenceTracks, PositionIsGreedy) {
    // Tracks 1 at x = 0 and 2 at x = 100, D = 60. Segment 1 at 45 (track 1 at 45, track 2 at 55), segment 2 at 5
    // (track 1 at 5; track 2 at 95, too far). The pairs in increasing d: (2, track 1) 5, (1, track 1) 45, (1, track
    // 2) 55. Segment 2 takes track 1, and segment 1, whose nearest track is taken, gets track 2 (mutual nearest would
    // have left it new, id 3).
    Tracker tr(params(60.0));
    next(tr, picture(kCorners, {{1, {0, 0, 1000}}, {2, {100, 0, 1000}}}));
    next(tr, picture(kEmpty));
    const std::vector<Track> r = next(tr, picture(kCorners, {{1, {45, 0, 1000}}, {2, {5, 0, 1000}}}));
    EXPECT_EQ(ids(r), (Ids{2, 1}));
    EXPECT_EQ(hows(r), "pp");
    EXPECT_EQ(hidden(r), (Ids{1, 1}));
}

TEST(ReferenceTracks, PositionTieDecidesTheRestOfTheChain) {
    // Tracks 1 at x = 0 and 2 at x = 100, D = 60. Segment 1 at 50 (both tracks 50 away), segment 2 at -60 (track 1
    // only, 60 away). In order: (1, track 1) 50, (1, track 2) 50, (2, track 1) 60. The tie goes to the smaller id, so
    // segment 1 takes track 1, and segment 2 finds track 1 taken: new. (The larger id first would give 2, 1.)
    Tracker tr(params(60.0));
    next(tr, picture(kCorners, {{1, {0, 0, 1000}}, {2, {100, 0, 1000}}}));
    next(tr, picture(kEmpty));
    const std::vector<Track> r = next(tr, picture(kCorners, {{1, {50, 0, 1000}}, {2, {-60, 0, 1000}}}));
    EXPECT_EQ(ids(r), (Ids{1, 3}));
    EXPECT_EQ(hows(r), "pn");
}

TEST(ReferenceTracks, PositionOrdersByDistanceBeforeId) {
    // Tracks 1 at x = 0 and 2 at x = 100; one segment at 55: track 2 (45 away) before track 1 (55 away).
    Tracker tr(params(60.0));
    next(tr, picture(kCorners, {{1, {0, 0, 1000}}, {2, {100, 0, 1000}}}));
    next(tr, picture(kEmpty));
    const std::vector<Track> r = next(tr, picture({"11..........", "11..........", "............", "............",
                                                   "............", "............", "............", "............"},
                                                  {{1, {55, 0, 1000}}}));
    EXPECT_EQ(ids(r), (Ids{2}));
    EXPECT_EQ(hows(r), "p");
}

TEST(ReferenceTracks, OverlapIsGreedy) {
    // Previous: j = 1 (22 pixels: rows 0 and 1), j = 2 (6 pixels, row 2). Now: k = 2 is row 0 (m(1, 2) = 12), k = 1
    // is rows 1 and 2 (m(1, 1) = 10, m(2, 1) = 6; 8 * 6 >= min(16, 6)). In decreasing m: (1, 2) matches; (1, 1)
    // finds j = 1 taken; (2, 1) matches. Mutual best would leave k = 1 unmatched (its best j = 1 prefers k = 2), and
    // with D = 1 new (id 3: track 2 at (0, 100, 1000) is 100 from k = 1; t = 0, every pair on the border).
    Tracker tr(params(1.0));
    next(tr, picture({"111111111111", "1111111111..", "222222......", "............", "............", "............",
                      "............", "............"},
                     {{1, {0, 0, 1000}}, {2, {0, 100, 1000}}}));
    const std::vector<Track> r = next(tr, picture({"222222222222", "1111111111..", "111111......", "............",
                                                   "............", "............", "............", "............"},
                                                  {{1, {0, 0, 1000}}, {2, {0, 0, 1000}}}));
    EXPECT_EQ(ids(r), (Ids{2, 1}));
    EXPECT_EQ(hows(r), "oo");
    EXPECT_EQ(ages(r), (Ids{2, 2}));
}

TEST(ReferenceTracks, OverlapTieDecidesTheRestOfTheChain) {
    // Previous: j = 1 (11 pixels: row 0's left half and 5 of row 1), j = 2 (row 0's right half, 6). Now: k = 1 is row 0
    // (m(1, 1) = m(2, 1) = 6), k = 2 is 5 of row 1 (m(1, 2) = 5, 8 * 5 >= 5). In order: (1, 1), (2, 1), (1, 2). The tie
    // goes to the smaller j, so k = 1 takes id 1, and k = 2 finds j = 1 taken: new with D = 1, id 3. (The larger j
    // first would give 2, 1.) Track 2 waits at (100, 0, 1000), 200 from k = 2 (t = 0, every pair on the border).
    Tracker tr(params(1.0));
    next(tr, picture({"111111222222", "11111.......", "............", "............", "............", "............",
                      "............", "............"},
                     {{1, {0, 0, 1000}}, {2, {100, 0, 1000}}}));
    const std::vector<Track> r = next(tr, picture({"111111111111", "22222.......", "............", "............",
                                                   "............", "............", "............", "............"},
                                                  {{1, {0, 0, 1000}}, {2, {300, 0, 1000}}}));
    EXPECT_EQ(ids(r), (Ids{1, 3}));
    EXPECT_EQ(hows(r), "on");
}

TEST(ReferenceTracks, OverlapIsWeighedByTheTracksAge) {
    // Track 1 (rows 0 and 1) is seen in frames 0 to 2, then splits: row 0 keeps id 1 (age 4), row 1 is new (id 2, age
    // 1; D = 1, so step 3 finds nothing). In frame 4 one segment holds 5 pixels of row 0 and all of row 1: m(1, 1) =
    // 5, m(2, 1) = 12, both at least an eighth of the smaller (12). Weighed by age, 5 * 4 = 20 > 12 * 1 = 12: it is
    // track 1 again, and track 2 is hidden. (By overlap alone it would be 2.)
    Tracker tr(params(1.0));
    const std::vector<std::string> whole = {"111111111111", "111111111111", "............", "............",
                                            "............", "............", "............", "............"};
    for (int f = 0; f < 3; ++f) next(tr, picture(whole, {{1, {0, 0, 1000}}}));
    std::vector<Track> r = next(tr, picture({"111111111111", "222222222222", "............", "............",
                                             "............", "............", "............", "............"},
                                            {{1, {0, 0, 1000}}, {2, {0, 100, 1000}}}));
    EXPECT_EQ(ids(r), (Ids{1, 2}));
    EXPECT_EQ(ages(r), (Ids{4, 1}));
    r = next(tr, picture({"11111.......", "111111111111", "............", "............", "............",
                          "............", "............", "............"},
                         {{1, {0, 0, 1000}}}));
    EXPECT_EQ(ids(r), (Ids{1}));
    EXPECT_EQ(hows(r), "o");
    EXPECT_EQ(ages(r), (Ids{5}));
}

TEST(ReferenceTracks, AgesAbove32WeighAs32) {
    // Track 1 (8 pixels) is seen in frames 0 to 40, track 2 (rows 2 to 4) from frame 40. In frame 41 one segment holds
    // 1 pixel of track 1 (8 * 1 >= min(34, 8)) and 33 of track 2: 1 * min(41, 32) = 32 < 33 * 1, so it is track 2.
    // (An uncapped age, 41, would make it track 1.)
    Tracker tr(params(1.0));
    const std::vector<std::string> small = {"11111111....", "............", "............", "............",
                                            "............", "............", "............", "............"};
    for (int f = 0; f < 40; ++f) next(tr, picture(small, {{1, {0, 0, 1000}}}));
    std::vector<Track> r = next(tr, picture({"11111111....", "............", "222222222222", "222222222222",
                                             "222222222222", "............", "............", "............"},
                                            {{1, {0, 0, 1000}}, {2, {0, 100, 1000}}}));
    EXPECT_EQ(ids(r), (Ids{1, 2}));
    EXPECT_EQ(ages(r), (Ids{41, 1}));
    r = next(tr, picture({"1...........", "............", "111111111111", "111111111111", "111111111...",
                          "............", "............", "............"},
                         {{1, {0, 0, 1000}}}));
    EXPECT_EQ(ids(r), (Ids{2}));
    EXPECT_EQ(hows(r), "o");
}

TEST(ReferenceTracks, NearestOnlyAmongTracksOfCloseSize) {
    // Track 1: 3 pixels at x = 0 (10 away, but 16 > 4 * 3); track 2: 16 pixels at x = 30 (20 away).
    Tracker tr(TrackParams{});
    next(tr, picture({"111.........", "............", "............", "............", "........2222", "........2222",
                      "........2222", "........2222"},
                     {{1, {0, 0, 1000}}, {2, {30, 0, 1000}}}));
    next(tr, picture(kEmpty));
    const std::vector<Track> r = next(tr, picture({"............", "............", "............", "............",
                                                   "1111........", "1111........", "1111........", "1111........"},
                                                  {{1, {10, 0, 1000}}}));
    EXPECT_EQ(ids(r), (Ids{2}));
    EXPECT_EQ(hows(r), "p");
}

TEST(ReferenceTracks, SegmentsWithoutCentroidMatchByOverlapButNotInMotion) {
    // A (24 pixels) moves by 40; M (24 pixels, no fillable pixel) overlaps itself fully and stays out of t; all off
    // the border. t = 40 (20 if M's pair counted with a zero shift). B is predicted at (40, 100, 1000).
    Tracker tr(params(1.0));
    next(tr, picture(drawn({{'1', 1, 1, 6, 4}, {'2', 7, 1, 12, 4}, {'3', 1, 7, 2, 8}}),
                     {{1, {0, 0, 1000}}, {3, {0, 100, 1000}}}, {2}));
    const std::vector<Track> r = next(tr, picture(drawn({{'1', 1, 1, 6, 4}, {'2', 7, 1, 12, 4}, {'3', 5, 7, 6, 8}}),
                                                  {{1, {40, 0, 1000}}, {3, {40, 100, 1000}}}, {2}));
    EXPECT_EQ(ids(r), (Ids{1, 2, 3}));
    EXPECT_EQ(hows(r), "oop");
}

TEST(ReferenceTracks, NoCentroidNoPositionMatch) {
    // Frame 0: track 1 without a centroid, track 2 at (100, 0, 0). Frame 2: segment 1 at (0, 0, 0) on track 1's
    // place (track 1 cannot be found by position; track 2 is 100 > 50 away), segment 2 without a centroid on track
    // 2's place. Both new.
    Tracker tr(TrackParams{});
    next(tr, picture(kCorners, {{2, {100, 0, 0}}}, {1}));
    next(tr, picture(kEmpty));
    const std::vector<Track> r = next(tr, picture(kCorners, {{1, {0, 0, 0}}}, {2}));
    EXPECT_EQ(ids(r), (Ids{3, 4}));
    EXPECT_EQ(hows(r), "nn");
}

TEST(ReferenceTracks, AgeFirstFrameAndHiddenFrames) {
    const std::vector<std::string> a = {
        "111111......", "111111......", "............", "............",
        "............", "............", "............", "............",
    };
    const std::vector<std::string> ab = {
        "111111......", "111111......", "............", "............",
        "............", "............", "........2222", "........2222",
    };
    Tracker tr(TrackParams{});
    next(tr, picture(a));
    std::vector<Track> r = next(tr, picture(ab));
    EXPECT_EQ(ids(r), (Ids{1, 2}));
    EXPECT_EQ(hows(r), "on");
    EXPECT_EQ(first_frames(r), (Ids{0, 1}));
    EXPECT_EQ(ages(r), (Ids{2, 1}));
    r = next(tr, picture(ab));
    EXPECT_EQ(ages(r), (Ids{3, 2}));
    EXPECT_EQ(hows(r), "oo");
    r = next(tr, picture(a));
    EXPECT_EQ(ages(r), (Ids{4}));
    r = next(tr, picture(ab));  // B back where it was: no overlap with frame 3, t = 0
    EXPECT_EQ(ids(r), (Ids{1, 2}));
    EXPECT_EQ(hows(r), "op");
    EXPECT_EQ(first_frames(r), (Ids{0, 1}));
    EXPECT_EQ(ages(r), (Ids{5, 3}));
    EXPECT_EQ(hidden(r), (Ids{0, 1}));
}

TEST(ReferenceTracks, ResetStartsANewStream) {
    Tracker tr(TrackParams{});
    next(tr, picture(kCorners));
    next(tr, picture(kCorners));
    EXPECT_EQ(ages(next(tr, picture(kCorners))), (Ids{3, 3}));
    tr.reset();
    // Another size is fine after a reset; no previous labels, no tracks, frame 0, ids from 1.
    const Frame small = picture({"..11", "..11", "...."});
    std::vector<Track> r = next(tr, small);
    EXPECT_EQ(ids(r), (Ids{1}));
    EXPECT_EQ(hows(r), "n");
    EXPECT_EQ(first_frames(r), (Ids{0}));
    EXPECT_EQ(ages(r), (Ids{1}));
    EXPECT_THROW(next(tr, picture(kCorners)), std::invalid_argument);
    tr.reset();
    r = next(tr, picture(kCorners));
    EXPECT_EQ(ids(r), (Ids{1, 2}));
    EXPECT_EQ(hows(r), "nn");
    r = next(tr, picture(kCorners));
    EXPECT_EQ(hows(r), "oo");
    EXPECT_EQ(ages(r), (Ids{2, 2}));
}

TEST(ReferenceTracks, BadFramesThrowAndChangeNothing) {
    Tracker tr(TrackParams{});
    next(tr, picture(kCorners));
    EXPECT_THROW(next(tr, picture({"..11", "..11", "...."})), std::invalid_argument);  // another size
    Frame transposed = picture(kCorners);                                              // the same pixel count as 8 x 12
    transposed.width = 8;
    transposed.height = 12;
    EXPECT_THROW(next(tr, transposed), std::invalid_argument);
    Frame wrong_size = picture(kCorners);
    wrong_size.height = 7;  // 12 * 7 != 96 labels
    EXPECT_THROW(next(tr, wrong_size), std::invalid_argument);
    wrong_size.height = -8;
    wrong_size.width = -12;
    EXPECT_THROW(next(tr, wrong_size), std::invalid_argument);
    Frame too_few = picture(kCorners);
    too_few.segments.pop_back();  // label 2 > K = 1
    EXPECT_THROW(next(tr, too_few), std::invalid_argument);
    // Still frame 1, after frame 0's labels.
    const std::vector<Track> r = next(tr, picture({"11..........", "11..........", "............", "....333.....",
                                                   "............", "............", "..........22", "..........22"}));
    EXPECT_EQ(ids(r), (Ids{1, 2, 3}));
    EXPECT_EQ(hows(r), "oon");
    EXPECT_EQ(first_frames(r), (Ids{0, 0, 1}));
    EXPECT_EQ(ages(r), (Ids{2, 2, 1}));
}

TEST(ReferenceTracks, OutputConvenience) {
    const Frame f = picture(kCorners);
    pyrseg_ref::Output out;
    out.labels = f.labels;
    out.segments = f.segments;
    out.segment_count = 2;
    Tracker tr(TrackParams{});
    EXPECT_EQ(ids(tr.next(out, 12, 8)), (Ids{1, 2}));
    EXPECT_EQ(hows(tr.next(out, 12, 8)), "oo");
    EXPECT_THROW(tr.next(out, 8, 12), std::invalid_argument);
    out.ok = false;
    EXPECT_THROW(tr.next(out, 12, 8), std::invalid_argument);
}

TEST(ReferenceTracks, ParametersOutOfRangeThrow) {
    EXPECT_THROW(Tracker(params(50.0, -1)), std::invalid_argument);
    EXPECT_THROW(Tracker(params(-1.0)), std::invalid_argument);
    EXPECT_THROW(Tracker(params(std::nan(""))), std::invalid_argument);
    EXPECT_THROW(Tracker(params(50.0, 10, 0.0)), std::invalid_argument);
    EXPECT_NO_THROW(Tracker(params(0.0, 0)));
}

}  // namespace
