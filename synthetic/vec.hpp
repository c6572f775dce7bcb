#pragma once
// Small double-precision vector algebra for the scene generator.
#include <cmath>

namespace pyrseg::synthetic::detail {

struct Vec3 {
    double x = 0, y = 0, z = 0;
};

inline Vec3 operator+(Vec3 a, Vec3 b) {
    return {a.x + b.x, a.y + b.y, a.z + b.z};
}
inline Vec3 operator-(Vec3 a, Vec3 b) {
    return {a.x - b.x, a.y - b.y, a.z - b.z};
}
inline Vec3 operator-(Vec3 a) {
    return {-a.x, -a.y, -a.z};
}
inline Vec3 operator*(Vec3 a, double s) {
    return {a.x * s, a.y * s, a.z * s};
}
inline Vec3 operator*(double s, Vec3 a) {
    return {a.x * s, a.y * s, a.z * s};
}
inline double dot(Vec3 a, Vec3 b) {
    return a.x * b.x + a.y * b.y + a.z * b.z;
}
inline Vec3 cross(Vec3 a, Vec3 b) {
    return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline double norm(Vec3 a) {
    return std::sqrt(dot(a, a));
}
inline Vec3 normalized(Vec3 a) {
    return a * (1.0 / norm(a));
}

// Rodrigues: v rotated by angle (radians) about the unit axis k.
inline Vec3 rotated(Vec3 v, Vec3 k, double angle) {
    const double c = std::cos(angle), s = std::sin(angle);
    return v * c + cross(k, v) * s + k * (dot(k, v) * (1.0 - c));
}

// A right-handed orthonormal frame; axis[i] are the local axes expressed in the parent frame.
struct Frame {
    Vec3 axis[3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};

    [[nodiscard]] Vec3 to_local(Vec3 v) const { return {dot(v, axis[0]), dot(v, axis[1]), dot(v, axis[2])}; }
    [[nodiscard]] Vec3 to_parent(Vec3 v) const { return axis[0] * v.x + axis[1] * v.y + axis[2] * v.z; }
};

// The frame whose z is the given unit vector and whose x is as close as possible to the hint.
inline Frame frame_from_z(Vec3 z, Vec3 x_hint) {
    Vec3 x = x_hint - z * dot(x_hint, z);
    if (dot(x, x) < 1e-12) x = std::abs(z.x) < 0.9 ? Vec3{1, 0, 0} - z * z.x : Vec3{0, 1, 0} - z * z.y;
    Frame f;
    f.axis[2] = z;
    f.axis[0] = normalized(x);
    f.axis[1] = cross(z, f.axis[0]);
    return f;
}

}  // namespace pyrseg::synthetic::detail
