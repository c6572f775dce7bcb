#include "tools/synthetic_scene_scores.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <set>
#include <tuple>

#include "tools/eval/tabletop_boxes.hpp"

namespace pyrseg::cli {
namespace {

using Vec3 = std::array<double, 3>;

double dot(const Vec3& a, const Vec3& b) {
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

// Which part of its primitive a point lies on: a box's face 0..5 (2 * axis, + 1 on the positive side), a cylinder's
// side 0 or caps 1, 2; planes and spheres one part, 0.
int part_of(const synthetic::Primitive& p, const Vec3& point) {
    const Vec3 d = {point[0] - p.center[0], point[1] - p.center[1], point[2] - p.center[2]};
    const Vec3 local = {dot(d, p.axes[0]), dot(d, p.axes[1]), dot(d, p.axes[2])};
    if (p.shape == synthetic::Shape::box) {
        std::size_t axis = 0;
        double most = -1;
        for (std::size_t a = 0; a < 3; ++a) {
            const double r = std::fabs(local[a]) / p.half_size[a];
            if (r > most) {
                most = r;
                axis = a;
            }
        }
        return int(2 * axis) + (local[axis] > 0 ? 1 : 0);
    }
    if (p.shape == synthetic::Shape::cylinder) {
        const double radial = std::hypot(local[0], local[1]) / p.half_size[0];
        const double along = std::fabs(local[2]) / p.half_size[2];
        return radial >= along ? 0 : (local[2] > 0 ? 2 : 1);
    }
    return 0;
}

struct Part {
    std::uint32_t id = 0;  // the generator's object id
    int part = 0;
    friend bool operator<(const Part& a, const Part& b) { return a.id != b.id ? a.id < b.id : a.part < b.part; }
};

// The flat part's plane: a point on it and its unit normal.
bool flat_part_plane(const synthetic::Primitive& p, int part, Vec3& point, Vec3& normal) {
    if (p.shape == synthetic::Shape::plane) {
        point = p.center;
        normal = p.axes[2];
        return true;
    }
    if (p.shape != synthetic::Shape::box) return false;
    const auto axis = std::size_t(part / 2);
    const double side = part % 2 == 1 ? 1.0 : -1.0;
    normal = p.axes[axis];
    for (std::size_t c = 0; c < 3; ++c) point[c] = p.center[c] + side * p.half_size[axis] * normal[c];
    return true;
}

// The angle between a plane's normal and the part's, and the part's plane's distance from the plane's centroid (mm).
void add_plane_error(const synthetic::Primitive& p, const Part& part, const Vec3& normal, const Vec3& centroid_mm,
                     SyntheticSceneScores& out) {
    Vec3 point{}, truth_normal{};
    if (!flat_part_plane(p, part.part, point, truth_normal)) return;
    const double cosine = std::min(1.0, std::fabs(dot(truth_normal, normal)));
    const double degrees = std::acos(cosine) * 180.0 / std::numbers::pi;
    out.plane_degrees.push_back(degrees);
    const Vec3 c = {centroid_mm[0] - point[0], centroid_mm[1] - point[1], centroid_mm[2] - point[2]};
    out.plane_mm.push_back(std::fabs(dot(truth_normal, c)));
    out.planes.push_back({out.frames, part.id, part.part, degrees, out.plane_mm.back()});
}

}  // namespace

void score_peer_planes(const synthetic::Scene& truth, const std::vector<float>& points,
                       const std::vector<PeerPlane>& planes, SyntheticSceneScores& out) {
    std::map<std::uint32_t, const synthetic::Primitive*> primitive;
    for (const synthetic::Primitive& p : truth.primitives) primitive[p.id] = &p;
    ++out.frames;
    for (const PeerPlane& plane : planes) {
        std::map<Part, std::size_t> on;
        Vec3 sum{};
        std::size_t n = 0;
        for (const std::uint32_t index : *plane.inliers) {
            const std::size_t i = index;
            const Vec3 pt = {points[3 * i], points[3 * i + 1], points[3 * i + 2]};
            const auto p = primitive.find(truth.object_id[i]);
            if (p == primitive.end() || !std::isfinite(pt[2])) continue;
            ++on[{p->first, part_of(*p->second, pt)}];
            for (std::size_t c = 0; c < 3; ++c) sum[c] += pt[c];
            ++n;
        }
        if (n == 0) continue;
        for (const auto& [part, count] : on) {
            if (count * 10 < n * 8) continue;
            const Vec3 centroid = {sum[0] / double(n), sum[1] / double(n), sum[2] / double(n)};
            add_plane_error(*primitive.at(part.id), part, plane.normal, centroid, out);
        }
    }
}

void score_synthetic_scene(const synthetic::Scene& truth, const std::vector<float>& points, const Result& result,
                           const Scene& scene, double unit_mm, SyntheticSceneScores& out) {
    std::map<std::uint32_t, const synthetic::Primitive*> primitive;
    for (const synthetic::Primitive& p : truth.primitives) primitive[p.id] = &p;
    // Pixels per (segment, part), per segment, per object.
    std::map<std::uint32_t, std::map<Part, std::size_t>> on;
    std::map<std::uint32_t, std::size_t> segment_pixels, object_pixels;
    for (std::size_t i = 0; i < result.labels.size(); ++i) {
        const std::uint32_t id = truth.object_id[i];
        const Vec3 pt = {points[3 * i], points[3 * i + 1], points[3 * i + 2]};
        if (id == synthetic::kNoDataId || !std::isfinite(pt[2])) continue;
        ++object_pixels[id];
        const std::uint32_t l = result.labels[i];
        if (l == 0) continue;
        ++segment_pixels[l];
        const auto p = primitive.find(id);
        ++on[l][{id, p == primitive.end() ? 0 : part_of(*p->second, pt)}];
    }
    // Each segment's dominant part (80% of it), and each object's segment holding most of it.
    std::map<std::uint32_t, Part> dominant;
    std::map<std::uint32_t, std::map<std::uint32_t, std::size_t>> object_in_segment;  // segment -> object -> pixels
    for (const auto& [label, parts] : on) {
        for (const auto& [part, n] : parts) {
            object_in_segment[label][part.id] += n;
            if (n * 10 >= segment_pixels[label] * 8) dominant[label] = part;
        }
    }
    ++out.frames;
    if (!scene.supports.empty()) {
        const auto d = dominant.find(scene.supports.front().label);
        if (d != dominant.end() && d->second.id == synthetic::kFloorId) ++out.floor_largest;
    }
    for (const SegmentStats& s : result.segments) {
        const auto d = dominant.find(s.label);
        if (d == dominant.end() || !std::isfinite(s.plane_rms)) continue;
        const synthetic::Primitive& p = *primitive.at(d->second.id);
        if (p.shape == synthetic::Shape::box) {
            ++out.planar_faces;
            if (s.planar) ++out.planar_faces_flagged;
        } else if (p.shape == synthetic::Shape::cylinder && d->second.part == 0) {
            ++out.cylinder_sides;
            if (s.planar) ++out.cylinder_sides_flagged;
        }
        if (!s.planar) continue;  // the plane models: segments flagged planar, as a peer returns only planes
        add_plane_error(p, d->second, s.plane_normal,
                        {s.centroid[0] * unit_mm, s.centroid[1] * unit_mm, s.centroid[2] * unit_mm}, out);
    }
    for (const SceneObject& o : scene.objects) {
        const auto held = object_in_segment.find(o.label);
        if (held == object_in_segment.end()) continue;
        std::uint32_t id = 0;
        std::size_t most = 0;
        for (const auto& [object, n] : held->second) {
            if (n > most) {
                most = n;
                id = object;
            }
        }
        const auto p = primitive.find(id);
        if (p == primitive.end() || p->second->shape != synthetic::Shape::box) continue;
        if (most * 10 < segment_pixels[o.label] * 8 || most * 10 < object_pixels[id] * 8) continue;
        const Vec3 scale = {unit_mm, unit_mm, unit_mm};
        const Vec3 centre = {o.box_centre[0] * scale[0], o.box_centre[1] * scale[1], o.box_centre[2] * scale[2]};
        const Vec3 extents = {o.extents[0] * unit_mm, o.extents[1] * unit_mm, o.extents[2] * unit_mm};
        const synthetic::Primitive& box = *p->second;
        out.box_iou.push_back(eval::box_iou(
            {o.label, centre, o.axes, extents},
            {box.id, box.center, box.axes, {2 * box.half_size[0], 2 * box.half_size[1], 2 * box.half_size[2]}}));
    }
}

MatchedPlanes match_planes(const SyntheticSceneScores& a, const SyntheticSceneScores& b) {
    std::map<std::tuple<std::size_t, std::uint32_t, int>, const PlaneScore*> first_of_b;
    for (const PlaneScore& p : b.planes) first_of_b.try_emplace({p.frame, p.object, p.part}, &p);
    std::set<std::tuple<std::size_t, std::uint32_t, int>> done;
    MatchedPlanes m;
    for (const PlaneScore& p : a.planes) {
        const std::tuple<std::size_t, std::uint32_t, int> key{p.frame, p.object, p.part};
        const auto other = first_of_b.find(key);
        if (other == first_of_b.end() || !done.insert(key).second) continue;
        m.a_degrees.push_back(p.degrees);
        m.a_mm.push_back(p.mm);
        m.b_degrees.push_back(other->second->degrees);
        m.b_mm.push_back(other->second->mm);
    }
    return m;
}

}  // namespace pyrseg::cli
