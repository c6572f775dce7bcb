// The conformance suite: every backend's labels, raw labels, fillable mask and normals are byte-identical to
// the independent reference (tests/reference) on the same scenes. Unavailable backends are skipped with the
// reason the backend gives.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <string>
#include <tuple>
#include <vector>

#include "conformance/cases.hpp"
#include "pyrseg/error.hpp"
#include "pyrseg/io.hpp"
#include "pyrseg/presets.hpp"
#include "pyrseg/segmenter.hpp"
#include "pyrseg/synthetic.hpp"
#include "support/oracle.hpp"

namespace pyrseg::test {
namespace {

// A colour image for a scene: each object's own colour, stripes on every other object (texture inside a surface),
// and seeded noise of a few levels, so that colour edges fall on object borders, inside objects and at random.
std::vector<std::uint8_t> scene_colors(const synthetic::Scene& scene, std::uint64_t seed) {
    std::vector<std::uint8_t> rgb(3 * scene.object_id.size());
    std::uint64_t state = seed * 6364136223846793005ull + 1442695040888963407ull;
    for (std::size_t i = 0; i < scene.object_id.size(); ++i) {
        const std::uint32_t id = scene.object_id[i];
        const std::size_t x = i % std::size_t(scene.width);
        const bool stripe = (id & 1u) != 0 && (x / 7) % 2 == 0;
        for (int c = 0; c < 3; ++c) {
            state = state * 6364136223846793005ull + 1442695040888963407ull;
            const auto noise = int((state >> 33) % 25) - 12;
            const int base = int((id * 2654435761u >> (8 * c)) & 0xffu) + (stripe ? 70 : 0) + noise;
            rgb[3 * i + std::size_t(c)] = std::uint8_t(std::clamp(base, 0, 255));
        }
    }
    return rgb;
}

// Segments `points` with `backend` and compares every output with the reference.
// color: packed RGB8 for the reference; the backend gets the same rows color_row_padding bytes apart.
void expect_conformance(const std::string& backend, const float* points, const float* normals, int width, int height,
                        const Params& params, const float* warmup_points = nullptr,
                        const std::vector<std::uint8_t>* color = nullptr, std::size_t color_row_padding = 0) {
    const pyrseg_ref::Output ref = pyrseg_ref::segment(points, normals, width, height, to_reference(params),
                                                       color != nullptr ? color->data() : nullptr);
    if (!ref.ok) {
        EXPECT_THROW(Segmenter(width, height, params, backend, everything()), pyrseg::Error)
            << "the reference rejects these parameters (" << ref.error << ") but the backend accepts them";
        return;
    }
    Segmenter segmenter(width, height, params, backend, everything());
    Result result;
    CloudView view;
    view.width = width;
    view.height = height;
    if (warmup_points != nullptr) {  // a different frame first: nothing may leak from one frame to the next
        view.points = warmup_points;
        segmenter.segment(view, result);
    }
    view.points = points;
    view.normals = normals;
    std::vector<std::uint8_t> padded;
    if (color != nullptr) {
        const std::size_t row = 3 * std::size_t(width);
        const std::size_t step = row + color_row_padding;
        padded.assign(step * std::size_t(height), 0xa5);
        for (std::size_t y = 0; y < std::size_t(height); ++y)
            std::copy_n(color->data() + y * row, row, padded.data() + y * step);
        view.color = padded.data();
        view.color_row_step_bytes = color_row_padding == 0 ? 0 : step;
    }
    segmenter.segment(view, result);
    EXPECT_TRUE(same_bytes("fillable mask", result.fillable_mask, ref.fillable, width));
    EXPECT_TRUE(same_bytes("normals", result.normals, ref.normals, width, 3));
    EXPECT_TRUE(same_bytes("raw labels", result.raw_labels, ref.raw_labels, width));
    EXPECT_TRUE(same_bytes("labels", result.labels, ref.labels, width));
    EXPECT_EQ(result.segment_count, ref.segment_count);
    EXPECT_TRUE(same_segments(result.segments, ref.segments));
    EXPECT_TRUE(same_graph(result.graph, ref.graph));
}

class SyntheticScenes : public ::testing::TestWithParam<std::tuple<std::string, int>> {};

TEST_P(SyntheticScenes, MatchesReference) {
    const auto& [backend, index] = GetParam();
    PYRSEG_SKIP_IF_UNAVAILABLE(backend);
    const ConformanceCase& c = conformance_cases()[std::size_t(index)];
    const synthetic::Scene scene = synthetic::generate(c.scene);
    const bool small = std::size_t(c.scene.width) * std::size_t(c.scene.height) <= 640u * 480u;
    synthetic::Scene other;
    if (small) {
        synthetic::SceneOptions o = c.scene;
        o.seed += 7777;
        other = synthetic::generate(o);
    }
    expect_conformance(backend, scene.points.data(), c.given_normals ? scene.normals.data() : nullptr, scene.width,
                       scene.height, c.params, small ? other.points.data() : nullptr);
}

INSTANTIATE_TEST_SUITE_P(Backends, SyntheticScenes,
                         ::testing::Combine(::testing::ValuesIn(available_backend_names()),
                                            ::testing::Range(0, int(conformance_cases().size()))),
                         [](const ::testing::TestParamInfo<SyntheticScenes::ParamType>& param_info) {
                             return std::get<0>(param_info.param) + "_" +
                                    conformance_cases()[std::size_t(std::get<1>(param_info.param))].name;
                         });

class RobustScenes : public ::testing::TestWithParam<std::tuple<std::string, int>> {};

TEST_P(RobustScenes, MatchesReference) {
    const auto& [backend, index] = GetParam();
    PYRSEG_SKIP_IF_UNAVAILABLE(backend);
    const ConformanceCase& c = robust_conformance_cases()[std::size_t(index)];
    const synthetic::Scene scene = synthetic::generate(c.scene);
    expect_conformance(backend, scene.points.data(), c.given_normals ? scene.normals.data() : nullptr, scene.width,
                       scene.height, c.params);
}

INSTANTIATE_TEST_SUITE_P(Backends, RobustScenes,
                         ::testing::Combine(::testing::ValuesIn(available_backend_names()),
                                            ::testing::Range(0, int(robust_conformance_cases().size()))),
                         [](const ::testing::TestParamInfo<RobustScenes::ParamType>& param_info) {
                             return std::get<0>(param_info.param) + "_" +
                                    robust_conformance_cases()[std::size_t(std::get<1>(param_info.param))].name;
                         });

class MergeScenes : public ::testing::TestWithParam<std::tuple<std::string, int>> {};

TEST_P(MergeScenes, MatchesReference) {
    const auto& [backend, index] = GetParam();
    PYRSEG_SKIP_IF_UNAVAILABLE(backend);
    const ConformanceCase& c = merge_conformance_cases()[std::size_t(index)];
    const synthetic::Scene scene = synthetic::generate(c.scene);
    expect_conformance(backend, scene.points.data(), c.given_normals ? scene.normals.data() : nullptr, scene.width,
                       scene.height, c.params);
}

INSTANTIATE_TEST_SUITE_P(Backends, MergeScenes,
                         ::testing::Combine(::testing::ValuesIn(available_backend_names()),
                                            ::testing::Range(0, int(merge_conformance_cases().size()))),
                         [](const ::testing::TestParamInfo<MergeScenes::ParamType>& param_info) {
                             return std::get<0>(param_info.param) + "_" +
                                    merge_conformance_cases()[std::size_t(std::get<1>(param_info.param))].name;
                         });

// The segment graph asked for alone (no statistics, labels only): a backend must keep what the graph reads (the
// quantized normals) without the other outputs that need it.
class GraphAlone : public ::testing::TestWithParam<std::string> {};

TEST_P(GraphAlone, MatchesReference) {
    PYRSEG_SKIP_IF_UNAVAILABLE(GetParam());
    std::size_t edges = 0;
    for (std::size_t index = 0; index < 8; ++index) {
        const ConformanceCase& c = conformance_cases()[index];
        SCOPED_TRACE(c.name);
        Params params = c.params;
        params.edge_rounds = 4;  // edge bands closed, so that segments touch
        const synthetic::Scene scene = synthetic::generate(c.scene);
        const float* normals = c.given_normals ? scene.normals.data() : nullptr;
        const pyrseg_ref::Output ref =
            pyrseg_ref::segment(scene.points.data(), normals, scene.width, scene.height, to_reference(params));
        if (!ref.ok) continue;  // parameters the reference refuses: the other suites check the refusal
        Outputs graph;
        graph.segment_graph = true;
        Segmenter segmenter(scene.width, scene.height, params, GetParam(), graph);
        const Result result = segmenter.segment(CloudView{scene.points.data(), normals, scene.width, scene.height});
        EXPECT_TRUE(same_bytes("labels", result.labels, ref.labels, scene.width));
        EXPECT_TRUE(same_graph(result.graph, ref.graph));
        edges += ref.graph.size();
    }
    EXPECT_GT(edges, 8u) << "the cases must have segments that touch";
}

INSTANTIATE_TEST_SUITE_P(Backends, GraphAlone, ::testing::ValuesIn(available_backend_names()),
                         [](const ::testing::TestParamInfo<std::string>& param_info) { return param_info.param; });

class ColorScenes : public ::testing::TestWithParam<std::tuple<std::string, int>> {};

TEST_P(ColorScenes, MatchesReference) {
    const auto& [backend, index] = GetParam();
    PYRSEG_SKIP_IF_UNAVAILABLE(backend);
    const ConformanceCase& c = color_conformance_cases()[std::size_t(index)];
    const synthetic::Scene scene = synthetic::generate(c.scene);
    const std::vector<std::uint8_t> color = scene_colors(scene, c.scene.seed);
    expect_conformance(backend, scene.points.data(), c.given_normals ? scene.normals.data() : nullptr, scene.width,
                       scene.height, c.params, nullptr, &color, std::size_t(c.color_row_padding));
}

INSTANTIATE_TEST_SUITE_P(Backends, ColorScenes,
                         ::testing::Combine(::testing::ValuesIn(available_backend_names()),
                                            ::testing::Range(0, int(color_conformance_cases().size()))),
                         [](const ::testing::TestParamInfo<ColorScenes::ParamType>& param_info) {
                             return std::get<0>(param_info.param) + "_" +
                                    color_conformance_cases()[std::size_t(std::get<1>(param_info.param))].name;
                         });

// Depths in the subnormal range: validity (z > 0) and the metric's float depth differences must follow IEEE on
// every backend, whatever a device's denormal mode (contract section 2; docs/algorithm.md section 9).
class TinyDepths : public ::testing::TestWithParam<std::string> {};

TEST_P(TinyDepths, SubnormalDepthsFollowIeee) {
    const int w = 48;
    const int h = 40;
    std::vector<float> points(3 * std::size_t(w) * std::size_t(h));
    std::vector<float> normals(points.size());
    for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) {
            float* p = &points[3 * (std::size_t(y) * std::size_t(w) + std::size_t(x))];
            // Subnormal depths (below 2^-126, about 1.18e-38): a step between the halves, noise-like variation.
            const int units = (x < w / 2 ? 40 : 90) + ((x * 7 + y * 13) % 5);
            p[0] = 0.0f;
            p[1] = 0.0f;
            p[2] = float(units) * std::numeric_limits<float>::denorm_min() * 1000.0f;
            float* n = &normals[3 * (std::size_t(y) * std::size_t(w) + std::size_t(x))];
            n[0] = 0.0f;
            n[1] = 0.0f;
            n[2] = -1.0f;
        }
    }
    ASSERT_LT(points[2], std::numeric_limits<float>::min());
    Params params;
    params.dt = 2e-41;  // subnormal too: the step (~7e-41) is an edge, the variation (<= ~6e-42) is not
    const pyrseg_ref::Output ref = pyrseg_ref::segment(points.data(), normals.data(), w, h, to_reference(params));
    ASSERT_TRUE(ref.ok);
    ASSERT_EQ(ref.segment_count, 2u) << "the scene must have a depth edge, or flushing denormals would go unseen";
    expect_conformance(GetParam(), points.data(), normals.data(), w, h, params);
}

