// The statistics' geometry (docs/algorithm.md section 10b): covariance, plane, box and the planar flag, checked
// against what the test computes from the labelled points in double, and on hand-made surfaces whose geometry is
// known. Bit-exactness of the words against the reference is the conformance suite's job.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <vector>

#include "pyrseg/error.hpp"
#include "pyrseg/segmenter.hpp"
#include "pyrseg/synthetic.hpp"

namespace pyrseg {
namespace {

Outputs stats_only() {
    Outputs o;
    o.segment_stats = true;
    return o;
}

struct Cloud {
    int width = 0;
    int height = 0;
    std::vector<float> points;
    std::vector<float> normals;
    [[nodiscard]] CloudView view() const { return CloudView{points.data(), normals.data(), width, height}; }
};

// A w x h grid on the plane through `origin` spanned by the unit vectors u and v, `step` mm apart, with normal u x v.
Cloud plane_patch(int w, int h, std::array<double, 3> origin, std::array<double, 3> u, std::array<double, 3> v,
                  double step) {
    Cloud c{w, h, std::vector<float>(3 * std::size_t(w) * std::size_t(h)), {}};
    c.normals.resize(c.points.size());
    const std::array<double, 3> n = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
    for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) {
            const std::size_t i = 3 * (std::size_t(y) * std::size_t(w) + std::size_t(x));
            for (std::size_t k = 0; k < 3; ++k) {
                c.points[i + k] = float(origin[k] + u[k] * step * x + v[k] * step * y);
                c.normals[i + k] = float(n[k]);
            }
        }
    }
    return c;
}

