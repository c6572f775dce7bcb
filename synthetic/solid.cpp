#include "solid.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace pyrseg::synthetic::detail {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kMinCos = 1e-5;

double sign_of(double v) {
    return v < 0 ? -1.0 : 1.0;
}

// Intersects the running entry/exit interval with the slab |o_i + t d_i| <= e; remembers which side was entered.
bool clip_slab(double o, double d, double e, int axis, double& t_in, double& t_out, int& in_axis, double& in_sign) {
    if (d == 0) return std::abs(o) <= e;
    const double inv = 1.0 / d;
    const double t_near = (-sign_of(d) * e - o) * inv;
    const double t_far = (sign_of(d) * e - o) * inv;
    if (t_near > t_in) {
        t_in = t_near;
        in_axis = axis;
        in_sign = -sign_of(d);
    }
    t_out = std::min(t_out, t_far);
    return true;
}

}  // namespace

Vec3 support(const Solid& solid, Vec3 d) {
    const Vec3 l = solid.frame.to_local(d);
    switch (solid.shape) {
        case Shape::box:
            return solid.center + solid.frame.to_parent({sign_of(l.x) * solid.half.x, sign_of(l.y) * solid.half.y,
                                                         sign_of(l.z) * solid.half.z});
        case Shape::cylinder: {
            const double radial = std::sqrt(l.x * l.x + l.y * l.y);
            Vec3 p{0, 0, sign_of(l.z) * solid.half.z};
            if (radial > 1e-300) {
                p.x = l.x / radial * solid.half.x;
                p.y = l.y / radial * solid.half.x;
            }
            return solid.center + solid.frame.to_parent(p);
        }
        case Shape::sphere: {
            const double n = norm(d);
            return n > 0 ? solid.center + d * (solid.half.x / n) : solid.center + Vec3{solid.half.x, 0, 0};
        }
        case Shape::plane:
            break;
    }
    return solid.center;
}

double bounding_radius(const Solid& solid) {
    switch (solid.shape) {
        case Shape::box:
            return norm(solid.half);
        case Shape::cylinder:
            return std::sqrt(solid.half.x * solid.half.x + solid.half.z * solid.half.z);
        case Shape::sphere:
            return solid.half.x;
        case Shape::plane:
            break;
    }
    return kInf;
}

void bounding_corners(const Solid& solid, Vec3 corners[8]) {
    for (int i = 0; i < 8; ++i) {
        const Vec3 l{(i & 1) ? solid.half.x : -solid.half.x, (i & 2) ? solid.half.y : -solid.half.y,
                     (i & 4) ? solid.half.z : -solid.half.z};
        corners[i] = solid.center + solid.frame.to_parent(l);
    }
}

bool ray_entry(const Solid& solid, Vec3 origin, Vec3 dir, double t_max, Hit& hit) {
    Hit h;
    switch (solid.shape) {
        case Shape::plane: {
            const Vec3 n = solid.frame.axis[2];
            const double nd = dot(n, dir);
            if (nd >= 0) return false;
            h.t = dot(n, solid.center - origin) / nd;
            h.normal = n;
            break;
        }
        case Shape::box: {
            const Vec3 o = solid.frame.to_local(origin - solid.center);
            const Vec3 d = solid.frame.to_local(dir);
            double t_in = -kInf, t_out = kInf, sign = 1;
            int axis = -1;
            if (!clip_slab(o.x, d.x, solid.half.x, 0, t_in, t_out, axis, sign)) return false;
            if (!clip_slab(o.y, d.y, solid.half.y, 1, t_in, t_out, axis, sign)) return false;
            if (!clip_slab(o.z, d.z, solid.half.z, 2, t_in, t_out, axis, sign)) return false;
            if (axis < 0 || t_in > t_out) return false;
            h.t = t_in;
            h.normal = solid.frame.axis[axis] * sign;
            break;
        }
        case Shape::cylinder: {
            const Vec3 o = solid.frame.to_local(origin - solid.center);
            const Vec3 d = solid.frame.to_local(dir);
            double t_in = -kInf, t_out = kInf, sign = 1;
            int axis = -1;
            if (!clip_slab(o.z, d.z, solid.half.z, 2, t_in, t_out, axis, sign)) return false;
            const double r = solid.half.x;
            const double a = d.x * d.x + d.y * d.y;
            const double b = o.x * d.x + o.y * d.y;
            const double c = o.x * o.x + o.y * o.y - r * r;
            bool side = false;
            if (a > 0) {
                const double disc = b * b - a * c;
                if (disc < 0) return false;
                // The numerically stable pair of roots of a t^2 + 2 b t + c.
                const double q = -(b + sign_of(b) * std::sqrt(disc));
                double t0 = q / a, t1 = q != 0 ? c / q : t0;
                if (t0 > t1) std::swap(t0, t1);
                if (t0 > t_in) {
                    t_in = t0;
                    side = true;
                }
                t_out = std::min(t_out, t1);
            } else if (c > 0) {
                return false;
            }
            if ((axis < 0 && !side) || t_in > t_out) return false;
            h.t = t_in;
            if (side) {
                const Vec3 radial{o.x + t_in * d.x, o.y + t_in * d.y, 0};
                h.normal = solid.frame.to_parent(normalized(radial));
            } else {
                h.normal = solid.frame.axis[2] * sign;
            }
            break;
        }
        case Shape::sphere: {
            const Vec3 oc = origin - solid.center;
            const double a = dot(dir, dir);
            const double b = dot(oc, dir);
            const double c = dot(oc, oc) - solid.half.x * solid.half.x;
            const double disc = b * b - a * c;
            if (disc < 0 || b >= 0) return false;
            h.t = c / (-b + std::sqrt(disc));  // the nearer root, without cancellation
            h.normal = normalized(oc + dir * h.t);
            break;
        }
    }
    if (!(h.t > 0) || !(h.t < t_max)) return false;
    if (dot(h.normal, dir) > -kMinCos * norm(dir)) return false;
    hit = h;
    return true;
}

Solid moved(const Solid& solid, Vec3 offset) {
    Solid s = solid;
    s.center = s.center + offset;
    return s;
}

}  // namespace pyrseg::synthetic::detail
