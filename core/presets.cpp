#include "pyrseg/presets.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "core/cloud_layout.hpp"
#include "core/plan.hpp"
#include "pyrseg/error.hpp"

namespace pyrseg {
namespace {

constexpr std::array kKinds = {SensorKind::structured_light, SensorKind::kinect_v1, SensorKind::realsense_d435,
                               SensorKind::azure_kinect};

// Above this trimmed mean |second difference| a frame is noisier than a structured-light scanner: the synthetic
// PhoXi-like model (0.1 mm sigma) measures 0.15 to 0.18 mm whatever its distance (0.6 to 2.5 m) and resolution
// (160x120 to 1032x772); the consumer models 0.86 to 12 mm (0.8 to 2 m); the shared scans 0.63 (stereo, mug), 1.00
// (Kinect-style, milk) and 5.27 (Kinect v1, CAPE, median depth 1.8 m).
constexpr double kConsumerSecondDifferenceMm = 0.4;
constexpr double kTrimmedShare = 0.9;  // the share of the smallest second differences averaged

// The robust metric with normal radius 1: the window (R) does the smoothing; and the merge (docs/algorithm.md section
// 5b) with its defaults: on the real RealSense tabletop frames it finds 12 of 21 objects whole instead of 9 and
// merges none more into the table, and on every consumer sensor model of the synthetic sweep it changes nothing
// (docs/quality.md). The structured-light scanner's preset keeps it off: on that model it merges 9 more objects.
struct Robust {
    double ct, ct_growth_per_m2, dt, dt_per_m2;
    int window, stride, edge_rounds;
};

Params robust(const Robust& r) {
    Params p;
    p.metric = Metric::robust;
    p.normal_radius = 1;
    p.normal_window = r.window;
    p.curvature_stride = r.stride;
    p.ct = r.ct;
    p.ct_growth_per_m2 = r.ct_growth_per_m2;
    p.dt = r.dt;
    p.dt_per_m2 = r.dt_per_m2;
    p.edge_rounds = r.edge_rounds;
    // Edge rounds stay on the surface whose depth they share (within 2%): without the test the surface around a small
    // object carries its label across the object's outline into the object's band. On the synthetic RealSense
    // model ARI 0.921 instead of 0.911 with as many objects merged; kinect-v1 and azure-kinect unchanged within
    // 0.001 (docs/quality.md).
    p.edge_max_depth_step = 0.02;
    p.merge = true;
    // The planar flag's tolerance grows with the noise, as z^2: 2 mm + 2 mm/m^2 flags every box face of the synthetic
    // tabletops planar for every consumer model (2 mm alone: 42% of them for kinect-v1, 58% for realsense-d435), and
    // as many cylinder sides for kinect-v1 (3), 3 more for realsense-d435 (14) (`pyrseg eval --tabletop-synthetic`,
    // docs/scene.md).
    p.planar_tolerance_per_m2 = 2.0;
    return p;
}

}  // namespace

std::span<const SensorKind> sensor_kinds() {
    return kKinds;
}

const char* sensor_kind_name(SensorKind kind) {
    switch (kind) {
        case SensorKind::structured_light:
            return "structured-light";
        case SensorKind::kinect_v1:
            return "kinect-v1";
        case SensorKind::realsense_d435:
            return "realsense-d435";
        case SensorKind::azure_kinect:
            return "azure-kinect";
    }
    return "unknown";
}

std::optional<SensorKind> sensor_kind_from_name(std::string_view name) {
    for (SensorKind k : kKinds) {
        if (name == sensor_kind_name(k)) return k;
    }
    return std::nullopt;
}

const char* sensor_kind_summary(SensorKind kind) {
    switch (kind) {
        case SensorKind::structured_light:
            return "low-noise structured-light scanners (PhoXi-like): the paper's metric and the contract's defaults";
        case SensorKind::kinect_v1:
            return "Kinect v1, Xtion, Orbbec Astra and other structured-light cameras with disparity steps: robust "
                   "metric";
        case SensorKind::realsense_d435:
            return "RealSense D4xx and other active stereo cameras: robust metric; with a colour image, colour edges "
                   "where the depth shows a crease";
        case SensorKind::azure_kinect:
            return "Azure Kinect, Kinect v2 and other time-of-flight cameras: robust metric, thresholds that grow "
                   "more slowly with depth";
    }
    return "";
}

Params sensor_preset(SensorKind kind, double unit_mm) {
    core::check_unit_mm(unit_mm);
    Params p;
    switch (kind) {
        case SensorKind::structured_light:
            break;
        // Chosen with `pyrseg eval` on the synthetic sensor models (docs/quality.md, "Choosing the presets") and
        // checked on the shared real scans (tests/cli): ct, ct growth, dt, dt growth, R, s, edge rounds.
        case SensorKind::kinect_v1:
            p = robust({0.6, 0.1, 5.0, 10.0, 3, 6, 8});
            break;
        case SensorKind::realsense_d435:
            p = robust({0.6, 0.3, 5.0, 10.0, 4, 6, 10});
            // With the colour camera's image: colour edges where the depth shows a crease too weak for the metric
            // (an object's foot that the stereo matcher rounds into the table). On the real RealSense tabletop
            // frames no object is merged with the table (2 without), as many are found whole (docs/quality.md).
            p.color_edge_threshold = 100;
            p.color_edge_curvature_share = 0.3;
            break;
        case SensorKind::azure_kinect:
            p = robust({0.4, 0.1, 5.0, 4.0, 3, 4, 8});
            break;
        default:
            throw Error(ErrorCode::invalid_parameter, "unknown sensor kind");
    }
    p.unit_mm = unit_mm;
    return p;
}

namespace {

constexpr double kKinectLevelStep = 2.2;  // mm per m^2: Kinect v1's disparity steps are about 2.9
constexpr double kLeftShadowShare = 0.6;
constexpr std::size_t kMinShadowHoles = 50;
constexpr double kLevelWindowMm = 40.0;
constexpr std::size_t kMinLevelPixels = 500;

// The features of FrameNoise from a depth accessor z(x, y) in millimetres (NaN or <= 0: no depth).
template <class DepthAt>
FrameNoise measure(std::size_t width, std::size_t height, const DepthAt& z_at) {
    FrameNoise out;
    const auto has = [](double z) { return std::isfinite(z) && z > 0; };
    std::vector<float> second;  // |second difference|, mm
    std::vector<double> depths;
    std::size_t nonzero = 0, whole = 0;
    for (std::size_t y = 0; y < height; y += 2) {  // every other row: plenty of samples
        for (std::size_t x = 1; x + 1 < width; ++x) {
            const double a = z_at(x - 1, y), b = z_at(x, y), c = z_at(x + 1, y);
            if (!(has(a) && has(b) && has(c))) continue;
            if (std::fabs(a - b) > b / 16 || std::fabs(c - b) > b / 16) continue;  // across an edge
            second.push_back(float(std::fabs(a - 2 * b + c)));
            const double d = std::fabs(c - b);
            if (d > 0) {
                ++nonzero;
                if (std::fabs(d - std::nearbyint(d)) < 1e-3) ++whole;
            }
            if (out.samples % 64 == 0) depths.push_back(b);
            ++out.samples;
        }
    }
    // Holes between a nearer and a farther side, and which side the nearer one is on.
    std::size_t left = 0;
    for (std::size_t y = 0; y < height; ++y) {
        std::size_t x = 0;
        while (x < width) {
            if (has(z_at(x, y))) {
                ++x;
                continue;
            }
            const std::size_t start = x;
            while (x < width && !has(z_at(x, y))) ++x;
            if (start == 0 || x >= width || x - start < 2) continue;
            const double zl = z_at(start - 1, y), zr = z_at(x, y);
            if (zr < zl * 0.9) {
                ++left;
                ++out.shadow_holes;
            } else if (zl < zr * 0.9) {
                ++out.shadow_holes;
            }
        }
    }
    char text[512];
    if (out.samples < kMinFrameNoiseSamples) {
        std::snprintf(text, sizeof text, "only %zu pixels could be measured, too few to judge the sensor", out.samples);
        out.reason = text;
        return out;
    }
    out.left_shadow_share = out.shadow_holes != 0 ? double(left) / double(out.shadow_holes) : 0.0;
    out.whole_mm_share = nonzero != 0 ? double(whole) / double(nonzero) : 0.0;
    std::sort(depths.begin(), depths.end());
    out.median_depth_mm = depths[depths.size() / 2];
    // The gaps between the whole-millimetre depths that occur near each quartile, per square metre of depth: which
    // depths occur in each quartile's window, from one pass over every other row.
    constexpr std::size_t kWindows = 3;
    const auto levels = std::size_t(2 * kLevelWindowMm);
    std::array<double, kWindows> first{};  // the depth of each window's first level
    for (std::size_t q = 0; q < kWindows; ++q) {
        const double quartile = 0.25 * double(q + 1);
        first[q] = std::nearbyint(depths[std::size_t(quartile * double(depths.size() - 1))]) - kLevelWindowMm;
    }
    std::vector<unsigned char> seen(kWindows * levels, 0);
    std::array<std::size_t, kWindows> pixels{};
    for (std::size_t y = 0; y < height; y += 2) {
        for (std::size_t x = 0; x < width; ++x) {
            const double z = z_at(x, y);
            if (!has(z)) continue;
            for (std::size_t q = 0; q < kWindows; ++q) {
                const double k = std::nearbyint(z) - first[q];
                if (k < 0 || k >= double(levels)) continue;
                seen[q * levels + std::size_t(k)] = 1;
                ++pixels[q];
            }
        }
    }
    std::vector<double> steps;
    for (std::size_t q = 0; q < kWindows; ++q) {
        std::vector<double> gaps;
        std::size_t previous = levels;
        for (std::size_t k = 0; k < levels; ++k) {
            if (seen[q * levels + k] == 0) continue;
            if (previous != levels) gaps.push_back(double(k - previous));
            previous = k;
        }
        if (pixels[q] < kMinLevelPixels || gaps.size() < 2) continue;
        std::nth_element(gaps.begin(), gaps.begin() + std::ptrdiff_t(gaps.size() / 2), gaps.end());
        const double metres = (first[q] + kLevelWindowMm) / 1000.0;
        steps.push_back(gaps[gaps.size() / 2] / (metres * metres));
    }
    if (!steps.empty()) {
        std::sort(steps.begin(), steps.end());
        out.level_step_mm_per_m2 = steps[steps.size() / 2];
    }
    const auto kept = std::ptrdiff_t(double(second.size()) * kTrimmedShare);
    std::nth_element(second.begin(), second.begin() + kept, second.end());
    double sum = 0.0;
    for (std::ptrdiff_t i = 0; i < kept; ++i) sum += second[std::size_t(i)];
    out.second_difference_mm = kept > 0 ? sum / double(kept) : 0.0;

    const bool whole_mm = out.whole_mm_share >= 0.9;
    const char* why = "";
    if (out.second_difference_mm <= kConsumerSecondDifferenceMm && !whole_mm) {
        out.suggested = SensorKind::structured_light;
        why = "low noise in sub-millimetre depth: a structured-light scanner";
    } else if (out.level_step_mm_per_m2 >= kKinectLevelStep) {
        out.suggested = SensorKind::kinect_v1;
        why = "depth in disparity steps: a Kinect v1-like structured-light camera";
    } else if (out.shadow_holes >= kMinShadowHoles && out.left_shadow_share >= kLeftShadowShare) {
        out.suggested = SensorKind::realsense_d435;
        why = "stereo shadows on the left of near surfaces: an active stereo camera";
    } else {
        out.suggested = SensorKind::azure_kinect;
        why = "dense depth levels without one-sided shadows: a time-of-flight camera";
    }
    std::snprintf(text, sizeof text,
                  "depth noise %.2f mm at a median depth of %.2f m, %s, depth levels %.1f mm apart per square metre, "
                  "%.0f%% of %zu holes beside near surfaces on their left: %s",
                  out.second_difference_mm, out.median_depth_mm / 1000.0,
                  whole_mm ? "in whole millimetres" : "not in whole millimetres", out.level_step_mm_per_m2,
                  100.0 * out.left_shadow_share, out.shadow_holes, why);
    out.reason = text;
    return out;
}

}  // namespace

FrameNoise measure_frame_noise(const CloudView& cloud, double unit_mm) {
    core::check_unit_mm(unit_mm);
    if (cloud.points == nullptr || cloud.width < 3 || cloud.height < 1) {
        FrameNoise out;
        out.reason = "the frame is too small to measure its noise";
        return out;
    }
    const core::CloudLayout layout = core::cloud_layout(cloud);
    return measure(std::size_t(cloud.width), std::size_t(cloud.height),
                   [&](std::size_t x, std::size_t y) { return double(cloud.points[layout.at(x, y) + 2]) * unit_mm; });
}

FrameNoise measure_frame_noise(const DepthView& depth) {
    if (!std::isfinite(depth.metres_per_unit) || depth.metres_per_unit <= 0) {
        throw Error(ErrorCode::invalid_parameter, "metres_per_unit must be a finite number of metres > 0, got " +
                                                      std::to_string(depth.metres_per_unit));
    }
    if (depth.depth == nullptr || depth.width < 3 || depth.height < 1) {
        FrameNoise out;
        out.reason = "the frame is too small to measure its noise";
        return out;
    }
    const std::size_t sample = depth.format == DepthFormat::u16 ? 2 : 4;
    if (depth.row_step_bytes != 0 && depth.row_step_bytes < sample * std::size_t(depth.width)) {
        throw Error(ErrorCode::invalid_argument, "row_step_bytes " + std::to_string(depth.row_step_bytes) +
                                                     " is shorter than a row of " + std::to_string(depth.width) +
                                                     " samples");
    }
    const std::size_t step = depth.row_step_bytes != 0 ? depth.row_step_bytes : sample * std::size_t(depth.width);
    const auto* bytes = static_cast<const unsigned char*>(depth.depth);
    const double mm = depth.metres_per_unit * 1000.0;
    return measure(std::size_t(depth.width), std::size_t(depth.height), [&](std::size_t x, std::size_t y) {
        const unsigned char* at = bytes + y * step + x * sample;
        if (depth.format == DepthFormat::u16) {
            std::uint16_t d;
            std::memcpy(&d, at, 2);
            return d == 0 ? std::nan("") : double(d) * mm;
        }
        float d;
        std::memcpy(&d, at, 4);
        return double(d) * mm;
    });
}

}  // namespace pyrseg
