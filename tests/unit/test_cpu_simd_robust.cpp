// The robust metric's vector rows (backends/cpu/simd/robust_rows-inl.h) on every Highway target this CPU runs: the
// texels, the normals from window sums and the fillable test give the words of the shared scalar functions
// (shaders/pyr_robust.h) on clouds with holes, depth jumps and special values, at every window and stride; and whole
// segmentations with the robust metric give the bytes of the scalar path and of the independent reference.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "backends/cpu/cpu_dialect.hpp"
#include "backends/cpu/robust_windows.hpp"
#include "backends/cpu/simd/cpu_simd.hpp"
#include "backends/cpu/thread_pool.hpp"
#include "pyrseg/presets.hpp"
#include "pyrseg/segmenter.hpp"
#include "pyrseg/synthetic.hpp"
#include "support/cpu_targets.hpp"
#include "support/oracle.hpp"
#include "support/test_frame.hpp"

namespace pyrseg::test {
namespace {

namespace simd = ::pyrseg::cpu::simd;
namespace pixel = ::pyrseg::cpu::pixel;
using ::pyrseg::cpu::kQuantWords;
using ::pyrseg::cpu::PassContext;
using ::pyrseg::cpu::RobustTexelPlanes;

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();

struct Size {
    int w, h;
};
const Size kSizes[] = {{1, 1},  {2, 3},  {5, 7},   {9, 9},   {16, 5},  {17, 6},
                       {33, 8}, {40, 3}, {65, 11}, {67, 45}, {131, 9}, {17, 40}};

// A bumpy surface with two depth steps (so that some windows hold pixels of both sides), holes (NaN or z <= 0),
// and a few special components; each point point_floats floats apart, rows padded by `pad` points of junk.
struct Cloud {
    std::vector<float> floats;
    std::size_t point_floats = 3;
    std::size_t row_floats = 0;
};

Cloud make_cloud(int w, int h, std::size_t point_floats, std::size_t pad, float scale, std::uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> noise(-0.6f, 0.6f);
    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
    Cloud c;
    c.point_floats = point_floats;
    c.row_floats = (std::size_t(w) + pad) * point_floats;
    c.floats.assign(c.row_floats * std::size_t(h), -555.0f);
    const float specials[] = {kNaN, kInf, -kInf, 0.0f, -0.0f, -3.0f, 3e38f, 1e-40f};
    for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) {
            float* p = &c.floats[std::size_t(y) * c.row_floats + std::size_t(x) * point_floats];
            const float step = (x > w / 3 ? 90.0f : 0.0f) + (y > h / 2 ? 45.0f : 0.0f);
            const float z = 1200.0f + 30.0f * std::sin(float(x) * 0.3f) * std::cos(float(y) * 0.2f) + step + noise(rng);
            p[0] = (float(x) - float(w) / 2) * 1.5f * scale;
            p[1] = (float(y) - float(h) / 2) * 1.5f * scale;
            p[2] = z * scale;
            const float u = unit(rng);
            if (u < 0.04f) p[2] = kNaN;
            if (u > 0.98f) p[rng() % 3] = specials[rng() % std::size(specials)];
        }
    }
    return c;
}

// The texels as 8 planes over one buffer.
struct Texels {
    std::vector<std::int32_t> words;
    RobustTexelPlanes planes;

    explicit Texels(std::size_t pixels) : words(8 * pixels, 0x5a5a5a5a) {
        planes.gz = words.data();
        planes.tangents = reinterpret_cast<std::uint32_t*>(words.data() + pixels);
        for (std::size_t k = 0; k < 3; ++k) {
            planes.th[k] = words.data() + (2 + k) * pixels;
            planes.tv[k] = words.data() + (5 + k) * pixels;
        }
    }
};

PassContext context_of(const Cloud& cloud) {
    PassContext c;
    c.points = cloud.floats.data();
    c.point_floats = cloud.point_floats;
    c.row_floats = cloud.row_floats;
    return c;
}

