#pragma once
// How well a segmentation's object boxes hold the ground truth's objects on a tabletop frame: for each truth object,
// the segment that holds most of its pixels, and the share of the object's points inside that segment's box (an
// oriented box: centre, three orthonormal axes, side lengths). The scene summary's boxes (docs/algorithm.md section
// 10c) are meant to hold an object's points; this measures it. Plain C++, no dependency on the library.
#include <array>
#include <cstdint>
#include <span>
#include <vector>

namespace pyrseg::eval {

struct OrientedBox {
    std::uint32_t label = 0;  // the segment it belongs to
    std::array<double, 3> centre{};
    std::array<std::array<double, 3>, 3> axes{};
    std::array<double, 3> extents{};
};

struct ObjectBoxScore {
    std::uint32_t truth_id = 0;
    std::uint32_t segment = 0;  // the segment holding most of its pixels (0: none is labelled)
    bool boxed = false;         // that segment has a box
    double inside = 0;          // the share of the object's points (pixels with a finite point) inside the box
};

// Whether point p lies inside the box (on its faces included).
[[nodiscard]] bool box_holds(const OrientedBox& box, const std::array<double, 3>& p);

// The 3D IoU of two oriented boxes, from a lattice of 24^3 points in each: the share of a's lattice inside b times
// a's volume, and the other way round, averaged, is the intersection's volume (within about 1% of a box's volume).
[[nodiscard]] double box_iou(const OrientedBox& a, const OrientedBox& b);

// truth: kTruthNone, kTruthTable or an object id (2 .. objects + 1) per pixel; predicted: the segment labels;
// points: 3 per pixel in the boxes' units (NaN where there is none). One score per truth object, in id order.
// Throws std::invalid_argument when the lengths disagree.
[[nodiscard]] std::vector<ObjectBoxScore> score_boxes(std::span<const std::uint32_t> truth, std::uint32_t objects,
                                                      std::span<const std::uint32_t> predicted,
                                                      std::span<const float> points,
                                                      std::span<const OrientedBox> boxes);

}  // namespace pyrseg::eval
