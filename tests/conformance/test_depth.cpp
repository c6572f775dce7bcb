// DepthView on every backend: depth images back-projected on the device (docs/algorithm.md section 1b) give the
// reference's labels, mask and normals byte for byte: u16 and f32 samples, rows with odd byte steps, missing data as
// 0, NaN, negative, subnormal and infinite samples, the paper's metric and a sensor preset, millimetres and metres.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "pyrseg/error.hpp"
#include "pyrseg/presets.hpp"
#include "pyrseg/segmenter.hpp"
#include "pyrseg/synthetic.hpp"
#include "support/oracle.hpp"

namespace pyrseg::test {
namespace {

// A synthetic frame as a camera's depth image: row y starts y * step bytes in (step need not be a multiple of 4).
struct DepthImage {
    std::vector<unsigned char> bytes;
    DepthView view;
};

DepthImage make_depth(const synthetic::Scene& s, DepthFormat format, std::size_t padding, double metres_per_unit) {
    const std::size_t w = std::size_t(s.width);
    const std::size_t h = std::size_t(s.height);
    const std::size_t sample = format == DepthFormat::u16 ? 2 : 4;
    const std::size_t step = w * sample + padding;
    DepthImage d;
    d.bytes.assign(h * step + 1, 0xAB);
    for (std::size_t y = 0; y < h; ++y) {
        for (std::size_t x = 0; x < w; ++x) {
            const float z_mm = s.points[3 * (y * w + x) + 2];
            const double units = double(z_mm) / (metres_per_unit * 1000.0);
            unsigned char* at = d.bytes.data() + 1 + y * step + x * sample;  // +1: rows start at odd addresses
            if (format == DepthFormat::u16) {
                const std::uint16_t v = std::isfinite(units) && units < 65535 ? std::uint16_t(std::lround(units)) : 0;
                std::memcpy(at, &v, 2);
            } else {
                // Every kind of missing sample: NaN (the scene's), and by position negative, -0, subnormal, inf.
                float v = float(units);
                const std::size_t k = (y * w + x) % 97;
                if (k == 1) v = -v;
                if (k == 2) v = -0.0f;
                if (k == 3) v = std::numeric_limits<float>::denorm_min();
                if (k == 4) v = std::numeric_limits<float>::infinity();
                std::memcpy(at, &v, 4);
            }
        }
    }
    d.view.depth = d.bytes.data() + 1;
    d.view.format = format;
    d.view.width = s.width;
    d.view.height = s.height;
    d.view.row_step_bytes = step;
    d.view.metres_per_unit = metres_per_unit;
    d.view.fx = s.fx;
    d.view.fy = s.fy;
    d.view.cx = s.cx + 0.37;  // off-centre, so that ku is not symmetric
    d.view.cy = s.cy - 0.61;
    return d;
}

pyrseg_ref::DepthInput to_reference(const DepthView& v) {
    pyrseg_ref::DepthInput r;
    r.samples = v.depth;
    r.format = v.format == DepthFormat::u16 ? pyrseg_ref::DepthFormat::u16 : pyrseg_ref::DepthFormat::f32;
    r.width = v.width;
    r.height = v.height;
    r.row_step_bytes = v.row_step_bytes;
    r.metres_per_unit = v.metres_per_unit;
    r.fx = v.fx;
    r.fy = v.fy;
    r.cx = v.cx;
    r.cy = v.cy;
    return r;
}

class DepthImages : public ::testing::TestWithParam<std::string> {};

TEST_P(DepthImages, MatchTheReference) {
    PYRSEG_SKIP_IF_UNAVAILABLE(GetParam());
    synthetic::SceneOptions o;
    o.width = 131;
    o.height = 97;
    o.sensor = synthetic::Sensor::kinect_v1;
    const synthetic::Scene scene = synthetic::generate(o);
    struct Case {
        DepthFormat format;
        std::size_t padding;
        double metres_per_unit;
        Params params;
        const char* what;
    };
    Params metres = sensor_preset(SensorKind::kinect_v1, 1000.0);
    const Case cases[] = {
        {DepthFormat::u16, 0, 0.001, Params{}, "u16 mm, packed rows, paper metric"},
        {DepthFormat::u16, 3, 0.001, sensor_preset(SensorKind::kinect_v1), "u16 mm, rows of 2W+3 bytes, kinect-v1"},
        {DepthFormat::u16, 1, 0.0002, metres, "u16 at 1/5000 m (TUM), points in metres, kinect-v1"},
        {DepthFormat::f32, 5, 1.0, sensor_preset(SensorKind::azure_kinect), "f32 metres, rows of 4W+5 bytes, azure"},
        {DepthFormat::f32, 0, 0.001, Params{}, "f32 mm, packed rows, paper metric"},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(c.what);
        const DepthImage d = make_depth(scene, c.format, c.padding, c.metres_per_unit);
        const pyrseg_ref::Output ref =
            pyrseg_ref::segment_depth(to_reference(d.view), o.width, o.height, pyrseg::test::to_reference(c.params));
        ASSERT_TRUE(ref.ok) << ref.error;
        Segmenter segmenter(o.width, o.height, c.params, GetParam(), everything());
        Result result;
        segmenter.segment(d.view, result);
        EXPECT_GT(ref.segment_count, 1u);
        EXPECT_TRUE(same_bytes("fillable mask", result.fillable_mask, ref.fillable, o.width));
        EXPECT_TRUE(same_bytes("normals", result.normals, ref.normals, o.width, 3));
        EXPECT_TRUE(same_bytes("raw labels", result.raw_labels, ref.raw_labels, o.width));
        EXPECT_TRUE(same_bytes("labels", result.labels, ref.labels, o.width));
        EXPECT_TRUE(same_segments(result.segments, ref.segments));
        EXPECT_TRUE(same_graph(result.graph, ref.graph));
        // A second frame on the same Segmenter: nothing of the first may leak into it.
        segmenter.segment(d.view, result);
        EXPECT_TRUE(same_bytes("labels, second frame", result.labels, ref.labels, o.width));
    }
}

TEST_P(DepthImages, IntrinsicsThatChangeBetweenFramesAreUsed) {
    // GPU backends keep the ray slopes on the device and send them only when they change: frames alternating two
    // calibrations (and the frame size's both tables), with a refused frame between, each match the reference.
    PYRSEG_SKIP_IF_UNAVAILABLE(GetParam());
    synthetic::SceneOptions o;
    o.width = 67;
    o.height = 45;
    const synthetic::Scene scene = synthetic::generate(o);
    const DepthImage a = make_depth(scene, DepthFormat::u16, 0, 0.001);
    DepthView b = a.view;
    b.fx *= 1.25;
    b.cy += 3.5;
    Segmenter segmenter(o.width, o.height, {}, GetParam(), everything());
    const auto check = [&](const DepthView& v, const char* what) {
        SCOPED_TRACE(what);
        const pyrseg_ref::Output ref =
            pyrseg_ref::segment_depth(to_reference(v), o.width, o.height, pyrseg::test::to_reference(Params{}));
        ASSERT_TRUE(ref.ok) << ref.error;
        const Result r = segmenter.segment(v);
        EXPECT_TRUE(same_bytes("normals", r.normals, ref.normals, o.width, 3));  // the points' x and y show here
        EXPECT_TRUE(same_bytes("labels", r.labels, ref.labels, o.width));
    };
    check(a.view, "calibration A");
    check(b, "calibration B");
    check(a.view, "A again");
    DepthView refused = b;
    refused.fy = -1;
    EXPECT_THROW((void)segmenter.segment(refused), Error);
    check(b, "B after a refused frame");
    check(b, "B twice");
}

TEST_P(DepthImages, BadViewsAreErrorsNamingTheProblem) {
    PYRSEG_SKIP_IF_UNAVAILABLE(GetParam());
    std::vector<std::uint16_t> samples(32 * 24, 1000);
    Segmenter segmenter(32, 24, {}, GetParam());
    const DepthView good{samples.data(), DepthFormat::u16, 32, 24, 0, 0.001, 500, 500, 16, 12};
    const auto expect = [&](DepthView v, ErrorCode code, const std::string& words) {
        try {
            (void)segmenter.segment(v);
            ADD_FAILURE() << "no error; expected one naming " << words;
        } catch (const Error& e) {
            EXPECT_EQ(e.code(), code) << e.what();
            EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
        }
    };
    DepthView v = good;
    v.depth = nullptr;
    expect(v, ErrorCode::invalid_argument, "null");
    for (const double m : {0.0, -0.001, std::nan(""), double(INFINITY)}) {
        v = good;
        v.metres_per_unit = m;
        expect(v, ErrorCode::invalid_parameter, "metres_per_unit");
    }
    v = good;
    v.fx = 0;
    expect(v, ErrorCode::invalid_parameter, "fx");
    v = good;
    v.fy = -500;
    expect(v, ErrorCode::invalid_parameter, "fy");
    v = good;
    v.cx = INFINITY;
    expect(v, ErrorCode::invalid_parameter, "cx");
    v = good;
    v.cy = std::nan("");
    expect(v, ErrorCode::invalid_parameter, "cy");
    v = good;
    v.metres_per_unit = 1e-45;  // a scale below float32's normal range
    expect(v, ErrorCode::invalid_parameter, "scale");
    v = good;
    v.row_step_bytes = 63;  // less than a row of 32 u16 samples
    expect(v, ErrorCode::invalid_argument, "row_step_bytes");
    v = good;
    v.width = 31;
    expect(v, ErrorCode::size_mismatch, "31 x 24");
    // After every refusal the Segmenter still segments a good frame.
    EXPECT_NO_THROW((void)segmenter.segment(good));
}

INSTANTIATE_TEST_SUITE_P(Backends, DepthImages, ::testing::ValuesIn(available_backend_names()),
                         [](const ::testing::TestParamInfo<std::string>& param_info) { return param_info.param; });

}  // namespace
}  // namespace pyrseg::test
