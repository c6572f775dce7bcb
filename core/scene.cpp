// Section 10c: supports and the objects resting on them, from the segment statistics alone.
#include "pyrseg/scene.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>

#include "pyrseg/error.hpp"

namespace pyrseg {
namespace {

using Vec3 = std::array<double, 3>;

double dot(const Vec3& a, const Vec3& b) {
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

Vec3 cross(const Vec3& a, const Vec3& b) {
    return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}

// u^T C w for the covariance's six entries xx, xy, xz, yy, yz, zz.
double quadratic(const std::array<double, 6>& c, const Vec3& u, const Vec3& w) {
    const Vec3 cw = {c[0] * w[0] + c[1] * w[1] + c[2] * w[2], c[1] * w[0] + c[3] * w[1] + c[4] * w[2],
                     c[2] * w[0] + c[4] * w[1] + c[5] * w[2]};
    return dot(u, cw);
}

// Half the width of a uniform distribution with variance v.
double half_width(double v) {
    return std::sqrt(3.0 * std::max(v, 0.0));
}

void check_threshold(double value, const char* name, double upper) {
    if (std::isfinite(value) && value >= 0 && value <= upper) return;
    char expected[64];
    if (upper < std::numeric_limits<double>::max()) {
        std::snprintf(expected, sizeof expected, "0..%g", upper);
    } else {
        std::snprintf(expected, sizeof expected, "a finite value >= 0");
    }
    throw Error(ErrorCode::invalid_parameter,
                std::string("SceneParams::") + name + " is " + std::to_string(value) + ": expected " + expected);
}

bool has_geometry(const SegmentStats& s) {
    return s.fillable_count >= 3 && std::isfinite(s.plane_rms) && std::isfinite(s.extents[1]);
}

struct Placement {
    double lowest = 0;  // the object's lowest point above the support's plane
    double top = 0;     // and its highest
};

// Where the object's points lie along the support's normal: their mean height h above its plane, and h -+ the half
// width of their spread along it.
Placement place(const SegmentStats& object, const SceneSupport& support) {
    const double h = dot(support.normal, object.centroid) + support.offset;
    const double spread = half_width(quadratic(object.covariance, support.normal, support.normal));
    return {h - spread, h + spread};
}

// The box over the support: up is the support's normal, the other axes the object's principal axes in the plane
// (the first with its largest component positive); from the plane to the object's top: what stands over a table
// rests on it, though the camera may see only its top.
void stand(const SegmentStats& s, const SceneSupport& support, const Placement& at, SceneObject& o) {
    const Vec3& up = support.normal;
    const Vec3& u = support.axes[0];
    const Vec3 w = cross(up, u);
    const double a = quadratic(s.covariance, u, u);
    const double b = quadratic(s.covariance, u, w);
    const double c = quadratic(s.covariance, w, w);
    const double angle = 0.5 * std::atan2(2.0 * b, a - c);
    const double cs = std::cos(angle);
    const double sn = std::sin(angle);
    Vec3 first = {cs * u[0] + sn * w[0], cs * u[1] + sn * w[1], cs * u[2] + sn * w[2]};
    std::size_t largest = 0;
    for (std::size_t i = 1; i < 3; ++i) {
        if (std::fabs(first[i]) > std::fabs(first[largest])) largest = i;
    }
    if (first[largest] < 0) {
        for (double& v : first) v = -v;
    }
    o.axes = {first, cross(up, first), up};
    const double bottom = 0.0;
    o.extents = {2.0 * half_width(quadratic(s.covariance, o.axes[0], o.axes[0])),
                 2.0 * half_width(quadratic(s.covariance, o.axes[1], o.axes[1])), at.top - bottom};
    // The centroid dropped onto the plane, then lifted to the middle of the box's height.
    const double h = dot(up, s.centroid) + support.offset;
    for (std::size_t i = 0; i < 3; ++i) o.box_centre[i] = s.centroid[i] - (h - 0.5 * (bottom + at.top)) * up[i];
    o.height = at.top;
}

}  // namespace

void describe_scene(const std::vector<SegmentStats>& segments, const Params& params, const SceneParams& scene_params,
                    Scene& out) {
    constexpr double kAny = std::numeric_limits<double>::max();
    check_threshold(scene_params.support_min_share, "support_min_share", 1.0);
    check_threshold(scene_params.support_flatness, "support_flatness", kAny);
    check_threshold(scene_params.contact_mm, "contact_mm", kAny);
    check_threshold(scene_params.max_height_mm, "max_height_mm", kAny);
    check_threshold(scene_params.level_degrees, "level_degrees", 90.0);
    if (!std::isfinite(params.unit_mm) || params.unit_mm <= 0) {
        throw Error(ErrorCode::invalid_parameter,
                    "Params::unit_mm is " + std::to_string(params.unit_mm) + ": expected a finite value > 0");
    }
    out.supports.clear();
    out.objects.clear();
    double labelled = 0;
    for (const SegmentStats& s : segments) labelled += s.pixel_count;

    for (const SegmentStats& s : segments) {
        if (!has_geometry(s) || double(s.pixel_count) < scene_params.support_min_share * labelled) continue;
        if (s.plane_rms > scene_params.support_flatness * s.extents[1]) continue;
        out.supports.push_back(
            {s.label, s.pixel_count, s.plane_normal, s.plane_offset, s.plane_rms, s.centroid, s.axes, s.extents});
    }
    std::sort(out.supports.begin(), out.supports.end(), [](const SceneSupport& a, const SceneSupport& b) {
        return a.pixel_count != b.pixel_count ? a.pixel_count > b.pixel_count : a.label < b.label;
    });
    // Level: parallel to the largest support (a table, a floor), within level_degrees; walls are not.
    const double level_cosine = std::cos(scene_params.level_degrees * 3.14159265358979323846 / 180.0);
    for (SceneSupport& support : out.supports) {
        support.level = dot(support.normal, out.supports.front().normal) >= level_cosine;
    }

    const double contact = scene_params.contact_mm / params.unit_mm;
    const double max_height = scene_params.max_height_mm / params.unit_mm;
    for (const SegmentStats& s : segments) {
        if (!has_geometry(s) || s.pixel_count < scene_params.object_min_pixels) continue;
        // A level support is no object; another (a wall, a box's large face) is one where it touches a level
        // support.
        const auto as_support = std::find_if(out.supports.begin(), out.supports.end(),
                                             [&](const SceneSupport& p) { return p.label == s.label; });
        if (as_support != out.supports.end() && as_support->level) continue;
        SceneObject o;
        o.label = s.label;
        o.pixel_count = s.pixel_count;
        o.centroid = s.centroid;
        // The nearest support below it: among the level planes the object lies above (its lowest point no more
        // than contact below, its top at most max_height above), the largest of those within contact of the nearest
        // (a table's pieces are one plane; the first, the largest, of equals).
        double nearest = std::numeric_limits<double>::infinity();
        for (const SceneSupport& support : out.supports) {
            const Placement at = place(s, support);
            if (support.level && at.lowest >= -contact && at.top > 0 && at.top <= max_height) {
                nearest = std::min(nearest, at.lowest);
            }
        }
        Placement best{};
        for (std::size_t j = 0; j < out.supports.size() && o.support < 0; ++j) {
            const Placement at = place(s, out.supports[j]);
            if (out.supports[j].level && at.lowest >= -contact && at.top > 0 && at.top <= max_height &&
                at.lowest <= nearest + contact) {
                o.support = int(j);
                best = at;
            }
        }
        // A wall or a large face is an object only where it stands on a level support.
        if (as_support != out.supports.end() && (o.support < 0 || best.lowest > contact)) continue;
        if (o.support >= 0) {
            o.touches = best.lowest <= contact;
            stand(s, out.supports[std::size_t(o.support)], best, o);
        } else {
            o.box_centre = s.centroid;
            o.axes = s.axes;
            o.extents = s.extents;
            o.height = std::numeric_limits<double>::quiet_NaN();
        }
        out.objects.push_back(o);
    }
    std::sort(out.objects.begin(), out.objects.end(),
              [](const SceneObject& a, const SceneObject& b) { return a.label < b.label; });
}

}  // namespace pyrseg

namespace pyrseg {

std::array<double, 3> box_corner(const std::array<double, 3>& centre, const std::array<std::array<double, 3>, 3>& axes,
                                 const std::array<double, 3>& extents, int bits) {
    Vec3 p = centre;
    for (std::size_t a = 0; a < 3; ++a) {
        const double half = ((bits >> a) & 1) != 0 ? 0.5 * extents[a] : -0.5 * extents[a];
        for (std::size_t c = 0; c < 3; ++c) p[c] += half * axes[a][c];
    }
    return p;
}

namespace {

// The least and greatest coordinates along o's axes (kept in o.box_centre and o.extents during the fit) over the
// pixels begin..end of one object's run that are fillable and have a point.
void project_run(std::span<const float> points, std::span<const std::uint8_t> fillable, std::size_t begin,
                 std::size_t end, SceneObject& o) {
    const std::array<Vec3, 3> axes = o.axes;
    Vec3 low = o.box_centre;
    Vec3 high = o.extents;
    for (std::size_t i = begin; i < end; ++i) {
        if (!fillable.empty() && fillable[i] == 0) continue;
        const Vec3 p = {points[3 * i], points[3 * i + 1], points[3 * i + 2]};
        if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2])) continue;
        for (std::size_t a = 0; a < 3; ++a) {
            const double along = dot(axes[a], p);
            low[a] = std::min(low[a], along);
            high[a] = std::max(high[a], along);
        }
    }
    o.box_centre = low;
    o.extents = high;
}

}  // namespace

