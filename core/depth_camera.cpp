// check_depth_camera (pyrseg/depth.hpp): a depth frame's scale and intrinsics against what depth cameras deliver.
#include "core/depth_camera.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <numbers>
#include <string>
#include <vector>

#include "core/depth_tables.hpp"
#include "pyrseg/error.hpp"

namespace pyrseg {
namespace {

constexpr double kMedianMetresMin = kMedianDepthMetresMin;
constexpr double kMedianMetresMax = kMedianDepthMetresMax;
// Legal but unusual: closer than the close-range cameras' usual working distance, farther than indoor frames.
constexpr double kUsualMedianMetresMin = 0.15;
constexpr double kUsualMedianMetresMax = 20.0;
// Pinhole fields of view beyond these are no camera's (fx = 1e-300 would make every ray slope overflow float32).
constexpr double kFieldOfViewMinDegrees = 0.1;
constexpr double kFieldOfViewMaxDegrees = 175.0;
constexpr double kSquarePixelsRatioMax = 1.25;
constexpr double kPrincipalPointOffCentreMax = 0.25;
constexpr int kMedianGrid = 64;
constexpr std::size_t kMedianSamplesMin = 16;

std::string number(double v) {
    char text[32];
    std::snprintf(text, sizeof text, "%.6g", v);
    return text;
}

[[noreturn]] void bad(const std::string& what) {
    throw Error(ErrorCode::invalid_parameter, "the depth image's " + what);
}

double field_of_view_degrees(int pixels, double focal) {
    return 2.0 * std::atan(double(pixels) / (2.0 * focal)) * 180.0 / std::numbers::pi;
}

void check_focal(const char* name, double focal, int pixels, const char* across) {
    const double fov = field_of_view_degrees(pixels, focal);
    if (fov < kFieldOfViewMinDegrees || fov > kFieldOfViewMaxDegrees) {
        bad(std::string(name) + " " + number(focal) + " gives a field of view of " + number(fov) + " degrees " +
            across + " " + std::to_string(pixels) + " pixels, outside any pinhole depth camera's (" +
            number(kFieldOfViewMinDegrees) + " to " + number(kFieldOfViewMaxDegrees) +
            "): the focal lengths are in pixels (a D435 at 640 x 480: about 380 to 615)");
    }
}

// How far the point (x, y) is from the image's centre, as a fraction of the width or the height (the larger).
double off_centre(double x, double y, int width, int height) {
    return std::max(std::fabs(x - width / 2.0) / width, std::fabs(y - height / 2.0) / height);
}

bool nearly_square(double fx, double fy, double ratio_max) {
    return fx / fy <= ratio_max && fy / fx <= ratio_max;
}

// Intrinsics given in the order cx, cy, fx, fy: as given, pixels far from square or a principal point far from the
// centre; read the other way round, square pixels and a centred principal point. Real intrinsics are never both.
bool looks_swapped(const DepthView& d) {
    const bool odd_as_given = !nearly_square(d.fx, d.fy, kSquarePixelsRatioMax) ||
                              off_centre(d.cx, d.cy, d.width, d.height) > kPrincipalPointOffCentreMax;
    const bool good_swapped =
        d.cx > 0 && d.cy > 0 && nearly_square(d.cx, d.cy, 1.05) && off_centre(d.fx, d.fy, d.width, d.height) <= 0.1;
    return odd_as_given && good_swapped;
}

std::string swap_hint(const DepthView& d) {
    return "the intrinsics look given as cx, cy, fx, fy: the order is fx, fy, cx, cy (fx " + number(d.cx) + ", fy " +
           number(d.cy) + ", cx " + number(d.fx) + ", cy " + number(d.fy) + "?)";
}

// A principal point outside the image is no camera's, and neither are intrinsics that read well only the other way
// round.
void check_principal_point(const DepthView& d) {
    const auto inside = [](double c, int pixels) { return c >= 0.0 && c <= double(pixels); };
    // Made only for a message: a frame that passes allocates nothing (tests/unit/test_no_allocation.cpp).
    const auto point = [&] { return "principal point (cx " + number(d.cx) + ", cy " + number(d.cy) + ")"; };
    if (!inside(d.cx, d.width) || !inside(d.cy, d.height)) {
        std::string message =
            point() + " lies outside the " + std::to_string(d.width) + " x " + std::to_string(d.height) + " image";
        if (inside(d.fx, d.width) && inside(d.fy, d.height)) {
            message += "; " + swap_hint(d);
        } else {
            message += ": cx and cy are in pixels, about half the width and the height";
        }
        bad(message);
    }
    if (looks_swapped(d)) {
        bad("intrinsics fx " + number(d.fx) + ", fy " + number(d.fy) + " with " + point() +
            " are no camera's: " + swap_hint(d));
    }
}

// The depth in metres of the sample at (x, y), or 0 when it has no data (docs/algorithm.md section 1b).
double sample_metres(const DepthView& d, int x, int y) {
    const std::size_t bytes = core::DepthTables::sample_bytes(d.format);
    const std::size_t step = d.row_step_bytes != 0 ? d.row_step_bytes : std::size_t(d.width) * bytes;
    const auto* at = static_cast<const unsigned char*>(d.depth) + std::size_t(y) * step + std::size_t(x) * bytes;
    if (d.format == DepthFormat::u16) {
        std::uint16_t v = 0;
        std::memcpy(&v, at, sizeof v);
        return double(v) * d.metres_per_unit;
    }
    float v = 0;
    std::memcpy(&v, at, sizeof v);
    return std::isnormal(v) && v > 0 ? double(v) * d.metres_per_unit : 0.0;
}

// The median of a grid of up to kMedianGrid x kMedianGrid samples, 0 when too few are valid: a few thousand reads
// say as much about the unit as the whole frame.
double sampled_median_metres(const DepthView& d) {
    // On the stack: a Segmenter's frames allocate nothing once sized (tests/unit/test_no_allocation.cpp).
    std::array<double, std::size_t(kMedianGrid) * kMedianGrid> depths{};
    std::size_t count = 0;
    const int columns = std::min(d.width, kMedianGrid), rows = std::min(d.height, kMedianGrid);
    for (int j = 0; j < rows; ++j) {
        const int y = int((2 * std::int64_t(j) + 1) * d.height / (2 * std::int64_t(rows)));
        for (int i = 0; i < columns; ++i) {
            const int x = int((2 * std::int64_t(i) + 1) * d.width / (2 * std::int64_t(columns)));
            const double m = sample_metres(d, x, y);
            if (m > 0 && std::isfinite(m)) depths[count++] = m;
        }
    }
    if (count < kMedianSamplesMin) return 0.0;
    const auto end = depths.begin() + std::ptrdiff_t(count);
    const auto middle = depths.begin() + std::ptrdiff_t(count / 2);
    std::nth_element(depths.begin(), middle, end);
    return *middle;
}

void check_median(const DepthView& d, double median) {
    if (median >= kMedianMetresMin && median <= kMedianMetresMax) return;
    const double units = median / d.metres_per_unit;
    std::string message = "median depth is " + number(median) + " m with metres_per_unit " + number(d.metres_per_unit) +
                          " (median sample " + number(units) + "), outside any depth sensor's range (" +
                          number(kMedianMetresMin) + " to " + number(kMedianMetresMax) +
                          " m): metres_per_unit is the depth of one sample unit in metres, as SDKs state it "
                          "(RealSense's depth scale: 0.001 for millimetres, 1 for float metres)";
    for (const double usual : {0.001, 1.0, 0.0001}) {
        if (usual != d.metres_per_unit && units * usual >= kMedianMetresMin && units * usual <= kMedianMetresMax) {
            message += "; metres_per_unit " + number(usual) + " makes it " + number(units * usual) + " m";
            break;
        }
    }
    bad(message);
}

}  // namespace

namespace core {

void check_depth_intrinsics(const DepthView& d) {
    const auto positive = [](double v) { return std::isfinite(v) && v > 0; };
    if (!positive(d.metres_per_unit)) {
        bad("metres_per_unit must be finite and > 0 (0.001 for millimetres), got " + number(d.metres_per_unit));
    }
    if (!positive(d.fx)) bad("fx must be finite and > 0, got " + number(d.fx));
    if (!positive(d.fy)) bad("fy must be finite and > 0, got " + number(d.fy));
    if (!std::isfinite(d.cx)) bad("cx must be finite, got " + number(d.cx));
    if (!std::isfinite(d.cy)) bad("cy must be finite, got " + number(d.cy));
    check_principal_point(d);
    check_focal("fx", d.fx, d.width, "across");
    check_focal("fy", d.fy, d.height, "down");
}

bool CheckedDepthCamera::same(const DepthView& d) const {
    return valid && d.metres_per_unit == metres_per_unit && d.fx == fx && d.fy == fy && d.cx == cx && d.cy == cy &&
           d.format == format;
}

void CheckedDepthCamera::remember(const DepthView& d) {
    valid = true;
    metres_per_unit = d.metres_per_unit;
    fx = d.fx;
    fy = d.fy;
    cx = d.cx;
    cy = d.cy;
    format = d.format;
}

}  // namespace core

DepthCameraCheck check_depth_camera(const DepthView& depth) {
    if (depth.width < 1 || depth.height < 1) {
        throw Error(ErrorCode::invalid_argument, "the depth image is " + std::to_string(depth.width) + " x " +
                                                     std::to_string(depth.height) + ": width and height must be >= 1");
    }
    core::check_depth_intrinsics(depth);
    DepthCameraCheck out;
    const double ratio = depth.fx / depth.fy;
    if (ratio > kSquarePixelsRatioMax || ratio < 1.0 / kSquarePixelsRatioMax) {
        out.warnings.push_back("fx / fy is " + number(ratio) + " (fx " + number(depth.fx) + ", fy " + number(depth.fy) +
                               "): depth cameras' pixels are nearly square; check the order fx, fy, cx, cy");
    }
    if (off_centre(depth.cx, depth.cy, depth.width, depth.height) > kPrincipalPointOffCentreMax) {
        out.warnings.push_back("the principal point (cx " + number(depth.cx) + ", cy " + number(depth.cy) +
                               ") is far from the centre of the " + std::to_string(depth.width) + " x " +
                               std::to_string(depth.height) + " image: check the order fx, fy, cx, cy");
    }
    if (depth.depth == nullptr) return out;
    out.median_depth_m = sampled_median_metres(depth);
    if (out.median_depth_m == 0.0) return out;
    check_median(depth, out.median_depth_m);
    if (out.median_depth_m < kUsualMedianMetresMin || out.median_depth_m > kUsualMedianMetresMax) {
        out.warnings.push_back("the median depth is " + number(out.median_depth_m) + " m with metres_per_unit " +
                               number(depth.metres_per_unit) + ", outside the usual " + number(kUsualMedianMetresMin) +
                               " to " + number(kUsualMedianMetresMax) +
                               " m: check the depth scale (a D405's is 0.0001, most cameras' 0.001)");
    }
    return out;
}

}  // namespace pyrseg
