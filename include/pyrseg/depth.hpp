#pragma once
// A depth image as depth SDKs hand it over: one sample per pixel and the camera's pinhole intrinsics. pyrseg
// back-projects it on the device (docs/algorithm.md section 1b), so a frame uploads 2 (u16) or 4 (f32) bytes per
// pixel instead of a float cloud's 12. Nothing viewed is ever modified.
#include <cstddef>
#include <cstdint>

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
};

}  // namespace pyrseg
