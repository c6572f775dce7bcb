// Step 6c's depth test (Params::edge_max_depth_step, docs/algorithm.md section 5): its range, its host constant, the
// presets' value and the refusal of mask frames. The labels themselves are the conformance suite's (EdgeDepthStep,
// RobustScenes: every backend against the reference) and the reference's own tests.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "core/plan.hpp"
#include "pyrseg/error.hpp"
#include "pyrseg/presets.hpp"
#include "pyrseg/segmenter.hpp"
#include "support/plan_error.hpp"

namespace pyrseg {
namespace {

using test::plan_error;

TEST(EdgeDepthStep, OutOfRangeIsRefusedByName) {
    Params p;
    p.edge_rounds = 4;
    for (const double c : {-1e-3, std::nan(""), std::numeric_limits<double>::infinity(), 0.5e-6, 1.0 + 1e-9, 2.0}) {
        p.edge_max_depth_step = c;
        EXPECT_NE(plan_error(p).find("edge_max_depth_step"), std::string::npos) << c;
    }
    for (const double c : {0.0, -0.0, kMinEdgeMaxDepthStep, 0.02, 1.0}) {
        p.edge_max_depth_step = c;
        EXPECT_EQ(plan_error(p), "") << c;
    }
}

TEST(EdgeDepthStep, TheShareReachesTheDevicesAsOneFloat) {
    Params p;
    p.edge_max_depth_step = 0.02;
    EXPECT_EQ(core::compute_thresholds(p).edge_depth_step, 0.02f);
    p.edge_max_depth_step = 0.0;
    EXPECT_EQ(core::compute_thresholds(p).edge_depth_step, 0.0f);
}

TEST(EdgeDepthStep, ConsumerPresetsTestDepthsTheScannerPresetDoesNot) {
    for (const SensorKind kind : sensor_kinds()) {
        const Params p = sensor_preset(kind);
        const bool consumer = kind != SensorKind::structured_light;
        EXPECT_EQ(p.edge_max_depth_step, consumer ? 0.02 : 0.0) << sensor_kind_name(kind);
        EXPECT_EQ(uses_edge_depth_step(p), consumer) << sensor_kind_name(kind);
    }
}

TEST(EdgeDepthStep, AMaskIsRefusedOnlyWhenTheTestWouldBeUsed) {
    constexpr int kW = 32;
    constexpr int kH = 24;
    const std::vector<unsigned char> fillable(std::size_t(kW) * kH, 1);
    MaskView mask;
    mask.fillable = fillable.data();
    mask.width = kW;
    mask.height = kH;
    const auto refused = [&](const Params& p) {
        Segmenter segmenter(kW, kH, p, "cpu");
        Result result;
        try {
            segmenter.segment_mask(mask, result);
        } catch (const Error& e) {
            EXPECT_EQ(e.code(), ErrorCode::invalid_parameter);
            EXPECT_NE(std::string(e.what()).find("edge_max_depth_step"), std::string::npos) << e.what();
            return true;
        }
        return false;
    };
    Params p;
    p.edge_rounds = 3;
    p.edge_max_depth_step = 0.02;
    EXPECT_TRUE(refused(p));
    p.edge_rounds = 1;  // round 1 has no test
    EXPECT_FALSE(refused(p));
    p.edge_rounds = 3;
    p.label_edges = false;
    EXPECT_FALSE(refused(p));
    p.label_edges = true;
    p.edge_max_depth_step = 0.0;
    EXPECT_FALSE(refused(p));
}

}  // namespace
}  // namespace pyrseg
