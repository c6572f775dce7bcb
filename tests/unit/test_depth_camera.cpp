// check_depth_camera (pyrseg/depth.hpp): the depth-scale and intrinsics mistakes that once segmented a frame into one
// segment or none without a word are errors naming the value and the fix; legal but unusual values are warnings;
// the Segmenter checks the same way (io::depth_to_cloud too: tests/io/test_depth.cpp).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

#include "pyrseg/depth.hpp"
#include "pyrseg/error.hpp"
#include "pyrseg/segmenter.hpp"

namespace pyrseg {
namespace {

// A RealSense D435's 640 x 480 depth frame of a wall at 0.8 m in millimetres (its intrinsics, shared/data/realsense).
struct Frame {
    std::vector<std::uint16_t> samples = std::vector<std::uint16_t>(640 * 480, 800);
    DepthView view() const {
        return DepthView{samples.data(), DepthFormat::u16, 640, 480, 0, 0.001, 612.937, 613.173, 322.549, 248.158};
    }
};

std::string refusal(const DepthView& v) {
    try {
        (void)check_depth_camera(v);
    } catch (const Error& e) {
        EXPECT_EQ(e.code(), ErrorCode::invalid_parameter) << e.what();
        return e.what();
    }
    return "no error";
}

bool has(const std::string& text, const std::string& words) {
    return text.find(words) != std::string::npos;
}

TEST(DepthCamera, AGoodFrameHasNoWarningAndItsMedianDepth) {
    const Frame f;
    const DepthCameraCheck c = check_depth_camera(f.view());
    EXPECT_DOUBLE_EQ(c.median_depth_m, 0.8);
    EXPECT_TRUE(c.warnings.empty()) << c.warnings.front();
}

TEST(DepthCamera, AWrongDepthScaleIsRefusedWithTheScaleThatFits) {
    const Frame f;
    for (const double wrong : {1.0, 1000.0}) {
        DepthView v = f.view();
        v.metres_per_unit = wrong;
        const std::string e = refusal(v);
        EXPECT_TRUE(has(e, "median depth is")) << e;
        EXPECT_TRUE(has(e, "outside any depth sensor's range (0.05 to 100 m)")) << e;
        EXPECT_TRUE(has(e, "metres_per_unit 0.001 makes it 0.8 m")) << e;
    }
}

TEST(DepthCamera, IntrinsicsInTheWrongOrderAreRefusedSayingTheOrder) {
    const Frame f;
    DepthView v = f.view();
    v.fx = 322.549;  // cx, cy, fx, fy
    v.fy = 248.158;
    v.cx = 612.937;
    v.cy = 613.173;
    const std::string e = refusal(v);
    EXPECT_TRUE(has(e, "principal point (cx 612.937, cy 613.173) lies outside the 640 x 480 image")) << e;
    EXPECT_TRUE(has(e, "the order is fx, fy, cx, cy")) << e;
    // A depth-native D435 stream (848 x 480): swapped, the principal point stays inside the image, but the pixels
    // would be far from square and the principal point far from the centre, while read as cx, cy, fx, fy all is right.
    const std::vector<std::uint16_t> wide(848 * 480, 800);
    const DepthView swapped{wide.data(), DepthFormat::u16, 848, 480, 0, 0.001, 424.1, 239.8, 421.3, 421.0};
    EXPECT_TRUE(has(refusal(swapped), "are no camera's: the intrinsics look given as cx, cy, fx, fy"))
        << refusal(swapped);
    const DepthView right{wide.data(), DepthFormat::u16, 848, 480, 0, 0.001, 421.3, 421.0, 424.1, 239.8};
    EXPECT_TRUE(check_depth_camera(right).warnings.empty());
    // A square image at 90 degrees has fx = cx and fy = cy: either order is a camera, and neither is refused.
    const std::vector<std::uint16_t> square(480 * 480, 800);
    EXPECT_NO_THROW(
        (void)check_depth_camera(DepthView{square.data(), DepthFormat::u16, 480, 480, 0, 0.001, 240, 240, 240, 240}));
    v = f.view();
    v.cx = -10;
    EXPECT_TRUE(has(refusal(v), "lies outside the 640 x 480 image: cx and cy are in pixels")) << refusal(v);
}

TEST(DepthCamera, FocalLengthsNoPinholeCameraHasAreRefused) {
    const Frame f;
    for (const double fx : {1e-300, 1.0, 1e300}) {
        DepthView v = f.view();
        v.fx = fx;
        const std::string e = refusal(v);
        EXPECT_TRUE(has(e, "fx ")) << e;
        EXPECT_TRUE(has(e, "field of view")) << e;
    }
    DepthView v = f.view();
    v.fy = 1e-300;
    EXPECT_TRUE(has(refusal(v), "fy 1e-300 gives a field of view of 180 degrees down 480 pixels")) << refusal(v);
}

TEST(DepthCamera, TheD405sScaleIsLegalAndAMillimetreFrameReadWithItAWarning) {
    Frame d405;  // 0.1 mm units: 3000 is 0.3 m
    std::fill(d405.samples.begin(), d405.samples.end(), std::uint16_t{3000});
    DepthView v = d405.view();
    v.metres_per_unit = 0.0001;
    DepthCameraCheck c = check_depth_camera(v);
    EXPECT_DOUBLE_EQ(c.median_depth_m, 0.3);
    EXPECT_TRUE(c.warnings.empty());
    const Frame mm;  // 800 mm read as 0.1 mm units: 0.08 m, possible, but closer than usual
    v = mm.view();
    v.metres_per_unit = 0.0001;
    c = check_depth_camera(v);
    ASSERT_EQ(c.warnings.size(), 1u);
    EXPECT_TRUE(has(c.warnings[0], "the median depth is 0.08 m with metres_per_unit 0.0001")) << c.warnings[0];
}

TEST(DepthCamera, PixelsFarFromSquareAndAnOffCentrePrincipalPointAreWarnings) {
    const Frame f;
    DepthView v = f.view();
    v.fx = 1.5 * v.fy;
    DepthCameraCheck c = check_depth_camera(v);
    ASSERT_EQ(c.warnings.size(), 1u);
    EXPECT_TRUE(has(c.warnings[0], "fx / fy is 1.5")) << c.warnings[0];
    v = f.view();
    v.cx = 600;  // a crop's principal point, say
    c = check_depth_camera(v);
    ASSERT_EQ(c.warnings.size(), 1u);
    EXPECT_TRUE(has(c.warnings[0], "is far from the centre of the 640 x 480 image")) << c.warnings[0];
}

TEST(DepthCamera, FramesWithoutSamplesOrWithTooFewAreNotMeasured) {
    Frame empty;
    std::fill(empty.samples.begin(), empty.samples.end(), std::uint16_t{0});
    DepthView v = empty.view();
    v.metres_per_unit = 1.0;  // no sample to say it is wrong
    EXPECT_EQ(check_depth_camera(v).median_depth_m, 0.0);
    v.depth = nullptr;  // a device frame: the intrinsics only
    EXPECT_EQ(check_depth_camera(v).median_depth_m, 0.0);
    v.fx = 1e-300;
    EXPECT_TRUE(has(refusal(v), "field of view")) << refusal(v);
}

TEST(DepthCamera, TheSegmenterRefusesAWrongScaleUntilAFrameWithDataPasses) {
    const Frame good;
    Frame covered;
    std::fill(covered.samples.begin(), covered.samples.end(), std::uint16_t{0});
    Segmenter segmenter(640, 480, Params{}, "cpu");
    DepthView wrong = good.view();
    wrong.metres_per_unit = 1.0;
    EXPECT_THROW((void)segmenter.segment(wrong), Error);
    // A covered lens first says nothing about the scale: the next frame with data is still checked.
    DepthView wrong_covered = covered.view();
    wrong_covered.metres_per_unit = 1.0;
    EXPECT_NO_THROW((void)segmenter.segment(wrong_covered));
    EXPECT_THROW((void)segmenter.segment(wrong), Error);
    // Once a frame has passed, the camera is not checked again: a stream's later content cannot stop it.
    EXPECT_NO_THROW((void)segmenter.segment(good.view()));
    EXPECT_NO_THROW((void)segmenter.segment(covered.view()));
    DepthView swapped = good.view();
    std::swap(swapped.fx, swapped.cx);
    std::swap(swapped.fy, swapped.cy);
    EXPECT_THROW((void)segmenter.segment(swapped), Error);
}

}  // namespace
}  // namespace pyrseg