void fit_object_boxes(std::span<const float> points, std::span<const std::uint32_t> labels,
                      std::span<const std::uint8_t> fillable, Scene& scene) {
    if (points.size() != 3 * labels.size()) {
        throw Error(ErrorCode::invalid_argument, "fit_object_boxes: " + std::to_string(points.size()) +
                                                     " point coordinates for " + std::to_string(labels.size()) +
                                                     " labels (3 per pixel expected)");
    }
    if (!fillable.empty() && fillable.size() != labels.size()) {
        throw Error(ErrorCode::invalid_argument, "fit_object_boxes: a fillable mask of " +
                                                     std::to_string(fillable.size()) + " pixels for " +
                                                     std::to_string(labels.size()) + " labels");
    }
    // Each object's box centre and extents hold, during the pass, the least and the greatest coordinate along its
    // axes (no scratch to allocate). The labels come in runs (a row of one segment): each run finds its object by
    // binary search (objects are sorted by label) and is projected with the object's axes and bounds in locals.
    constexpr double kInf = std::numeric_limits<double>::infinity();
    for (SceneObject& o : scene.objects) {
        o.box_centre = {kInf, kInf, kInf};
        o.extents = {-kInf, -kInf, -kInf};
    }
    const std::size_t n = labels.size();
    for (std::size_t begin = 0; begin < n;) {
        const std::uint32_t l = labels[begin];
        std::size_t end = begin + 1;
        while (end < n && labels[end] == l) ++end;
        if (l != 0) {
            const auto it = std::lower_bound(scene.objects.begin(), scene.objects.end(), l,
                                             [](const SceneObject& o, std::uint32_t v) { return o.label < v; });
            if (it != scene.objects.end() && it->label == l) project_run(points, fillable, begin, end, *it);
        }
        begin = end;
    }
    for (SceneObject& o : scene.objects) {
        Vec3 low = o.box_centre;
        Vec3 high = o.extents;
        if (!(low[0] <= high[0])) {  // none of its pixels has a point: an empty box at its centroid
            low = high = {dot(o.axes[0], o.centroid), dot(o.axes[1], o.centroid), dot(o.axes[2], o.centroid)};
        }
        if (o.support >= 0) {
            // From the support's plane (at -offset along its normal, the box's third axis), or its lowest point below
            // the plane (noise), to its top.
            const double plane = -scene.supports[std::size_t(o.support)].offset;
            low[2] = std::min(low[2], plane);
            high[2] = std::max(high[2], low[2]);
            o.height = high[2] - plane;
        }
        o.box_centre = {0, 0, 0};
        for (std::size_t a = 0; a < 3; ++a) {
            o.extents[a] = high[a] - low[a];
            const double mid = 0.5 * (low[a] + high[a]);
            for (std::size_t c = 0; c < 3; ++c) o.box_centre[c] += mid * o.axes[a][c];
        }
    }
}

}  // namespace pyrseg
