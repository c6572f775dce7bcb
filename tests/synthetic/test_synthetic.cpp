// Tests of the synthetic scene generator: determinism, sizes, the ground truth's invariants, contacts, holes and
// noise.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <set>
#include <stdexcept>

#include "pyrseg/synthetic.hpp"
#include "synthetic/scene_checks.hpp"

namespace {

using pyrseg::synthetic::generate;
using pyrseg::synthetic::Primitive;
using pyrseg::synthetic::Scene;
using pyrseg::synthetic::SceneOptions;
using pyrseg::synthetic::Shape;
namespace syn = pyrseg::synthetic;

using namespace pyrseg::synthetic_test;  // the shared checks (scene_checks.hpp)

std::size_t missing(const Scene& s) {
    return static_cast<std::size_t>(std::count(s.object_id.begin(), s.object_id.end(), syn::kNoDataId));
}

// The per-pixel invariants every scene must hold.
void expect_consistent(const Scene& s) {
    const std::size_t n = pixel_count(s);
    ASSERT_EQ(s.points.size(), 3 * n);
    ASSERT_EQ(s.normals.size(), 3 * n);
    ASSERT_EQ(s.object_id.size(), n);
    std::size_t bad = 0;
    for (std::size_t i = 0; i < n; ++i) {
        const bool valid = s.object_id[i] != syn::kNoDataId;
        for (int c = 0; c < 3; ++c) {
            bad += std::isnan(s.points[3 * i + static_cast<std::size_t>(c)]) == valid;
            bad += std::isnan(s.normals[3 * i + static_cast<std::size_t>(c)]) == valid;
        }
        if (!valid) continue;
        const V3 p = point_at(s, i), nrm = normal_at(s, i);
        bad += std::abs(length(nrm) - 1) > 1e-6;
        bad += !(dot(nrm, p) < 0);
        bad += !(p[2] > 0);
    }
    EXPECT_EQ(bad, 0u);
}

SceneOptions clean(SceneOptions o = {}) {
    o.noise_mm = 0;
    o.hole_fraction = 0;
    return o;
}

TEST(Synthetic, SameSeedGivesIdenticalBytes) {
    SceneOptions o;
    o.seed = 42;
    const Scene a = generate(o), b = generate(o);
    EXPECT_TRUE(same_scene(a, b));
}

TEST(Synthetic, DifferentSeedsDiffer) {
    SceneOptions o;
    const Scene a = generate(o);
    o.seed = 2;
    const Scene b = generate(o);
    EXPECT_FALSE(same_bytes(a.points, b.points));
    EXPECT_FALSE(same_bytes(a.object_id, b.object_id));
    EXPECT_NE(a.primitives, b.primitives);
}

TEST(Synthetic, ThreadCountDoesNotChangeOutput) {
    SceneOptions o;
    o.width = 331;  // not a multiple of the tile width, so tiles and bands end ragged
    o.height = 203;
    o.threads = 1;
    const Scene one = generate(o);
    o.threads = 3;
    EXPECT_TRUE(same_scene(one, generate(o)));
    o.threads = 0;
    EXPECT_TRUE(same_scene(one, generate(o)));
}

TEST(Synthetic, LayoutDoesNotDependOnSizeNoiseOrHoles) {
    SceneOptions o;
    o.seed = 9;
    const Scene a = generate(o);
    SceneOptions other = o;
    other.width = 160;
    other.height = 90;
    other.noise_mm = 2;
    other.hole_fraction = 0.2;
    const Scene b = generate(other);
    EXPECT_EQ(a.primitives, b.primitives);
    EXPECT_EQ(a.objects_placed, b.objects_placed);
}

TEST(Synthetic, SmallAndOddSizesWork) {
    const int sizes[][2] = {{1, 1}, {1, 7}, {7, 1}, {9, 9}, {640, 480}, {33, 17}};
    for (const auto& size : sizes) {
        SCOPED_TRACE(std::to_string(size[0]) + "x" + std::to_string(size[1]));
        SceneOptions o = clean();
        o.width = size[0];
        o.height = size[1];
        const Scene s = generate(o);
        EXPECT_EQ(s.width, size[0]);
        EXPECT_EQ(s.height, size[1]);
        EXPECT_GT(s.fx, 0);
        EXPECT_EQ(s.fx, s.fy);
        EXPECT_EQ(s.cx, (size[0] - 1) / 2.0);
        EXPECT_EQ(s.cy, (size[1] - 1) / 2.0);
        expect_consistent(s);
        EXPECT_EQ(missing(s), 0u) << "a frame without holes has data everywhere";
    }
}

TEST(Synthetic, FocalLengthScalesWithWidth) {
    SceneOptions o = clean();
    o.object_count = 0;
    const Scene small = generate(o);
    o.width *= 2;
    o.height *= 2;
    const Scene large = generate(o);
    EXPECT_NEAR(large.fx, 2 * small.fx, 1e-9);
    EXPECT_NEAR(small.fx, 320 / std::tan(30 * 3.141592653589793 / 180), 1e-9);  // 60 degrees across
}

TEST(Synthetic, RejectsInvalidOptions) {
    const auto throws = [](auto change) {
        SceneOptions o;
        o.width = 8;
        o.height = 8;
        change(o);
        EXPECT_THROW(generate(o), std::invalid_argument);
    };
    throws([](SceneOptions& o) { o.width = 0; });
    throws([](SceneOptions& o) { o.width = -3; });
    throws([](SceneOptions& o) { o.height = 0; });
    throws([](SceneOptions& o) { o.width = syn::kMaxImageSide + 1; });
    throws([](SceneOptions& o) { o.height = syn::kMaxImageSide + 1; });
    throws([](SceneOptions& o) { o.object_count = -1; });
    throws([](SceneOptions& o) { o.object_count = syn::kMaxObjectCount + 1; });
    throws([](SceneOptions& o) { o.noise_mm = -0.1; });
    throws([](SceneOptions& o) { o.noise_mm = std::nan(""); });
    throws([](SceneOptions& o) { o.hole_fraction = -0.01; });
    throws([](SceneOptions& o) { o.hole_fraction = 1.5; });
    throws([](SceneOptions& o) { o.hole_fraction = std::nan(""); });
    throws([](SceneOptions& o) { o.threads = -1; });
}

TEST(Synthetic, NormalsAreUnitAndFaceTheCamera) {
    for (std::uint64_t seed = 1; seed <= 3; ++seed) {
        SceneOptions o;
        o.seed = seed;
        o.noise_mm = 1;
        o.hole_fraction = 0.05;
        expect_consistent(generate(o));
    }
}

TEST(Synthetic, ShowsFloorBinAndSeveralObjects) {
    for (std::uint64_t seed = 1; seed <= 3; ++seed) {
        SCOPED_TRACE(seed);
        SceneOptions o;
        o.seed = seed;
        const Scene s = generate(o);
        EXPECT_EQ(s.objects_placed, o.object_count);
        ASSERT_EQ(s.primitives.size(), 6u + static_cast<std::size_t>(s.objects_placed));
        std::map<std::uint32_t, std::size_t> seen;
        for (const std::uint32_t id : s.object_id) ++seen[id];
        EXPECT_GT(seen[syn::kFloorId], pixel_count(s) / 10);
        EXPECT_GT(seen[syn::kBinBottomId], pixel_count(s) / 20);
        for (std::uint32_t wall = syn::kFirstWallId; wall < syn::kFirstObjectId; ++wall) EXPECT_GT(seen[wall], 100u);
        const auto objects =
            std::count_if(seen.begin(), seen.end(), [](const auto& e) { return e.first >= syn::kFirstObjectId; });
        EXPECT_GE(objects, 8);
        EXPECT_LT(seen.rbegin()->first, syn::kFirstObjectId + static_cast<std::uint32_t>(s.objects_placed));
    }
}

TEST(Synthetic, WithoutBinObjectsLieOnThePlainFloor) {
    SceneOptions o;
    o.bin = false;
    const Scene s = generate(o);
    expect_consistent(s);
    EXPECT_EQ(s.objects_placed, o.object_count);
    EXPECT_EQ(s.primitives.size(), 1u + static_cast<std::size_t>(s.objects_placed));
    std::set<std::uint32_t> ids(s.object_id.begin(), s.object_id.end());
    for (std::uint32_t id = syn::kBinBottomId; id < syn::kFirstObjectId; ++id) EXPECT_EQ(ids.count(id), 0u);
    EXPECT_GE(std::count_if(ids.begin(), ids.end(), [](std::uint32_t id) { return id >= syn::kFirstObjectId; }), 8);
}

TEST(Synthetic, EmptyBin) {
    SceneOptions o;
    o.object_count = 0;
    const Scene s = generate(o);
    EXPECT_EQ(s.objects_placed, 0);
    EXPECT_EQ(*std::max_element(s.object_id.begin(), s.object_id.end()), syn::kFirstObjectId - 1);
}

// Lowest point of an object along up, relative to the plane through origin with normal up.
double lowest(const Primitive& p, const V3& up, const V3& origin) {
    const double centre = dot(sub(p.center, origin), up);
    switch (p.shape) {
        case Shape::box:
            return centre - p.half_size[0] * std::abs(dot(p.axes[0], up)) -
                   p.half_size[1] * std::abs(dot(p.axes[1], up)) - p.half_size[2] * std::abs(dot(p.axes[2], up));
        case Shape::cylinder: {
            const double c = std::abs(dot(p.axes[2], up));
            return centre - p.half_size[2] * c - p.half_size[0] * std::sqrt(std::max(0.0, 1 - c * c));
        }
        case Shape::sphere:
            return centre - p.half_size[0];
        case Shape::plane:
            break;
    }
    return 0;
}

TEST(Synthetic, ObjectsRestOnTheBinBottomWithoutSinkingIn) {
    for (std::uint64_t seed = 1; seed <= 5; ++seed) {
        SCOPED_TRACE(seed);
        SceneOptions o;
        o.seed = seed;
        o.width = o.height = 8;
        const Scene s = generate(o);
        const Primitive& bottom = primitive(s, syn::kBinBottomId);
        const V3 up = bottom.axes[2];
        V3 top = bottom.center;
        for (int c = 0; c < 3; ++c)
            top[static_cast<std::size_t>(c)] += up[static_cast<std::size_t>(c)] * bottom.half_size[2];
        EXPECT_LT(up[2], -0.98) << "the bin's up points toward the camera";
        int resting = 0;
        for (const Primitive& p : s.primitives) {
            if (p.id < syn::kFirstObjectId) continue;
            const double gap = lowest(p, up, top);
            EXPECT_GT(gap, -1e-6) << "object " << p.id;
            resting += gap < 0.05;
        }
        EXPECT_GE(resting, s.objects_placed / 2);
    }
}

// Points spread over the surface of a solid primitive, in camera space.
std::vector<V3> surface_samples(const Primitive& p) {
    std::vector<V3> local;
    const double pi = 3.141592653589793;
    const int n = 8;
    switch (p.shape) {
        case Shape::box:
            for (int axis = 0; axis < 3; ++axis) {
                for (const double side : {-1.0, 1.0}) {
                    for (int i = 0; i <= n; ++i) {
                        for (int j = 0; j <= n; ++j) {
                            V3 l{};
                            const auto a = static_cast<std::size_t>(axis), b = (a + 1) % 3, c = (a + 2) % 3;
                            l[a] = side * p.half_size[a];
                            l[b] = (2.0 * i / n - 1) * p.half_size[b];
                            l[c] = (2.0 * j / n - 1) * p.half_size[c];
                            local.push_back(l);
                        }
                    }
                }
            }
            break;
        case Shape::cylinder:
            for (int i = 0; i < 4 * n; ++i) {
                const double angle = 2 * pi * i / (4 * n);
                for (int j = 0; j <= n; ++j) {
                    const double r = p.half_size[0], h = p.half_size[2];
                    local.push_back({r * std::cos(angle), r * std::sin(angle), (2.0 * j / n - 1) * h});
                    for (const double side : {-1.0, 1.0}) {
                        local.push_back({r * j / n * std::cos(angle), r * j / n * std::sin(angle), side * h});
                    }
                }
            }
            break;
        case Shape::sphere:
            for (int i = 0; i <= 2 * n; ++i) {
                const double polar = pi * i / (2 * n);
                for (int j = 0; j < 4 * n; ++j) {
                    const double azimuth = 2 * pi * j / (4 * n), r = p.half_size[0];
                    local.push_back({r * std::sin(polar) * std::cos(azimuth), r * std::sin(polar) * std::sin(azimuth),
                                     r * std::cos(polar)});
                }
            }
            break;
        case Shape::plane:
            break;
    }
    std::vector<V3> out;
    for (const V3& l : local) {
        V3 q = p.center;
        for (std::size_t a = 0; a < 3; ++a) {
            for (std::size_t c = 0; c < 3; ++c) q[c] += p.axes[a][c] * l[a];
        }
        out.push_back(q);
    }
    return out;
}

TEST(Synthetic, ObjectsDoNotInterpenetrate) {
    for (const bool touching : {true, false}) {
        for (std::uint64_t seed = 1; seed <= 4; ++seed) {
            SCOPED_TRACE(std::to_string(seed) + (touching ? " touching" : " apart"));
            SceneOptions o;
            o.seed = seed;
            o.touching = touching;
            o.object_count = 40;
            o.width = o.height = 4;
            const Scene s = generate(o);
            int deep = 0;
            for (const Primitive& a : s.primitives) {
                if (a.id < syn::kFirstObjectId) continue;
                const std::vector<V3> samples = surface_samples(a);
                for (const Primitive& b : s.primitives) {
                    if (b.id == a.id || b.shape == Shape::plane) continue;
                    for (const V3& q : samples) {
                        // A point of a inside b by more than a micrometre means the two overlap.
                        if (check_surface(b, q, {0, 0, 0}).distance < -1e-3) {
                            ++deep;
                            break;
                        }
                    }
                }
            }
            EXPECT_EQ(deep, 0);
        }
    }
}

TEST(Synthetic, AFullBinTakesNoMore) {
    SceneOptions o;
    o.width = 64;
    o.height = 48;
    o.object_count = 150;
    const Scene s = generate(o);
    EXPECT_GT(s.objects_placed, 50);
    EXPECT_LT(s.objects_placed, o.object_count);
    EXPECT_EQ(s.primitives.size(), 6u + static_cast<std::size_t>(s.objects_placed));
}

TEST(Synthetic, SomeDistinctObjectsTouch) {
    for (std::uint64_t seed = 1; seed <= 6; ++seed) {
        SCOPED_TRACE(seed);
        SceneOptions o;
        o.seed = seed;
        const Scene s = generate(o);
        const int w = s.width, h = s.height;
        int touching = 0;
        for (int v = 0; v < h; ++v) {
            for (int u = 0; u < w; ++u) {
                const std::size_t a =
                    static_cast<std::size_t>(v) * static_cast<std::size_t>(w) + static_cast<std::size_t>(u);
                for (const std::size_t b : {a + 1, a + static_cast<std::size_t>(w)}) {
                    if ((b == a + 1 && u + 1 == w) || b >= pixel_count(s)) continue;
                    const std::uint32_t ia = s.object_id[a], ib = s.object_id[b];
                    if (ia < syn::kFirstObjectId || ib < syn::kFirstObjectId || ia == ib) continue;
                    touching += std::abs(s.points[3 * a + 2] - s.points[3 * b + 2]) < 2.0f;
                }
            }
        }
        EXPECT_GT(touching, 0);
    }
}

TEST(Synthetic, HolesFollowHoleFraction) {
    SceneOptions o;
    o.shadows = false;
    o.hole_fraction = 0;
    EXPECT_EQ(missing(generate(o)), 0u);
    o.shadows = true;
    EXPECT_EQ(missing(generate(o)), 0u) << "shadows only come with holes";

    o.shadows = false;
    for (const double fraction : {0.01, 0.1, 0.3}) {
        SCOPED_TRACE(fraction);
        o.hole_fraction = fraction;
        const Scene s = generate(o);
        const double measured = static_cast<double>(missing(s)) / static_cast<double>(pixel_count(s));
        EXPECT_GT(measured, 0.4 * fraction);
        EXPECT_LT(measured, 1.6 * fraction);
    }

    o.hole_fraction = 0.01;
    const std::size_t blobs = missing(generate(o));
    o.shadows = true;
    const Scene shadowed = generate(o);
    EXPECT_GT(missing(shadowed), blobs + pixel_count(shadowed) / 200) << "tall objects and walls cast shadows";
    expect_consistent(shadowed);
}

TEST(Synthetic, NoiselessPointsLieOnTheirSurfaces) {
    for (const bool bin : {true, false}) {
        SCOPED_TRACE(bin);
        SceneOptions o = clean();
        o.bin = bin;
        o.seed = 5;
        o.object_count = 20;
        const Scene s = generate(o);
        std::size_t off_surface = 0, wrong_normal = 0;
        double floor_min = 1e300, floor_max = -1e300;
        const Primitive& floor = primitive(s, syn::kFloorId);
        for (std::size_t i = 0; i < pixel_count(s); ++i) {
            const V3 p = point_at(s, i);
            const SurfaceCheck c = check_surface(primitive(s, s.object_id[i]), p, normal_at(s, i));
            off_surface += std::abs(c.distance) > 1e-3;
            wrong_normal += !c.normal_ok;
            if (s.object_id[i] == syn::kFloorId) {
                floor_min = std::min(floor_min, dot(p, floor.axes[2]));
                floor_max = std::max(floor_max, dot(p, floor.axes[2]));
            }
        }
        EXPECT_EQ(off_surface, 0u);
        EXPECT_EQ(wrong_normal, 0u);
        EXPECT_LT(floor_max - floor_min, 2e-3) << "floor points all satisfy one plane equation";
    }
}

TEST(Synthetic, NoiseMovesPointsAlongTheirRays) {
    SceneOptions o = clean();
    const Scene exact = generate(o);
    o.noise_mm = 0.5;
    const Scene noisy = generate(o);
    ASSERT_TRUE(same_bytes(exact.object_id, noisy.object_id));
    ASSERT_TRUE(same_bytes(exact.normals, noisy.normals));
    double sum = 0, sum2 = 0, worst_sideways = 0;
    const std::size_t n = pixel_count(exact);
    for (std::size_t i = 0; i < n; ++i) {
        const V3 a = point_at(exact, i), b = point_at(noisy, i);
        const double along = length(b) - length(a);
        sum += along;
        sum2 += along * along;
        const double la = length(a), lb = length(b);
        const V3 ua{a[0] / la, a[1] / la, a[2] / la}, ub{b[0] / lb, b[1] / lb, b[2] / lb};
        worst_sideways = std::max(worst_sideways, length(sub(ua, ub)));
    }
    const double mean = sum / static_cast<double>(n);
    const double sigma = std::sqrt(sum2 / static_cast<double>(n) - mean * mean);
    EXPECT_NEAR(mean, 0, 0.01);
    EXPECT_NEAR(sigma, 0.5, 0.02);
    EXPECT_LT(worst_sideways, 1e-6);
}

TEST(Synthetic, FullResolutionFrameGenerates) {
    SceneOptions o;
    o.width = 4128;
    o.height = 3088;
    const Scene s = generate(o);
    EXPECT_EQ(s.width, 4128);
    EXPECT_EQ(s.height, 3088);
    EXPECT_EQ(s.points.size(), 3u * 4128u * 3088u);
    EXPECT_EQ(s.normals.size(), 3u * 4128u * 3088u);
    EXPECT_EQ(s.object_id.size(), 4128u * 3088u);
}

}  // namespace

