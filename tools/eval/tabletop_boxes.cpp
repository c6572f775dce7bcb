#include "tools/eval/tabletop_boxes.hpp"

#include <cmath>
#include <map>
#include <stdexcept>
#include <unordered_map>

namespace pyrseg::eval {

bool box_holds(const OrientedBox& box, const std::array<double, 3>& p) {
    const std::array<double, 3> d = {p[0] - box.centre[0], p[1] - box.centre[1], p[2] - box.centre[2]};
    for (std::size_t i = 0; i < 3; ++i) {
        const double along = d[0] * box.axes[i][0] + d[1] * box.axes[i][1] + d[2] * box.axes[i][2];
        if (!(std::fabs(along) <= 0.5 * box.extents[i])) return false;
    }
    return true;
}

namespace {

// The share of a lattice of points filling `box` that lies inside `other`.
double lattice_share_inside(const OrientedBox& box, const OrientedBox& other) {
    constexpr int kSteps = 24;
    int held = 0;
    for (int i = 0; i < kSteps; ++i) {
        for (int j = 0; j < kSteps; ++j) {
            for (int k = 0; k < kSteps; ++k) {
                const std::array<double, 3> f = {(i + 0.5) / kSteps - 0.5, (j + 0.5) / kSteps - 0.5,
                                                 (k + 0.5) / kSteps - 0.5};
                std::array<double, 3> q = box.centre;
                for (std::size_t a = 0; a < 3; ++a) {
                    for (std::size_t c = 0; c < 3; ++c) q[c] += f[a] * box.extents[a] * box.axes[a][c];
                }
                if (box_holds(other, q)) ++held;
            }
        }
    }
    return double(held) / (kSteps * kSteps * kSteps);
}

double volume(const OrientedBox& b) {
    return b.extents[0] * b.extents[1] * b.extents[2];
}

}  // namespace

double box_iou(const OrientedBox& a, const OrientedBox& b) {
    const double intersection = 0.5 * (lattice_share_inside(a, b) * volume(a) + lattice_share_inside(b, a) * volume(b));
    const double union_volume = volume(a) + volume(b) - intersection;
    return union_volume > 0 ? intersection / union_volume : 0.0;
}

std::vector<ObjectBoxScore> score_boxes(std::span<const std::uint32_t> truth, std::uint32_t objects,
                                        std::span<const std::uint32_t> predicted, std::span<const float> points,
                                        std::span<const OrientedBox> boxes) {
    if (predicted.size() != truth.size() || points.size() != 3 * truth.size()) {
        throw std::invalid_argument("score_boxes: truth, labels and points differ in length");
    }
    // Overlap counts per object, to find the segment holding most of it (the smaller label of equals).
    std::vector<std::map<std::uint32_t, std::uint64_t>> overlap(objects);
    for (std::size_t i = 0; i < truth.size(); ++i) {
        const std::uint32_t t = truth[i];
        if (t < 2 || t >= objects + 2 || predicted[i] == 0) continue;
        ++overlap[t - 2][predicted[i]];
    }
    std::unordered_map<std::uint32_t, const OrientedBox*> by_label;
    for (const OrientedBox& b : boxes) by_label[b.label] = &b;
    std::vector<ObjectBoxScore> scores(objects);
    for (std::uint32_t k = 0; k < objects; ++k) {
        scores[k].truth_id = k + 2;
        std::uint64_t most = 0;
        for (const auto& [label, count] : overlap[k]) {
            if (count > most) {
                most = count;
                scores[k].segment = label;
            }
        }
        scores[k].boxed = by_label.count(scores[k].segment) != 0;
    }
    std::vector<std::uint64_t> held(objects, 0), total(objects, 0);
    for (std::size_t i = 0; i < truth.size(); ++i) {
        const std::uint32_t t = truth[i];
        if (t < 2 || t >= objects + 2) continue;
        const std::array<double, 3> p = {points[3 * i], points[3 * i + 1], points[3 * i + 2]};
        if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2])) continue;
        ++total[t - 2];
        const ObjectBoxScore& s = scores[t - 2];
        if (s.boxed && box_holds(*by_label.at(s.segment), p)) ++held[t - 2];
    }
    for (std::uint32_t k = 0; k < objects; ++k) {
        scores[k].inside = total[k] == 0 ? 0.0 : double(held[k]) / double(total[k]);
    }
    return scores;
}

}  // namespace pyrseg::eval