// Fixed-point scales as the plan makes them (exact powers of two), down to those that clamp most coordinates.
const float kScales[] = {16.0f, 1.0f, 0x1p-10f, 0x1p12f, 0x1p20f};

class CpuSimdRobustRows : public ::testing::TestWithParam<std::string> {};

TEST_P(CpuSimdRobustRows, TexelsMatchTheSharedFunction) {
    const simd::VectorRows& k = rows_named(GetParam());
    std::uint32_t seed = 1;
    std::size_t with_both = 0;
    std::size_t pixels = 0;
    for (const Size s : kSizes) {
        for (const std::uint32_t r : {1u, 2u, 3u, 5u, 9u}) {
            for (const std::size_t pf : {std::size_t{3}, std::size_t{4}}) {
                const float scale = kScales[seed % std::size(kScales)];
                const Cloud cloud = make_cloud(s.w, s.h, pf, pf == 3 ? 0 : 2, 1.0f, seed++);
                const auto w = std::uint32_t(s.w);
                const auto h = std::uint32_t(s.h);
                Texels actual(std::size_t(w) * h);
                PassContext c = context_of(cloud);
                c.robust_texels = actual.planes;
                for (std::uint32_t y = 0; y < h; ++y) k.robust_texels_row(c, w, h, y, r, scale);
                for (std::uint32_t y = 0; y < h; ++y) {
                    for (std::uint32_t x = 0; x < w; ++x) {
                        const PyrRobustTexel e = pixel::pyr_robust_texel(c, w, h, x, y, r, scale);
                        const PyrRobustTexel a = actual.planes.load(std::size_t(y) * w + x);
                        const bool same = a.gz == e.gz && a.tangents == e.tangents && a.th.x == e.th.x &&
                                          a.th.y == e.th.y && a.th.z == e.th.z && a.tv.x == e.tv.x &&
                                          a.tv.y == e.tv.y && a.tv.z == e.tv.z;
                        ASSERT_TRUE(same) << s.w << "x" << s.h << " r=" << r << " pf=" << pf << " scale=" << scale
                                          << " pixel " << x << "," << y << ": gz " << a.gz << " vs " << e.gz
                                          << ", tangents " << a.tangents << " vs " << e.tangents;
                        with_both += e.tangents == 3u ? 1 : 0;
                    }
                }
                pixels += std::size_t(w) * h;
            }
        }
    }
    EXPECT_GT(with_both, pixels / 3) << "too few pixels with both tangents to test much";
}

