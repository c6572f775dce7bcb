// The CPU backend's fused front end (backends/cpu/points_to_mask.hpp): normals, quantize and metric over bands of
// rows in per-thread windows. Chunks meet (each recomputes its neighbours' rows, or takes those its thread's last
// chunk made), the point rows are kept in a ring (or, too wide for it, three rows split again for each normal), the
// windows still hold another frame's rows, clouds come packed or in PCL's padded layout, and what the frame keeps
// depends on the outputs asked for; each case against the reference, at two thread counts, on every Highway target
// this CPU runs.
#include <gtest/gtest.h>

#include <cstddef>
#include <cstdlib>
#include <string>
#include <vector>

#include "pyrseg/segmenter.hpp"
#include "pyrseg/synthetic.hpp"
#include "support/cpu_targets.hpp"
#include "support/oracle.hpp"

namespace pyrseg {
namespace {

using test::same_bytes;
using test::same_segments;
using test::ScopedEnv;
using test::target_names;
using test::to_reference;

struct Case {
    int width = 0;
    int height = 0;
    bool given_normals = false;
    int radius = kDefaultNormalRadius;
    int point_stride = 3;  // floats a point (4: PCL's padded points)
    int row_pad = 0;       // points of padding after each row
};

// Packed points (3 floats each) in a case's layout, the padding filled with junk.
std::vector<float> lay_out(const std::vector<float>& packed, const Case& k) {
    const std::size_t pf = std::size_t(k.point_stride);
    const std::size_t row = (std::size_t(k.width) + std::size_t(k.row_pad)) * pf;
    std::vector<float> out(row * std::size_t(k.height), -777.0f);
    for (std::size_t y = 0; y < std::size_t(k.height); ++y) {
        for (std::size_t x = 0; x < std::size_t(k.width); ++x) {
            for (std::size_t c = 0; c < 3; ++c) {
                out[y * row + x * pf + c] = packed[3 * (y * std::size_t(k.width) + x) + c];
            }
        }
    }
    return out;
}

class CpuPointsToMask : public ::testing::TestWithParam<std::string> {};

TEST_P(CpuPointsToMask, MatchesTheReferenceWhateverTheWindowsAndOutputs) {
    const ScopedEnv simd("PYRSEG_CPU_SIMD", GetParam());
    // The point rows' ring holds 2r + 1 rows up to about 1 MiB: 4096 and 11000 wide with radius 2 keep their 5
    // rows, 4096 wide with radius 10 splits three rows for each row of normals; radius 40 keeps more rows than the
    // image has.
    const Case cases[] = {{4096, 150, false},       {4096, 150, true},         {11000, 40, false},
                          {64, 300, false},         {300, 2, false},           {4096, 60, false, 10, 4, 3},
                          {640, 90, true, 2, 4, 2}, {640, 90, false, 1, 4, 0}, {131, 70, false, 40}};
    Outputs mask_only;
    mask_only.fillable_mask = true;
    Outputs with_normals = mask_only;
    with_normals.normals = true;
    Outputs with_stats = mask_only;
    with_stats.segment_stats = true;
    std::uint32_t seed = 5;
    std::uint32_t segments = 0;
    for (const Case& k : cases) {
        synthetic::SceneOptions o;
        o.width = k.width;
        o.height = k.height;
        o.seed = seed++;
        o.object_count = 12;
        const synthetic::Scene scene = synthetic::generate(o);
        o.seed += 1000;
        const synthetic::Scene before = synthetic::generate(o);  // a frame before it, in the same windows
        Params params;
        params.normal_radius = k.radius;
        const pyrseg_ref::Output ref =
            pyrseg_ref::segment(scene.points.data(), k.given_normals ? scene.normals.data() : nullptr, k.width,
                                k.height, to_reference(params));
        ASSERT_TRUE(ref.ok) << ref.error;
        segments += ref.segment_count;
        const std::vector<float> points = lay_out(scene.points, k);
        const std::vector<float> normals = k.given_normals ? lay_out(scene.normals, k) : std::vector<float>();
        const std::vector<float> points_before = lay_out(before.points, k);
        const std::vector<float> normals_before = k.given_normals ? lay_out(before.normals, k) : std::vector<float>();
        CloudView view{points.data(), k.given_normals ? normals.data() : nullptr, k.width, k.height};
        view.point_stride = k.point_stride;
        view.row_stride = std::size_t(k.width) + std::size_t(k.row_pad);
        CloudView view_before = view;
        view_before.points = points_before.data();
        view_before.normals = k.given_normals ? normals_before.data() : nullptr;
        for (const int threads : {1, 3}) {  // one chunk makes the whole frame in its window; three meet unevenly
            const ScopedEnv env("PYRSEG_THREADS", std::to_string(threads));
            for (const Outputs& outputs : {mask_only, with_normals, with_stats}) {
                SCOPED_TRACE(std::to_string(k.width) + "x" + std::to_string(k.height) +
                             (k.given_normals ? " given" : " estimated") + ", radius " + std::to_string(k.radius) +
                             ", point stride " + std::to_string(k.point_stride) + ", " + std::to_string(threads) +
                             " threads, normals " + std::to_string(int(outputs.normals)) + ", stats " +
                             std::to_string(int(outputs.segment_stats)));
                Segmenter segmenter(k.width, k.height, params, "cpu", outputs);
                Result r;
                // The second frame's windows hold the rows of another frame: none of them may be taken.
                for (const CloudView* frame : {&view_before, &view}) {
                    segmenter.segment(*frame, r);
                    if (frame != &view) continue;
                    EXPECT_TRUE(same_bytes("fillable mask", r.fillable_mask, ref.fillable, k.width));
                    EXPECT_TRUE(same_bytes("labels", r.labels, ref.labels, k.width));
                    if (outputs.normals) {
                        EXPECT_TRUE(same_bytes("normals", r.normals, ref.normals, k.width, 3));
                    }
                    if (outputs.segment_stats) {
                        EXPECT_TRUE(same_segments(r.segments, ref.segments));
                    }
                }
                if (::testing::Test::HasFailure()) return;
            }
        }
    }
    EXPECT_GT(segments, 20u) << "the frames must have segments for the labels to say much";
}

INSTANTIATE_TEST_SUITE_P(Targets, CpuPointsToMask, ::testing::ValuesIn(target_names()),
                         [](const ::testing::TestParamInfo<std::string>& param_info) { return param_info.param; });

}  // namespace
}  // namespace pyrseg
