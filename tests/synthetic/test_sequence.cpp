// Tests of the generator's frames of a sequence: the camera's pose, objects moved or hidden, per-frame noise, and
// sequence()'s walk and object plans.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <set>
#include <stdexcept>

#include "pyrseg/synthetic.hpp"
#include "synthetic/scene_checks.hpp"

namespace {

using pyrseg::synthetic::generate;
using pyrseg::synthetic::ObjectChange;
using pyrseg::synthetic::Pose;
using pyrseg::synthetic::Scene;
using pyrseg::synthetic::SceneOptions;
using pyrseg::synthetic::SequenceOptions;
namespace syn = pyrseg::synthetic;

using namespace pyrseg::synthetic_test;  // the shared checks (scene_checks.hpp)

constexpr double kPi = 3.141592653589793;

SceneOptions clean_small() {
    SceneOptions o;
    o.width = 320;
    o.height = 240;
    o.noise_mm = 0;
    o.hole_fraction = 0;
    return o;
}

// A rotation by angle (radians) about the unit axis k, row-major.
Pose turned(const V3& k, double angle) {
    Pose pose;
    const double c = std::cos(angle), s = std::sin(angle), t = 1 - c;
    pose.rotation = {{{t * k[0] * k[0] + c, t * k[0] * k[1] - s * k[2], t * k[0] * k[2] + s * k[1]},
                      {t * k[0] * k[1] + s * k[2], t * k[1] * k[1] + c, t * k[1] * k[2] - s * k[0]},
                      {t * k[0] * k[2] - s * k[1], t * k[1] * k[2] + s * k[0], t * k[2] * k[2] + c}}};
    return pose;
}

// A point (or, without the translation, a direction) of the moved camera's frame in the default camera's frame:
// rotation q + translation.
V3 to_default(const Pose& pose, const V3& q, bool point = true) {
    V3 p{};
    for (std::size_t r = 0; r < 3; ++r) {
        p[r] = dot(pose.rotation[r], q) + (point ? pose.translation[r] : 0.0);
    }
    return p;
}

// The step (mm) and the turn (degrees) from pose a to pose b.
double step_mm(const Pose& a, const Pose& b) {
    return length(sub(b.translation, a.translation));
}
double turn_deg(const Pose& a, const Pose& b) {
    double trace = 0;  // of a^T b
    for (std::size_t r = 0; r < 3; ++r) {
        for (std::size_t c = 0; c < 3; ++c) trace += a.rotation[r][c] * b.rotation[r][c];
    }
    return std::acos(std::clamp((trace - 1) / 2, -1.0, 1.0)) * 180 / kPi;
}

// Every valid pixel of the moved frame, taken back into the default camera's frame, lies on the still scene's
// primitive of its id, with that primitive's normal there.
void expect_seen_from(const Scene& moved, const Pose& pose, const Scene& still) {
    std::size_t seen = 0, off_surface = 0, wrong_normal = 0;
    for (std::size_t i = 0; i < pixel_count(moved); ++i) {
        if (moved.object_id[i] == syn::kNoDataId) continue;
        ++seen;
        const SurfaceCheck c = check_surface(primitive(still, moved.object_id[i]), to_default(pose, point_at(moved, i)),
                                             to_default(pose, normal_at(moved, i), false));
        off_surface += std::abs(c.distance) > 2e-3;
        wrong_normal += !c.normal_ok;
    }
    EXPECT_GT(seen, pixel_count(moved) / 2);
    EXPECT_EQ(off_surface, 0u);
    EXPECT_EQ(wrong_normal, 0u);
}

TEST(SyntheticSequence, StillFrameIsTheSceneByteForByte) {
    for (const syn::Sensor sensor : {syn::Sensor::structured_light, syn::Sensor::realsense_d435}) {
        SCOPED_TRACE(syn::sensor_name(sensor));
        SceneOptions o;
        o.width = 320;
        o.height = 240;
        o.seed = 3;
        o.sensor = sensor;
        const Scene still = generate(o);
        SceneOptions explicit_identity = o;
        explicit_identity.camera_pose.rotation = {{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}};
        explicit_identity.camera_pose.translation = {0, 0, 0};
        explicit_identity.noise_seed = o.seed;  // the seed's own noise, named
        EXPECT_TRUE(same_scene(still, generate(explicit_identity)));
        // A change that changes nothing (an object of the layout, not moved) leaves the frame as it was.
        SceneOptions unchanged = o;
        unchanged.object_changes.push_back({syn::kFirstObjectId, {0, 0, 0}, false});
        unchanged.object_changes.push_back({syn::kFirstObjectId + 500, {10, 0, 0}, true});  // not placed: ignored
        EXPECT_TRUE(same_scene(still, generate(unchanged)));
        // A sequence starts from the still scene.
        SequenceOptions so;
        so.scene = o;
        so.frames = 3;
        const std::vector<SceneOptions> frames = syn::sequence(so);
        ASSERT_EQ(frames.size(), 3u);
        EXPECT_TRUE(same_scene(still, generate(frames[0])));
        EXPECT_FALSE(same_bytes(still.object_id, generate(frames[1]).object_id)) << "the camera moved";
    }
}

TEST(SyntheticSequence, PureTranslationMovesAPointWhereGeometrySays) {
    const SceneOptions o = clean_small();
    const Scene still = generate(o);
    // The point at the image's centre, and a sideways translation that moves it exactly 8 pixels right and 5 down.
    const auto u = static_cast<std::size_t>(o.width / 2), v = static_cast<std::size_t>(o.height / 2);
    const std::size_t at = v * static_cast<std::size_t>(o.width) + u;
    ASSERT_NE(still.object_id[at], syn::kNoDataId);
    const V3 p = point_at(still, at);
    ASSERT_NEAR((p[0] / p[2]) * still.fx + still.cx, double(u), 1e-6);
    SceneOptions moved = o;
    moved.camera_pose.translation = {-8 * p[2] / still.fx, -5 * p[2] / still.fy, 0};
    const Scene after = generate(moved);
    const std::size_t there = (v + 5) * static_cast<std::size_t>(o.width) + u + 8;
    EXPECT_EQ(after.object_id[there], still.object_id[at]);
    const V3 expected = sub(p, moved.camera_pose.translation);
    const V3 q = point_at(after, there);
    EXPECT_NEAR(q[0], expected[0], 1e-3);
    EXPECT_NEAR(q[1], expected[1], 1e-3);
    EXPECT_NEAR(q[2], expected[2], 1e-3);
    // Every primitive moved by -t, axes unchanged.
    ASSERT_EQ(after.primitives.size(), still.primitives.size());
    for (std::size_t k = 0; k < still.primitives.size(); ++k) {
        const V3 c = sub(still.primitives[k].center, moved.camera_pose.translation);
        for (std::size_t i = 0; i < 3; ++i) EXPECT_NEAR(after.primitives[k].center[i], c[i], 1e-9);
        EXPECT_EQ(after.primitives[k].axes, still.primitives[k].axes);
    }
    // And every pixel sees the still scene's surfaces from there.
    expect_seen_from(after, moved.camera_pose, still);
}

TEST(SyntheticSequence, TurnedAndMovedCameraSeesTheSameSurfaces) {
    const SceneOptions o = clean_small();
    const Scene still = generate(o);
    for (const double degrees : {3.0, -7.0}) {
        SCOPED_TRACE(degrees);
        SceneOptions moved = o;
        const double n = std::sqrt(0.2 * 0.2 + 1 + 0.3 * 0.3);
        moved.camera_pose = turned({0.2 / n, 1 / n, 0.3 / n}, degrees * kPi / 180);
        moved.camera_pose.translation = {25, -40, 60};
        expect_seen_from(generate(moved), moved.camera_pose, still);
    }
    // A turn about the optical axis by 90 degrees: the still frame's centre row is the moved frame's centre column.
    SceneOptions square = o;
    square.width = square.height = 241;
    const Scene a = generate(square);
    square.camera_pose = turned({0, 0, 1}, kPi / 2);
    const Scene b = generate(square);
    const auto w = static_cast<std::size_t>(square.width), mid = w / 2;
    std::size_t same = 0;
    for (std::size_t x = 0; x < w; ++x) {
        // The moved camera's y axis is the default's -x: the default's pixel (x, mid) is the moved one's
        // (mid, w - 1 - x).
        same += a.object_id[mid * w + x] == b.object_id[(w - 1 - x) * w + mid];
    }
    EXPECT_GE(same, w - 2);
}

TEST(SyntheticSequence, ObjectIdsAreStableAcrossFrames) {
    for (const bool object_motion : {false, true}) {
        SCOPED_TRACE(object_motion);
        SequenceOptions so;
        so.scene = clean_small();
        so.scene.width = 160;
        so.scene.height = 120;
        so.scene.seed = 2;
        so.frames = 40;
        so.object_motion = object_motion;
        const std::vector<SceneOptions> frames = syn::sequence(so);
        const Scene first = generate(frames[0]);
        std::size_t hidden_seen = 0, moved_seen = 0;
        for (std::size_t f = 0; f < frames.size(); f += 3) {
            SCOPED_TRACE(f);
            const Scene s = generate(frames[f]);
            const Pose& pose = frames[f].camera_pose;
            std::map<std::uint32_t, const ObjectChange*> changes;
            for (const ObjectChange& c : frames[f].object_changes) changes[c.id] = &c;
            // Frame 0's primitives (objects hidden there put back: the still scene's), moved as the frame's
            // changes say.
            const Scene& reference = first;
            for (const auto& prim : s.primitives) {
                const auto it = changes.find(prim.id);
                V3 offset{};
                if (it != changes.end()) {
                    ASSERT_FALSE(it->second->hidden) << "a hidden object has no primitive";
                    offset = it->second->offset;
                    moved_seen += length(offset) > 0;
                }
                const auto same = std::find_if(reference.primitives.begin(), reference.primitives.end(),
                                               [&](const auto& r) { return r.id == prim.id; });
                if (same == reference.primitives.end()) continue;  // hidden in frame 0
                EXPECT_EQ(prim.shape, same->shape);
                EXPECT_EQ(prim.half_size, same->half_size);
                const V3 back = to_default(pose, prim.center);
                for (std::size_t i = 0; i < 3; ++i) EXPECT_NEAR(back[i], same->center[i] + offset[i], 1e-6);
            }
            for (const auto& [id, change] : changes) {
                if (!change->hidden) continue;
                ++hidden_seen;
                EXPECT_EQ(std::count(s.object_id.begin(), s.object_id.end(), id), 0) << id;
            }
        }
        if (object_motion) {
            EXPECT_GT(hidden_seen, 0u);
            EXPECT_GT(moved_seen, 0u);
        } else {
            EXPECT_EQ(hidden_seen + moved_seen, 0u);
        }
    }
}

TEST(SyntheticSequence, WalkStaysWithinItsStepAndTurn) {
    for (const std::uint64_t seed : {1u, 7u}) {
        SequenceOptions so;
        so.scene.seed = seed;
        so.frames = 300;
        const std::vector<SceneOptions> frames = syn::sequence(so);
        ASSERT_EQ(frames.size(), 300u);
        EXPECT_EQ(frames[0].camera_pose, Pose{});
        EXPECT_EQ(frames[0].noise_seed, 0u);
        double largest_step = 0, largest_turn = 0, farthest = 0;
        std::set<std::uint64_t> noise_seeds;
        for (std::size_t f = 1; f < frames.size(); ++f) {
            const Pose& a = frames[f - 1].camera_pose;
            const Pose& b = frames[f].camera_pose;
            largest_step = std::max(largest_step, step_mm(a, b));
            largest_turn = std::max(largest_turn, turn_deg(a, b));
            farthest = std::max(farthest, length(b.translation));
            for (std::size_t i = 0; i < 3; ++i) {
                for (std::size_t j = 0; j < 3; ++j) {
                    double d = 0;
                    for (std::size_t r = 0; r < 3; ++r) d += b.rotation[r][i] * b.rotation[r][j];
                    EXPECT_NEAR(d, i == j ? 1.0 : 0.0, 1e-12);
                }
            }
            EXPECT_TRUE(frames[f].object_changes.empty());
            noise_seeds.insert(frames[f].noise_seed);
        }
        EXPECT_NEAR(largest_step, 20.0, 1e-9);
        EXPECT_LE(largest_turn, 2.0 + 1e-6);
        EXPECT_GT(largest_turn, 2.0 - 1e-6);
        EXPECT_LT(farthest, 300.0) << "the walk stays near its start";
        EXPECT_EQ(noise_seeds.size(), frames.size() - 1) << "every frame its own noise";
        EXPECT_EQ(noise_seeds.count(0), 0u);
        // Deterministic.
        const std::vector<SceneOptions> again = syn::sequence(so);
        for (std::size_t f = 0; f < frames.size(); ++f) {
            EXPECT_EQ(again[f].camera_pose, frames[f].camera_pose);
            EXPECT_EQ(again[f].noise_seed, frames[f].noise_seed);
        }
    }
    SequenceOptions still;
    still.max_step_mm = 0;
    still.max_turn_deg = 0;
    still.frames = 5;
    for (const SceneOptions& f : syn::sequence(still)) EXPECT_EQ(f.camera_pose, Pose{});
}

TEST(SyntheticSequence, ObjectsSlideVanishAndComeBack) {
    std::size_t sliding = 0, occluded = 0, leaving = 0, appearing = 0;
    for (std::uint64_t seed = 1; seed <= 4; ++seed) {
        SequenceOptions so;
        so.scene.seed = seed;
        so.frames = 300;
        so.object_motion = true;
        const std::vector<SceneOptions> frames = syn::sequence(so);
        std::map<std::uint32_t, std::vector<const ObjectChange*>> by_id;  // nullptr: no change that frame
        const int placed = generate([&] {
                               SceneOptions tiny = so.scene;
                               tiny.width = tiny.height = 1;
                               return tiny;
                           }())
                               .objects_placed;
        for (int k = 0; k < placed; ++k) by_id[syn::kFirstObjectId + std::uint32_t(k)].assign(frames.size(), nullptr);
        for (std::size_t f = 0; f < frames.size(); ++f) {
            for (const ObjectChange& c : frames[f].object_changes) {
                ASSERT_TRUE(by_id.count(c.id)) << c.id;
                by_id[c.id][f] = &c;
            }
        }
        for (const auto& [id, changes] : by_id) {
            double fastest = 0;
            std::vector<int> hidden;
            for (std::size_t f = 0; f < changes.size(); ++f) {
                if (changes[f] != nullptr && changes[f]->hidden) hidden.push_back(int(f));
                if (f == 0) continue;
                const V3 a = changes[f - 1] ? changes[f - 1]->offset : V3{};
                const V3 b = changes[f] ? changes[f]->offset : V3{};
                fastest = std::max(fastest, length(sub(a, b)));
            }
            EXPECT_LE(fastest, 4.2) << id;
            sliding += fastest > 0;
            // The runs of hidden frames: from frame 0 (appears), to the end (leaves), or between (occluded; an
            // occlusion next to the others joins their run, so those allow 8 frames more).
            for (std::size_t h = 0; h < hidden.size();) {
                std::size_t e = h;
                while (e + 1 < hidden.size() && hidden[e + 1] == hidden[e] + 1) ++e;
                const int first = hidden[h], last = hidden[e];
                if (first == 0) {
                    ++appearing;
                    EXPECT_LT(last, 200 + 8) << id;
                } else if (last == int(frames.size()) - 1) {
                    ++leaving;
                    EXPECT_GE(first, 100 - 8) << id;
                } else {
                    ++occluded;
                    EXPECT_GE(last - first + 1, 2) << id;
                    EXPECT_LE(last - first + 1, 8) << id;
                }
                h = e + 1;
            }
        }
    }
    EXPECT_GT(sliding, 5u);
    EXPECT_GT(occluded, 5u);
    EXPECT_GT(leaving + appearing, 0u);
}

TEST(SyntheticSequence, NoiseSeedChangesTheNoiseAlone) {
    for (const syn::Sensor sensor : {syn::Sensor::structured_light, syn::Sensor::azure_kinect}) {
        SCOPED_TRACE(syn::sensor_name(sensor));
        SceneOptions o;
        o.width = 160;
        o.height = 120;
        o.sensor = sensor;
        o.shadows = false;  // the blobs alone: they follow seed
        const Scene a = generate(o);
        o.noise_seed = 77;
        const Scene b = generate(o);
        EXPECT_EQ(a.primitives, b.primitives);
        EXPECT_FALSE(same_bytes(a.points, b.points));
        if (sensor == syn::Sensor::structured_light) {
            EXPECT_TRUE(same_bytes(a.object_id, b.object_id));
        }
    }
}

TEST(SyntheticSequence, RejectsBadFrameAndSequenceOptions) {
    const auto rejects = [](const SceneOptions& o) { EXPECT_THROW((void)generate(o), std::invalid_argument); };
    SceneOptions o = clean_small();
    o.width = o.height = 8;
    SceneOptions bad = o;
    bad.camera_pose.rotation[0][0] = 1.01;  // not orthonormal
    rejects(bad);
    bad = o;
    bad.camera_pose.rotation[2][2] = -1;  // a reflection
    rejects(bad);
    bad = o;
    bad.camera_pose.translation[1] = std::numeric_limits<double>::quiet_NaN();
    rejects(bad);
    bad = o;
    bad.object_changes.push_back({syn::kFloorId, {}, true});
    rejects(bad);
    bad = o;
    bad.object_changes = {{syn::kFirstObjectId, {}, true}, {syn::kFirstObjectId, {1, 0, 0}, false}};
    rejects(bad);
    bad = o;
    bad.object_changes.push_back({syn::kFirstObjectId, {0, std::numeric_limits<double>::infinity(), 0}, false});
    rejects(bad);

    const auto rejects_sequence = [](const SequenceOptions& s) {
        EXPECT_THROW((void)syn::sequence(s), std::invalid_argument);
    };
    SequenceOptions s;
    s.scene = o;
    SequenceOptions bad_sequence = s;
    bad_sequence.frames = 0;
    rejects_sequence(bad_sequence);
    bad_sequence = s;
    bad_sequence.max_step_mm = -1;
    rejects_sequence(bad_sequence);
    bad_sequence = s;
    bad_sequence.max_turn_deg = 31;
    rejects_sequence(bad_sequence);
    bad_sequence = s;
    bad_sequence.scene.object_count = -1;  // the scene's own checks
    rejects_sequence(bad_sequence);
    bad_sequence = s;
    bad_sequence.scene.camera_pose.translation[0] = 5;  // replaced, not checked
    EXPECT_NO_THROW((void)syn::sequence(bad_sequence));
}

}  // namespace