// Points far beyond the statistics' fixed-point range (about +-134 km in millimetres) saturate the same way on every
// backend, and the 64-bit sums carry across their low words (every coordinate adds close to 2^35).
class FarPoints : public ::testing::TestWithParam<std::string> {};

TEST_P(FarPoints, SaturateInTheStatisticsLikeTheReference) {
    PYRSEG_SKIP_IF_UNAVAILABLE(GetParam());
    const int w = 24;
    const int h = 20;
    std::vector<float> points(3 * std::size_t(w) * std::size_t(h));
    std::vector<float> normals(points.size());
    for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) {
            float* p = &points[3 * (std::size_t(y) * std::size_t(w) + std::size_t(x))];
            p[0] = float(x - w / 2) * 4e7f;  // saturates from |x - 12| = 4 on (16 * 1.6e8 > 2^31)
            p[1] = -float(y) * 1e3f;
            p[2] = 3e9f;
            float* n = &normals[3 * (std::size_t(y) * std::size_t(w) + std::size_t(x))];
            n[0] = 0.0f;
            n[1] = 0.6f;
            n[2] = -0.8f;
        }
    }
    const pyrseg_ref::Output ref = pyrseg_ref::segment(points.data(), normals.data(), w, h, to_reference({}));
    ASSERT_TRUE(ref.ok);
    ASSERT_EQ(ref.segments.size(), 1u);
    ASSERT_EQ(ref.segments[0].point_sum[2], std::int64_t(2147483520) * w * h) << "z must saturate";
    ASSERT_GT(ref.segments[0].product_sum[5], pyrseg_ref::Int128(std::numeric_limits<std::int64_t>::max()))
        << "the sum of z * z must need more than 64 bits";
    ASSERT_LT(ref.segments[0].product_sum[2], pyrseg_ref::Int128(std::numeric_limits<std::int64_t>::min()))
        << "the sum of x * z must be negative and need more than 64 bits";
    expect_conformance(GetParam(), points.data(), normals.data(), w, h, {});
}

