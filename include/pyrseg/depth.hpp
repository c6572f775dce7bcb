#pragma once
// A depth image as depth SDKs hand it over: one sample per pixel and the camera's pinhole intrinsics. pyrseg
// back-projects it on the device (docs/algorithm.md section 1b), so a frame uploads 2 (u16) or 4 (f32) bytes per
// pixel instead of a float cloud's 12. Nothing viewed is ever modified.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "pyrseg/export.hpp"

namespace pyrseg {

enum class DepthFormat : std::uint8_t {
    u16,  // unsigned 16-bit samples (RealSense, Kinect, Orbbec, PNG depth maps); 0 = no data
    f32,  // float32 samples; zero, negative, subnormal, infinite and NaN samples = no data
};

struct DepthView {
    const void* depth = nullptr;  // required; row-major samples
    DepthFormat format = DepthFormat::u16;
    int width = 0;
    int height = 0;
    std::size_t row_step_bytes = 0;  // bytes from one row to the next; 0: width samples
    // The depth of one sample unit in metres, as the SDK states it (RealSense's depth scale, 0.001 for millimetres,
    // 1 for float metres). Required: there is no default, because guessing it wrong scales every threshold.
    double metres_per_unit = 0.0;
    // Pinhole intrinsics in pixels: pixel (u, v) at depth z is ((u - cx) z / fx, (v - cy) z / fy, z).
    double fx = 0.0, fy = 0.0, cx = 0.0, cy = 0.0;
    // Optional: the colour image registered to the depth (RealSense's align-to-depth, Azure Kinect's transformed
    // colour), 8-bit R, G, B per pixel; pixel (x, y) is color[y * color_row_step_bytes + 3 * x + c]. With it, pixels on
    // a colour edge are not fillable (Params::color_edge_threshold; docs/algorithm.md section 2c).
    const std::uint8_t* color = nullptr;
    std::size_t color_row_step_bytes = 0;  // 0: 3 * width
};

// The median depths in metres that depth cameras' frames have. Outside them the unit given for the samples (or a
// cloud's) is wrong, usually by a factor of 1000 or inverted, and every threshold in millimetres with it.
inline constexpr double kMedianDepthMetresMin = 0.05;
inline constexpr double kMedianDepthMetresMax = 100.0;

// What check_depth_camera found in a frame whose camera is usable.
struct DepthCameraCheck {
    // The median depth in metres of a grid of up to 64 x 64 of the frame's samples; 0 when it was not measured (no
    // host samples: a device frame; or fewer than 16 valid samples in the grid).
    double median_depth_m = 0.0;
    // Values that are legal but unusual, each a sentence naming the value and what to check: a median depth under
    // 0.15 m or over 20 m, pixels far from square (fx / fy outside 0.8 to 1.25), a principal point more than a
    // quarter of the width or the height from the centre.
    std::vector<std::string> warnings;
};

// Checks a depth frame's camera (metres_per_unit and the intrinsics) for the mistakes that otherwise segment a frame
// into one segment or none without a word: throws pyrseg::Error (invalid_parameter), naming the value and the fix,
// when metres_per_unit, fx or fy is not finite and > 0, cx or cy is not finite; the principal point (cx, cy) lies
// outside the image, or the intrinsics read well only as cx, cy, fx, fy (far from square pixels or an off-centre
// principal point as given; square and centred the other way round); fx or fy gives a field of view outside 0.1 to 175
// degrees (fx = 1e-300); or, with host samples, the median depth lies outside 0.05 to 100 m, where no depth camera
// sees a frame (a millimetre image read with metres_per_unit 1 or 1000). Segmenter::segment(DepthView) runs these
// checks on its first depth frame and whenever the camera changes (the intrinsics on every frame); the CLI and the
// Python module report the warnings. docs/algorithm.md section 1b.
[[nodiscard]] PYRSEG_EXPORT DepthCameraCheck check_depth_camera(const DepthView& depth);

}  // namespace pyrseg
