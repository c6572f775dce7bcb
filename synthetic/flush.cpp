#include <algorithm>
#include <cmath>

#include "pyrseg/synthetic.hpp"

namespace pyrseg::synthetic {
namespace {

using Vec = std::array<double, 3>;

double dot(const Vec& a, const Vec& b) {
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
Vec minus(const Vec& a, const Vec& b) {
    return {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
}

// Placement leaves touching solids at most 0.01 mm apart; this allows for the rounding of the camera transform.
constexpr double kTolerance = 0.05;
constexpr double kParallel = 1.0 - 1e-9;

// The half extent of box b along the unit direction d, when d is parallel to one of b's side axes (x or y).
bool side_extent(const Primitive& b, const Vec& d, double& extent) {
    for (int axis = 0; axis < 2; ++axis) {
        if (std::abs(dot(b.axes[axis], d)) > kParallel) {
            extent = b.half_size[axis];
            return true;
        }
    }
    return false;
}

bool flush(const Primitive& a, const Primitive& b) {
    if (a.shape != Shape::box || b.shape != Shape::box) return false;
    // Up is each box's local z (the boxes the layout stands upright keep z vertical); both must share it.
    if (dot(a.axes[2], b.axes[2]) < kParallel) return false;
    const Vec up = a.axes[2];
    const double top_a = dot(a.center, up) + a.half_size[2];
    const double top_b = dot(b.center, up) + b.half_size[2];
    if (std::abs(top_a - top_b) > kTolerance) return false;
    const Vec offset = minus(b.center, a.center);
    for (int across = 0; across < 2; ++across) {
        const Vec& normal = a.axes[across];  // a's side face normal
        const Vec& along = a.axes[1 - across];
        double b_across = 0;
        double b_along = 0;
        if (!side_extent(b, normal, b_across) || !side_extent(b, along, b_along)) return false;
        const double gap = std::abs(dot(offset, normal)) - a.half_size[across] - b_across;
        const double overlap = a.half_size[1 - across] + b_along - std::abs(dot(offset, along));
        if (std::abs(gap) <= kTolerance && overlap > kTolerance) return true;
    }
    return false;
}

}  // namespace

std::vector<std::array<std::uint32_t, 2>> flush_pairs(const Scene& scene) {
    std::vector<std::array<std::uint32_t, 2>> pairs;
    const std::vector<Primitive>& p = scene.primitives;
    for (std::size_t i = 0; i < p.size(); ++i) {
        if (p[i].id < kFirstObjectId) continue;
        for (std::size_t j = i + 1; j < p.size(); ++j) {
            if (p[j].id < kFirstObjectId || !flush(p[i], p[j])) continue;
            pairs.push_back({std::min(p[i].id, p[j].id), std::max(p[i].id, p[j].id)});
        }
    }
    std::sort(pairs.begin(), pairs.end());
    return pairs;
}

}  // namespace pyrseg::synthetic
