// The real-frame ground truth (tools/eval/tabletop_truth.hpp) on tabletop frames ray-cast here, whose truth is known:
// a table plane seen from above at 45 degrees, the floor below it, boxes standing on it (two of them touching), one
// box too small to count; and its refusals.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <optional>
#include <stdexcept>
#include <vector>

#include "tools/eval/tabletop_truth.hpp"

namespace {

using pyrseg::eval::kTruthNone;
using pyrseg::eval::kTruthTable;
using pyrseg::eval::make_tabletop_truth;
using pyrseg::eval::TabletopCamera;
using Vec3 = std::array<double, 3>;

constexpr int kWidth = 640;
constexpr int kHeight = 480;
constexpr TabletopCamera kCamera{525.0, 525.0, 319.5, 239.5};

struct Box {
    Vec3 lo;
    Vec3 hi;
};

// What the ray of a pixel hits first: the table (z = 0 inside its extent), the floor (z = floor_z) or a box.
enum class Hit { none, table, floor, box };
struct Pixel {
    float depth = 0;
    Hit hit = Hit::none;
    int box = -1;
    double height = 0;  // of the hit point above the table plane (world z)
};

struct Scene {
    Vec3 eye{0, -0.2, 0.7};  // the camera looks at (0, 0.5, 0): 45 degrees down, image x along world x
    double table_x = 0.6;    // the table: |x| <= table_x, 0 <= y <= table_y, z = 0
    double table_y = 1.2;
    double floor_z = -0.7;
    std::vector<Box> boxes;
};

// The camera's axes in the world (x right, y down in the image, z forward), orthonormal.
constexpr double kA = 0.70710678118654752;
constexpr Vec3 kRight{1, 0, 0};
constexpr Vec3 kDown{0, -kA, -kA};
constexpr Vec3 kForward{0, kA, -kA};

std::optional<double> hit_box(const Vec3& o, const Vec3& d, const Box& b) {
    double t0 = 0;
    double t1 = std::numeric_limits<double>::infinity();
    for (std::size_t k = 0; k < 3; ++k) {
        if (std::abs(d[k]) < 1e-15) {
            if (o[k] < b.lo[k] || o[k] > b.hi[k]) return std::nullopt;
            continue;
        }
        double a = (b.lo[k] - o[k]) / d[k];
        double c = (b.hi[k] - o[k]) / d[k];
        if (a > c) std::swap(a, c);
        t0 = std::max(t0, a);
        t1 = std::min(t1, c);
        if (t0 > t1) return std::nullopt;
    }
    return t0;
}

std::vector<Pixel> render(const Scene& s) {
    std::vector<Pixel> out(std::size_t(kWidth) * kHeight);
    for (int y = 0; y < kHeight; ++y) {
        for (int x = 0; x < kWidth; ++x) {
            const double dx = (x - kCamera.cx) / kCamera.fx;
            const double dy = (y - kCamera.cy) / kCamera.fy;
            Vec3 d{};
            for (std::size_t k = 0; k < 3; ++k) d[k] = kRight[k] * dx + kDown[k] * dy + kForward[k];
            Pixel& p = out[std::size_t(y) * kWidth + std::size_t(x)];
            double best = std::numeric_limits<double>::infinity();
            const auto at = [&](double t, std::size_t k) { return s.eye[k] + t * d[k]; };
            if (d[2] < 0) {
                const double t = -s.eye[2] / d[2];
                if (std::abs(at(t, 0)) <= s.table_x && at(t, 1) >= 0 && at(t, 1) <= s.table_y) {
                    best = t;
                    p.hit = Hit::table;
                } else {
                    best = (s.floor_z - s.eye[2]) / d[2];
                    p.hit = Hit::floor;
                }
            }
            for (std::size_t b = 0; b < s.boxes.size(); ++b) {
                const std::optional<double> t = hit_box(s.eye, d, s.boxes[b]);
                if (t && *t < best) {
                    best = *t;
                    p.hit = Hit::box;
                    p.box = int(b);
                }
            }
            if (p.hit == Hit::none) continue;
            p.depth = float(best);  // the forward component of d is 1: t is the depth
            p.height = at(best, 2);
        }
    }
    return out;
}

std::vector<float> depths(const std::vector<Pixel>& pixels) {
    std::vector<float> d;
    for (const Pixel& p : pixels) d.push_back(p.depth);
    return d;
}

Scene tabletop() {
    Scene s;
    s.boxes = {
        {{-0.35, 0.30, 0.0}, {-0.20, 0.45, 0.12}},  // A, alone
        {{0.05, 0.40, 0.0}, {0.15, 0.50, 0.08}},    // B and C, touching: one object
        {{0.15, 0.40, 0.0}, {0.25, 0.50, 0.08}},
        {{0.40, 0.90, 0.0}, {0.41, 0.91, 0.03}},  // D: a few pixels, under the minimum
    };
    return s;
}

TEST(TabletopTruth, FindsTheTablePlaneAndTheObjectsOnIt) {
    const Scene scene = tabletop();
    const std::vector<Pixel> pixels = render(scene);
    const auto truth = make_tabletop_truth(kWidth, kHeight, depths(pixels), kCamera);
    ASSERT_TRUE(truth.found_plane);
    // The table's plane in the camera's frame: the world's up, n = (0, -a, -a), at the eye's height 0.7 m.
    const Vec3 expected{0, -kA, -kA};
    double cosine = 0;
    for (std::size_t k = 0; k < 3; ++k) cosine += truth.plane.normal[k] * expected[k];
    EXPECT_GT(cosine, std::cos(0.1 * 3.14159265358979 / 180)) << "normal within 0.1 degree";
    EXPECT_NEAR(truth.plane.offset, 0.7, 0.0005);
    EXPECT_EQ(truth.objects, 2u) << "A, and B with C touching it; D is too small";

    // Each box's id: the truth label most of its pixels (above the minimum height) carry.
    std::array<std::map<std::uint32_t, int>, 4> votes;
    std::size_t table_pixels = 0;
    for (std::size_t i = 0; i < pixels.size(); ++i) {
        const Pixel& p = pixels[i];
        if (p.hit == Hit::table) {
            ++table_pixels;
            EXPECT_EQ(truth.labels[i], kTruthTable) << "table pixel " << i;
        } else if (p.hit == Hit::floor || p.hit == Hit::none) {
            EXPECT_EQ(truth.labels[i], kTruthNone) << "floor or empty pixel " << i;
        } else if (p.height >= 0.015) {
            ++votes[std::size_t(p.box)][truth.labels[i]];
        } else {
            EXPECT_TRUE(truth.labels[i] == kTruthNone || truth.labels[i] == kTruthTable || truth.labels[i] > 1)
                << "a box's foot, within 15 mm of the table";
        }
    }
    EXPECT_GT(table_pixels, 100000u);
    // The label nearly all of a box's pixels carry (0 if none has 99% of them): a few pixels on its silhouette,
    // where the rays graze a face, are fragments of their own.
    const auto only = [](const std::map<std::uint32_t, int>& v) {
        int total = 0;
        for (const auto& [label, count] : v) total += count;
        for (const auto& [label, count] : v) {
            if (count >= 0.99 * total) return label;
        }
        return std::uint32_t(0);
    };
    const std::uint32_t a = only(votes[0]);
    const std::uint32_t b = only(votes[1]);
    const std::uint32_t c = only(votes[2]);
    EXPECT_GE(a, 2u) << "A above 15 mm is one object";
    EXPECT_GE(b, 2u);
    EXPECT_EQ(b, c) << "touching boxes stay one object";
    EXPECT_NE(a, b);
    for (const auto& [label, count] : votes[3]) {
        EXPECT_EQ(label, kTruthNone) << count << " pixels of D";
    }
}

// A small table seen from farther up fills less of the frame than the floor around it (as low_table_5 of the shared
// RealSense frames): the support is still the table, the plane above the floor, and its boxes are the objects.
TEST(TabletopTruth, ASmallTableAboveAWideFloorIsTheSupport) {
    Scene scene = tabletop();
    scene.table_x = 0.3;
    scene.table_y = 0.7;
    scene.floor_z = -0.45;
    scene.boxes.pop_back();
    const std::vector<Pixel> pixels = render(scene);
    std::size_t table = 0, floor = 0;
    for (const Pixel& p : pixels) {
        table += p.hit == Hit::table;
        floor += p.hit == Hit::floor;
    }
    ASSERT_GT(floor, table) << "the floor fills more of the frame";
    const auto truth = make_tabletop_truth(kWidth, kHeight, depths(pixels), kCamera);
    ASSERT_TRUE(truth.found_plane);
    EXPECT_NEAR(truth.plane.offset, 0.7, 0.0005) << "the table's plane, not the floor's (1.15 m below the eye)";
    EXPECT_EQ(truth.objects, 2u);
    // Without the rule (no plane above the first counts), the floor would be the support.
    pyrseg::eval::TabletopTruthParams first_plane_only;
    first_plane_only.min_support_share = 2.0;
    const auto floor_truth = make_tabletop_truth(kWidth, kHeight, depths(pixels), kCamera, first_plane_only);
    EXPECT_NEAR(floor_truth.plane.offset, 1.15, 0.001);
}

TEST(TabletopTruth, HolesAndFarPixelsOutsideTheTableAreNotObjects) {
    Scene scene = tabletop();
    // A box standing on the floor behind the table rises above the table's plane, outside its outline.
    scene.boxes.push_back({{-0.10, 1.25, -0.70}, {0.10, 1.35, 0.10}});
    std::vector<Pixel> pixels = render(scene);
    // Stereo shadows: a band of missing depth through box A.
    for (int y = 0; y < kHeight; ++y) {
        for (int x = 150; x < 156; ++x) pixels[std::size_t(y) * kWidth + std::size_t(x)].depth = 0;
    }
    const auto truth = make_tabletop_truth(kWidth, kHeight, depths(pixels), kCamera);
    ASSERT_TRUE(truth.found_plane);
    std::size_t behind_above = 0;  // pixels of the box behind the table higher than an object's minimum
    for (std::size_t i = 0; i < pixels.size(); ++i) {
        behind_above += pixels[i].hit == Hit::box && pixels[i].box == 4 && pixels[i].height >= 0.015;
        if (pixels[i].depth == 0) {
            EXPECT_EQ(truth.labels[i], kTruthNone) << "a pixel without depth, " << i;
        }
        if (pixels[i].hit == Hit::box && pixels[i].box == 4) {
            EXPECT_LE(truth.labels[i], kTruthTable) << "the box behind the table is no object, pixel " << i;
        }
    }
    EXPECT_GT(behind_above, 1000u) << "the box behind the table is in view";
}

TEST(TabletopTruth, IsTheSameEveryTime) {
    const std::vector<float> d = depths(render(tabletop()));
    const auto first = make_tabletop_truth(kWidth, kHeight, d, kCamera);
    const auto second = make_tabletop_truth(kWidth, kHeight, d, kCamera);
    EXPECT_EQ(first.labels, second.labels);
    EXPECT_EQ(first.plane.normal, second.plane.normal);
}

TEST(TabletopTruth, AFrameWithoutDepthHasNoTruth) {
    const std::vector<float> none(std::size_t(kWidth) * kHeight, 0.0f);
    const auto truth = make_tabletop_truth(kWidth, kHeight, none, kCamera);
    EXPECT_FALSE(truth.found_plane);
    EXPECT_EQ(truth.objects, 0u);
    EXPECT_TRUE(std::all_of(truth.labels.begin(), truth.labels.end(), [](std::uint32_t l) { return l == 0; }));
}

TEST(TabletopTruth, RefusesSizesAndCamerasThatDisagree) {
    const std::vector<float> d(10, 1.0f);
    EXPECT_THROW((void)make_tabletop_truth(4, 3, d, kCamera), std::invalid_argument);
    EXPECT_THROW((void)make_tabletop_truth(5, 2, d, TabletopCamera{0, 525, 2, 1}), std::invalid_argument);
    EXPECT_THROW((void)make_tabletop_truth(5, 2, d, TabletopCamera{525, 525, std::nan(""), 1}), std::invalid_argument);
}

}  // namespace