// The vector rows' normals against pyr_robust_normal_q over the same texels, for every pixel they take (from box
// sums, or pixel by pixel where a window holds a non-member); they leave every pixel whose window reaches past the
// image's columns.
TEST_P(CpuSimdRobustRows, NormalsMatchTheSharedFunction) {
    const simd::VectorRows& k = rows_named(GetParam());
    std::uint32_t seed = 7;
    std::size_t taken = 0;
    std::size_t left = 0;
    std::size_t defined = 0;
    std::size_t across = 0;  // taken with a window across a depth edge or a hole (summed pixel by pixel)
    for (const Size s : kSizes) {
        for (const std::uint32_t window : {1u, 2u, 3u, 5u, 7u}) {
            for (const std::size_t pf : {std::size_t{3}, std::size_t{4}}) {
                const float scale = kScales[seed % std::size(kScales)];
                const std::uint32_t r = 1 + seed % 3;
                const Cloud cloud = make_cloud(s.w, s.h, pf, pf == 3 ? 0 : 3, 1.0f, seed++);
                const auto w = std::uint32_t(s.w);
                const auto h = std::uint32_t(s.h);
                Texels texels(std::size_t(w) * h);
                PassContext c = context_of(cloud);
                c.robust_texels = texels.planes;
                for (std::uint32_t y = 0; y < h; ++y) {
                    for (std::uint32_t x = 0; x < w; ++x) {
                        texels.planes.store(std::size_t(y) * w + x, pixel::pyr_robust_texel(c, w, h, x, y, r, scale));
                    }
                }
                cpu::RobustWindows windows;
                cpu::ThreadPool one_thread(cpu::ThreadSetting{1, nullptr});  // the rows in order: the counts are plain
                const std::size_t words = (std::size_t(w) + 63) / 64;
                std::vector<float> out(3 * std::size_t(w), 99.0f);
                std::vector<std::uint64_t> rest(words, ~std::uint64_t{0});
                windows.run(one_thread, texels.planes, w, h, window, nullptr,
                            [&](std::size_t row_y, const simd::RobustWindowRow& sums) {
                                const auto y = std::uint32_t(row_y);
                                k.robust_normals_row(c, sums, w, h, y, window, out.data(), rest.data());
                                for (std::uint32_t x = 0; x < w; ++x) {
                                    const float* p = cloud.floats.data() + std::size_t(y) * cloud.row_floats + x * pf;
                                    const bool valid = pixel::pyr_point_valid(p[0], p[1], p[2]) != 0u;
                                    const bool inside = x >= window && x + window < w;
                                    bool members = false;
                                    if (valid) {
                                        const std::int32_t zi = pixel::pyr_robust_fixed(p[2], scale);
                                        members = cpu::RobustWindows::all_members(sums, x, zi, zi >> 4);
                                    }
                                    const bool was_left = ((rest[x / 64] >> (x % 64)) & 1u) != 0;
                                    const bool should_leave = !inside;
                                    // (Rows too narrow for a vector are left whole.)
                                    ASSERT_TRUE(was_left || !should_leave)
                                        << s.w << "x" << s.h << " window=" << window << " pixel " << x << "," << y;
                                    if (was_left) {
                                        ++left;
                                        continue;
                                    }
                                    const PyrIVec3 q = pixel::pyr_robust_normal_q(c, w, h, x, y, window, scale);
                                    const float e[3] = {float(q.x) * PYR_NORMAL_UNIT, float(q.y) * PYR_NORMAL_UNIT,
                                                        float(q.z) * PYR_NORMAL_UNIT};
                                    for (std::size_t i = 0; i < 3; ++i) {
                                        ASSERT_EQ(std::bit_cast<std::uint32_t>(out[3 * std::size_t(x) + i]),
                                                  std::bit_cast<std::uint32_t>(e[i]))
                                            << s.w << "x" << s.h << " window=" << window << " pf=" << pf << " pixel "
                                            << x << "," << y << " component " << i;
                                    }
                                    ++taken;
                                    across += valid && !members ? 1 : 0;
                                    defined += (q.x | q.y | q.z) != 0 ? 1 : 0;
                                }
                                for (std::size_t i = w; i < 64 * words; ++i) {
                                    ASSERT_EQ((rest[i / 64] >> (i % 64)) & 1u, 0u) << "a bit past the row";
                                }
                            });
                if (HasFatalFailure()) return;
            }
        }
    }
    // (Small rows, wide windows, holes and the depth steps leave many pixels to the caller; these counts are what the
    // frames above give on every target.)
    EXPECT_GT(defined, 2000u) << "too few normals compared to test much";
    EXPECT_GT(taken, 8000u) << "the vector rows must take a good share of the pixels for this to test much";
    EXPECT_GT(across, 2000u) << "too few windows summed pixel by pixel to test much";
}

