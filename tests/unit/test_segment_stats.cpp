// Per-segment statistics (docs/algorithm.md section 10): what the derived fields mean, checked against values the
// test computes from the frame itself. Bit-exactness against the reference is the conformance suite's job.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <vector>

#include "pyrseg/segmenter.hpp"
#include "pyrseg/synthetic.hpp"

namespace pyrseg {
namespace {

synthetic::Scene test_scene() {
    synthetic::SceneOptions o;
    o.width = 320;
    o.height = 240;
    o.seed = 11;
    return synthetic::generate(o);
}

Outputs stats_only() {
    Outputs o;
    o.segment_stats = true;
    return o;
}

TEST(SegmentStats, DescribeTheLabelledPixelsOfEachSegment) {
    const synthetic::Scene s = test_scene();
    Outputs with_mask = stats_only();
    with_mask.fillable_mask = true;
    Segmenter seg(s.width, s.height, {}, "cpu", with_mask);
    const Result r = seg.segment(CloudView{s.points.data(), s.normals.data(), s.width, s.height});
    ASSERT_GT(r.segment_count, 3u);
    ASSERT_EQ(r.segments.size(), r.segment_count);

    // The exact means, in double, over the same pixels.
    struct Expected {
        std::uint32_t count = 0;
        std::uint32_t fillable = 0;
        int x_min = 1 << 30, y_min = 1 << 30, x_max = -1, y_max = -1;
        double sum[3] = {0, 0, 0};
        double normal[3] = {0, 0, 0};
    };
    std::vector<Expected> expected(r.segment_count);
    for (int y = 0; y < s.height; ++y) {
        for (int x = 0; x < s.width; ++x) {
            const std::size_t i = std::size_t(y) * std::size_t(s.width) + std::size_t(x);
            if (r.labels[i] == 0) continue;
            Expected& e = expected[r.labels[i] - 1];
            ++e.count;
            e.x_min = std::min(e.x_min, x);
            e.y_min = std::min(e.y_min, y);
            e.x_max = std::max(e.x_max, x);
            e.y_max = std::max(e.y_max, y);
            if (r.fillable_mask[i] == 0) continue;  // the sums are of the fillable pixels
            ++e.fillable;
            for (int c = 0; c < 3; ++c) {
                e.sum[c] += double(s.points[3 * i + std::size_t(c)]);
                e.normal[c] += double(s.normals[3 * i + std::size_t(c)]);
            }
        }
    }
    for (std::uint32_t k = 0; k < r.segment_count; ++k) {
        const SegmentStats& got = r.segments[k];
        const Expected& e = expected[k];
        SCOPED_TRACE("segment " + std::to_string(k + 1));
        EXPECT_EQ(got.label, k + 1);
        EXPECT_EQ(got.pixel_count, e.count);
        EXPECT_EQ(got.fillable_count, e.fillable);
        EXPECT_LT(got.fillable_count, got.pixel_count) << "edge pixels are counted, not summed";
        EXPECT_EQ(got.x_min, e.x_min);
        EXPECT_EQ(got.y_min, e.y_min);
        EXPECT_EQ(got.x_max, e.x_max);
        EXPECT_EQ(got.y_max, e.y_max);
        EXPECT_EQ(got.point_shift, 4) << "millimetres: steps of 1/16 mm";
        double length = 0;
        for (int c = 0; c < 3; ++c) {
            // Each point is rounded to the nearest 1/16 mm, so the mean is off by at most 1/32 mm.
            EXPECT_NEAR(got.centroid[c], e.sum[c] / e.fillable, 1.0 / 32 + 1e-9) << "coordinate " << c;
            length += got.mean_normal[c] * got.mean_normal[c];
        }
        EXPECT_NEAR(length, 1.0, 1e-12);
        // The mean normal points where the normals do (they are quantized to 2^-13 first).
        double dot = 0;
        double e_length = 0;
        for (int c = 0; c < 3; ++c) {
            dot += got.mean_normal[c] * e.normal[c];
            e_length += e.normal[c] * e.normal[c];
        }
        EXPECT_NEAR(dot / std::sqrt(e_length), 1.0, 1e-6);
    }
}

TEST(SegmentStats, FollowTheCallersUnits) {
    const synthetic::Scene s = test_scene();
    std::vector<float> metres(s.points.size());
    for (std::size_t i = 0; i < metres.size(); ++i) metres[i] = s.points[i] / 1000.0f;
    Params mm;
    Params m;
    m.unit_mm = 1000.0;
    Segmenter seg_mm(s.width, s.height, mm, "cpu", stats_only());
    Segmenter seg_m(s.width, s.height, m, "cpu", stats_only());
    const Result a = seg_mm.segment(CloudView{s.points.data(), s.normals.data(), s.width, s.height});
    const Result b = seg_m.segment(CloudView{metres.data(), s.normals.data(), s.width, s.height});
    ASSERT_EQ(a.labels, b.labels);
    ASSERT_EQ(b.segments.size(), a.segments.size());
    for (std::size_t k = 0; k < a.segments.size(); ++k) {
        EXPECT_EQ(b.segments[k].point_shift, 14) << "metres: steps of 2^-14 m (0.061 mm)";
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(b.segments[k].centroid[c] * 1000.0, a.segments[k].centroid[c], 0.1);
    }
}

TEST(SegmentStats, OfAMaskHaveNoGeometry) {
    const int w = 40;
    const int h = 30;
    std::vector<std::uint8_t> fillable(std::size_t(w) * h, 0);
    for (int y = 5; y < 25; ++y) {
        for (int x = 3; x < 17; ++x) fillable[std::size_t(y) * w + std::size_t(x)] = 1;
    }
    Segmenter seg(w, h, {}, "cpu", stats_only());
    Result r;
    seg.segment_mask(MaskView{fillable.data(), nullptr, w, h}, r);
    ASSERT_EQ(r.segments.size(), 1u);
    const SegmentStats& s = r.segments[0];
    EXPECT_EQ(s.pixel_count, 20u * 14u + 2u * 20u + 2u * 14u) << "the block and the valid pixels around it (step 6c)";
    EXPECT_EQ(s.x_min, 2);
    EXPECT_EQ(s.x_max, 17);
    EXPECT_EQ(s.y_min, 4);
    EXPECT_EQ(s.y_max, 25);
    EXPECT_TRUE(std::isnan(s.centroid[0]));
    EXPECT_TRUE(std::isnan(s.mean_normal[2]));
}

TEST(SegmentStats, AreEmptyUnlessAskedFor) {
    const synthetic::Scene s = test_scene();
    Segmenter seg(s.width, s.height, {}, "cpu");
    const Result r = seg.segment(CloudView{s.points.data(), s.normals.data(), s.width, s.height});
    EXPECT_GT(r.segment_count, 0u);
    EXPECT_TRUE(r.segments.empty());
}

TEST(SegmentStats, KeepRawLabelsWhenLabelsAreNotCompacted) {
    const synthetic::Scene s = test_scene();
    Params p;
    p.compact = false;
    Segmenter seg(s.width, s.height, p, "cpu", stats_only());
    const Result r = seg.segment(CloudView{s.points.data(), s.normals.data(), s.width, s.height});
    ASSERT_EQ(r.segments.size(), r.segment_count);
    for (std::size_t k = 1; k < r.segments.size(); ++k) EXPECT_LT(r.segments[k - 1].label, r.segments[k].label);
    for (const SegmentStats& seg_stats : r.segments) {
        const std::size_t i = std::size_t(seg_stats.y_min) * std::size_t(s.width);
        bool found = false;
        for (int x = seg_stats.x_min; x <= seg_stats.x_max && !found; ++x)
            found = r.labels[i + std::size_t(x)] == seg_stats.label;
        EXPECT_TRUE(found) << "label " << seg_stats.label << " not on the top row of its box";
    }
}

}  // namespace
}  // namespace pyrseg
