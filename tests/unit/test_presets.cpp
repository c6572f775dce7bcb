// Sensor presets and the frame-noise measurement behind `--sensor auto` and the CLI's hint.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "core/plan.hpp"
#include "pyrseg/error.hpp"
#include "pyrseg/presets.hpp"
#include "pyrseg/synthetic.hpp"

namespace pyrseg {
namespace {

TEST(Presets, NamesRoundTripAndUnknownNamesAreNone) {
    for (SensorKind k : sensor_kinds()) {
        EXPECT_EQ(sensor_kind_from_name(sensor_kind_name(k)), k);
        EXPECT_NE(std::string(sensor_kind_summary(k)), "");
    }
    EXPECT_FALSE(sensor_kind_from_name("kinect"));
    EXPECT_FALSE(sensor_kind_from_name(""));
}

TEST(Presets, StructuredLightIsTheContractsDefaultsAndConsumerPresetsAreRobust) {
    const Params d;
    const Params s = sensor_preset(SensorKind::structured_light, 1000.0);
    EXPECT_EQ(s.metric, Metric::paper);
    EXPECT_EQ(s.ct, d.ct);
    EXPECT_EQ(s.dt, d.dt);
    EXPECT_EQ(s.normal_radius, d.normal_radius);
    EXPECT_EQ(s.unit_mm, 1000.0);
    for (SensorKind k : {SensorKind::kinect_v1, SensorKind::realsense_d435, SensorKind::azure_kinect}) {
        const Params p = sensor_preset(k);
        EXPECT_EQ(p.metric, Metric::robust) << sensor_kind_name(k);
        EXPECT_GT(p.dt_per_m2, 0.0) << sensor_kind_name(k);
        // Every preset is a valid plan.
        EXPECT_NO_THROW((void)core::make_plan(640, 480, p)) << sensor_kind_name(k);
    }
}

TEST(Presets, RobustParametersAreValidatedAndBelongToTheRobustMetric) {
    Params p;
    p.normal_window = 4;  // paper metric: must stay at the default
    EXPECT_THROW((void)core::make_plan(64, 48, p), Error);
    p.metric = Metric::robust;
    EXPECT_NO_THROW((void)core::make_plan(64, 48, p));
    for (int bad : {0, kMaxNormalWindow + 1}) {
        Params q = p;
        q.normal_window = bad;
        EXPECT_THROW((void)core::make_plan(64, 48, q), Error) << bad;
    }
    for (int bad : {0, kMaxCurvatureStride + 1}) {
        Params q = p;
        q.curvature_stride = bad;
        EXPECT_THROW((void)core::make_plan(64, 48, q), Error) << bad;
    }
    for (double bad : {-1.0, std::nan(""), double(INFINITY), 1e300}) {
        Params q = p;
        q.dt_per_m2 = bad;
        EXPECT_THROW((void)core::make_plan(64, 48, q), Error);
        q = p;
        q.ct_growth_per_m2 = bad;
        EXPECT_THROW((void)core::make_plan(64, 48, q), Error);
    }
}

TEST(Presets, RobustThresholdsFollowTheText) {
    Params p = sensor_preset(SensorKind::kinect_v1, 1000.0);  // metres
    const core::Thresholds t = core::compute_thresholds(p);
    const double c0 = 1.0 - std::cos(p.ct);
    EXPECT_EQ(t.curvature_base, float(c0 * 67108864.0));
    EXPECT_EQ(t.curvature_growth, float(c0 * 67108864.0 * p.ct_growth_per_m2 * 1.0));  // (1000 mm / 1000)^2 = 1
    EXPECT_EQ(t.depth_growth, float(p.dt_per_m2 * 1e-6 * 1000.0));
    EXPECT_EQ(t.point_scale, 16384.0f);  // 2^14 >= 16 * 1000
    p.ct = 4.0;                          // >= pi: always passes
    EXPECT_EQ(core::compute_thresholds(p).curvature_base, 268435456.0f);
    EXPECT_EQ(core::compute_thresholds(p).curvature_growth, 0.0f);
}

CloudView view_of(const synthetic::Scene& s) {
    CloudView v;
    v.points = s.points.data();
    v.width = s.width;
    v.height = s.height;
    return v;
}

TEST(FrameNoise, ScannerFramesKeepTheDefaultsAndConsumerFramesAreRecognised) {
    synthetic::SceneOptions o;
    o.width = 320;
    o.height = 240;
    const synthetic::Scene scanner = synthetic::generate(o);
    const FrameNoise quiet = measure_frame_noise(view_of(scanner), 1.0);
    EXPECT_GT(quiet.samples, 1000u);
    EXPECT_EQ(quiet.suggested, SensorKind::structured_light) << quiet.reason;
    EXPECT_NEAR(quiet.median_depth_mm, 1150.0, 250.0);
    for (synthetic::Sensor s :
         {synthetic::Sensor::kinect_v1, synthetic::Sensor::realsense_d435, synthetic::Sensor::azure_kinect}) {
        o.sensor = s;
        o.camera_distance_mm = 2000;
        const FrameNoise noisy = measure_frame_noise(view_of(synthetic::generate(o)), 1.0);
        EXPECT_NE(noisy.suggested, SensorKind::structured_light) << synthetic::sensor_name(s) << ": " << noisy.reason;
    }
}

TEST(FrameNoise, EmptyOrTinyFramesAreTooSmallToJudge) {
    EXPECT_EQ(measure_frame_noise(CloudView{}, 1.0).samples, 0u);
    float points[9] = {0, 0, 1000, 0, 0, 1000, 0, 0, 1000};
    CloudView v;
    v.points = points;
    v.width = 3;
    v.height = 1;
    const FrameNoise n = measure_frame_noise(v, 1.0);
    EXPECT_EQ(n.suggested, SensorKind::structured_light);
    EXPECT_NE(n.reason.find("too few"), std::string::npos) << n.reason;
}

}  // namespace
}  // namespace pyrseg
