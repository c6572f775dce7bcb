#pragma once
// From segments to a scene (docs/algorithm.md section 10c): the support surfaces of a frame (large flat segments:
// a floor, a table, a wall) and the objects resting on them, each with a box that stands on its support. Derived on
// the host from the segment statistics alone (Outputs::segment_stats), so it costs no pass over the frame and comes
// out the same for device-resident frames and on every backend.
#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "pyrseg/export.hpp"
#include "pyrseg/params.hpp"
#include "pyrseg/result.hpp"

namespace pyrseg {

// The rule's thresholds (section 10c). Lengths in millimetres, whatever the cloud's unit.
struct SceneParams {
    double support_min_share = 0.05;  // a support holds at least this share of the frame's labelled pixels ...
    double support_flatness = 0.03;   // ... and lies within this share of its box's second side of its plane (RMS)
    double contact_mm = 25.0;         // an object touches its support when its lowest point is this close to it;
                                      // it stands over one when no more than this below it ...
    double max_height_mm = 1000.0;    // ... and its top at most this far above it
    double level_degrees = 20.0;      // objects stand on supports whose normal is this close to the largest support's
    std::uint32_t object_min_pixels = 100;  // smaller segments are no objects (specks, sensor noise)
};

// A support surface: a large flat segment; the largest, and those parallel to it, are level (a table, a floor, a
// shelf), the others walls or the large faces of objects. Its plane (normal . p + offset = 0, the unit normal towards
// the camera) and box are the segment's (SegmentStats).
struct SceneSupport {
    std::uint32_t label = 0;  // the segment's value in Result::labels
    std::uint32_t pixel_count = 0;
    std::array<double, 3> normal{};
    double offset = 0;
    double rms = 0;  // the points' RMS distance to the plane (the cloud's units)
    std::array<double, 3> centroid{};
    std::array<std::array<double, 3>, 3> axes{};  // the segment's box: axes[2] is the normal
    std::array<double, 3> extents{};
    bool level = false;  // parallel to the largest support (within level_degrees): objects can stand on it
};

// An object: a segment that is no support, with at least object_min_pixels pixels. It stands over the nearest
// support below it (section 10c), whose normal is then its box's third axis (up), the other two its principal axes
// in the plane; the box reaches from the plane to its top (what stands over a table rests on it, though the camera
// may see only its top, or a part of it). Over no support (support -1), its box is the segment's box of the moments.
struct SceneObject {
    std::uint32_t label = 0;
    std::uint32_t pixel_count = 0;
    int support = -1;      // index into Scene::supports, -1 when it stands over none
    bool touches = false;  // its lowest point lies within contact_mm of the support's plane (its foot is seen)
    std::array<double, 3> centroid{};
    std::array<double, 3> box_centre{};
    std::array<std::array<double, 3>, 3> axes{};
    std::array<double, 3> extents{};  // side lengths along axes (the cloud's units)
    double height = 0;                // its top above the support's plane (the cloud's units); NaN over no support
};

struct Scene {
    std::vector<SceneSupport> supports;  // by decreasing pixel count (then label)
    std::vector<SceneObject> objects;    // by label
};

// The scene of one frame's statistics (Result::segments of a cloud or depth image; a mask's segments have no
// geometry and give an empty scene). `params` gives the frame's unit (unit_mm). `out` keeps its capacity, so once
// sized it allocates only when a frame has more segments than every frame before. Throws pyrseg::Error
// (invalid_parameter) for a negative, NaN or infinite threshold, a share outside 0..1 or an angle above 90 degrees.
PYRSEG_EXPORT void describe_scene(const std::vector<SegmentStats>& segments, const Params& params,
                                  const SceneParams& scene_params, Scene& out);

}  // namespace pyrseg

namespace pyrseg {

// Corner `bits` (0..7) of a box (a SceneObject's box_centre, axes, extents, or a support's centroid, axes, extents):
// bit a set puts it on the positive side of axes[a]. With extents[2] = 0, corners 0, 1, 3, 2 go round the rectangle
// of the first two axes (a support's outline).
[[nodiscard]] PYRSEG_EXPORT std::array<double, 3> box_corner(const std::array<double, 3>& centre,
                                                             const std::array<std::array<double, 3>, 3>& axes,
                                                             const std::array<double, 3>& extents, int bits);

// The boxes of the moments hold a uniformly covered block exactly, but less of a disc or a cylinder's side, whose
// points crowd towards the rims. Where the caller has the frame's points on the host, this tightens every object's
// box to them: along each of its axes, from the least to the greatest coordinate of the object's points (from the
// support's plane up, for an object over one), in one pass over the frame. points: 3 floats per pixel (x, y, z in
// the units the statistics came in; a non-finite coordinate: no point); labels: Result::labels of the same frame;
// fillable: Result::fillable_mask (Outputs::fillable_mask), or empty for every labelled pixel. With the mask, only
// the fillable pixels count, as in the statistics: the edge pixels of step 6c are mixed pixels, halfway between an
// object and what lies behind it, and would stretch a box towards the background. Throws pyrseg::Error
// (invalid_argument) when the sizes disagree.
PYRSEG_EXPORT void fit_object_boxes(std::span<const float> points, std::span<const std::uint32_t> labels,
                                    std::span<const std::uint8_t> fillable, Scene& scene);

}  // namespace pyrseg
