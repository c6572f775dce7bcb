// The merge (docs/algorithm.md section 5b): its parameters, its host constants, the pair table's size and the
// join test's exact comparison. The labels themselves are the conformance suite's (every backend against the
// reference) and the reference's own tests.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <random>
#include <string>

#include "backends/cpu/cpu_dialect.hpp"
#include "core/plan.hpp"
#include "pyrseg/error.hpp"
#include "pyrseg/segmenter.hpp"
#include "support/plan_error.hpp"

namespace pyrseg {
namespace {

using test::plan_error;

TEST(Merge, ParametersOutOfRangeAreRefusedByName) {
    Params p;
    p.merge = true;
    EXPECT_EQ(plan_error(p), "");
    const auto refused = [&](auto edit, const char* name) {
        Params q = p;
        edit(q);
        EXPECT_NE(plan_error(q).find(name), std::string::npos) << name;
    };
    refused([](Params& q) { q.merge_reach = 0; }, "merge_reach");
    refused([](Params& q) { q.merge_reach = kMaxMergeReach + 1; }, "merge_reach");
    refused([](Params& q) { q.merge_tolerance_mm = -1; }, "merge_tolerance_mm");
    refused([](Params& q) { q.merge_tolerance_mm = std::nan(""); }, "merge_tolerance_mm");
    refused([](Params& q) { q.merge_tolerance_per_m2 = INFINITY; }, "merge_tolerance_per_m2");
    refused([](Params& q) { q.merge_min_crossings = 0; }, "merge_min_crossings");
    refused([](Params& q) { q.merge_max_bad_share = 1.5; }, "merge_max_bad_share");
    refused([](Params& q) { q.merge_max_bad_share = std::nan(""); }, "merge_max_bad_share");
    refused([](Params& q) { q.merge_tolerance_mm = 1e300; }, "merge_tolerance");
}

TEST(Merge, HostConstantsFollowTheText) {
    Params p;
    p.merge = true;
    p.unit_mm = 1000.0;  // metres: e = 14 (2^14 >= 16000)
    p.merge_tolerance_mm = 1.5;
    p.merge_tolerance_per_m2 = 2.0;
    p.merge_max_bad_share = 0.1;
    const core::Thresholds t = core::compute_thresholds(p);
    EXPECT_EQ(t.merge_point_scale, 16384.0f);
    const double u = std::ldexp(1.0, 14 + 13);
    EXPECT_EQ(t.merge_tolerance_base, float((1.5 / 1000.0) * u));
    EXPECT_EQ(t.merge_tolerance_growth, float(((2.0 * 1e-6) * 1000.0) * u));
    EXPECT_EQ(t.merge_share, 26u);  // rint(25.6)
}

TEST(Merge, ThePairTableHoldsTwiceThePlanarBound) {
    Params p;
    EXPECT_EQ(core::make_plan(640, 480, p).merge_slots, 0u);  // no merge, no table
    p.merge = true;
    // Level M of 640 x 480 is 160 x 120: at most 3 * 19200 + 3 pairs, and the next power of two above twice that.
    EXPECT_EQ(core::make_plan(640, 480, p).merge_slots, 131072u);
    EXPECT_EQ(core::make_plan(8, 8, p).merge_slots, 0u);  // the small-image fallback has no merge
}

TEST(Merge, TheJoinTestComparesExactlyLikeSixtyFourBits) {
    std::mt19937 rng(7);
    const auto expected = [](std::uint32_t good, std::uint32_t bad, std::uint32_t min, std::uint32_t share) {
        const std::uint64_t total = std::uint64_t(good) + bad;
        return total >= min && std::uint64_t(bad) * 256 <= std::uint64_t(share) * total;
    };
    const std::uint32_t edges[] = {0u, 1u, 255u, 256u, 65535u, 65536u, 16777215u, 16777216u, 0x7fffffffu};
    for (std::uint32_t good : edges) {
        for (std::uint32_t bad : edges) {
            for (std::uint32_t share : {0u, 1u, 13u, 128u, 255u, 256u}) {
                EXPECT_EQ(cpu::pixel::pyr_merge_joins(good, bad, 1u, share) != 0, expected(good, bad, 1u, share))
                    << good << " " << bad << " " << share;
            }
        }
    }
    for (int i = 0; i < 100000; ++i) {
        const std::uint32_t good = rng() >> (rng() % 32);
        const std::uint32_t bad = rng() >> (rng() % 32);
        const std::uint32_t share = rng() % 257;
        const std::uint32_t min = rng() % 64;
        if (std::uint64_t(good) + bad > 0xffffffffu) continue;  // counts of one frame never wrap
        ASSERT_EQ(cpu::pixel::pyr_merge_joins(good, bad, min, share) != 0, expected(good, bad, min, share))
            << good << " " << bad << " " << share << " " << min;
    }
}

TEST(Merge, AMaskFrameIsRefusedWithTheMergeOn) {
    Params p;
    p.merge = true;
    Segmenter segmenter(32, 24, p, "cpu");
    std::vector<std::uint8_t> fillable(32 * 24, 1);
    MaskView mask{};
    mask.fillable = fillable.data();
    mask.width = 32;
    mask.height = 24;
    try {
        Result out;
        segmenter.segment_mask(mask, out);
        FAIL() << "a mask frame with the merge on was segmented";
    } catch (const Error& e) {
        EXPECT_EQ(e.code(), ErrorCode::invalid_parameter);
        EXPECT_NE(std::string(e.what()).find("merge"), std::string::npos) << e.what();
    }
}

}  // namespace
}  // namespace pyrseg
