// The API's edges (issue 18): a moved-from Segmenter throws a clear pyrseg::Error from every member instead of
// dereferencing null, and a frame of given normals all far from unit length is refused instead of silently unlabelled
// (docs/algorithm.md section 1), while the normals real tools write, "no normal" markers, and a single normal off unit
// length (the contract's clamping) still go through.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "pyrseg/error.hpp"
#include "pyrseg/presets.hpp"
#include "pyrseg/segmenter.hpp"
#include "pyrseg/synthetic.hpp"
#include "tests/support/cpu_targets.hpp"

namespace pyrseg {
namespace {

// The message of the pyrseg::Error `f` throws with `code`; a failure (and "") when it throws nothing or another code.
std::string error_message(ErrorCode code, const std::function<void()>& f) {
    try {
        f();
    } catch (const Error& e) {
        EXPECT_EQ(e.code(), code) << e.what();
        return e.what();
    }
    ADD_FAILURE() << "no pyrseg::Error";
    return "";
}

TEST(ApiEdges, EveryMemberOfAMovedFromSegmenterThrows) {
    Segmenter moved_from(32, 24, {}, "cpu");
    const Segmenter moved_to = std::move(moved_from);
    EXPECT_EQ(moved_to.width(), 32);
    const std::vector<float> points(std::size_t{32} * 24 * 3, 1.0f);
    const std::vector<std::uint16_t> depth(std::size_t{32} * 24, 1000);
    const std::vector<unsigned char> mask(std::size_t{32} * 24, 1);
    Result out;
    const Segmenter& s = moved_from;  // NOLINT(bugprone-use-after-move): what is under test
    const std::vector<std::function<void()>> members = {
        [&] { (void)s.width(); },
        [&] { (void)s.height(); },
        [&] { (void)s.params(); },
        [&] { (void)s.backend_name(); },
        [&] { (void)s.last_timings(); },
        [&] { (void)s.last_fill_rounds(); },
        [&] { (void)s.last_dispatches(); },
        [&] { (void)s.last_host_syncs(); },
        [&] {
            moved_from.segment(CloudView{points.data(), nullptr, 32, 24}, out);
        },
        [&] {
            (void)moved_from.segment(CloudView{points.data(), nullptr, 32, 24});
        },
        [&] {
            moved_from.segment(DepthView{depth.data(), DepthFormat::u16, 32, 24, 0, 0.001, 30, 30, 16, 12}, out);
        },
        [&] {
            moved_from.segment_mask(MaskView{mask.data(), nullptr, 32, 24}, out);
        },
    };
    for (std::size_t i = 0; i < members.size(); ++i) {
        EXPECT_NE(error_message(ErrorCode::invalid_argument, members[i]).find("moved from"), std::string::npos)
            << "member " << i;
    }
    // Assigning a live Segmenter to it makes it usable again.
    moved_from = Segmenter(16, 8, {}, "cpu");
    EXPECT_EQ(moved_from.width(), 16);
}

class GivenNormals : public ::testing::Test {
protected:
    static constexpr int kWidth = 33;
    static constexpr int kHeight = 31;

    void SetUp() override {
        synthetic::SceneOptions o;
        o.width = kWidth;
        o.height = kHeight;
        o.seed = 4;
        o.object_count = 2;
        scene_ = synthetic::generate(o);
    }

    Result segment(const std::vector<float>& normals) {
        Segmenter seg(kWidth, kHeight, {}, "cpu");
        return seg.segment(CloudView{scene_.points.data(), normals.data(), kWidth, kHeight});
    }

    // The scene's normals with pixel (x, y)'s replaced.
    std::vector<float> with_normal(int x, int y, float nx, float ny, float nz) const {
        std::vector<float> n = scene_.normals;
        const std::size_t i = 3 * (std::size_t(y) * kWidth + std::size_t(x));
        n[i] = nx;
        n[i + 1] = ny;
        n[i + 2] = nz;
        return n;
    }

