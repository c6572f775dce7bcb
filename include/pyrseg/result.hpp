#pragma once
// What a segmentation returns. A Result is reused frame after frame: its buffers are sized once.
#include <array>
#include <cstdint>
#include <vector>

namespace pyrseg {

// Intermediate images a caller may ask for, for inspection and conformance tests.
struct Outputs {
    bool raw_labels = false;     // labels before compaction (step 7)
    bool fillable_mask = false;  // the metric pass's mask B: 1 fillable, 0 edge/invalid/isolated
    bool normals = false;        // the normals the metric used (given, or estimated), 3 floats per pixel
    bool segment_stats = false;  // per-segment statistics (Result::segments), a pass of every backend
    bool segment_graph = false;  // which segments touch which, and how (Result::graph), a pass of every backend
    // Track ids that carry over from frame to frame (Result::tracks; docs/algorithm.md section 11): the Segmenter's
    // frames are one stream until Segmenter::reset_tracks(). Needs Params::compact; runs the statistics pass.
    bool segment_tracks = false;
    bool track_ids = false;  // an image of the track ids beside the labels (Result::track_ids); implies segment_tracks
};

// A 128-bit two's-complement integer, high * 2^64 + low: an exact sum too wide for 64 bits.
struct WideSum {
    std::uint64_t low = 0;
    std::int64_t high = 0;
    friend bool operator==(const WideSum&, const WideSum&) = default;
};

// One segment's statistics (docs/algorithm.md section 10). Every backend computes the integer fields with the same
// exact arithmetic, so they agree bit for bit; the double fields are derived from them on the host.
struct SegmentStats {
    std::uint32_t label = 0;                         // its value in Result::labels (the compacted id, or the raw label)
    std::uint32_t pixel_count = 0;                   // labelled pixels, edge pixels of step 6c included
    int x_min = 0, y_min = 0, x_max = 0, y_max = 0;  // bounding box in pixels, inclusive
    std::uint32_t fillable_count = 0;  // its fillable pixels (not edge pixels), which the sums and the geometry are of
    // Sums over the segment's fillable pixels, exact: points in fixed point (rint(p * 2^point_shift), the caller's
    // units, each coordinate clamped to +-(2^31 - 128)) and the quantized normals qn (units of 2^-13). Zero for a mask.
    std::array<std::int64_t, 3> point_sum{};
    std::array<std::int64_t, 3> normal_sum{};
    int point_shift = 0;  // the fixed point's binary exponent, from Params::unit_mm (steps of 1/16 mm or finer)
    // The second moments, exact: sums of the products of the fixed-point coordinates xx, xy, xz, yy, yz, zz (units
    // of 2^(-2 point_shift)). And the least and greatest fixed-point z. Zero for a mask.
    std::array<WideSum, 6> point_product_sum{};
    std::int32_t z_fixed_min = 0;
    std::int32_t z_fixed_max = 0;
    // Derived on the host (docs/algorithm.md section 10b). NaN when the frame was a caller's mask, which has no
    // points. The 3D centroid (mean fillable point, the caller's units) and the unit mean normal (normal_sum
    // normalised; zero when it is zero).
    std::array<double, 3> centroid{};
    std::array<double, 3> mean_normal{};
    std::array<double, 6> covariance{};  // xx, xy, xz, yy, yz, zz: the points' covariance, the caller's units squared
    double z_min = 0, z_max = 0;         // the depth range (the caller's units)
    // The least-squares plane: plane_normal . p + plane_offset = 0, the unit normal towards the camera (at the
    // origin); plane_rms the points' RMS distance to it; curvature the smallest eigenvalue of the covariance over the
    // sum of the three (0 flat .. 1/3 isotropic).
    std::array<double, 3> plane_normal{};
    double plane_offset = 0;
    double plane_rms = 0;
    double curvature = 0;
    // The oriented box: centred on the centroid, rows of `axes` the principal axes by decreasing variance (a
    // right-handed frame whose third axis is plane_normal), `extents` its side lengths along them, 2 sqrt(3 lambda)
    // (the width of a uniform distribution with the segment's variance lambda along that axis).
    std::array<std::array<double, 3>, 3> axes{};
    std::array<double, 3> extents{};
    bool planar = false;  // plane_rms within the frame's planar tolerance (section 10b); false for a mask
};

// One edge of the segment graph (docs/algorithm.md section 10d): two segments that touch, and the crossings of their
// shared boundary (pairs of 4-neighbours, one in each) by the kind of boundary each shows. Every backend counts
// them exactly, so they agree bit for bit.
struct SegmentEdge {
    std::uint32_t a = 0, b = 0;  // the two labels, as in Result::labels, a < b
    std::uint32_t length = 0;    // the crossings: the shared boundary's length in pixel sides
    // For a cloud (zero for a caller's mask), the crossings where the two sides meet flat (each within the merge's
    // tolerance of the other's tangent plane), at a convex crease (an object's own edge), at a concave crease (an
    // object on its support, two walls) and at a depth step (one in front of the other). They add up to length.
    std::uint32_t flat = 0, convex = 0, concave = 0, step = 0;
    friend bool operator==(const SegmentEdge&, const SegmentEdge&) = default;
};

// How a segment got its track id (docs/algorithm.md section 11).
enum class TrackMatch : std::uint8_t {
    new_track,  // a new id: it matched no track
    overlap,    // a previous frame's segment it shares pixels with (greedily, by the pixels times the track's age)
    position,   // a track not matched by overlap (hidden, or not overlapping) found where the camera's motion put it
};

// One segment's track (docs/algorithm.md section 11).
struct SegmentTrack {
    std::uint32_t label = 0;          // its label in Result::labels
    std::uint32_t id = 0;             // its track id: from 1, never reused within a stream
    std::uint32_t first_frame = 0;    // the stream's frame (0 = its first) the id was first seen in
    std::uint32_t age = 0;            // the frames the id was seen in, this one included
    std::uint32_t hidden_frames = 0;  // the frames just before this one in which the id was not seen
    TrackMatch how = TrackMatch::new_track;
    friend bool operator==(const SegmentTrack&, const SegmentTrack&) = default;
};

struct Result {
    int width = 0;
    int height = 0;
    std::vector<std::uint32_t> labels;        // width*height, row-major; compacted 1..K unless Params::compact is false
    std::uint32_t segment_count = 0;          // K, the number of distinct non-zero labels
    std::vector<std::uint32_t> raw_labels;    // filled when Outputs::raw_labels
    std::vector<std::uint8_t> fillable_mask;  // filled when Outputs::fillable_mask
    std::vector<float> normals;               // filled when Outputs::normals
    // Filled when Outputs::segment_stats: K entries, segment k at k - 1. It keeps its capacity, so it allocates
    // only when a frame has more segments than every frame before.
    std::vector<SegmentStats> segments;
    // Filled when Outputs::segment_graph: every pair of touching segments once, by increasing (a, b). It keeps its
    // capacity, as segments does.
    std::vector<SegmentEdge> graph;
    // Filled when Outputs::segment_tracks: K entries, segment k at k - 1. It keeps its capacity, as segments does.
    std::vector<SegmentTrack> tracks;
    // Filled when Outputs::track_ids: width*height, each labelled pixel's track id (0 where unlabelled).
    std::vector<std::uint32_t> track_ids;
};

}  // namespace pyrseg