INSTANTIATE_TEST_SUITE_P(Backends, FarPoints, ::testing::ValuesIn(available_backend_names()),
                         [](const ::testing::TestParamInfo<std::string>& param_info) { return param_info.param; });

INSTANTIATE_TEST_SUITE_P(Backends, TinyDepths, ::testing::ValuesIn(available_backend_names()),
                         [](const ::testing::TestParamInfo<std::string>& param_info) { return param_info.param; });

// Clouds in the caller's own layout: PCL's PointNormal (x y z pad nx ny nz pad curvature pad pad pad, 12 floats)
// in rows padded to a larger stride. Every backend must read them exactly as the packed arrays.
class StridedClouds : public ::testing::TestWithParam<std::string> {};

TEST_P(StridedClouds, MatchTheReferenceLikePackedOnes) {
    PYRSEG_SKIP_IF_UNAVAILABLE(GetParam());
    synthetic::SceneOptions o;
    o.width = 160;
    o.height = 120;
    o.seed = 7;
    const synthetic::Scene scene = synthetic::generate(o);
    const std::size_t w = std::size_t(o.width);
    const std::size_t h = std::size_t(o.height);
    const std::size_t row_stride = w + 13;  // points per row in memory
    const int point_stride = 12;            // floats per point
    std::vector<float> interleaved(h * row_stride * std::size_t(point_stride), -12345.0f);
    for (std::size_t y = 0; y < h; ++y) {
        for (std::size_t x = 0; x < w; ++x) {
            float* p = &interleaved[(y * row_stride + x) * std::size_t(point_stride)];
            for (std::size_t c = 0; c < 3; ++c) {
                p[c] = scene.points[3 * (y * w + x) + c];
                p[4 + c] = scene.normals[3 * (y * w + x) + c];
            }
        }
    }
    for (const bool given_normals : {false, true}) {
        const pyrseg_ref::Output ref = pyrseg_ref::segment(
            scene.points.data(), given_normals ? scene.normals.data() : nullptr, o.width, o.height, to_reference({}));
        ASSERT_TRUE(ref.ok) << ref.error;
        Segmenter segmenter(o.width, o.height, {}, GetParam(), everything());
        CloudView view;
        view.points = interleaved.data();
        view.normals = given_normals ? interleaved.data() + 4 : nullptr;
        view.width = o.width;
        view.height = o.height;
        view.row_stride = row_stride;
        view.point_stride = point_stride;
        Result result;
        segmenter.segment(view, result);
        EXPECT_TRUE(same_bytes("fillable mask", result.fillable_mask, ref.fillable, o.width));
        EXPECT_TRUE(same_bytes("normals", result.normals, ref.normals, o.width, 3));
        EXPECT_TRUE(same_bytes("labels", result.labels, ref.labels, o.width));
        EXPECT_EQ(result.segment_count, ref.segment_count) << (given_normals ? "given normals" : "estimated normals");
        EXPECT_TRUE(same_segments(result.segments, ref.segments));
        EXPECT_TRUE(same_graph(result.graph, ref.graph));
    }
}