    synthetic::Scene scene_;
};

TEST_F(GivenNormals, AFrameOfScaledNormalsIsRefusedNamingTheFirst) {
    // The scene's first rows are background with normals; make the first two "no normal" so that the first normal
    // the message names is pixel (2, 0).
    for (const float scale : {0.5f, 0.95f, 1.05f, 1000.0f, 1e-30f, 1e30f}) {
        std::vector<float> scaled = scene_.normals;
        for (float& v : scaled) v *= scale;
        for (std::size_t c = 0; c < 6; ++c) scaled[c] = c < 3 ? 0.0f : std::numeric_limits<float>::quiet_NaN();
        const std::string message = error_message(ErrorCode::invalid_argument, [&] { (void)segment(scaled); });
        EXPECT_NE(message.find("none of the frame's"), std::string::npos) << scale << ": " << message;
        EXPECT_NE(message.find("is unit length (within 1%); the first, at pixel (2, 0)"), std::string::npos)
            << scale << ": " << message;
    }
    // A strided layout (x y z nx ny nz per point) is checked the same way.
    std::vector<float> interleaved(std::size_t(kWidth) * kHeight * 6);
    for (std::size_t i = 0; i < std::size_t(kWidth) * kHeight; ++i) {
        for (std::size_t c = 0; c < 3; ++c) {
            interleaved[6 * i + c] = scene_.points[3 * i + c];
            interleaved[6 * i + 3 + c] = 0.3f * scene_.normals[3 * i + c];
        }
    }
    Segmenter seg(kWidth, kHeight, {}, "cpu");
    const std::string message = error_message(ErrorCode::invalid_argument, [&] {
        (void)seg.segment(CloudView{interleaved.data(), interleaved.data() + 3, kWidth, kHeight, 0, 6});
    });
    EXPECT_NE(message.find("pixel (0, 0), has length 0.3"), std::string::npos) << message;
}

TEST_F(GivenNormals, NearUnitNormalsAndNoNormalMarkersAreAccepted) {
    const Result exact = segment(scene_.normals);
    EXPECT_GT(exact.segment_count, 0u);
    // Off by a few 1e-3, as stored half floats or rounded text give them.
    std::vector<float> near = scene_.normals;
    for (std::size_t i = 0; i < near.size(); ++i) near[i] *= i % 2 == 0 ? 1.004f : 0.996f;
    EXPECT_GT(segment(near).segment_count, 0u);
    // One normal off unit length among unit ones is the contract's business (quantization clamps it), not an error.
    EXPECT_GT(segment(with_normal(5, 7, 0.0f, 0.0f, -2.0f)).segment_count, 0u);
    // (0, 0, 0), NaN and infinite components say "no normal": those pixels are invalid, the frame goes on.
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const float inf = std::numeric_limits<float>::infinity();
    for (const std::vector<float>& n : {with_normal(5, 7, 0, 0, 0), with_normal(5, 7, nan, 0, 1),
                                        with_normal(5, 7, inf, 0, 0), with_normal(5, 7, 0, -inf, nan)}) {
        const Result r = segment(n);
        EXPECT_EQ(r.labels[7 * kWidth + 5], 0u);
        EXPECT_GT(r.segment_count, 0u);
    }
}

// A unit that is not a length was once a preset in that unit, or a noise measurement of "the frame is too small".
TEST(ApiEdges, PresetsAndTheNoiseMeasureRefuseAUnitThatIsNotALength) {
    const synthetic::Scene scene = synthetic::generate(synthetic::SceneOptions{});
    CloudView view;
    view.points = scene.points.data();
    view.width = scene.width;
    view.height = scene.height;
    for (const double unit : {-1.0, 0.0, std::nan(""), std::numeric_limits<double>::infinity()}) {
        SCOPED_TRACE(unit);
        EXPECT_NE(error_message(ErrorCode::invalid_parameter, [&] { (void)sensor_preset(SensorKind::kinect_v1, unit); })
                      .find("unit_mm must be a finite number of millimetres > 0"),
                  std::string::npos);
        EXPECT_NE(
            error_message(ErrorCode::invalid_parameter, [&] { (void)measure_frame_noise(view, unit); }).find("unit_mm"),
            std::string::npos);
    }
    EXPECT_NO_THROW((void)measure_frame_noise(view, 1.0));
}

// PYRSEG_THREADS=two or 2x once gave a pool of every core without a word.
TEST(ApiEdges, AThreadCountThatIsNotOneIsAnError) {
    for (const char* bad : {"two", "2x", "0", "-3", "100000", " 2"}) {
        SCOPED_TRACE(bad);
        const test::ScopedEnv env("PYRSEG_THREADS", bad);
        EXPECT_NE(error_message(ErrorCode::invalid_parameter, [] { Segmenter s(32, 24, Params{}, "cpu"); })
                      .find("PYRSEG_THREADS='"),
                  std::string::npos);
    }
    for (const char* good : {"1", "3", ""}) {
        const test::ScopedEnv env("PYRSEG_THREADS", good);
        EXPECT_NO_THROW(Segmenter(32, 24, Params{}, "cpu")) << good;
    }
}

}  // namespace
}  // namespace pyrseg
