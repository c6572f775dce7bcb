#pragma once
// Parameters for the kinds of depth sensor pyrseg users have, and a look at a frame that says which kind it resembles.
// The numbers and how they were chosen are in docs/quality.md; the sensor models they were tuned on in
// docs/sensors.md.
#include <optional>
#include <span>
#include <string>
#include <string_view>

#include "pyrseg/cloud.hpp"
#include "pyrseg/depth.hpp"
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

// What kind of sensor a frame's depth looks like, measured on the frame itself (no ground truth needed), from its
// depth alone:
//  - noise: the mean absolute second difference of depth along rows, |z(x-1) - 2 z(x) + z(x+1)|, over triples of
//    valid pixels on one surface (each neighbour within z/16), leaving out the largest 10% (the curvature of small
//    objects and creases). On a smooth surface that is the sensor's noise and quantization: a structured-light
//    scanner shows about 0.2 mm, consumer depth cameras 0.3 mm and more at 1 m;
//  - whole millimetres: the share of the non-zero depth differences of those triples that are whole millimetres (a
//    camera's 16-bit millimetre depth: a consumer camera, whatever its noise after the SDK's smoothing);
//  - depth levels: the median gap between the distinct depths (whole millimetres) that occur within 40 mm of the
//    quartiles of the frame's depth, per square metre of that depth. A Kinect v1 (and Xtion, Astra) reports depth
//    in steps of its disparity, about 2.9 mm at 1 m growing with z^2; stereo and time-of-flight cameras fill every
//    millimetre;
//  - stereo shadows: of the holes (runs of pixels without depth, 2 or more, between two valid pixels on one row)
//    whose sides differ in depth by more than 10%, the share whose nearer side is on the right. An active stereo
//    camera that matches from its left imager (RealSense D4xx) leaves them on the left of near objects.
// The suggestion, in that order: too few samples (under 1000): the defaults (structured-light); noise at most 0.4 mm
// in depth that is not whole millimetres: structured-light; depth levels at least 2.2 mm per square metre:
// kinect-v1; stereo shadows on the left (at least 60% of at least 50 holes): realsense-d435; otherwise (dense
// levels, no one-sided shadows, as a time-of-flight camera's): azure-kinect.
struct FrameNoise {
    std::size_t samples = 0;            // triples measured
    double median_depth_mm = 0.0;       // of the valid pixels sampled
    double second_difference_mm = 0.0;  // the trimmed mean above, millimetres
    double whole_mm_share = 0.0;        // of the non-zero differences, 0..1
    double level_step_mm_per_m2 = 0.0;  // 0 when not measured
    std::size_t shadow_holes = 0;       // holes between a near and a far side
    double left_shadow_share = 0.0;     // of those, with the near side on the right, 0..1
    SensorKind suggested = SensorKind::structured_light;
    std::string reason;  // one sentence for users: what was measured and why that kind
};
// Below this many samples a frame is too small to judge: it is suggested the defaults.
inline constexpr std::size_t kMinFrameNoiseSamples = 1000;
// unit_mm as in Params.
[[nodiscard]] PYRSEG_EXPORT FrameNoise measure_frame_noise(const CloudView& cloud, double unit_mm);
// The same from a depth image's samples (metres_per_unit as in DepthView; the intrinsics are not needed).
[[nodiscard]] PYRSEG_EXPORT FrameNoise measure_frame_noise(const DepthView& depth);

}  // namespace pyrseg