// A ROS sensor_msgs/PointCloud2-like buffer: fields x y z rgb normal_x normal_y normal_z curvature (point_step 32
// bytes, normal_x at byte 16) in rows padded by 20 bytes (row_step = 32 * width + 20, not a whole number of points),
// viewed in place through the byte steps, with the robust metric's preset too.
TEST_P(StridedClouds, ByteStepsOfAPointCloud2MatchTheReference) {
    PYRSEG_SKIP_IF_UNAVAILABLE(GetParam());
    synthetic::SceneOptions o;
    o.width = 96;
    o.height = 70;
    o.seed = 11;
    o.sensor = synthetic::Sensor::kinect_v1;
    const synthetic::Scene scene = synthetic::generate(o);
    const std::size_t w = std::size_t(o.width);
    const std::size_t h = std::size_t(o.height);
    const std::size_t point_step = 32;
    const std::size_t row_step = point_step * w + 20;
    std::vector<float> buffer(h * row_step / sizeof(float), -12345.0f);
    for (std::size_t y = 0; y < h; ++y) {
        for (std::size_t x = 0; x < w; ++x) {
            float* p = &buffer[(y * row_step + x * point_step) / sizeof(float)];
            for (std::size_t c = 0; c < 3; ++c) {
                p[c] = scene.points[3 * (y * w + x) + c];
                p[4 + c] = scene.normals[3 * (y * w + x) + c];
            }
        }
    }
    for (const Params& params : {Params{}, sensor_preset(SensorKind::kinect_v1)}) {
        for (const bool given_normals : {false, true}) {
            const pyrseg_ref::Output ref =
                pyrseg_ref::segment(scene.points.data(), given_normals ? scene.normals.data() : nullptr, o.width,
                                    o.height, to_reference(params));
            ASSERT_TRUE(ref.ok) << ref.error;
            Segmenter segmenter(o.width, o.height, params, GetParam(), everything());
            CloudView view;
            view.points = buffer.data();
            view.normals = given_normals ? buffer.data() + 4 : nullptr;
            view.width = o.width;
            view.height = o.height;
            view.point_step_bytes = point_step;
            view.row_step_bytes = row_step;
            Result result;
            segmenter.segment(view, result);
            const std::string what = std::string(params.metric == Metric::robust ? "robust" : "paper") +
                                     (given_normals ? ", given normals" : ", estimated normals");
            EXPECT_TRUE(same_bytes("fillable mask", result.fillable_mask, ref.fillable, o.width)) << what;
            EXPECT_TRUE(same_bytes("normals", result.normals, ref.normals, o.width, 3)) << what;
            EXPECT_TRUE(same_bytes("labels", result.labels, ref.labels, o.width)) << what;
            EXPECT_TRUE(same_segments(result.segments, ref.segments)) << what;
            EXPECT_TRUE(same_graph(result.graph, ref.graph)) << what;
        }
    }
}

