#pragma once
// `pyrseg segment --pcl-png`: PCL's organized segmentation of the same frame, for a side-by-side look at the peer
// pyrseg is measured against (peers/pcl_segmentation.hpp), with the settings `pyrseg eval` tuned for each kind of
// sensor (docs/quality.md). Available when pyrseg is built with PCL.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

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

}  // namespace pyrseg::cli