// The windows' sums and depth ranges that RobustWindows hands each row, against sums and ranges taken pixel by pixel:
// in bands of rows on three threads (the rings started at a band's first row, or going on from the thread's last
// band), two frames in a row through the same windows (the second must not take the first's rows), sums that wrap.
TEST_P(CpuSimdRobustRows, WindowsInBandsMatchSumsTakenPixelByPixel) {
    const simd::VectorRows& k = rows_named(GetParam());
    cpu::ThreadPool three_threads(cpu::ThreadSetting{3, nullptr});
    std::mt19937 rng(97);
    for (const Size s : {Size{37, 53}, Size{64, 200}, Size{5, 3}}) {
        for (const std::uint32_t window : {1u, 3u, 6u}) {
            const auto w = std::size_t(s.w);
            const auto h = std::size_t(s.h);
            cpu::RobustWindows windows;
            for (int frame = 0; frame < 2; ++frame) {
                Texels texels(w * h);
                for (std::size_t i = 0; i < w * h; ++i) {
                    texels.planes.gz[i] = std::int32_t(rng() % 100000);
                    for (std::size_t c = 0; c < 3; ++c) {
                        texels.planes.th[c][i] = std::int32_t(rng());  // full range: the sums wrap
                        texels.planes.tv[c][i] = std::int32_t(rng() % 2001) - 1000;
                    }
                }
                // Each row is handed to one thread once: its results go to its own rows of these.
                std::vector<std::int32_t> sums(6 * w * h, 0);
                std::vector<std::int32_t> lo(w * h, 0);
                std::vector<std::int32_t> hi(w * h, 0);
                std::vector<int> visits(h, 0);
                windows.run(three_threads, texels.planes, w, h, window, &k,
                            [&](std::size_t y, const simd::RobustWindowRow& row) {
                                ++visits[y];
                                for (std::size_t x = 0; x < w; ++x) {
                                    PyrIVec3 u{};
                                    PyrIVec3 v{};
                                    windows.sums(row, x, u, v);
                                    const std::int32_t got[6] = {u.x, u.y, u.z, v.x, v.y, v.z};
                                    std::copy_n(got, 6, sums.begin() + std::ptrdiff_t(6 * (y * w + x)));
                                    lo[y * w + x] = row.min[x];
                                    hi[y * w + x] = row.max[x];
                                }
                            });
                for (std::size_t y = 0; y < h; ++y) {
                    ASSERT_EQ(visits[y], 1) << "row " << y;
                    const std::size_t y0 = y >= window ? y - window : 0;
                    const std::size_t y1 = std::min(y + window, h - 1);
                    for (std::size_t x = 0; x < w; ++x) {
                        const std::size_t x0 = x >= window ? x - window : 0;
                        const std::size_t x1 = std::min(x + window, w - 1);
                        std::uint32_t e[6] = {};
                        std::int32_t least = texels.planes.gz[y0 * w + x0];
                        std::int32_t greatest = least;
                        for (std::size_t j = y0; j <= y1; ++j) {
                            for (std::size_t i = x0; i <= x1; ++i) {
                                const std::size_t at = j * w + i;
                                for (std::size_t c = 0; c < 3; ++c) {
                                    e[c] += std::uint32_t(texels.planes.th[c][at]);
                                    e[3 + c] += std::uint32_t(texels.planes.tv[c][at]);
                                }
                                least = std::min(least, texels.planes.gz[at]);
                                greatest = std::max(greatest, texels.planes.gz[at]);
                            }
                        }
                        for (std::size_t c = 0; c < 6; ++c) {
                            ASSERT_EQ(sums[6 * (y * w + x) + c], std::int32_t(e[c]))
                                << s.w << "x" << s.h << " window " << window << " frame " << frame << " pixel " << x
                                << "," << y << " component " << c;
                        }
                        ASSERT_EQ(lo[y * w + x], least) << "pixel " << x << "," << y;
                        ASSERT_EQ(hi[y * w + x], greatest) << "pixel " << x << "," << y;
                    }
                }
            }
        }
    }
}

