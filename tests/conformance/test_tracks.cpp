// Tracks (docs/algorithm.md section 11) on every backend against the reference's tracker (tests/reference), frame by
// frame over streams: a pan over a wide scene that jumps, and an object that hides and comes back.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "conformance/cases.hpp"
#include "pyrseg/error.hpp"
#include "pyrseg/presets.hpp"
#include "pyrseg/segmenter.hpp"
#include "pyrseg/synthetic.hpp"
#include "reference/reference_tracks.hpp"
#include "support/oracle.hpp"

namespace pyrseg::test {
namespace {

// Column x0 on of `wide`, `width` wide; the points of object `hidden` (0: none) left out.
std::vector<float> view_of(const synthetic::Scene& wide, int x0, int width, std::uint32_t hidden) {
    std::vector<float> points(3 * std::size_t(width) * std::size_t(wide.height));
    for (int y = 0; y < wide.height; ++y) {
        for (int x = 0; x < width; ++x) {
            const std::size_t from = std::size_t(y) * std::size_t(wide.width) + std::size_t(x0 + x);
            float* to = points.data() + 3 * (std::size_t(y) * std::size_t(width) + std::size_t(x));
            if (hidden != 0 && wide.object_id[from] == hidden) {
                std::fill_n(to, 3, std::nanf(""));
            } else {
                std::copy_n(wide.points.data() + 3 * from, 3, to);
            }
        }
    }
    return points;
}

TrackMatch to_library(pyrseg_ref::TrackMatch how) {
    switch (how) {
        case pyrseg_ref::TrackMatch::overlap:
            return TrackMatch::overlap;
        case pyrseg_ref::TrackMatch::position:
            return TrackMatch::position;
        case pyrseg_ref::TrackMatch::new_track:
            break;
    }
    return TrackMatch::new_track;
}

struct StreamCase {
    const char* name;
    synthetic::Sensor sensor;
    bool robust;  // the sensor's preset-like robust metric with the merge, else the paper's defaults
};

class TrackStreams : public ::testing::TestWithParam<std::tuple<std::string, int>> {};

const StreamCase kStreams[] = {
    {"paper", synthetic::Sensor::structured_light, false},
    {"robust_merge", synthetic::Sensor::realsense_d435, true},
};

TEST_P(TrackStreams, MatchesReference) {
    const auto& [backend, index] = GetParam();
    PYRSEG_SKIP_IF_UNAVAILABLE(backend);
    const StreamCase& c = kStreams[index];
    const int width = 200;
    const int height = 150;
    synthetic::SceneOptions o;
    o.width = width + 48;
    o.height = height;
    o.seed = 11;
    o.object_count = 12;
    o.sensor = c.sensor;
    o.camera_distance_mm = 900;
    const synthetic::Scene wide = synthetic::generate(o);
    Params params;
    if (c.robust) {
        params.metric = Metric::robust;
        params.dt_per_m2 = 6.0;
        params.ct_growth_per_m2 = 1.0;
        params.edge_rounds = 4;
        params.merge = true;
        params.merge_tolerance_mm = 1.5;
    }
    params.track_hold_frames = 3;
    Outputs outputs;
    outputs.segment_tracks = true;
    outputs.track_ids = true;
    auto segmenter = std::make_unique<Segmenter>(width, height, params, backend, outputs);
    pyrseg_ref::TrackParams track_params;
    track_params.unit_mm = params.unit_mm;
    track_params.max_distance_mm = params.track_max_distance_mm;
    track_params.hold_frames = params.track_hold_frames;
    pyrseg_ref::Tracker tracker(track_params);
    // The window's column and the object left out, frame by frame: a pan, a jump, an object hidden for 2 frames (it
    // comes back by position), one hidden for 5 (longer than the hold: a new id), a reset.
    struct Frame {
        int x0;
        std::uint32_t hidden;
        bool reset;
    };
    const std::uint32_t a = synthetic::kFirstObjectId + 2;
    const std::uint32_t b = synthetic::kFirstObjectId + 5;
    const std::vector<Frame> frames = {{0, 0, false},  {1, 0, false},  {3, 0, false},  {3, a, false},
                                       {4, a, false},  {4, 0, false},  {20, 0, false}, {21, b, false},
                                       {21, b, false}, {22, b, false}, {22, b, false}, {23, b, false},
                                       {24, 0, false}, {40, 0, false}, {40, 0, true},  {41, 0, false}};
    Result result;
    std::size_t by_position = 0;
    std::size_t matched = 0;
    for (std::size_t f = 0; f < frames.size(); ++f) {
        SCOPED_TRACE("frame " + std::to_string(f));
        if (frames[f].reset) {
            segmenter->reset_tracks();
            tracker.reset();
        }
        const std::vector<float> points = view_of(wide, frames[f].x0, width, frames[f].hidden);
        const pyrseg_ref::Output ref = pyrseg_ref::segment(points.data(), nullptr, width, height, to_reference(params));
        ASSERT_TRUE(ref.ok) << ref.error;
        const std::vector<pyrseg_ref::Track> expected = tracker.next(ref, width, height);
        segmenter->segment(CloudView{points.data(), nullptr, width, height}, result);
        ASSERT_TRUE(same_bytes("labels", result.labels, ref.labels, width));
        ASSERT_EQ(result.tracks.size(), expected.size());
        for (std::size_t k = 0; k < expected.size(); ++k) {
            const SegmentTrack& got = result.tracks[k];
            const pyrseg_ref::Track& want = expected[k];
            EXPECT_EQ(got.label, want.label) << "segment " << k + 1;
            EXPECT_EQ(got.id, want.id) << "segment " << k + 1;
            EXPECT_EQ(got.first_frame, want.first_frame) << "segment " << k + 1;
            EXPECT_EQ(got.age, want.age) << "segment " << k + 1;
            EXPECT_EQ(got.hidden_frames, want.hidden_frames) << "segment " << k + 1;
            EXPECT_EQ(got.how, to_library(want.how)) << "segment " << k + 1;
            by_position += want.how == pyrseg_ref::TrackMatch::position ? 1 : 0;
            matched += want.how != pyrseg_ref::TrackMatch::new_track ? 1 : 0;
        }
        for (std::size_t i = 0; i < result.labels.size(); ++i) {
            const std::uint32_t k = result.labels[i];
            ASSERT_EQ(result.track_ids[i], k == 0 ? 0u : expected[k - 1].id);
        }
    }
    EXPECT_GT(matched, 100u) << "the stream must carry ids over";
    EXPECT_GT(by_position, 0u) << "the stream must match some segments by position";
}

// A camera on the generator's random walk (up to 2 cm and 2 degrees a frame) over a scene whose objects slide,
// hide and come back: the camera's shift of step 2, its border rule, and step 3 at work.
TEST_P(TrackStreams, MovingCameraMatchesReference) {
    const auto& [backend, index] = GetParam();
    PYRSEG_SKIP_IF_UNAVAILABLE(backend);
    const StreamCase& c = kStreams[index];
    const int width = 200;
    const int height = 150;
    synthetic::SequenceOptions so;
    so.scene.width = width;
    so.scene.height = height;
    so.scene.seed = 3;
    so.scene.sensor = c.sensor;
    so.frames = 24;
    so.object_motion = true;
    const std::vector<synthetic::SceneOptions> frames = synthetic::sequence(so);
    Params params = c.robust ? sensor_preset(SensorKind::realsense_d435) : Params{};
    params.color_edge_threshold = kMaxColorEdgeThreshold;
    Outputs outputs;
    outputs.segment_tracks = true;
    Segmenter segmenter(width, height, params, backend, outputs);
    pyrseg_ref::TrackParams track_params;
    track_params.unit_mm = params.unit_mm;
    track_params.max_distance_mm = params.track_max_distance_mm;
    track_params.hold_frames = params.track_hold_frames;
    pyrseg_ref::Tracker tracker(track_params);
    Result result;
    std::size_t by_position = 0;
    for (std::size_t f = 0; f < frames.size(); ++f) {
        SCOPED_TRACE("frame " + std::to_string(f));
        const synthetic::Scene scene = synthetic::generate(frames[f]);
        const pyrseg_ref::Output ref =
            pyrseg_ref::segment(scene.points.data(), nullptr, width, height, to_reference(params));
        ASSERT_TRUE(ref.ok) << ref.error;
        const std::vector<pyrseg_ref::Track> expected = tracker.next(ref, width, height);
        segmenter.segment(CloudView{scene.points.data(), nullptr, width, height}, result);
        ASSERT_TRUE(same_bytes("labels", result.labels, ref.labels, width));
        ASSERT_EQ(result.tracks.size(), expected.size());
        for (std::size_t k = 0; k < expected.size(); ++k) {
            EXPECT_EQ(result.tracks[k].id, expected[k].id) << "segment " << k + 1;
            EXPECT_EQ(result.tracks[k].first_frame, expected[k].first_frame) << "segment " << k + 1;
            EXPECT_EQ(result.tracks[k].age, expected[k].age) << "segment " << k + 1;
            EXPECT_EQ(result.tracks[k].hidden_frames, expected[k].hidden_frames) << "segment " << k + 1;
            EXPECT_EQ(result.tracks[k].how, to_library(expected[k].how)) << "segment " << k + 1;
            by_position += expected[k].how == pyrseg_ref::TrackMatch::position ? 1 : 0;
        }
    }
    EXPECT_GT(by_position, 0u) << "the stream must match some segments by position";
}

INSTANTIATE_TEST_SUITE_P(Backends, TrackStreams,
                         ::testing::Combine(::testing::ValuesIn(available_backend_names()),
                                            ::testing::Range(0, int(std::size(kStreams)))),
                         [](const ::testing::TestParamInfo<TrackStreams::ParamType>& param_info) {
                             return std::get<0>(param_info.param) + "_" +
                                    kStreams[std::size_t(std::get<1>(param_info.param))].name;
                         });

}  // namespace
}  // namespace pyrseg::test
