// Bad input: each either gives a pyrseg::Error naming the problem or the contract's defined result (invalid
// pixels), never a crash; and nothing the caller passed in is modified.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include <unistd.h>

#include "pyrseg/backend.hpp"
#include "pyrseg/error.hpp"
#include "pyrseg/segmenter.hpp"

namespace pyrseg {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();

// A frontal plane at z = 1000 with normals toward the camera.
struct Plane {
    int width, height;
    std::vector<float> points, normals;
    Plane(int w, int h) : width(w), height(h), points(3 * std::size_t(w) * std::size_t(h)), normals(points.size()) {
        for (int y = 0; y < h; ++y) {
            for (int x = 0; x < w; ++x) {
                float* p = &points[3 * (std::size_t(y) * std::size_t(w) + std::size_t(x))];
                p[0] = float(x - w / 2);
                p[1] = float(y - h / 2);
                p[2] = 1000.0f;
                float* n = &normals[3 * (std::size_t(y) * std::size_t(w) + std::size_t(x))];
                n[0] = 0.0f;
                n[1] = 0.0f;
                n[2] = -1.0f;
            }
        }
    }
    [[nodiscard]] CloudView view(bool with_normals = true) const {
        CloudView v;
        v.points = points.data();
        v.normals = with_normals ? normals.data() : nullptr;
        v.width = width;
        v.height = height;
        return v;
    }
    float* point(int x, int y) { return &points[3 * (std::size_t(y) * std::size_t(width) + std::size_t(x))]; }
    float* normal(int x, int y) { return &normals[3 * (std::size_t(y) * std::size_t(width) + std::size_t(x))]; }
};

void expect_error(ErrorCode code, const std::string& needle, const std::function<void()>& f) {
    try {
        f();
        ADD_FAILURE() << "expected pyrseg::Error mentioning '" << needle << "'";
    } catch (const Error& e) {
        EXPECT_EQ(e.code(), code) << e.what();
        EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
    }
}

TEST(BadInput, InvalidPointsAreInvalidPixelsAndNeverLabelled) {
    for (const bool with_normals : {true, false}) {
        Plane plane(32, 32);
        plane.point(3, 3)[2] = kNaN;
        plane.point(10, 10)[0] = kInf;
        plane.point(20, 5)[2] = 0.0f;
        plane.point(5, 20)[2] = -1000.0f;
        plane.point(25, 25)[1] = -kInf;
        plane.point(15, 15)[2] = -0.0f;
        Outputs o;
        o.fillable_mask = true;
        Segmenter s(32, 32, {}, "cpu", o);
        const Result r = s.segment(plane.view(with_normals));
        for (const auto& [x, y] : {std::pair{3, 3}, {10, 10}, {20, 5}, {5, 20}, {25, 25}, {15, 15}}) {
            const std::size_t i = std::size_t(y) * 32 + std::size_t(x);
            EXPECT_EQ(r.fillable_mask[i], 0) << x << "," << y;
            EXPECT_EQ(r.labels[i], 0u) << x << "," << y << " is invalid but labelled";
        }
        EXPECT_EQ(r.labels[0], 1u);
        EXPECT_EQ(r.segment_count, 1u);
    }
}

TEST(BadInput, ZeroAndNonFiniteNormalsMakeInvalidPixels) {
    Plane plane(32, 32);
    plane.normal(4, 4)[0] = 0.0f;
    plane.normal(4, 4)[2] = 0.0f;
    plane.normal(8, 8)[1] = kNaN;
    plane.normal(12, 12)[2] = -kInf;
    Outputs o;
    o.fillable_mask = true;
    Segmenter s(32, 32, {}, "cpu", o);
    const Result r = s.segment(plane.view());
    for (const auto& [x, y] : {std::pair{4, 4}, {8, 8}, {12, 12}}) {
        EXPECT_EQ(r.fillable_mask[std::size_t(y) * 32 + std::size_t(x)], 0);
        EXPECT_EQ(r.labels[std::size_t(y) * 32 + std::size_t(x)], 0u);
    }
}

TEST(BadInput, AnAllInvalidFrameHasNoSegments) {
    Plane plane(40, 30);
    std::fill(plane.points.begin(), plane.points.end(), kNaN);
    for (const bool with_normals : {true, false}) {
        Segmenter s(40, 30, {}, "cpu");
        const Result r = s.segment(plane.view(with_normals));
        EXPECT_EQ(r.segment_count, 0u);
        EXPECT_TRUE(std::all_of(r.labels.begin(), r.labels.end(), [](std::uint32_t l) { return l == 0; }));
    }
}

TEST(BadInput, SizesAndLayoutsThatDoNotFitAreErrors) {
    Plane plane(32, 24);
    Segmenter s(32, 24, {}, "cpu");
    expect_error(ErrorCode::invalid_argument, "empty", [] { Segmenter(0, 0, {}, "cpu"); });
    expect_error(ErrorCode::invalid_argument, "empty", [] { Segmenter(-3, 5, {}, "cpu"); });
    expect_error(ErrorCode::size_mismatch, "32 x 24", [&] {
        CloudView v = plane.view();
        v.width = 24;
        v.height = 32;
        (void)s.segment(v);
    });
    expect_error(ErrorCode::invalid_argument, "row_stride", [&] {
        CloudView v = plane.view();
        v.row_stride = 31;
        (void)s.segment(v);
    });
    expect_error(ErrorCode::invalid_argument, "row_stride", [&] {
        CloudView v = plane.view();
        v.row_stride = std::numeric_limits<std::size_t>::max() / 2;
        (void)s.segment(v);
    });
    expect_error(ErrorCode::invalid_argument, "point_stride", [&] {
        CloudView v = plane.view();
        v.point_stride = 2;
        (void)s.segment(v);
    });
    // Byte steps: multiples of 4, at least x y z, rows that hold a row of points, one way of giving each step.
    for (const std::size_t bad : {std::size_t(13), std::size_t(8), std::size_t(0) - 4}) {
        expect_error(ErrorCode::invalid_argument, "point_step_bytes", [&] {
            CloudView v = plane.view();
            v.point_step_bytes = bad;
            (void)s.segment(v);
        });
    }
    expect_error(ErrorCode::invalid_argument, "row_step_bytes", [&] {
        CloudView v = plane.view();
        v.row_step_bytes = 12 * 32 - 4;  // one float short of a row of 32 packed points
        (void)s.segment(v);
    });
    expect_error(ErrorCode::invalid_argument, "row_step_bytes", [&] {
        CloudView v = plane.view();
        v.row_step_bytes = 12 * 32 + 2;
        (void)s.segment(v);
    });
    expect_error(ErrorCode::invalid_argument, "both given", [&] {
        CloudView v = plane.view();
        v.row_stride = 40;
        v.row_step_bytes = 12 * 40;
        (void)s.segment(v);
    });
    expect_error(ErrorCode::invalid_argument, "both given", [&] {
        CloudView v = plane.view();
        v.point_stride = 4;
        v.point_step_bytes = 16;
        (void)s.segment(v);
    });
    expect_error(ErrorCode::invalid_argument, "aligned", [&] {
        CloudView v = plane.view();
        v.points = reinterpret_cast<const float*>(reinterpret_cast<const char*>(v.points) + 1);
        (void)s.segment(v);
    });
    expect_error(ErrorCode::invalid_argument, "null", [&] {
        CloudView v = plane.view();
        v.points = nullptr;
        (void)s.segment(v);
    });
    expect_error(ErrorCode::invalid_argument, "null", [&] {
        Result r;
        s.segment_mask(MaskView{}, r);
    });
}

TEST(BadInput, BridgeParametersThatDoNotFitAndHugeImagesAreErrors) {
    Params p;
    p.bridge_levels = 2;
    expect_error(ErrorCode::invalid_parameter, "do not fit", [&] { Segmenter(8, 8, p, "cpu"); });
    p.bridge_levels = 9;
    expect_error(ErrorCode::invalid_parameter, "bridge_levels", [&] { Segmenter(640, 480, p, "cpu"); });
    expect_error(ErrorCode::image_too_large, "32-bit", [] { Segmenter(70000, 70000, {}, "cpu"); });
    expect_error(ErrorCode::image_too_large, "32-bit", [] { Segmenter(60000, 60000, {}, "cpu"); });
}

TEST(BadInput, ImagesTooLargeForThisMachinesMemoryAreErrors) {
    // 55000 x 55000 passes the 32-bit checks but needs about 70 GiB on the CPU backend.
    const long pages = sysconf(_SC_PHYS_PAGES);
    const double gib = double(pages) * double(sysconf(_SC_PAGE_SIZE)) / double(1 << 30);
    if (gib > 64)
        GTEST_SKIP() << "this machine has " << gib << " GiB: the image would fit, and this test allocates nothing";
    expect_error(ErrorCode::out_of_memory, "55000 x 55000 image needs about",
                 [] { Segmenter(55000, 55000, {}, "cpu"); });
}

TEST(BadInput, TheCallersBuffersAreNotModified) {
    Plane plane(64, 48);
    plane.point(7, 7)[2] = kNaN;
    const std::vector<float> points_before = plane.points;
    const std::vector<float> normals_before = plane.normals;
    Segmenter with(64, 48, {}, "cpu");
    (void)with.segment(plane.view(true));
    Segmenter without(64, 48, {}, "cpu");
    (void)without.segment(plane.view(false));
    EXPECT_EQ(std::memcmp(points_before.data(), plane.points.data(), points_before.size() * sizeof(float)), 0);
    EXPECT_EQ(std::memcmp(normals_before.data(), plane.normals.data(), normals_before.size() * sizeof(float)), 0);
}

TEST(BadInput, UnknownAndUnavailableBackendsAreErrors) {
    expect_error(ErrorCode::backend_unavailable, "unknown backend 'nope'", [] { Segmenter(8, 8, {}, "nope"); });
    // A backend this build lacks names the reason (the configure-time one).
    for (const std::string& name : backend_names()) {
        try {
            Segmenter s(16, 16, {}, name);
        } catch (const Error& e) {
            EXPECT_EQ(e.code(), ErrorCode::backend_unavailable);
            EXPECT_NE(std::string(e.what()).find("unavailable"), std::string::npos) << e.what();
        }
    }
}

}  // namespace
}  // namespace pyrseg