// The windows' depth range along a row, clipped at both ends, against the minimum and maximum written out.
TEST_P(CpuSimdRobustRows, RangeRowMatchesTheWindowsExtremes) {
    const simd::VectorRows& k = rows_named(GetParam());
    std::mt19937 rng(31);
    for (const std::uint32_t w : {1u, 2u, 5u, 15u, 16u, 17u, 33u, 64u, 100u, 257u}) {
        for (const std::uint32_t r : {1u, 2u, 3u, 7u, 20u}) {
            std::vector<std::int32_t> in(w);
            for (std::int32_t& v : in) v = rng() % 5 == 0 ? -1 : std::int32_t(rng() % 4194305);
            std::vector<std::int32_t> lo(w, 7);
            std::vector<std::int32_t> hi(w, 7);
            k.robust_range_row(in.data(), w, r, lo.data(), hi.data());
            for (std::uint32_t x = 0; x < w; ++x) {
                const std::uint32_t x0 = x >= r ? x - r : 0;
                const std::uint32_t x1 = std::min(x + r, w - 1);
                const auto first = in.begin() + x0;
                const auto last = in.begin() + x1 + 1;
                ASSERT_EQ(lo[x], *std::min_element(first, last)) << "w=" << w << " r=" << r << " x=" << x;
                ASSERT_EQ(hi[x], *std::max_element(first, last)) << "w=" << w << " r=" << r << " x=" << x;
            }
        }
    }
}

// Random quantized pixels, every stride, and thresholds that grow with depth or do not.
TEST_P(CpuSimdRobustRows, MetricMatchesTheSharedFunction) {
    const simd::VectorRows& k = rows_named(GetParam());
    std::mt19937 rng(21);
    std::uniform_int_distribution<int> near(-300, 300);
    std::uniform_int_distribution<int> qn(-8192, 8192);
    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
    struct Thresholds {
        float base, growth, dt, depth_growth;
    };
    // A = (1 - cos ct) 2^26 for a few angles; growth per square unit of depth; the pass value 2^28 and beyond.
    const Thresholds thresholds[] = {{2.0e5f, 0.0f, 3.0f, 0.0f},   {6.0e5f, 0.02f, 1.0f, 2e-6f},
                                     {0.0f, 0.0f, 0.0f, 0.0f},     {268435456.0f, 0.0f, 10.0f, 0.0f},
                                     {1.0e6f, 1e30f, 5.0f, 1e30f}, {3.0e5f, 0.5f, 0.5f, 1e-5f}};
    std::size_t fillable = 0;
    std::size_t pixels = 0;
    int round = 0;
    for (const Size s : kSizes) {
        for (const std::uint32_t stride : {1u, 2u, 4u, 7u, 64u}) {
            const Thresholds& t = thresholds[std::size_t(round++) % std::size(thresholds)];
            const auto w = std::uint32_t(s.w);
            const auto h = std::uint32_t(s.h);
            std::vector<std::uint32_t> words(kQuantWords * std::size_t(w) * h);
            const bool smooth = round % 3 != 0;
            for (std::size_t i = 0; i < std::size_t(w) * h; ++i) {
                const bool valid = unit(rng) < 0.88f;
                const std::int32_t qx = smooth ? near(rng) : qn(rng);
                const std::int32_t qy = smooth ? near(rng) : qn(rng);
                const std::int32_t qz = smooth ? -8150 + near(rng) / 10 : qn(rng);
                const float u = unit(rng);
                float z = u < 0.03f ? 3e38f * unit(rng) : 1000.0f + 4.0f * unit(rng);
                if (!valid && u < 0.3f) z = kNaN;  // invalid pixels may hold anything
                ::pyrseg::cpu::store_quant(words.data() + kQuantWords * i, qx, qy, qz, valid ? 1u : 0u, z);
            }
            PassContext c;
            c.quant = words.data();
            std::vector<std::uint8_t> actual(std::size_t(w) * h, 0x55);
            for (std::uint32_t y = 0; y < h; ++y) {
                k.metric_robust_row(c, w, h, y, stride, t.base, t.growth, t.dt, t.depth_growth,
                                    actual.data() + std::size_t(y) * w);
                for (std::uint32_t x = 0; x < w; ++x) {
                    const std::uint32_t e = pixel::pyr_metric_robust_fillable(c, w, h, x, y, stride, t.base, t.growth,
                                                                              t.dt, t.depth_growth);
                    ASSERT_EQ(std::uint32_t(actual[std::size_t(y) * w + x]), e)
                        << s.w << "x" << s.h << " stride=" << stride << " thresholds " << round << " pixel " << x << ","
                        << y;
                    fillable += e;
                }
            }
            pixels += std::size_t(w) * h;
        }
    }
    EXPECT_GT(fillable, pixels / 20) << "too few fillable pixels to test much";
    EXPECT_LT(fillable, pixels / 2) << "too many fillable pixels to test much";
}