double dot(const std::array<double, 3>& a, const std::array<double, 3>& b) {
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

TEST(SegmentGeometry, CovarianceAndDepthRangeMatchTheFillablePoints) {
    synthetic::SceneOptions o;
    o.width = 320;
    o.height = 240;
    o.seed = 11;
    const synthetic::Scene s = synthetic::generate(o);
    Outputs with_mask = stats_only();
    with_mask.fillable_mask = true;
    Segmenter seg(s.width, s.height, {}, "cpu", with_mask);
    const Result r = seg.segment(CloudView{s.points.data(), s.normals.data(), s.width, s.height});
    ASSERT_GT(r.segment_count, 3u);
    // Two passes in double over the same pixels: the mean, then the centred products.
    const std::size_t k_count = r.segment_count;
    std::vector<std::array<double, 3>> mean(k_count, {0, 0, 0});
    std::vector<std::array<double, 6>> cov(k_count, {0, 0, 0, 0, 0, 0});
    std::vector<double> z_min(k_count, 1e300);
    std::vector<double> z_max(k_count, -1e300);
    const std::size_t n = std::size_t(s.width) * std::size_t(s.height);
    for (std::size_t i = 0; i < n; ++i) {
        if (r.labels[i] == 0 || r.fillable_mask[i] == 0) continue;
        const std::size_t k = r.labels[i] - 1;
        for (std::size_t c = 0; c < 3; ++c) mean[k][c] += double(s.points[3 * i + c]) / r.segments[k].fillable_count;
        z_min[k] = std::min(z_min[k], double(s.points[3 * i + 2]));
        z_max[k] = std::max(z_max[k], double(s.points[3 * i + 2]));
    }
    for (std::size_t i = 0; i < n; ++i) {
        if (r.labels[i] == 0 || r.fillable_mask[i] == 0) continue;
        const std::size_t k = r.labels[i] - 1;
        std::array<double, 3> d{};
        for (std::size_t c = 0; c < 3; ++c) d[c] = double(s.points[3 * i + c]) - mean[k][c];
        const std::array<double, 6> products = {d[0] * d[0], d[0] * d[1], d[0] * d[2],
                                                d[1] * d[1], d[1] * d[2], d[2] * d[2]};
        for (std::size_t j = 0; j < 6; ++j) cov[k][j] += products[j] / r.segments[k].fillable_count;
    }
    for (std::size_t k = 0; k < k_count; ++k) {
        const SegmentStats& got = r.segments[k];
        SCOPED_TRACE("segment " + std::to_string(k + 1) + ", " + std::to_string(got.fillable_count) +
                     " fillable pixels");
        // Each coordinate is rounded to 1/16 mm: a variance moves by less than about 2 * sigma / 32 + 1/256 mm^2.
        for (std::size_t j = 0; j < 6; ++j) {
            const double scale = std::sqrt(cov[k][0] + cov[k][3] + cov[k][5]);
            EXPECT_NEAR(got.covariance[j], cov[k][j], scale / 16 + 1.0 / 128) << "entry " << j;
        }
        EXPECT_NEAR(got.z_min, z_min[k], 1.0 / 32);
        EXPECT_NEAR(got.z_max, z_max[k], 1.0 / 32);
        // The plane holds the centroid; its normal points towards the camera.
        EXPECT_NEAR(dot(got.plane_normal, got.plane_normal), 1.0, 1e-12);
        EXPECT_NEAR(dot(got.plane_normal, got.centroid) + got.plane_offset, 0.0, 1e-6 * std::fabs(got.centroid[2]));
        EXPECT_LT(dot(got.plane_normal, got.centroid), 0.0);
        EXPECT_GE(got.curvature, 0.0);
        EXPECT_LE(got.curvature, 1.0 / 3.0 + 1e-12);
        // The box frame is orthonormal and right-handed, its third axis the plane normal.
        for (std::size_t a = 0; a < 3; ++a) {
            for (std::size_t b = 0; b < 3; ++b) EXPECT_NEAR(dot(got.axes[a], got.axes[b]), a == b ? 1.0 : 0.0, 1e-9);
        }
        const std::array<double, 3>& x = got.axes[0];
        const std::array<double, 3>& y = got.axes[1];
        const std::array<double, 3> cross = {x[1] * y[2] - x[2] * y[1], x[2] * y[0] - x[0] * y[2],
                                             x[0] * y[1] - x[1] * y[0]};
        EXPECT_NEAR(dot(cross, got.axes[2]), 1.0, 1e-9);
        EXPECT_GE(got.extents[0], got.extents[1]);
        EXPECT_GE(got.extents[1], got.extents[2]);
    }
}

TEST(SegmentGeometry, ATiltedPlaneGivesItsEquationAndItsSides) {
    // 0.5 mm apart: a 120 x 80 grid is a 59.5 x 39.5 mm rectangle, tilted 30 degrees about x, about 600 mm away.
    const double t = std::numbers::pi / 6;
    const Cloud c = plane_patch(120, 80, {-30, -20, 600}, {1, 0, 0}, {0, std::cos(t), std::sin(t)}, 0.5);
    Segmenter seg(c.width, c.height, {}, "cpu", stats_only());
    const Result r = seg.segment(c.view());
    ASSERT_EQ(r.segment_count, 1u);
    const SegmentStats& s = r.segments[0];
    ASSERT_EQ(s.pixel_count, 120u * 80u);
    // u x v = (0, -sin t, cos t) points away from the camera: the fit turns it round.
    const std::array<double, 3> towards = {0, std::sin(t), -std::cos(t)};
    EXPECT_NEAR(dot(s.plane_normal, towards), 1.0, 1e-9);
    EXPECT_NEAR(s.plane_offset, -dot(towards, {-30, -20, 600}), 1.0 / 32) << "the centroid is within 1/32 mm";
    EXPECT_LT(s.plane_rms, 0.01) << "the points lie on the plane up to their 1/16 mm steps";
    EXPECT_LT(s.curvature, 1e-6);
    EXPECT_TRUE(s.planar);
    // A uniform grid of n points with spacing d has the variance of n d wide uniform: 2 sqrt(3 lambda) = n d.
    EXPECT_NEAR(s.extents[0], 120 * 0.5, 0.05);
    EXPECT_NEAR(s.extents[1], 80 * 0.5, 0.05);
    EXPECT_LT(s.extents[2], 0.05);
    EXPECT_NEAR(std::fabs(s.axes[0][0]), 1.0, 1e-9) << "the long side runs along x";
    EXPECT_NEAR(s.z_min, 600.0, 1.0 / 32);
    EXPECT_NEAR(s.z_max, 600.0 + 79 * 0.5 * std::sin(t), 1.0 / 32);
}

TEST(SegmentGeometry, ACylinderSideIsNotPlanar) {
    // The near half of a can (radius 33 mm, 100 mm tall, 700 mm away), seen along z.
    const int w = 90;
    const int h = 100;
    Cloud c{w, h, std::vector<float>(3 * std::size_t(w) * std::size_t(h)), {}};
    c.normals.resize(c.points.size());
    for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) {
            const double a = std::numbers::pi * (0.05 + 0.9 * x / (w - 1));  // 9 .. 171 degrees round the axis
            const std::size_t i = 3 * (std::size_t(y) * std::size_t(w) + std::size_t(x));
            const double p[3] = {-33 * std::cos(a), y - 50.0, 700 - 33 * std::sin(a)};
            const double nrm[3] = {-std::cos(a), 0, -std::sin(a)};
            for (std::size_t k = 0; k < 3; ++k) {
                c.points[i + k] = float(p[k]);
                c.normals[i + k] = float(nrm[k]);
            }
        }
    }
    Params p;
    p.ct = std::numbers::pi;  // no curvature edges: the side is one segment
    Segmenter seg(w, h, p, "cpu", stats_only());
    const Result r = seg.segment(c.view());
    ASSERT_EQ(r.segment_count, 1u);
    const SegmentStats& s = r.segments[0];
    EXPECT_GT(s.plane_rms, 5.0);
    EXPECT_GT(s.curvature, 0.02);
    EXPECT_FALSE(s.planar);
    EXPECT_NEAR(std::fabs(s.plane_normal[2]), 1.0, 1e-6) << "the best plane faces the camera";
}