INSTANTIATE_TEST_SUITE_P(Backends, StridedClouds, ::testing::ValuesIn(available_backend_names()),
                         [](const ::testing::TestParamInfo<std::string>& param_info) { return param_info.param; });

class RealScans : public ::testing::TestWithParam<std::tuple<std::string, std::string>> {};

// Step 6c's depth test (edge_max_depth_step) on a depth step with a wide edge band between a far surface (left)
// and a near one (right), given normals: without the test the far surface's smaller label crosses the step into the
// near side's band; with it the near side's label fills its band. Both as the reference, on every backend.
class EdgeDepthStep : public ::testing::TestWithParam<std::string> {};

TEST_P(EdgeDepthStep, KeepsBandsOnTheirSurfaceLikeTheReference) {
    PYRSEG_SKIP_IF_UNAVAILABLE(GetParam());
    constexpr int kSize = 16;
    std::vector<float> points;
    std::vector<float> normals;
    for (int y = 0; y < kSize; ++y) {
        for (int x = 0; x < kSize; ++x) {
            const float z = x <= 5 ? 2000.0f : (x == 6 || x == 8 ? 1015.0f : 1000.0f);
            points.insert(points.end(), {float(x), float(y), z});
            normals.insert(normals.end(), {0.0f, 0.0f, -1.0f});
        }
    }
    Params params;
    params.edge_rounds = 8;
    std::vector<std::uint32_t> band[2];
    for (const double step : {0.0, 0.02}) {
        params.edge_max_depth_step = step;
        expect_conformance(GetParam(), points.data(), normals.data(), kSize, kSize, params);
        Outputs outputs;
        outputs.raw_labels = true;
        Segmenter segmenter(kSize, kSize, params, GetParam(), outputs);
        CloudView view;
        view.points = points.data();
        view.normals = normals.data();
        view.width = kSize;
        view.height = kSize;
        const Result r = segmenter.segment(view);
        band[step > 0.0 ? 1 : 0] = {r.raw_labels.begin() + 5, r.raw_labels.begin() + 10};  // row 0, x = 5..9
    }
    // The far side's label (that of x = 0) crosses to x = 7 without the test and stops at x = 5 with it.
    EXPECT_EQ(band[0][2], band[0][0]);
    EXPECT_NE(band[1][1], band[1][0]);
    EXPECT_EQ(band[1][1], band[1][4]);
}