namespace {

// The 4-neighbour pixel pairs where ids a and b meet in the ground truth, and how many of them are *flat*: a
// depth step under 3 mm (a few pixels' slope of a tilted face) and the same normal on both sides.
struct Seam {
    int pairs = 0;
    int flat = 0;
};
Seam seam(const Scene& s, std::uint32_t a, std::uint32_t b) {
    Seam r;
    const auto w = static_cast<std::size_t>(s.width);
    for (std::size_t i = 0; i < pixel_count(s); ++i) {
        for (const std::size_t j : {i + 1, i + w}) {
            if (j >= pixel_count(s) || (j == i + 1 && (i + 1) % w == 0)) continue;
            const std::uint32_t ia = s.object_id[i], ib = s.object_id[j];
            if (!((ia == a && ib == b) || (ia == b && ib == a))) continue;
            ++r.pairs;
            const double step = std::abs(double(s.points[3 * i + 2]) - double(s.points[3 * j + 2]));
            r.flat += step < 3.0 && dot(normal_at(s, i), normal_at(s, j)) > 1 - 1e-6;
        }
    }
    return r;
}

}  // namespace

TEST(Synthetic, FlushPairsMeetWithoutStepOrCrease) {
    // Checked on the noiseless rendering itself, not on the primitives flush_pairs reads: where the two objects'
    // tops meet in the image, the depth is continuous and the normals are the same (their visible sides meet
    // with a crease or a step, but the tops alone join them).
    int flush_seen = 0;
    for (std::uint64_t seed = 1; seed <= 6; ++seed) {
        SCOPED_TRACE(seed);
        SceneOptions o = clean();
        o.seed = seed;
        const Scene s = generate(o);
        for (const auto& [a, b] : syn::flush_pairs(s)) {
            SCOPED_TRACE(std::to_string(a) + "-" + std::to_string(b));
            ASSERT_LT(a, b);
            EXPECT_EQ(primitive(s, a).shape, Shape::box);
            EXPECT_EQ(primitive(s, b).shape, Shape::box);
            // They touch: their nearest points are a pixel apart (about 2 mm here), not across a gap.
            std::vector<V3> of_a, of_b;
            for (std::size_t i = 0; i < pixel_count(s); ++i) {
                if (s.object_id[i] == a) of_a.push_back(point_at(s, i));
                if (s.object_id[i] == b) of_b.push_back(point_at(s, i));
            }
            double nearest = 1e300;
            for (const V3& p : of_a)
                for (const V3& q : of_b) nearest = std::min(nearest, length(sub(p, q)));
            EXPECT_LT(nearest, 5.0);
            const Seam m = seam(s, a, b);
            if (m.pairs == 0) continue;  // a third object hides the contact
            ++flush_seen;
            EXPECT_GE(m.flat, 10) << m.pairs << " seam pixel pairs";
        }
    }
    EXPECT_GE(flush_seen, 5) << "the layout places a flush pair in every touching scene";
}

