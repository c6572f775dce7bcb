// core/plan: level geometry, label offsets, thresholds and parameter validation.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>

#include "core/plan.hpp"
#include "pyrseg/error.hpp"

namespace pyrseg::core {
namespace {

TEST(Plan, LevelCountIsOnePlusCeilLog2OfTheLargerSide) {
    EXPECT_EQ(make_plan(1, 1, {}).level_count, 1);
    EXPECT_EQ(make_plan(2, 1, {}).level_count, 2);
    EXPECT_EQ(make_plan(8, 8, {}).level_count, 4);
    EXPECT_EQ(make_plan(9, 9, {}).level_count, 5);
    EXPECT_EQ(make_plan(640, 480, {}).level_count, 11);
    EXPECT_EQ(make_plan(2064, 1544, {}).level_count, 13);
}

TEST(Plan, LevelsHalveRoundingUpAndOffsetsAccumulate) {
    const Plan p = make_plan(9, 5, {});
    ASSERT_EQ(p.level_count, 5);
    const unsigned expected[][2] = {{1, 1}, {2, 1}, {3, 2}, {5, 3}, {9, 5}};
    unsigned offset = 0;
    for (int k = 1; k <= 5; ++k) {
        EXPECT_EQ(p.level(k).width, expected[k - 1][0]) << "level " << k;
        EXPECT_EQ(p.level(k).height, expected[k - 1][1]) << "level " << k;
        EXPECT_EQ(p.level(k).offset, offset) << "level " << k;
        offset += expected[k - 1][0] * expected[k - 1][1];
    }
    EXPECT_EQ(p.total_texels, offset);
    // N = 5, M = 3, U = 1: old labels are those of level 1 only.
    EXPECT_EQ(p.bridge_level, 3);
    EXPECT_EQ(p.unjoinable_level, 1);
    EXPECT_EQ(p.old_label_max, 1u);
    EXPECT_EQ(p.max_label, 1u + 2u + 6u);
    EXPECT_FALSE(p.small_image);
}

TEST(Plan, SmallImagesFallBackWithDefaultParameters) {
    EXPECT_TRUE(make_plan(8, 8, {}).small_image);
    EXPECT_TRUE(make_plan(1, 7, {}).small_image);
    EXPECT_FALSE(make_plan(9, 1, {}).small_image);
    EXPECT_EQ(make_plan(8, 8, {}).max_label, 64u);
}

TEST(Plan, ExplicitBridgeParametersThatDoNotFitAreRejected) {
    Params p;
    p.bridge_levels = 2;
    EXPECT_THROW((void)make_plan(8, 8, p), Error);
    p.bridge_levels = 3;
    p.unjoinable_gap = 2;
    EXPECT_THROW((void)make_plan(9, 9, p), Error);  // N = 5: U = 0
    p.bridge_levels = 2;
    EXPECT_NO_THROW((void)make_plan(9, 9, p));
    try {
        p.bridge_levels = 12;
        (void)make_plan(640, 480, p);
        FAIL() << "expected an error";
    } catch (const Error& e) {
        EXPECT_EQ(e.code(), ErrorCode::invalid_parameter);
        EXPECT_NE(std::string(e.what()).find("bridge_levels"), std::string::npos) << e.what();
    }
    p.bridge_levels = 0;
    EXPECT_THROW((void)make_plan(640, 480, p), Error);
    p.bridge_levels = 2;
    p.unjoinable_gap = 0;
    EXPECT_THROW((void)make_plan(640, 480, p), Error);
}

TEST(Plan, CurvatureThresholdIsFloorOfCosineTimes2To26) {
    Params p;
    EXPECT_EQ(compute_thresholds(p).curvature, std::int32_t(std::floor(std::cos(0.25) * 67108864.0)));
    p.ct = 0.0;
    EXPECT_EQ(compute_thresholds(p).curvature, 1 << 26);
    p.ct = std::numbers::pi / 2;
    EXPECT_EQ(compute_thresholds(p).curvature, std::int32_t(std::floor(std::cos(std::numbers::pi / 2) * 67108864.0)));
    p.ct = std::numbers::pi;
    EXPECT_EQ(compute_thresholds(p).curvature, -(1 << 28));
    EXPECT_LE(std::int64_t(8) * compute_thresholds(p).curvature, std::int64_t(8) * -3 * (1 << 26));
}

TEST(Plan, DepthThresholdIsInInputUnits) {
    Params p;
    p.dt = 10.0;
    p.unit_mm = 1000.0;
    EXPECT_EQ(compute_thresholds(p).depth, 0.01f);
    p.dt = std::numeric_limits<double>::infinity();
    EXPECT_TRUE(std::isinf(compute_thresholds(p).depth));
}

TEST(Plan, BadParametersNameTheParameter) {
    const auto expect_named = [](Params p, const char* name) {
        try {
            (void)make_plan(64, 64, p);
            ADD_FAILURE() << "expected an error naming " << name;
        } catch (const Error& e) {
            EXPECT_EQ(e.code(), ErrorCode::invalid_parameter);
            EXPECT_NE(std::string(e.what()).find(name), std::string::npos) << e.what();
        }
    };
    Params p;
    p.ct = -0.1;
    expect_named(p, "ct");
    p = {};
    p.ct = std::numeric_limits<double>::quiet_NaN();
    expect_named(p, "ct");
    p = {};
    p.dt = -1;
    expect_named(p, "dt");
    p = {};
    p.dt = std::numeric_limits<double>::quiet_NaN();
    expect_named(p, "dt");
    p = {};
    p.unit_mm = 0;
    expect_named(p, "unit_mm");
    p = {};
    p.unit_mm = std::numeric_limits<double>::infinity();
    expect_named(p, "unit_mm");
    p = {};
    p.normal_radius = 0;
    expect_named(p, "normal_radius");
}

TEST(Plan, EmptyAndHugeImagesAreRejectedBeforeAllocating) {
    EXPECT_THROW((void)make_plan(0, 0, {}), Error);
    EXPECT_THROW((void)make_plan(-5, 10, {}), Error);
    try {
        (void)make_plan(70000, 70000, {});  // 4.9e9 pixels: more than 32-bit labels address
        FAIL();
    } catch (const Error& e) {
        EXPECT_EQ(e.code(), ErrorCode::image_too_large);
    }
    try {
        (void)make_plan(60000, 60000, {});  // 3.6e9 pixels, but the pyramid needs 4.8e9 texels
        FAIL();
    } catch (const Error& e) {
        EXPECT_EQ(e.code(), ErrorCode::image_too_large);
    }
    EXPECT_NO_THROW((void)make_plan(40000, 40000, {}));  // plans are cheap: nothing is allocated
}

}  // namespace
}  // namespace pyrseg::core
