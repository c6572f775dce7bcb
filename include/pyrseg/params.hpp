#pragma once
// Segmentation parameters. Defaults are the algorithm contract's (docs/algorithm.md).
#include <cstdint>
#include <optional>

namespace pyrseg {

inline constexpr double kDefaultCurvatureThreshold = 0.25;  // ct, radians
inline constexpr double kDefaultDepthThresholdMm = 10.0;    // dt, millimetres
inline constexpr int kDefaultBridgeLevels = 2;              // b
inline constexpr int kDefaultUnjoinableGap = 2;             // g
inline constexpr int kDefaultNormalRadius = 2;              // normals pass neighbour offset, pixels
inline constexpr int kDefaultNormalWindow = 3;              // robust normals: (2R+1)^2 window of tangents
inline constexpr int kDefaultCurvatureStride = 4;           // robust metric: pairs of normals s before and after
inline constexpr int kMaxNormalWindow = 7;
inline constexpr int kMaxCurvatureStride = 64;
inline constexpr int kMaxEdgeRounds = 63;
inline constexpr double kMinEdgeMaxDepthStep = 1e-6;  // the smallest edge_max_depth_step other than 0
inline constexpr int kMaxMergeReach = 16;
inline constexpr int kMaxTrackHoldFrames = 1000;
inline constexpr int kMaxColorEdgeStride = 16;
inline constexpr int kMaxColorEdgeThreshold = 765;

// Which fillable test (docs/algorithm.md): the paper's (section 2, the contract) for low-noise scanners, or the
// robust one (sections 2b and 8b) for depth cameras whose noise grows with the square of the depth.
enum class Metric : std::uint8_t { paper, robust };

struct Params {
    double ct = kDefaultCurvatureThreshold;  // curvature threshold in radians; >= pi disables curvature edges
    double dt = kDefaultDepthThresholdMm;    // depth-difference threshold in millimetres (+inf disables)
    double unit_mm = 1.0;                    // millimetres per input unit (1000 for metres)
    // Unset means the default (2) with the contract's small-image fallback; a value set explicitly that does
    // not fit the image is rejected instead.
    std::optional<int> bridge_levels;
    std::optional<int> unjoinable_gap;
    bool label_edges = true;  // step 6c: valid edge pixels join their smallest labelled neighbour
    // Rounds of step 6c, 1..63 (docs/algorithm.md section 5): 1 is the contract's one layer of edge pixels; each
    // further round labels the next layer of an edge band from the layer before, so that wide bands (the robust
    // metric's) are shared out among the segments on either side.
    int edge_rounds = 1;
    // 0 (no test) or a share in [1e-6, 1]: rounds after the first label a pixel only from neighbours whose depth
    // differs from its own by at most this share of it, so that a band's labels stay on the surface they spread
    // along and do not cross the depth step at an object's outline (docs/algorithm.md section 5, step 6c). Needs
    // points: a mask frame is refused when it would be used (label_edges, edge_rounds >= 2 and a share > 0).
    double edge_max_depth_step = 0.0;
    // Step 6d, the merge (docs/algorithm.md section 5b): segments that meet along a convex or flat boundary join
    // (an object's faces and parts), never across a concave crease or a depth step (an object and its support).
    bool merge = false;
    int merge_reach = 2;  // 1..16: a crossing of a boundary is measured up to this many pixels into each side
    // How far each side of a crossing may lie above the other's tangent plane and still count as convex or flat:
    // merge_tolerance_mm + merge_tolerance_per_m2 * z_m^2 millimetres.
    double merge_tolerance_mm = 1.0;
    double merge_tolerance_per_m2 = 0.0;
    int merge_min_crossings = 16;       // a shorter boundary never joins
    double merge_max_bad_share = 0.05;  // 0..1: the share of its crossings a joining boundary may have bad
    // The colour edge term (docs/algorithm.md section 2c), used on frames that come with a colour image: a pixel is
    // not fillable where its neighbours color_edge_stride pixels before and after it, along its row or its column,
    // differ by more than color_edge_threshold, the sum of the absolute differences of R, G and B (0..765; 765
    // ignores the colour).
    int color_edge_threshold = 765;
    int color_edge_stride = 1;  // 1..16
    // The colour edge's curvature gate (metric = robust only): 0 (the default) lets every colour edge cut; a share g in
    // (0, 1] lets a colour edge cut only where the normals across the pixel turn by more than g of the curvature limit
    // (a crease too weak for the metric alone, as where a stereo camera rounds an object's foot into its support), so
    // that print, grain and shadows on a flat or smooth surface do not cut it.
    double color_edge_curvature_share = 0.0;
    // Segment statistics (docs/algorithm.md section 10b): a segment is planar when its points' RMS distance to their
    // least-squares plane is at most planar_tolerance_mm + planar_tolerance_per_m2 * z_m^2 millimetres (z_m: its
    // centroid's depth in metres). Only the `planar` flag reads them.
    double planar_tolerance_mm = 2.0;
    double planar_tolerance_per_m2 = 0.0;
    // Tracks (Outputs::segment_tracks; docs/algorithm.md section 11): a segment that no previous segment overlaps
    // enough takes the id of a track whose predicted centroid is at most track_max_distance_mm from its own; a track
    // not seen for more than track_hold_frames frames (0..1000) is dropped.
    double track_max_distance_mm = 50.0;
    int track_hold_frames = 10;
    bool compact = true;                       // step 7: renumber labels 1..K
    int normal_radius = kDefaultNormalRadius;  // used only when normals are estimated
    Metric metric = Metric::paper;
    // The robust metric's own parameters; with Metric::paper they must keep these defaults.
    int normal_window = kDefaultNormalWindow;        // R, 1..7: estimated normals sum tangents over (2R+1)^2 pixels
    int curvature_stride = kDefaultCurvatureStride;  // s, 1..64: the curvature term compares the normals s
                                                     // pixels before and after each pixel, along 4 axes
    double dt_per_m2 = 0.0;         // millimetres added to dt per square metre of depth (dt + dt_per_m2 * z_m^2)
    double ct_growth_per_m2 = 0.0;  // 1 - cos(ct) grows by this factor per square metre of depth
};

// Whether step 6c's rounds test depths (docs/algorithm.md section 5): edge pixels labelled, several rounds and an
// edge_max_depth_step above 0. A mask frame, which has no depths, is refused then.
[[nodiscard]] inline bool uses_edge_depth_step(const Params& p) {
    return p.label_edges && p.edge_rounds >= 2 && p.edge_max_depth_step > 0.0;
}

}  // namespace pyrseg