TEST(SegmentGeometry, ThePlanarToleranceGrowsWithDepth) {
    // A plane with a 3 mm RMS ripple at 2 m: planar only once the tolerance allows for its depth.
    const int w = 64;
    const int h = 64;
    Cloud c = plane_patch(w, h, {-64, -64, 2000}, {1, 0, 0}, {0, 1, 0}, 2.0);
    for (std::size_t i = 0; i < std::size_t(w) * h; ++i) c.points[3 * i + 2] += (i / std::size_t(w)) % 2 ? 3.f : -3.f;
    Params p;
    p.dt = 1e9;
    p.ct = std::numbers::pi;
    Segmenter strict(w, h, p, "cpu", stats_only());
    const Result a = strict.segment(c.view());
    ASSERT_EQ(a.segment_count, 1u);
    EXPECT_NEAR(a.segments[0].plane_rms, 3.0, 0.01);
    EXPECT_FALSE(a.segments[0].planar) << "3 mm is more than the default 2 mm";
    p.planar_tolerance_per_m2 = 0.25;  // 2 + 0.25 * 4 = 3 mm at 2 m
    p.planar_tolerance_mm = 2.01;
    Segmenter lenient(w, h, p, "cpu", stats_only());
    EXPECT_TRUE(lenient.segment(c.view()).segments[0].planar);
}

TEST(SegmentGeometry, ANoisySliverIsNotPlanar) {
    // A strip 128 mm long and 4 mm across (16 rows 0.25 mm apart) with a 0.5 mm ripple: its RMS is well within the
    // 2 mm tolerance, but its plane is any plane through a line (second variance 1.3 mm^2, smallest 0.25); the same
    // ripple on a 128 mm square is planar.
    for (const bool sliver : {true, false}) {
        const int w = 64;
        const int h = sliver ? 16 : 64;
        Cloud c = plane_patch(w, h, {-64, -64, 1000}, {1, 0, 0}, {0, 1, 0}, 2.0);
        for (std::size_t i = 0; i < std::size_t(w) * std::size_t(h); ++i) {
            if (sliver) c.points[3 * i + 1] = float(-64.0 + 0.25 * double(i / std::size_t(w)));
            c.points[3 * i + 2] += i % 2 ? 0.5f : -0.5f;
        }
        Params p;
        p.dt = 1e9;
        p.ct = std::numbers::pi;
        Segmenter seg(w, h, p, "cpu", stats_only());
        const Result r = seg.segment(c.view());
        ASSERT_EQ(r.segment_count, 1u) << sliver;
        EXPECT_NEAR(r.segments[0].plane_rms, 0.5, 0.01) << sliver;
        EXPECT_EQ(r.segments[0].planar, !sliver) << sliver;
    }
}

TEST(SegmentGeometry, OfAMaskIsNaN) {
    const int w = 40;
    const int h = 30;
    std::vector<std::uint8_t> fillable(std::size_t(w) * h, 1);
    Segmenter seg(w, h, {}, "cpu", stats_only());
    Result r;
    seg.segment_mask(MaskView{fillable.data(), nullptr, w, h}, r);
    ASSERT_EQ(r.segments.size(), 1u);
    const SegmentStats& s = r.segments[0];
    EXPECT_TRUE(std::isnan(s.covariance[0]));
    EXPECT_TRUE(std::isnan(s.plane_normal[2]));
    EXPECT_TRUE(std::isnan(s.extents[0]));
    EXPECT_TRUE(std::isnan(s.z_min));
    EXPECT_FALSE(s.planar);
    EXPECT_EQ(s.point_product_sum[5], WideSum{});
}

TEST(SegmentGeometry, RefusesANegativePlanarTolerance) {
    Params p;
    p.planar_tolerance_mm = -1;
    EXPECT_THROW(Segmenter(16, 16, p, "cpu", stats_only()), Error);
    p.planar_tolerance_mm = 1;
    p.planar_tolerance_per_m2 = std::nan("");
    EXPECT_THROW(Segmenter(16, 16, p, "cpu", stats_only()), Error);
}

}  // namespace
}  // namespace pyrseg
