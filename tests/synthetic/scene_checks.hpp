#pragma once
// Checks shared by the synthetic generator's tests: byte comparison of scenes, and whether a point lies on a
// primitive's surface with the surface's normal there.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

#include "pyrseg/synthetic.hpp"

namespace pyrseg::synthetic_test {

using synthetic::Primitive;
using synthetic::Scene;
using synthetic::Shape;

using V3 = std::array<double, 3>;

inline V3 point_at(const Scene& s, std::size_t i) {
    return {s.points[3 * i], s.points[3 * i + 1], s.points[3 * i + 2]};
}
inline V3 normal_at(const Scene& s, std::size_t i) {
    return {s.normals[3 * i], s.normals[3 * i + 1], s.normals[3 * i + 2]};
}
inline double dot(const V3& a, const V3& b) {
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
inline V3 sub(const V3& a, const V3& b) {
    return {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
}
inline double length(const V3& a) {
    return std::sqrt(dot(a, a));
}

template <typename T>
inline bool same_bytes(const std::vector<T>& a, const std::vector<T>& b) {
    return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
}

inline bool same_scene(const Scene& a, const Scene& b) {
    return a.width == b.width && a.height == b.height && same_bytes(a.points, b.points) &&
           same_bytes(a.normals, b.normals) && same_bytes(a.object_id, b.object_id) && a.primitives == b.primitives;
}

inline std::size_t pixel_count(const Scene& s) {
    return static_cast<std::size_t>(s.width) * static_cast<std::size_t>(s.height);
}

inline const Primitive& primitive(const Scene& s, std::uint32_t id) {
    const auto it =
        std::find_if(s.primitives.begin(), s.primitives.end(), [&](const Primitive& p) { return p.id == id; });
    if (it == s.primitives.end()) throw std::logic_error("no primitive with id " + std::to_string(id));
    return *it;
}

// How far p is outside the primitive's surface (negative: inside) along with whether n is a normal of the surface
// there; planes measure the signed distance.
struct SurfaceCheck {
    double distance;
    bool normal_ok;
};

inline SurfaceCheck check_surface(const Primitive& prim, const V3& p, const V3& n) {
    constexpr double kTol = 1e-3;
    const V3 d = sub(p, prim.center);
    const V3 l{dot(d, prim.axes[0]), dot(d, prim.axes[1]), dot(d, prim.axes[2])};
    const V3 nl{dot(n, prim.axes[0]), dot(n, prim.axes[1]), dot(n, prim.axes[2])};
    auto is_axis = [&](int i, double sign) { return std::abs(nl[static_cast<std::size_t>(i)] - sign) < 1e-5; };
    switch (prim.shape) {
        case Shape::plane:
            return {l[2], is_axis(2, 1)};
        case Shape::sphere:
            return {length(d) - prim.half_size[0],
                    length(sub(n, {d[0] / length(d), d[1] / length(d), d[2] / length(d)})) < 1e-4};
        case Shape::box: {
            double outside = -1e300;
            bool normal_ok = false;
            for (int i = 0; i < 3; ++i) {
                const double e = std::abs(l[static_cast<std::size_t>(i)]) - prim.half_size[static_cast<std::size_t>(i)];
                outside = std::max(outside, e);
                if (e > -kTol && is_axis(i, l[static_cast<std::size_t>(i)] < 0 ? -1 : 1)) normal_ok = true;
            }
            return {outside, normal_ok};
        }
        case Shape::cylinder: {
            const double radial = std::hypot(l[0], l[1]);
            const double side = radial - prim.half_size[0], cap = std::abs(l[2]) - prim.half_size[2];
            bool normal_ok = cap > -kTol && is_axis(2, l[2] < 0 ? -1 : 1);
            if (side > -kTol) {
                normal_ok = normal_ok || (std::abs(nl[0] - l[0] / radial) < 1e-4 &&
                                          std::abs(nl[1] - l[1] / radial) < 1e-4 && std::abs(nl[2]) < 1e-5);
            }
            return {std::max(side, cap), normal_ok};
        }
    }
    return {1e300, false};
}

}  // namespace pyrseg::synthetic_test
