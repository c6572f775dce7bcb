#pragma once
// The analytic solids a scene is made of: support mapping (for contact placement) and ray entry (for rendering).
#include <cstdint>

#include "pyrseg/synthetic.hpp"
#include "vec.hpp"

namespace pyrseg::synthetic::detail {

struct Solid {
    Shape shape = Shape::plane;
    std::uint32_t id = 0;
    Vec3 center;  // plane: a point on it
    Frame frame;  // plane: axis[2] is the normal; cylinder: axis[2] is the axis
    Vec3 half;    // box: half edges; cylinder: radius, radius, half length; sphere: radius x3
};

struct Hit {
    double t = 0;
    Vec3 normal;
};

// The point of the solid farthest along d (d need not be unit). Planes have none; never call it for one.
Vec3 support(const Solid& solid, Vec3 d);

// Radius of a sphere about the centre that holds the solid.
double bounding_radius(const Solid& solid);

// The 8 corners of a box about the solid (cylinders and spheres get their bounding box).
void bounding_corners(const Solid& solid, Vec3 corners[8]);

// Where the ray origin + t * dir, 0 < t < t_max, enters the solid, with the outward normal there. The origin must be
// outside. Entries at glancing incidence (|cos| < 1e-5) count as misses, so that every returned normal clearly faces
// the origin even after rounding to float.
bool ray_entry(const Solid& solid, Vec3 origin, Vec3 dir, double t_max, Hit& hit);

Solid moved(const Solid& solid, Vec3 offset);

}  // namespace pyrseg::synthetic::detail
