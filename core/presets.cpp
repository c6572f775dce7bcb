#include "pyrseg/presets.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
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
constexpr std::size_t kMinSamples = 1000;

// The robust metric with normal radius 1: the window (R) does the smoothing.
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
            return "RealSense D4xx and other active stereo cameras: robust metric";
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

FrameNoise measure_frame_noise(const CloudView& cloud, double unit_mm) {
    core::check_unit_mm(unit_mm);
    FrameNoise out;
    if (cloud.points == nullptr || cloud.width < 3 || cloud.height < 1) {
        out.reason = "the frame is too small to measure its noise";
        return out;
    }
    const core::CloudLayout layout = core::cloud_layout(cloud);
    const auto z_at = [&](std::size_t x, std::size_t y) { return double(cloud.points[layout.at(x, y) + 2]) * unit_mm; };
    std::vector<float> second;  // |second difference|, mm
    std::vector<double> depths;
    for (std::size_t y = 0; y < std::size_t(cloud.height); y += 2) {  // every other row: plenty of samples
        for (std::size_t x = 1; x + 1 < std::size_t(cloud.width); ++x) {
            const double a = z_at(x - 1, y), b = z_at(x, y), c = z_at(x + 1, y);
            if (!(std::isfinite(a) && std::isfinite(b) && std::isfinite(c) && a > 0 && b > 0 && c > 0)) continue;
            if (std::fabs(a - b) > b / 16 || std::fabs(c - b) > b / 16) continue;  // across an edge
            second.push_back(float(std::fabs(a - 2 * b + c)));
            if (out.samples % 64 == 0) depths.push_back(b);
            ++out.samples;
        }
    }
    char text[256];
    if (out.samples < kMinSamples) {
        std::snprintf(text, sizeof text, "only %zu pixels could be measured, too few to judge the sensor", out.samples);
        out.reason = text;
        return out;
    }
    std::nth_element(depths.begin(), depths.begin() + std::ptrdiff_t(depths.size() / 2), depths.end());
    out.median_depth_mm = depths[depths.size() / 2];
    const auto kept = std::ptrdiff_t(double(second.size()) * kTrimmedShare);
    std::nth_element(second.begin(), second.begin() + kept, second.end());
    double sum = 0.0;
    for (std::ptrdiff_t i = 0; i < kept; ++i) sum += second[std::size_t(i)];
    out.second_difference_mm = kept > 0 ? sum / double(kept) : 0.0;
    const bool noisy = out.second_difference_mm > kConsumerSecondDifferenceMm;
    out.suggested = noisy ? SensorKind::kinect_v1 : SensorKind::structured_light;
    std::snprintf(text, sizeof text,
                  "depth noise %.2f mm (mean |second difference| along rows) at a median depth of %.2f m; above "
                  "%.1f mm looks like a consumer depth camera",
                  out.second_difference_mm, out.median_depth_mm / 1000.0, kConsumerSecondDifferenceMm);
    out.reason = text;
    return out;
}

}  // namespace pyrseg