TEST(Synthetic, ObjectsThatTouchOtherwiseAreNotFlush) {
    // No other pair of boxes meets along a flat seam: a depth step or a crease separates them everywhere
    // (standing cylinders that touch meet at a single point of their rims, which segmentation must cut).
    for (std::uint64_t seed = 1; seed <= 6; ++seed) {
        SCOPED_TRACE(seed);
        SceneOptions o = clean();
        o.seed = seed;
        const Scene s = generate(o);
        const auto flush = syn::flush_pairs(s);
        const auto ids = static_cast<std::uint32_t>(s.primitives.size());
        for (std::uint32_t a = syn::kFirstObjectId; a <= ids; ++a) {
            for (std::uint32_t b = a + 1; b <= ids; ++b) {
                if (std::find(flush.begin(), flush.end(), std::array<std::uint32_t, 2>{a, b}) != flush.end()) continue;
                if (primitive(s, a).shape != Shape::box || primitive(s, b).shape != Shape::box) continue;
                EXPECT_LT(seam(s, a, b).flat, 3) << a << "-" << b;
            }
        }
    }
}

TEST(Synthetic, FlushPairsAreTheSameForEverySensorAndDistance) {
    SceneOptions o;
    o.seed = 2;
    const auto expected = syn::flush_pairs(generate(o));
    ASSERT_FALSE(expected.empty());
    o.sensor = syn::Sensor::azure_kinect;
    o.camera_distance_mm = 2000;
    EXPECT_EQ(syn::flush_pairs(generate(o)), expected) << "the layout, and so the pairs, depend on the seed only";
}