INSTANTIATE_TEST_SUITE_P(Targets, CpuSimdRobustRows, ::testing::ValuesIn(target_names()),
                         [](const ::testing::TestParamInfo<std::string>& param_info) { return param_info.param; });

// ---- Whole segmentations with the robust metric

std::vector<TestFrame> robust_frames() {
    std::vector<TestFrame> out;
    const Size sizes[] = {{131, 97}, {67, 45}, {2, 3}, {17, 300}, {200, 7}};
    const SensorKind sensors[] = {SensorKind::kinect_v1, SensorKind::realsense_d435, SensorKind::azure_kinect};
    std::uint32_t seed = 41;
    for (const Size s : sizes) {
        for (const SensorKind sensor : sensors) {
            synthetic::SceneOptions o;
            o.width = s.w;
            o.height = s.h;
            o.seed = seed++;
            o.object_count = 6;
            o.threads = 1;
            const synthetic::Scene scene = synthetic::generate(o);
            TestFrame f;
            f.w = s.w;
            f.h = s.h;
            f.points = scene.points;
            f.params = sensor_preset(sensor);
            std::ostringstream name;
            name << s.w << "x" << s.h << "_" << sensor_kind_name(sensor);
            f.name = name.str();
            out.push_back(std::move(f));
        }
    }
    return out;
}

class CpuSimdRobustFrames : public ::testing::TestWithParam<std::string> {};

TEST_P(CpuSimdRobustFrames, MatchTheScalarPathAndTheReference) {
    std::uint32_t segments = 0;
    for (const TestFrame& f : robust_frames()) {
        SCOPED_TRACE(f.name);
        const pyrseg_ref::Output ref = pyrseg_ref::segment(f.points.data(), nullptr, f.w, f.h, to_reference(f.params));
        ASSERT_TRUE(ref.ok) << ref.error;
        segments += ref.segment_count;
        const Result scalar = segment_on_target("scalar", f, everything());
        const Result r = segment_on_target(GetParam(), f, everything());
        EXPECT_TRUE(same_bytes("normals", r.normals, ref.normals, f.w, 3));
        EXPECT_TRUE(same_bytes("fillable mask", r.fillable_mask, ref.fillable, f.w));
        EXPECT_TRUE(same_bytes("labels", r.labels, ref.labels, f.w));
        EXPECT_TRUE(same_bytes("normals (scalar path)", r.normals, scalar.normals, f.w, 3));
        EXPECT_TRUE(same_bytes("labels (scalar path)", r.labels, scalar.labels, f.w));
        if (::testing::Test::HasFailure()) return;
    }
    EXPECT_GT(segments, 20u) << "the frames must have segments for the labels to say much";
}

INSTANTIATE_TEST_SUITE_P(Targets, CpuSimdRobustFrames, ::testing::ValuesIn(simd::accepted_names()),
                         [](const ::testing::TestParamInfo<std::string>& param_info) { return param_info.param; });

}  // namespace
}  // namespace pyrseg::test
