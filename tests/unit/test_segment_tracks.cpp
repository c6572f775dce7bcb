// Tracks (docs/algorithm.md section 11): ids that carry over while a camera pans over a scene, objects that hide and
// come back, and the parameters and backends that are refused. Bit-exactness against the reference is the
// conformance suite's job (tests/conformance/test_tracks.cpp).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "pyrseg/error.hpp"
#include "pyrseg/segmenter.hpp"
#include "pyrseg/synthetic.hpp"

namespace pyrseg {
namespace {

Outputs tracks_and_ids() {
    Outputs o;
    o.segment_tracks = true;
    o.track_ids = true;
    return o;
}

// The window of `wide` from column x0 on, `width` wide: the view of a camera whose image slides over the scene.
std::vector<float> window(const synthetic::Scene& wide, int x0, int width) {
    std::vector<float> points(3 * std::size_t(width) * std::size_t(wide.height));
    for (int y = 0; y < wide.height; ++y) {
        const float* from = wide.points.data() + 3 * (std::size_t(y) * std::size_t(wide.width) + std::size_t(x0));
        std::copy_n(from, 3 * std::size_t(width), points.data() + 3 * std::size_t(y) * std::size_t(width));
    }
    return points;
}

synthetic::Scene wide_scene(int width, int height) {
    synthetic::SceneOptions o;
    o.width = width;
    o.height = height;
    o.seed = 5;
    o.object_count = 10;
    o.hole_fraction = 0.0;
    return synthetic::generate(o);
}

// The share of the pixels labelled in both frames of a pan by one pixel whose ids agree: frame b's pixel (x, y) is
// frame a's (x + 1, y).
double kept_share(const std::vector<std::uint32_t>& a, const std::vector<std::uint32_t>& b, int width, int height) {
    std::size_t both = 0;
    std::size_t same = 0;
    for (int y = 0; y < height; ++y) {
        for (int x = 0; x + 1 < width; ++x) {
            const std::uint32_t before = a[std::size_t(y) * std::size_t(width) + std::size_t(x + 1)];
            const std::uint32_t after = b[std::size_t(y) * std::size_t(width) + std::size_t(x)];
            if (before == 0 || after == 0) continue;
            ++both;
            same += before == after ? 1 : 0;
        }
    }
    return both == 0 ? 0.0 : double(same) / double(both);
}

TEST(SegmentTracks, APanKeepsTheIdsThatPlainLabelsLose) {
    const int width = 320;
    const int height = 240;
    const synthetic::Scene wide = wide_scene(width + 12, height);
    Segmenter segmenter(width, height, Params{}, "cpu", tracks_and_ids());
    Result result;
    std::vector<std::uint32_t> ids_before;
    std::vector<std::uint32_t> labels_before;
    double least_ids = 1.0;
    double least_labels = 1.0;
    for (int frame = 0; frame < 10; ++frame) {
        const std::vector<float> points = window(wide, frame, width);
        segmenter.segment(CloudView{points.data(), nullptr, width, height}, result);
        ASSERT_EQ(result.tracks.size(), result.segment_count);
        ASSERT_EQ(result.track_ids.size(), result.labels.size());
        for (std::uint32_t k = 1; k <= result.segment_count; ++k) {
            const SegmentTrack& t = result.tracks[k - 1];
            EXPECT_EQ(t.label, k);
            EXPECT_LE(t.first_frame, std::uint32_t(frame));
            EXPECT_LE(t.age, std::uint32_t(frame) - t.first_frame + 1);
            if (frame == 0) {
                EXPECT_EQ(t.id, k) << "the first frame's ids are 1..K in label order";
                EXPECT_EQ(t.how, TrackMatch::new_track);
            }
            // A surface's segment is seen in every frame; a few pixels of noise may be seen in some only.
            if (frame > 0 && result.segments[k - 1].pixel_count >= 200) {
                EXPECT_EQ(t.how, TrackMatch::overlap) << "segment " << k << " of frame " << frame;
                EXPECT_EQ(t.first_frame, 0u);
                EXPECT_EQ(t.age, std::uint32_t(frame) + 1);
                EXPECT_EQ(t.hidden_frames, 0u);
            }
        }
        for (std::size_t i = 0; i < result.labels.size(); ++i) {
            const std::uint32_t k = result.labels[i];
            ASSERT_EQ(result.track_ids[i], k == 0 ? 0u : result.tracks[k - 1].id);
        }
        if (frame > 0) {
            least_ids = std::min(least_ids, kept_share(ids_before, result.track_ids, width, height));
            least_labels = std::min(least_labels, kept_share(labels_before, result.labels, width, height));
        }
        ids_before = result.track_ids;
        labels_before = result.labels;
    }
    EXPECT_GE(least_ids, 0.99);
    EXPECT_LT(least_labels, least_ids) << "the scene must be one whose plain labels change in a pan";
}

TEST(SegmentTracks, AnObjectHiddenForAFewFramesComesBackWithItsId) {
    const int width = 320;
    const int height = 240;
    const synthetic::Scene scene = wide_scene(width, height);
    // The object with the most pixels: frames 2..4 do not see it (no data there), frame 5 does again.
    std::vector<std::size_t> pixels(scene.primitives.size() + 8, 0);
    for (const std::uint32_t id : scene.object_id) {
        if (id >= synthetic::kFirstObjectId && id < pixels.size()) ++pixels[id];
    }
    const auto hidden_id = std::uint32_t(std::max_element(pixels.begin(), pixels.end()) - pixels.begin());
    std::vector<float> without = scene.points;
    for (std::size_t i = 0; i < scene.object_id.size(); ++i) {
        if (scene.object_id[i] == hidden_id) std::fill_n(without.data() + 3 * i, 3, std::nanf(""));
    }
    // A pixel well inside the object (its 7 x 7 window all the object's): labelled, not an edge.
    std::size_t probe = 0;
    for (int y = 3; y + 3 < height && probe == 0; ++y) {
        for (int x = 3; x + 3 < width && probe == 0; ++x) {
            bool inside = true;
            for (int dy = -3; dy <= 3; ++dy) {
                for (int dx = -3; dx <= 3; ++dx)
                    inside = inside && scene.object_id[std::size_t(y + dy) * width + std::size_t(x + dx)] == hidden_id;
            }
            if (inside) probe = std::size_t(y) * std::size_t(width) + std::size_t(x);
        }
    }
    ASSERT_NE(probe, 0u);
    Params params;
    Segmenter segmenter(width, height, params, "cpu", tracks_and_ids());
    Result result;
    std::uint32_t id = 0;
    std::uint32_t ids_so_far = 0;
    for (int frame = 0; frame < 7; ++frame) {
        const bool hidden = frame >= 2 && frame <= 4;
        const std::vector<float>& points = hidden ? without : scene.points;
        segmenter.segment(CloudView{points.data(), nullptr, width, height}, result);
        for (const SegmentTrack& t : result.tracks) ids_so_far = std::max(ids_so_far, t.id);
        if (hidden) continue;
        const std::uint32_t k = result.labels[probe];
        ASSERT_NE(k, 0u);
        const SegmentTrack& t = result.tracks[k - 1];
        if (frame == 0) id = t.id;
        EXPECT_EQ(t.id, id) << "frame " << frame;
        if (frame == 5) {
            EXPECT_EQ(t.how, TrackMatch::position);
            EXPECT_EQ(t.hidden_frames, 3u);
            EXPECT_EQ(t.age, 3u);
        }
    }
    // Held for fewer frames than it hides: the object comes back with a new id.
    params.track_hold_frames = 2;
    Segmenter short_hold(width, height, params, "cpu", tracks_and_ids());
    for (int frame = 0; frame < 6; ++frame) {
        const bool hidden = frame >= 2 && frame <= 4;
        short_hold.segment(CloudView{(hidden ? without : scene.points).data(), nullptr, width, height}, result);
        if (frame == 0) id = result.tracks[result.labels[probe] - 1].id;
    }
    const SegmentTrack& back = result.tracks[result.labels[probe] - 1];
    EXPECT_NE(back.id, id);
    EXPECT_EQ(back.how, TrackMatch::new_track);
    EXPECT_EQ(back.first_frame, 5u);
}

TEST(SegmentTracks, ResetStartsANewStream) {
    const synthetic::Scene scene = wide_scene(160, 120);
    Segmenter segmenter(160, 120, Params{}, "cpu", tracks_and_ids());
    const CloudView view{scene.points.data(), nullptr, 160, 120};
    Result first = segmenter.segment(view);
    Result second = segmenter.segment(view);
    ASSERT_GT(first.segment_count, 1u);
    for (const SegmentTrack& t : second.tracks) {
        EXPECT_EQ(t.age, 2u);
        EXPECT_EQ(t.how, TrackMatch::overlap);
    }
    segmenter.reset_tracks();
    const Result again = segmenter.segment(view);
    EXPECT_EQ(again.tracks, first.tracks);
}

TEST(SegmentTracks, BadRequestsAreRefused) {
    Params params;
    params.compact = false;
    EXPECT_THROW(Segmenter(64, 48, params, "cpu", tracks_and_ids()), Error);
    for (const int hold : {-1, 1001}) {
        params = Params{};
        params.track_hold_frames = hold;
        EXPECT_THROW(Segmenter(64, 48, params, "cpu", tracks_and_ids()), Error) << hold;
    }
    for (const double d : {-1.0, std::numeric_limits<double>::infinity(), std::nan("")}) {
        params = Params{};
        params.track_max_distance_mm = d;
        EXPECT_THROW(Segmenter(64, 48, params, "cpu", tracks_and_ids()), Error) << d;
    }
}

}  // namespace
}  // namespace pyrseg