INSTANTIATE_TEST_SUITE_P(Backends, EdgeDepthStep, ::testing::ValuesIn(available_backend_names()),
                         [](const ::testing::TestParamInfo<std::string>& param_info) { return param_info.param; });

TEST_P(RealScans, MatchesReference) {
    const auto& [backend, file] = GetParam();
    PYRSEG_SKIP_IF_UNAVAILABLE(backend);
    const std::filesystem::path path = std::filesystem::path(shared_data_dir()) / file;
    if (!std::filesystem::exists(path)) GTEST_SKIP() << "sample scan not present: " << path.string();
    const io::PointCloud cloud = io::read_pcd(path);
    ASSERT_TRUE(cloud.normals.empty()) << "the shared scans carry no normals; they are estimated";
    Params params;
    params.unit_mm = 1000.0;  // the scans are in metres
    expect_conformance(backend, cloud.points.data(), nullptr, cloud.width, cloud.height, params);
    params.normal_radius = 2;
    params.bridge_levels = 3;
    expect_conformance(backend, cloud.points.data(), nullptr, cloud.width, cloud.height, params);
}

INSTANTIATE_TEST_SUITE_P(Backends, RealScans,
                         ::testing::Combine(::testing::ValuesIn(available_backend_names()),
                                            ::testing::Values("table_scene_mug_stereo_textured.pcd",
                                                              "milk_cartoon_all_small_clorox.pcd")),
                         [](const ::testing::TestParamInfo<RealScans::ParamType>& param_info) {
                             std::string file = std::get<1>(param_info.param);
                             file = file.substr(0, file.find('.'));
                             return std::get<0>(param_info.param) + "_" + file;
                         });

