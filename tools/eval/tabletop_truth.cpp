#include "tools/eval/tabletop_truth.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <stdexcept>
#include <string>
#include <utility>

namespace pyrseg::eval {
namespace {

using Vec3 = std::array<double, 3>;

Vec3 sub(const Vec3& a, const Vec3& b) {
    return {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
}
double dot(const Vec3& a, const Vec3& b) {
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
Vec3 cross(const Vec3& a, const Vec3& b) {
    return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
double norm(const Vec3& a) {
    return std::sqrt(dot(a, a));
}
Vec3 scaled(const Vec3& a, double s) {
    return {a[0] * s, a[1] * s, a[2] * s};
}

// splitmix64: a generator of its own, so that the truth does not depend on the standard library's distributions.
struct SplitMix {
    std::uint64_t state;
    std::uint64_t next() {
        std::uint64_t z = (state += 0x9E3779B97F4A7C15ull);
        z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
        z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
        return z ^ (z >> 31);
    }
    std::size_t below(std::size_t n) { return std::size_t(next() % n); }
};

// The eigenvector of the smallest eigenvalue of a symmetric 3x3 matrix (cyclic Jacobi rotations).
Vec3 smallest_eigenvector(std::array<std::array<double, 3>, 3> a) {
    std::array<std::array<double, 3>, 3> v{{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}};
    for (int sweep = 0; sweep < 50; ++sweep) {
        const double off = a[0][1] * a[0][1] + a[0][2] * a[0][2] + a[1][2] * a[1][2];
        if (off < 1e-30) break;
        for (int p = 0; p < 2; ++p) {
            for (int q = p + 1; q < 3; ++q) {
                if (a[p][q] == 0) continue;
                const double theta = (a[q][q] - a[p][p]) / (2 * a[p][q]);
                const double t = (theta >= 0 ? 1.0 : -1.0) / (std::abs(theta) + std::sqrt(theta * theta + 1));
                const double c = 1 / std::sqrt(t * t + 1);
                const double s = t * c;
                for (int k = 0; k < 3; ++k) {  // a = a * J
                    const double akp = a[k][p];
                    const double akq = a[k][q];
                    a[k][p] = c * akp - s * akq;
                    a[k][q] = s * akp + c * akq;
                }
                for (int k = 0; k < 3; ++k) {  // a = J^T * a
                    const double apk = a[p][k];
                    const double aqk = a[q][k];
                    a[p][k] = c * apk - s * aqk;
                    a[q][k] = s * apk + c * aqk;
                }
                for (int k = 0; k < 3; ++k) {  // v = v * J
                    const double vkp = v[k][p];
                    const double vkq = v[k][q];
                    v[k][p] = c * vkp - s * vkq;
                    v[k][q] = s * vkp + c * vkq;
                }
            }
        }
    }
    int smallest = 0;
    for (int k = 1; k < 3; ++k) {
        if (a[k][k] < a[smallest][smallest]) smallest = k;
    }
    return {v[0][smallest], v[1][smallest], v[2][smallest]};
}

struct Points {
    std::vector<Vec3> xyz;             // per pixel (zero where there is no depth)
    std::vector<unsigned char> valid;  // per pixel
    std::vector<std::size_t> valid_pixels;
};

Points back_project(int width, int height, std::span<const float> depth, const TabletopCamera& k) {
    Points p;
    const std::size_t n = std::size_t(width) * std::size_t(height);
    p.xyz.assign(n, Vec3{0, 0, 0});
    p.valid.assign(n, 0);
    for (int y = 0; y < height; ++y) {
        for (int x = 0; x < width; ++x) {
            const std::size_t i = std::size_t(y) * std::size_t(width) + std::size_t(x);
            const double z = depth[i];
            if (!std::isfinite(z) || z <= 0) continue;
            p.xyz[i] = {(x - k.cx) * z / k.fx, (y - k.cy) * z / k.fy, z};
            p.valid[i] = 1;
            p.valid_pixels.push_back(i);
        }
    }
    return p;
}

// The plane with unit normal n through `point`, oriented towards the camera at the origin (offset >= 0).
SupportPlane oriented_plane(Vec3 n, const Vec3& point) {
    double d = -dot(n, point);
    if (d < 0) {
        n = scaled(n, -1);
        d = -d;
    }
    SupportPlane plane;
    plane.normal = n;
    plane.offset = d;
    return plane;
}

// The plane through the points, oriented towards the camera (oriented_plane); a zero normal when they are collinear.
SupportPlane plane_through(const Vec3& a, const Vec3& b, const Vec3& c) {
    Vec3 n = cross(sub(b, a), sub(c, a));
    const double length = norm(n);
    if (length < 1e-12) return SupportPlane{{0, 0, 0}, 0, 0};
    return oriented_plane(scaled(n, 1 / length), a);
}

double height_above(const SupportPlane& plane, const Vec3& p) {
    return dot(plane.normal, p) + plane.offset;
}

// Least squares through the inliers of `plane`; the inliers of the result counted over every valid pixel.
SupportPlane refine(const SupportPlane& plane, const Points& p, double tolerance) {
    Vec3 centroid{0, 0, 0};
    std::uint64_t count = 0;
    for (const std::size_t i : p.valid_pixels) {
        if (std::abs(height_above(plane, p.xyz[i])) > tolerance) continue;
        for (int k = 0; k < 3; ++k) centroid[std::size_t(k)] += p.xyz[i][std::size_t(k)];
        ++count;
    }
    if (count < 3) return plane;
    centroid = scaled(centroid, 1.0 / double(count));
    std::array<std::array<double, 3>, 3> cov{};
    for (const std::size_t i : p.valid_pixels) {
        if (std::abs(height_above(plane, p.xyz[i])) > tolerance) continue;
        const Vec3 q = sub(p.xyz[i], centroid);
        for (std::size_t r = 0; r < 3; ++r) {
            for (std::size_t c = 0; c < 3; ++c) cov[r][c] += q[r] * q[c];
        }
    }
    const Vec3 n = smallest_eigenvector(cov);
    SupportPlane out = oriented_plane(scaled(n, 1 / norm(n)), centroid);
    for (const std::size_t i : p.valid_pixels) out.inliers += std::abs(height_above(out, p.xyz[i])) <= tolerance;
    return out;
}

// RANSAC over p's valid pixels, then least squares; with `parallel_to`, only hypotheses within
// params.support_parallel_degrees of parallel to it.
SupportPlane find_plane(const Points& p, const TabletopTruthParams& params, bool* found,
                        const SupportPlane* parallel_to = nullptr) {
    *found = false;
    SupportPlane best;
    if (p.valid_pixels.size() < 3) return best;
    const double min_cosine = std::cos(params.support_parallel_degrees * 3.14159265358979323846 / 180.0);
    // Hypotheses are scored on an even subsample of at most 20,000 valid pixels; the winner on all of them.
    const std::size_t stride = std::max<std::size_t>(1, p.valid_pixels.size() / 20000);
    SplitMix rng{params.seed};
    std::uint64_t best_score = 0;
    for (std::uint32_t it = 0; it < params.ransac_iterations; ++it) {
        const Vec3& a = p.xyz[p.valid_pixels[rng.below(p.valid_pixels.size())]];
        const Vec3& b = p.xyz[p.valid_pixels[rng.below(p.valid_pixels.size())]];
        const Vec3& c = p.xyz[p.valid_pixels[rng.below(p.valid_pixels.size())]];
        const SupportPlane h = plane_through(a, b, c);
        if (h.normal == Vec3{0, 0, 0}) continue;
        if (parallel_to != nullptr && std::abs(dot(h.normal, parallel_to->normal)) < min_cosine) continue;
        std::uint64_t score = 0;
        for (std::size_t j = 0; j < p.valid_pixels.size(); j += stride) {
            score += std::abs(height_above(h, p.xyz[p.valid_pixels[j]])) <= params.plane_tolerance;
        }
        if (score > best_score) {
            best_score = score;
            best = h;
        }
    }
    if (best_score <= 3) return best;
    *found = true;
    for (int round = 0; round < 3; ++round) best = refine(best, p, params.plane_tolerance);
    return best;
}

// The support: the plane RANSAC finds first; then, as long as the points above it hold a plane parallel to it with at
// least params.min_support_share of the frame's valid pixels, that plane: a table stands above the floor it is on,
// and may fill less of the frame than the floor around it.
SupportPlane find_support(const Points& p, const TabletopTruthParams& params, bool* found) {
    SupportPlane support = find_plane(p, params, found);
    if (!*found) return support;
    const double min_inliers = params.min_support_share * double(p.valid_pixels.size());
    Points above = p;
    for (int level = 0; level < 4; ++level) {
        above.valid_pixels.clear();
        for (const std::size_t i : p.valid_pixels) {
            if (height_above(support, p.xyz[i]) > params.plane_tolerance) above.valid_pixels.push_back(i);
        }
        if (double(above.valid_pixels.size()) < min_inliers) break;
        bool higher_found = false;
        const SupportPlane higher = find_plane(above, params, &higher_found, &support);
        if (!higher_found || double(higher.inliers) < min_inliers ||
            std::abs(dot(higher.normal, support.normal)) <
                std::cos(params.support_parallel_degrees * 3.14159265358979323846 / 180.0)) {
            break;
        }
        support = refine(higher, p, params.plane_tolerance);
    }
    return support;
}

// 4-connected components of the pixels `member` admits, joined where `joins(i, j)` holds for neighbours i, j; each
// component's pixels, in raster order of the components' first pixels.
template <class Member, class Joins>
std::vector<std::vector<std::size_t>> components(int width, int height, const Member& member, const Joins& joins) {
    const std::size_t n = std::size_t(width) * std::size_t(height);
    std::vector<unsigned char> seen(n, 0);
    std::vector<std::vector<std::size_t>> out;
    std::vector<std::size_t> stack;
    for (std::size_t start = 0; start < n; ++start) {
        if (seen[start] != 0 || !member(start)) continue;
        std::vector<std::size_t> pixels;
        seen[start] = 1;
        stack.push_back(start);
        while (!stack.empty()) {
            const std::size_t i = stack.back();
            stack.pop_back();
            pixels.push_back(i);
            const std::size_t x = i % std::size_t(width);
            const std::size_t y = i / std::size_t(width);
            const auto visit = [&](std::size_t j) {
                if (seen[j] == 0 && member(j) && joins(i, j)) {
                    seen[j] = 1;
                    stack.push_back(j);
                }
            };
            if (x > 0) visit(i - 1);
            if (x + 1 < std::size_t(width)) visit(i + 1);
            if (y > 0) visit(i - std::size_t(width));
            if (y + 1 < std::size_t(height)) visit(i + std::size_t(width));
        }
        std::sort(pixels.begin(), pixels.end());
        out.push_back(std::move(pixels));
    }
    return out;
}

using Vec2 = std::array<double, 2>;

double cross2(const Vec2& o, const Vec2& a, const Vec2& b) {
    return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]);
}

// Andrew's monotone chain: the hull counter-clockwise, without repeating the first point.
std::vector<Vec2> convex_hull(std::vector<Vec2> pts) {
    std::sort(pts.begin(), pts.end());
    pts.erase(std::unique(pts.begin(), pts.end()), pts.end());
    if (pts.size() < 3) return pts;
    std::vector<Vec2> hull(2 * pts.size());
    std::size_t k = 0;
    for (const Vec2& p : pts) {
        while (k >= 2 && cross2(hull[k - 2], hull[k - 1], p) <= 0) --k;
        hull[k++] = p;
    }
    const std::size_t lower = k + 1;
    for (std::size_t i = pts.size() - 1; i-- > 0;) {
        while (k >= lower && cross2(hull[k - 2], hull[k - 1], pts[i]) <= 0) --k;
        hull[k++] = pts[i];
    }
    hull.resize(k - 1);
    return hull;
}

bool inside_hull(const std::vector<Vec2>& hull, const Vec2& p) {
    if (hull.size() < 3) return false;
    for (std::size_t i = 0; i < hull.size(); ++i) {
        if (cross2(hull[i], hull[(i + 1) % hull.size()], p) < 0) return false;
    }
    return true;
}

}  // namespace

TabletopTruth make_tabletop_truth(int width, int height, std::span<const float> depth, const TabletopCamera& camera,
                                  const TabletopTruthParams& params) {
    if (width <= 0 || height <= 0 || depth.size() != std::size_t(width) * std::size_t(height)) {
        throw std::invalid_argument("tabletop truth: " + std::to_string(depth.size()) + " depths for a " +
                                    std::to_string(width) + " x " + std::to_string(height) + " frame");
    }
    for (const double v : {camera.fx, camera.fy}) {
        if (!std::isfinite(v) || v <= 0)
            throw std::invalid_argument("tabletop truth: fx and fy must be finite and > 0");
    }
    if (!std::isfinite(camera.cx) || !std::isfinite(camera.cy)) {
        throw std::invalid_argument("tabletop truth: cx and cy must be finite");
    }
    TabletopTruth truth;
    truth.labels.assign(depth.size(), kTruthNone);
    const Points p = back_project(width, height, depth, camera);
    truth.plane = find_support(p, params, &truth.found_plane);
    if (!truth.found_plane) return truth;
    const SupportPlane& plane = truth.plane;
    const auto height_of = [&](std::size_t i) { return height_above(plane, p.xyz[i]); };

    // The table: the plane's inliers in their largest component.
    const auto on_plane = [&](std::size_t i) {
        return p.valid[i] != 0 && std::abs(height_of(i)) <= params.plane_tolerance;
    };
    const auto anywhere = [](std::size_t, std::size_t) { return true; };
    std::vector<std::vector<std::size_t>> parts = components(width, height, on_plane, anywhere);
    if (parts.empty()) return truth;
    const auto largest =
        std::max_element(parts.begin(), parts.end(), [](const auto& a, const auto& b) { return a.size() < b.size(); });
    for (const std::size_t i : *largest) truth.labels[i] = kTruthTable;

    // Its outline on the plane: the convex hull of its points in a basis of the plane.
    const Vec3& n = plane.normal;
    const Vec3 axis = std::abs(n[0]) < 0.9 ? Vec3{1, 0, 0} : Vec3{0, 1, 0};
    Vec3 e1 = cross(n, axis);
    e1 = scaled(e1, 1 / norm(e1));
    const Vec3 e2 = cross(n, e1);
    const auto in_plane = [&](std::size_t i) { return Vec2{dot(p.xyz[i], e1), dot(p.xyz[i], e2)}; };
    std::vector<Vec2> table_points;
    table_points.reserve(largest->size());
    for (const std::size_t i : *largest) table_points.push_back(in_plane(i));
    const std::vector<Vec2> hull = convex_hull(std::move(table_points));

    // The objects: what stands above the table inside its outline, in depth-continuous components.
    std::vector<unsigned char> candidate(depth.size(), 0);
    for (const std::size_t i : p.valid_pixels) {
        const double h = height_of(i);
        candidate[i] = truth.labels[i] == kTruthNone && h >= params.min_height && h <= params.max_height &&
                       inside_hull(hull, in_plane(i));
    }
    const auto is_candidate = [&](std::size_t i) { return candidate[i] != 0; };
    const auto continuous = [&](std::size_t i, std::size_t j) {
        const double zi = p.xyz[i][2];
        const double zj = p.xyz[j][2];
        return std::abs(zi - zj) <= params.step_base + params.step_growth * std::min(zi, zj);
    };
    std::uint32_t next = kTruthTable + 1;
    for (const std::vector<std::size_t>& object : components(width, height, is_candidate, continuous)) {
        if (object.size() < params.min_object_pixels) continue;
        for (const std::size_t i : object) truth.labels[i] = next;
        ++next;
    }
    truth.objects = next - (kTruthTable + 1);
    return truth;
}

}  // namespace pyrseg::eval
