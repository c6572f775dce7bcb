#pragma once
// How the scene summary (docs/algorithm.md section 10c) of a synthetic frame compares with the generator's own
// scene: whether the largest support is the floor; the 3D IoU of each box object's box with the generator's box
// (objects the segmentation finds whole: one segment holding 80% of the object's pixels and lying 80% on it); the
// plane of each segment lying 80% on one flat part (a box face, the floor) against that part's plane; and the
// `planar` flag on segments lying 80% on a box face (planar) or a cylinder's side (not).
#include <array>
#include <cstdint>
#include <vector>

#include "pyrseg/result.hpp"
#include "pyrseg/scene.hpp"
#include "pyrseg/synthetic.hpp"

namespace pyrseg::cli {

// One plane scored against its flat part: which frame (the scores' frame count when it was scored) and part.
struct PlaneScore {
    std::size_t frame = 0;
    std::uint32_t object = 0;  // the generator's object id
    int part = 0;
    double degrees = 0, mm = 0;
};

struct SyntheticSceneScores {
    std::size_t frames = 0;
    std::size_t floor_largest = 0;  // frames whose largest support lies 90% on the floor
    std::vector<double> box_iou;
    std::vector<double> plane_degrees;  // the angle between a flat part's segment's plane and the part's
    std::vector<double> plane_mm;       // the part's plane's distance from the segment's centroid
    std::vector<PlaneScore> planes;     // the same, each with its frame and part
    std::size_t planar_faces = 0, planar_faces_flagged = 0;  // segments on a box face; of them, flagged planar
    std::size_t cylinder_sides = 0, cylinder_sides_flagged = 0;
};

// points: the frame's points in millimetres (3 per pixel, NaN where none); result: labels and segments of a frame
// segmented with unit_mm; scene: its scene with the boxes fitted.
void score_synthetic_scene(const synthetic::Scene& truth, const std::vector<float>& points, const Result& result,
                           const Scene& scene, double unit_mm, SyntheticSceneScores& out);

// A peer's planes (PCL's OrganizedMultiPlaneSegmentation) on the same frame, scored as the segments' planes are:
// each plane whose inliers lie 80% on one flat part, against that part's plane (the distance from its inliers'
// centroid). normals[k] and offsets don't matter beyond the normal: the angle is the normal's.
struct PeerPlane {
    std::array<double, 3> normal{};
    const std::vector<std::uint32_t>* inliers = nullptr;  // pixel indices
};
void score_peer_planes(const synthetic::Scene& truth, const std::vector<float>& points,
                       const std::vector<PeerPlane>& planes, SyntheticSceneScores& out);

// The flat parts of the same frames that both scored a plane of (the first of each), with a's and b's errors: for
// comparing two methods on the same planes, not on the ones each happened to find.
struct MatchedPlanes {
    std::vector<double> a_degrees, a_mm, b_degrees, b_mm;
};
MatchedPlanes match_planes(const SyntheticSceneScores& a, const SyntheticSceneScores& b);

}  // namespace pyrseg::cli
