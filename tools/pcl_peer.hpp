#pragma once
// `pyrseg segment --pcl-png`: PCL's organized segmentation of the same frame, for a side-by-side look at the peer
// pyrseg is measured against (peers/pcl_segmentation.hpp), with the settings `pyrseg eval` tuned for each kind of
// sensor (docs/quality.md). Available when pyrseg is built with PCL.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "peers/pcl_lccp.hpp"
#include "peers/pcl_planes.hpp"
#include "pyrseg/io.hpp"
#include "pyrseg/presets.hpp"

namespace pyrseg::cli {

// Why there is no PCL peer in this build; empty when there is one.
[[nodiscard]] std::string pcl_peer_missing();

struct PclRun {
    std::vector<std::uint32_t> labels;  // W*H, 0: no region (or one under PCL's 100 points)
    std::uint32_t regions = 0;
    std::string settings;  // what PCL ran with, in words
};

// Segments `cloud` (in units of unit_mm millimetres) with PCL: the settings tuned for `kind`, or PCL's defaults.
// Throws pyrseg::Error when this build has no PCL peer.
[[nodiscard]] PclRun pcl_segment(const io::PointCloud& cloud, double unit_mm, std::optional<SensorKind> kind);

// PCL's supervoxels + LCCP (peers/pcl_lccp.hpp) of a cloud in millimetres with its colour (packed RGB8 per pixel,
// or null); the settings in words in `settings`. Throws pyrseg::Error when this build has no PCL peer.
[[nodiscard]] PclRun lccp_segment(const io::PointCloud& cloud_mm, const std::uint8_t* rgb,
                                  const peers::LccpSettings& settings);
// PCL's OrganizedMultiPlaneSegmentation (peers/pcl_planes.hpp) of a cloud in millimetres: its integral-image normals,
// angular and distance thresholds those `pyrseg eval` tuned PCL's organized segmentation with for `kind`, at least 100
// inliers (the scene's object_min_pixels), and the given maximum curvature (PCL's default 0.001 keeps no plane of a
// noisy sensor: `pyrseg eval --tabletop-synthetic` picks it per sensor from a small grid). Throws pyrseg::Error when
// this build has no PCL peer.
[[nodiscard]] std::vector<peers::PclPlane> pcl_planes(const io::PointCloud& cloud_mm, std::optional<SensorKind> kind,
                                                      float maximum_curvature, std::string* settings = nullptr);

// The small grid `pyrseg eval --tabletop` tunes LCCP over: seed resolution 20 and 30 mm x concavity tolerance 10 and
// 20 degrees x colour importance 0 and 0.2, the rest PCL's LCCP example's (voxels of 7.5 mm, spatial importance 1,
// normal importance 4, smoothness check 0.1, sanity check, one camera's transform).
[[nodiscard]] std::vector<peers::LccpSettings> lccp_grid();

}  // namespace pyrseg::cli
