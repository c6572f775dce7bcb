#include "gjk.hpp"

namespace pyrseg::synthetic::detail {
namespace {

struct Simplex {
    Vec3 p[4];  // p[0] is the newest point
    int n = 0;
};

// Keeps the feature of the simplex (newest point a first) nearest the origin and the search direction toward the
// origin from it; true when the origin is inside.
bool triangle_case(Simplex& s, Vec3& d) {
    const Vec3 a = s.p[0], b = s.p[1], c = s.p[2];
    const Vec3 ab = b - a, ac = c - a, ao = -a;
    const Vec3 abc = cross(ab, ac);
    if (dot(cross(abc, ac), ao) > 0) {
        if (dot(ac, ao) > 0) {
            s = {{a, c}, 2};
            d = cross(cross(ac, ao), ac);
            return false;
        }
    } else if (dot(cross(ab, abc), ao) <= 0) {
        const double side = dot(abc, ao);
        if (side == 0) return true;
        d = side > 0 ? abc : -abc;
        return false;
    }
    if (dot(ab, ao) > 0) {
        s = {{a, b}, 2};
        d = cross(cross(ab, ao), ab);
    } else {
        s = {{a}, 1};
        d = ao;
    }
    return false;
}

bool tetrahedron_case(Simplex& s, Vec3& d) {
    const Vec3 a = s.p[0], ao = -a;
    // The three faces through the newest point, each with the vertex it leaves out.
    const Vec3 faces[3][3] = {{s.p[1], s.p[2], s.p[3]}, {s.p[2], s.p[3], s.p[1]}, {s.p[3], s.p[1], s.p[2]}};
    for (const auto& f : faces) {
        Vec3 n = cross(f[0] - a, f[1] - a);
        if (dot(n, f[2] - a) > 0) n = -n;
        if (dot(n, ao) > 0) {
            s = {{a, f[0], f[1]}, 3};
            return triangle_case(s, d);
        }
    }
    return true;
}

bool update(Simplex& s, Vec3& d) {
    if (s.n == 2) {
        const Vec3 a = s.p[0], ab = s.p[1] - a, ao = -a;
        if (dot(ab, ao) > 0) {
            d = cross(cross(ab, ao), ab);
        } else {
            s.n = 1;
            d = ao;
        }
        return false;
    }
    if (s.n == 3) return triangle_case(s, d);
    return tetrahedron_case(s, d);
}

}  // namespace

bool overlaps(const Solid& a, const Solid& b, double margin) {
    const Vec3 between = a.center - b.center;
    const double reach = bounding_radius(a) + bounding_radius(b) + margin;
    if (dot(between, between) > reach * reach) return false;

    auto minkowski = [&](Vec3 dir) {
        const double n = norm(dir);
        return support(a, dir) + dir * (margin / n) - support(b, -dir);
    };
    Vec3 d = dot(between, between) > 0 ? between : Vec3{1, 0, 0};
    Simplex s;
    s.p[0] = minkowski(d);
    s.n = 1;
    d = -s.p[0];
    for (int iteration = 0; iteration < 64; ++iteration) {
        // A vanishing direction means the origin lies on the simplex: touching, which counts as overlap.
        if (dot(d, d) < 1e-24) return true;
        const Vec3 p = minkowski(d);
        if (dot(p, d) < 0) return false;
        s.p[3] = s.p[2];
        s.p[2] = s.p[1];
        s.p[1] = s.p[0];
        s.p[0] = p;
        ++s.n;
        if (update(s, d)) return true;
    }
    return true;
}

}  // namespace pyrseg::synthetic::detail
