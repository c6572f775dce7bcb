// The CPU backend's fused front end (backends/cpu/points_to_mask.hpp): normals, quantize and metric over bands of
// rows in per-thread windows. The window slides (a chunk taller than its window), chunks meet (each recomputes
// its neighbours' rows), and what the frame keeps depends on the outputs asked for; each case against the
// reference, at two thread counts, on every Highway target this CPU runs.
#include <gtest/gtest.h>

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
    int width;
    int height;
    bool given_normals;
};

class CpuPointsToMask : public ::testing::TestWithParam<std::string> {};

TEST_P(CpuPointsToMask, MatchesTheReferenceWhateverTheWindowsAndOutputs) {
    const ScopedEnv simd("PYRSEG_CPU_SIMD", GetParam());
    // Windows are about 512 KiB: 4096 wide holds 10 rows (chunks of 19 or more rows slide), 11000 wide the
    // minimum of 4 (it slides every other row); 64 wide holds more rows than the image.
    const Case cases[] = {{4096, 150, false}, {4096, 150, true}, {11000, 40, false}, {64, 300, false}, {300, 2, false}};
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
        const float* normals = k.given_normals ? scene.normals.data() : nullptr;
        const pyrseg_ref::Output ref =
            pyrseg_ref::segment(scene.points.data(), normals, k.width, k.height, to_reference(Params{}));
        ASSERT_TRUE(ref.ok) << ref.error;
        segments += ref.segment_count;
        for (const int threads : {1, 3}) {  // one chunk slides its window all the way; three meet unevenly
            const ScopedEnv env("PYRSEG_THREADS", std::to_string(threads));
            for (const Outputs& outputs : {mask_only, with_normals, with_stats}) {
                SCOPED_TRACE(std::to_string(k.width) + "x" + std::to_string(k.height) +
                             (k.given_normals ? " given" : " estimated") + ", " + std::to_string(threads) +
                             " threads, normals " + std::to_string(int(outputs.normals)) + ", stats " +
                             std::to_string(int(outputs.segment_stats)));
                Segmenter segmenter(k.width, k.height, {}, "cpu", outputs);
                Result r;
                for (int frame = 0; frame < 2; ++frame) {  // the second frame reuses the windows
                    segmenter.segment(CloudView{scene.points.data(), normals, k.width, k.height}, r);
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
