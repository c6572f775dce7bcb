#pragma once
// Parameters for the kinds of depth sensor pyrseg users have, and a look at a frame that says which kind it resembles.
// The numbers and how they were chosen are in docs/quality.md; the sensor models they were tuned on in
// docs/sensors.md.
#include <optional>
#include <span>
#include <string>
#include <string_view>

#include "pyrseg/cloud.hpp"
#include "pyrseg/export.hpp"
#include "pyrseg/params.hpp"

namespace pyrseg {

enum class SensorKind : std::uint8_t {
    structured_light,  // low-noise structured-light scanners (PhoXi-like): the paper's metric and defaults
    kinect_v1,         // Kinect v1 / Xtion / Orbbec Astra-like structured light: disparity steps of 1/8 px
    realsense_d435,    // Intel RealSense D4xx-like active stereo
    azure_kinect,      // Azure Kinect / Kinect v2-like time of flight
};

// Every kind, in this order.
[[nodiscard]] PYRSEG_EXPORT std::span<const SensorKind> sensor_kinds();
// "structured-light", "kinect-v1", "realsense-d435", "azure-kinect".
[[nodiscard]] PYRSEG_EXPORT const char* sensor_kind_name(SensorKind kind);
[[nodiscard]] PYRSEG_EXPORT std::optional<SensorKind> sensor_kind_from_name(std::string_view name);
// One line on what the preset suits and how it differs from the defaults, for --help and messages.
[[nodiscard]] PYRSEG_EXPORT const char* sensor_kind_summary(SensorKind kind);

// The preset for a kind of sensor, for clouds in units of unit_mm millimetres. Every other field keeps its default.
// A unit_mm that is not finite and > 0 is pyrseg::Error(invalid_parameter), as in measure_frame_noise.
[[nodiscard]] PYRSEG_EXPORT Params sensor_preset(SensorKind kind, double unit_mm = 1.0);

// How noisy a frame's depth is, measured on the frame itself (no ground truth needed): the mean absolute second
// difference of depth along rows, |z(x-1) - 2 z(x) + z(x+1)|, over triples of valid pixels on one surface (each
// neighbour within z/16), leaving out the largest 10% (the curvature of small objects and creases, which grow as the
// resolution falls). On a smooth surface that is the sensor's noise and quantization: a structured-light scanner
// shows about 0.2 mm, consumer depth cameras 0.5 mm and more at 1 m.
struct FrameNoise {
    std::size_t samples = 0;            // triples measured
    double median_depth_mm = 0.0;       // of the valid pixels sampled
    double second_difference_mm = 0.0;  // the trimmed mean above, millimetres
    SensorKind suggested = SensorKind::structured_light;
    std::string reason;  // one sentence for users: what was measured and why that kind
};
// unit_mm as in Params. Frames with fewer than 1000 samples are suggested the defaults (structured_light).
[[nodiscard]] PYRSEG_EXPORT FrameNoise measure_frame_noise(const CloudView& cloud, double unit_mm);

}  // namespace pyrseg
