// The scene summary (docs/algorithm.md section 10c): supports and the objects standing on them, from the segment
// statistics; on hand-made statistics whose answer is known, and on synthetic tabletops, whose boxes the generator
// knows.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <map>
#include <vector>

#include "pyrseg/error.hpp"
#include "pyrseg/presets.hpp"
#include "pyrseg/scene.hpp"
#include "pyrseg/segmenter.hpp"
#include "pyrseg/synthetic.hpp"
#include "tools/eval/tabletop_boxes.hpp"

namespace pyrseg {
namespace {

using Vec3 = std::array<double, 3>;

double dot(const Vec3& a, const Vec3& b) {
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

// A segment's statistics as section 10b derives them, for an axis-aligned block of points: centred on `centre`,
// with these variances along x, y and z (the camera looks along +z, so "up", towards the camera, is -z).
SegmentStats block(std::uint32_t label, std::uint32_t pixels, Vec3 centre, Vec3 variance) {
    SegmentStats s;
    s.label = label;
    s.pixel_count = pixels;
    s.fillable_count = pixels;
    s.centroid = centre;
    s.covariance = {variance[0], 0, 0, variance[1], 0, variance[2]};
    // Axes by decreasing variance, the third the plane normal towards the camera.
    std::array<std::size_t, 3> order = {0, 1, 2};
    std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return variance[a] > variance[b]; });
    for (std::size_t i = 0; i < 3; ++i) {
        s.axes[i] = {0, 0, 0};
        s.axes[i][order[i]] = 1;
        s.extents[i] = 2 * std::sqrt(3 * variance[order[i]]);
    }
    s.plane_normal = s.axes[2];
    if (dot(s.plane_normal, centre) > 0) {
        for (double& c : s.plane_normal) c = -c;
    }
    s.axes[2] = s.plane_normal;
    s.plane_offset = -dot(s.plane_normal, centre);
    s.plane_rms = std::sqrt(variance[order[2]]);
    return s;
}

TEST(Scene, AnObjectStandsOnTheTableNotOnTheFloorOrTheWall) {
    // Millimetres; the camera looks down +z at a table 1000 mm away and a floor 1700 mm away.
    const SegmentStats table = block(1, 50000, {0, 0, 1000}, {40000, 20000, 1});
    const SegmentStats floor = block(2, 30000, {0, 300, 1700}, {90000, 30000, 4});
    const SegmentStats wall = block(3, 20000, {0, -600, 1200}, {40000, 1, 20000});  // its normal along y
    // A mug: 100 mm tall (z 900..1000), its points spread uniformly.
    const SegmentStats mug = block(4, 2000, {10, 20, 950}, {30 * 30 / 3.0, 40 * 40 / 3.0, 50 * 50 / 3.0});
    const SegmentStats speck = block(5, 20, {0, 0, 990}, {4, 4, 4});
    Scene scene;
    describe_scene({table, floor, wall, mug, speck}, Params{}, SceneParams{}, scene);
    ASSERT_EQ(scene.supports.size(), 3u);
    EXPECT_EQ(scene.supports[0].label, 1u);  // the largest first
    EXPECT_TRUE(scene.supports[0].level);
    EXPECT_TRUE(scene.supports[1].level);   // the floor, parallel to the table
    EXPECT_FALSE(scene.supports[2].level);  // the wall
    ASSERT_EQ(scene.objects.size(), 1u);    // the speck is under object_min_pixels, the wall stands on nothing
    const SceneObject& o = scene.objects[0];
    EXPECT_EQ(o.label, 4u);
    EXPECT_EQ(o.support, 0);
    EXPECT_TRUE(o.touches);
    EXPECT_NEAR(o.height, 100.0, 1e-9);
    EXPECT_NEAR(dot(o.axes[2], {0, 0, -1}), 1.0, 1e-12);  // up is the table's normal
    EXPECT_NEAR(o.extents[2], 100.0, 1e-9);
    EXPECT_NEAR(o.box_centre[2], 950.0, 1e-9);
    // Its in-plane axes: the larger spread (y, 80 mm) first.
    EXPECT_NEAR(std::fabs(o.axes[0][1]), 1.0, 1e-12);
    EXPECT_NEAR(o.extents[0], 80.0, 1e-9);
    EXPECT_NEAR(o.extents[1], 60.0, 1e-9);
}

TEST(Scene, TheLargestOfCoplanarSupportsAndObjectsAboveTheTable) {
    // The table in two pieces (a colour edge split it): the object stands on the larger, though its foot lies a
    // millimetre nearer the smaller's plane.
    const SegmentStats big = block(1, 50000, {0, 0, 1000}, {40000, 20000, 1});
    const SegmentStats piece = block(2, 20000, {300, 0, 999}, {4000, 2000, 1});
    // A cap 60..100 mm above the table (its body not labelled): over the table, but not touching it.
    const SegmentStats cap = block(3, 500, {0, 0, 920}, {100, 100, 20 * 20 / 3.0});
    Scene scene;
    describe_scene({big, piece, cap}, Params{}, SceneParams{}, scene);
    ASSERT_EQ(scene.supports.size(), 2u);
    ASSERT_EQ(scene.objects.size(), 1u);
    EXPECT_EQ(scene.objects[0].support, 0);
    EXPECT_FALSE(scene.objects[0].touches);
    EXPECT_NEAR(scene.objects[0].height, 100.0, 1e-9);
    EXPECT_NEAR(scene.objects[0].extents[2], 100.0, 1e-9);  // down to the table: it rests there, unseen
    EXPECT_NEAR(scene.objects[0].box_centre[2], 950.0, 1e-9);
}

TEST(Scene, UnitsAndThresholds) {
    // The same scene in metres: contact_mm is millimetres whatever the unit.
    const SegmentStats table = block(1, 50000, {0, 0, 1.0}, {0.04, 0.02, 1e-6});
    const SegmentStats lifted = block(2, 2000, {0, 0, 0.92}, {1e-4, 1e-4, 0.02 * 0.02 / 3.0});  // 60 mm up
    Params metres;
    metres.unit_mm = 1000;
    Scene scene;
    describe_scene({table, lifted}, metres, SceneParams{}, scene);
    ASSERT_EQ(scene.objects.size(), 1u);
    EXPECT_FALSE(scene.objects[0].touches);
    EXPECT_NEAR(scene.objects[0].extents[2], 0.1, 1e-12);
    SceneParams loose;
    loose.contact_mm = 70;
    describe_scene({table, lifted}, metres, loose, scene);
    EXPECT_TRUE(scene.objects[0].touches);

    SceneParams bad;
    bad.support_min_share = 1.5;
    EXPECT_THROW(describe_scene({table}, Params{}, bad, scene), Error);
    bad = SceneParams{};
    bad.contact_mm = std::numeric_limits<double>::quiet_NaN();
    EXPECT_THROW(describe_scene({table}, Params{}, bad, scene), Error);
    bad = SceneParams{};
    bad.level_degrees = 91;
    EXPECT_THROW(describe_scene({table}, Params{}, bad, scene), Error);
    std::vector<float> points(6);
    std::vector<std::uint32_t> labels(3);
    EXPECT_THROW(fit_object_boxes(points, labels, {}, scene), Error);
}

// A synthetic tabletop: objects apart on a plain floor, seen by a RealSense model from 1 m.
struct Tabletop {
    synthetic::Scene frame;
    Result result;
};

Tabletop tabletop(std::uint64_t seed) {
    synthetic::SceneOptions o;
    o.seed = seed;
    o.object_count = 8;
    o.bin = false;
    o.touching = false;
    o.sensor = synthetic::Sensor::realsense_d435;
    o.camera_distance_mm = 1000;
    Tabletop t{synthetic::generate(o), {}};
    Outputs outputs;
    outputs.segment_stats = true;
    outputs.fillable_mask = true;
    Segmenter segmenter(o.width, o.height, sensor_preset(SensorKind::realsense_d435), "cpu", outputs);
    t.result = segmenter.segment(CloudView{t.frame.points.data(), nullptr, o.width, o.height});
    return t;
}

// The 3D IoU of an object's box with a generator box.
double box_iou(const SceneObject& o, const synthetic::Primitive& p) {
    return eval::box_iou({o.label, o.box_centre, o.axes, o.extents},
                         {p.id, p.center, p.axes, {2 * p.half_size[0], 2 * p.half_size[1], 2 * p.half_size[2]}});
}

TEST(Scene, SyntheticTabletopsTheFloorIsTheSupportAndTheBoxesFitTheGeneratorsBoxes) {
    std::vector<double> ious;
    for (const std::uint64_t seed : {1u, 2u, 3u, 4u}) {
        const Tabletop t = tabletop(seed);
        Scene scene;
        describe_scene(t.result.segments, sensor_preset(SensorKind::realsense_d435), SceneParams{}, scene);
        fit_object_boxes(t.frame.points, t.result.labels, t.result.fillable_mask, scene);
        ASSERT_FALSE(scene.supports.empty());
        // The largest support is the floor: most of its pixels are the floor's.
        std::map<std::uint32_t, std::map<std::uint32_t, std::size_t>> overlap;  // label -> object id -> pixels
        for (std::size_t i = 0; i < t.result.labels.size(); ++i) {
            if (t.result.labels[i] != 0) ++overlap[t.result.labels[i]][t.frame.object_id[i]];
        }
        const auto& floor_overlap = overlap[scene.supports[0].label];
        EXPECT_GT(floor_overlap.count(synthetic::kFloorId) ? floor_overlap.at(synthetic::kFloorId) : 0u,
                  scene.supports[0].pixel_count * 9 / 10)
            << "seed " << seed;
        EXPECT_GT(dot(scene.supports[0].normal, {0, 0, -1}), 0.5) << "the floor's normal points at the camera";
        // Each box object the segmentation finds whole (one segment holding 80% of the box's pixels and lying 80%
        // on it) stands on the floor, and its box fits the generator's.
        for (const SceneObject& o : scene.objects) {
            std::uint32_t id = 0;
            std::size_t most = 0;
            for (const auto& [object_id, pixels] : overlap[o.label]) {
                if (pixels > most) {
                    most = pixels;
                    id = object_id;
                }
            }
            if (id < synthetic::kFirstObjectId || most * 10 < o.pixel_count * 8) continue;
            const auto primitive = std::find_if(t.frame.primitives.begin(), t.frame.primitives.end(),
                                                [&](const synthetic::Primitive& q) { return q.id == id; });
            ASSERT_NE(primitive, t.frame.primitives.end());
            const synthetic::Primitive& p = *primitive;
            const auto object_pixels = std::size_t(std::count(t.frame.object_id.begin(), t.frame.object_id.end(), id));
            if (p.shape != synthetic::Shape::box || most * 10 < object_pixels * 8) continue;
            EXPECT_EQ(o.support, 0) << "seed " << seed << ", object " << id;
            ious.push_back(box_iou(o, p));
        }
    }
    for (const double iou : ious) std::printf("box IoU %.3f\n", iou);
    ASSERT_GE(ious.size(), 8u);
    std::sort(ious.begin(), ious.end());
    EXPECT_GE(ious[ious.size() / 2], 0.6) << "median box IoU over " << ious.size() << " boxes";
}

TEST(Scene, FittedBoxesHoldEveryFillablePointOfTheirSegment) {
    const Tabletop t = tabletop(5);
    Scene scene;
    describe_scene(t.result.segments, sensor_preset(SensorKind::realsense_d435), SceneParams{}, scene);
    fit_object_boxes(t.frame.points, t.result.labels, t.result.fillable_mask, scene);
    ASSERT_FALSE(scene.objects.empty());
    std::map<std::uint32_t, const SceneObject*> by_label;
    for (const SceneObject& o : scene.objects) by_label[o.label] = &o;
    std::size_t checked = 0;
    for (std::size_t i = 0; i < t.result.labels.size(); ++i) {
        const auto it = by_label.find(t.result.labels[i]);
        if (it == by_label.end() || t.result.fillable_mask[i] == 0) continue;
        const Vec3 p = {t.frame.points[3 * i], t.frame.points[3 * i + 1], t.frame.points[3 * i + 2]};
        if (!std::isfinite(p[2])) continue;
        const SceneObject& o = *it->second;
        // A millionth of the box's size for the rounding of its centre.
        const double slack = 1e-6 * (o.extents[0] + o.extents[1] + o.extents[2]);
        const eval::OrientedBox grown{
            o.label, o.box_centre, o.axes, {o.extents[0] + slack, o.extents[1] + slack, o.extents[2] + slack}};
        ASSERT_TRUE(eval::box_holds(grown, p)) << "pixel " << i << " of segment " << o.label;
        ++checked;
    }
    EXPECT_GT(checked, 1000u);
}

}  // namespace
}  // namespace pyrseg
