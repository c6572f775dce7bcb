#pragma once
// Non-owning views of an organized point cloud. Nothing viewed is ever modified.
#include <cstddef>

namespace pyrseg {

// Point (x, y) component c is points[(y * row_stride + x) * point_stride + c]; normals use the same layout.
// point_stride 3 is packed xyz; 4 is PCL's padded PointXYZ; a PCL PointNormal array works with both pointers
// into the same array (&cloud[0].x and &cloud[0].normal_x) and point_stride = sizeof(PointNormal)/sizeof(float).
struct CloudView {
    const float* points = nullptr;   // required; camera space, z along the optical axis, in the caller's unit
    const float* normals = nullptr;  // optional; unit length expected; estimated when null
    int width = 0;
    int height = 0;
    std::size_t row_stride = 0;  // in points; 0 means width
    int point_stride = 3;        // floats from one point to the next, >= 3
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
