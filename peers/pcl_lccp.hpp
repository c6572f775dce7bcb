#pragma once
// PCL's supervoxels + LCCP (Stein et al., "Object Partitioning using Local Convexity", CVPR 2014): the classical
// peer for whole objects, which pyrseg's merge (docs/algorithm.md section 5b) is measured against in
// `pyrseg eval --tabletop`. SupervoxelClustering over the frame's valid points (with their colour, when given),
// then LCCPSegmentation on the supervoxels and their adjacency, as PCL's LCCP example runs them, and the segments
// mapped back to the frame's pixels. PCL's headers stay in the .cpp.
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

namespace pyrseg::peers {

struct LccpSettings {
    // SupervoxelClustering (PCL's example's defaults).
    float voxel_resolution_m = 0.0075f;
    float seed_resolution_m = 0.03f;
    float color_importance = 0.0f;
    float spatial_importance = 1.0f;
    float normal_importance = 4.0f;
    bool single_camera_transform = true;  // depth from one camera: voxels grow with depth
    // LCCPSegmentation.
    float concavity_tolerance_deg = 10.0f;
    float smoothness_threshold = 0.1f;  // the smoothness check, on
    bool extended_convexity = false;    // k = 1 when on
    bool sanity_check = true;
    std::uint32_t min_segment_size = 0;  // supervoxels; smaller segments merge into their largest neighbour
    friend bool operator==(const LccpSettings&, const LccpSettings&) = default;
};
// One line: "voxel 7.5 mm, seed 30 mm, colour 0, spatial 1, normal 4, concavity 10 deg, smoothness 0.1, sanity"
// (inline: builds without PCL name the settings too).
[[nodiscard]] inline std::string describe(const LccpSettings& s) {
    char text[256];
    std::snprintf(text, sizeof text,
                  "voxel %g mm, seed %g mm, colour %g, spatial %g, normal %g, concavity %g deg, smoothness %g%s%s",
                  double(s.voxel_resolution_m) * 1000.0, double(s.seed_resolution_m) * 1000.0,
                  double(s.color_importance), double(s.spatial_importance), double(s.normal_importance),
                  double(s.concavity_tolerance_deg), double(s.smoothness_threshold), s.sanity_check ? ", sanity" : "",
                  s.extended_convexity ? ", extended convexity" : "");
    return text;
}

// Segments a frame: packed xyz in millimetres (NaN or z <= 0: no data), W x H; rgb packed 8-bit per pixel or null.
// Returns W*H labels, 0 where there is no point (or its voxel got no supervoxel), 1..K otherwise.
[[nodiscard]] std::vector<std::uint32_t> lccp_segment(const float* points_mm, const std::uint8_t* rgb, int width,
                                                      int height, const LccpSettings& settings);

}  // namespace pyrseg::peers
