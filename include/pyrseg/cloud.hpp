#pragma once
// Non-owning views of an organized point cloud. Nothing viewed is ever modified.
#include <cstddef>
#include <cstdint>

namespace pyrseg {

// Point (x, y) component c is points[(y * row_stride + x) * point_stride + c]; normals use the same layout.
// point_stride 3 is packed xyz; 4 is PCL's padded PointXYZ; a PCL PointNormal array works with both pointers
// into the same array (&cloud[0].x and &cloud[0].normal_x) and point_stride = sizeof(PointNormal)/sizeof(float).
//
// Layouts whose rows are not whole points (a ROS sensor_msgs/PointCloud2 with padded rows, an SDK's interleaved
// buffer) are given in bytes instead: point (x, y) then starts y * row_step_bytes + x * point_step_bytes bytes after
// `points` (and after `normals`). ROS: point_step and row_step, with `points` at the x field's offset; PCL:
// sizeof(PointT). Byte steps must be multiples of 4 (floats are read in place, so the pointers must be 4-byte
// aligned too); a step given in bytes replaces the one given in floats or points, which must then keep its default.
struct CloudView {
    const float* points = nullptr;   // required; camera space, z along the optical axis, in the caller's unit
    const float* normals = nullptr;  // optional; unit length expected; estimated when null
    int width = 0;
    int height = 0;
    std::size_t row_stride = 0;        // in points; 0 means width
    int point_stride = 3;              // floats from one point to the next, >= 3
    std::size_t point_step_bytes = 0;  // bytes from one point to the next, >= 12; 0: point_stride floats
    std::size_t row_step_bytes = 0;    // bytes from one row to the next; 0: row_stride points
    // Optional: the colour camera's image registered to the points (an RGB-D camera's aligned colour), 8-bit R, G, B
    // per pixel; pixel (x, y) is color[y * color_row_step_bytes + 3 * x + c]. With it, pixels on a colour edge are
    // not fillable (Params::color_edge_threshold; docs/algorithm.md section 2c).
    const std::uint8_t* color = nullptr;
    std::size_t color_row_step_bytes = 0;  // 0: 3 * width
};

}  // namespace pyrseg

namespace pyrseg {

// A fillable mask made by the caller's own edge detector, to be labelled by the pyramid (passes 3..7).
// Pixel (x, y) is fillable[y * row_stride + x] != 0; valid (optional, same layout; null = every pixel valid) says
// which non-fillable pixels edge labelling may label.
struct MaskView {
    const unsigned char* fillable = nullptr;
    const unsigned char* valid = nullptr;
    int width = 0;
    int height = 0;
    std::size_t row_stride = 0;  // in pixels; 0 means width
};

}  // namespace pyrseg