// A real depth image (Kinect-style, integer millimetres) back-projected with its calibration: quantized depth is
// the input depth cameras give most often.
class RealDepthImages : public ::testing::TestWithParam<std::string> {};

TEST_P(RealDepthImages, MatchesReference) {
    PYRSEG_SKIP_IF_UNAVAILABLE(GetParam());
    const std::filesystem::path data(shared_data_dir());
    if (!std::filesystem::exists(data / "cape_depth_0.png")) {
        GTEST_SKIP() << "sample depth image not present: " << (data / "cape_depth_0.png").string();
    }
    const io::PointCloud cloud =
        io::depth_to_cloud(io::read_depth_image(data / "cape_depth_0.png"),
                           io::read_intrinsics(data / "cape_calib_params.xml", "IR_intrinsic_params"), 0.001);
    Params params;
    expect_conformance(GetParam(), cloud.points.data(), nullptr, cloud.width, cloud.height, params);
    params.normal_radius = 4;
    params.dt = 20.0;
    params.ct = 0.35;
    expect_conformance(GetParam(), cloud.points.data(), nullptr, cloud.width, cloud.height, params);
}

INSTANTIATE_TEST_SUITE_P(Backends, RealDepthImages, ::testing::ValuesIn(available_backend_names()),
                         [](const ::testing::TestParamInfo<std::string>& param_info) { return param_info.param; });

// The real RealSense tabletop frames with the realsense-d435 preset and the merge: the frames the merge was made for.
class RealTabletops : public ::testing::TestWithParam<std::string> {};

TEST_P(RealTabletops, MatchTheReferenceWithTheMerge) {
    PYRSEG_SKIP_IF_UNAVAILABLE(GetParam());
    const std::filesystem::path dir = std::filesystem::path(shared_data_dir()) / "realsense";
    if (!std::filesystem::exists(dir / "wood_table_1_depth.png")) {
        GTEST_SKIP() << "real RealSense frames not present: " << dir.string();
    }
    const auto k = io::read_intrinsics(dir / "camera.yml");
    for (const char* name : {"wood_table_1", "office_table_7"}) {
        const io::PointCloud cloud =
            io::depth_to_cloud(io::read_depth_image(dir / (std::string(name) + "_depth.png")), k, 0.001);
        Params params = sensor_preset(SensorKind::realsense_d435);
        params.merge = true;
        SCOPED_TRACE(name);
        expect_conformance(GetParam(), cloud.points.data(), nullptr, cloud.width, cloud.height, params);
        // With the frame's colour image: the preset's colour edges and their curvature gate (section 2c) on real data.
        const io::Image rgb = io::read_png(dir / (std::string(name) + "_color.png"));
        ASSERT_EQ(rgb.channels, 3);
        ASSERT_EQ(rgb.bit_depth, 8);
        SCOPED_TRACE("with colour");
        expect_conformance(GetParam(), cloud.points.data(), nullptr, cloud.width, cloud.height, params, nullptr,
                           &rgb.data);
    }
}

INSTANTIATE_TEST_SUITE_P(Backends, RealTabletops, ::testing::ValuesIn(available_backend_names()),
                         [](const ::testing::TestParamInfo<std::string>& param_info) { return param_info.param; });

}  // namespace
}  // namespace pyrseg::test
