#pragma once
// PCL's organized segmentation, the peer pyrseg is measured against (bench/) and scored against (pyrseg eval):
// OrganizedConnectedComponentSegmentation with EdgeAwarePlaneComparator, as PCL's organized-segmentation demo runs
// it, with integral-image normals (covariance, smoothing 10, depth change 0.02) unless normals are given. Thresholds
// follow pyrseg's defaults where they mean the same thing: 0.25 rad between normals, 10 mm along them. PCL's
// headers stay in the .cpp.
#include <cstdint>
#include <memory>
#include <vector>

namespace pyrseg::peers {

// The PCL version this was built with ("1.13.0").
[[nodiscard]] const char* pcl_version();

class PclOrganizedSegmentation {
public:
    PclOrganizedSegmentation();
    ~PclOrganizedSegmentation();
    PclOrganizedSegmentation(const PclOrganizedSegmentation&) = delete;
    PclOrganizedSegmentation& operator=(const PclOrganizedSegmentation&) = delete;

    // The frame: packed xyz in millimetres (NaN: no data), converted to PCL's metres; normals packed, or null to
    // estimate them in run(). The conversion is not part of run(), so that benchmarks time PCL alone.
    void set_cloud(const float* points_mm, const float* normals, int width, int height);

    // Segments the frame set last. Returns the regions of at least min_points points (PCL's organized plane
    // segmentation's default is 100); when labels is given, writes W*H labels 1..count for those regions
    // (0: no region, or a smaller one), in order of each region's first pixel.
    std::uint32_t run(std::vector<std::uint32_t>* labels = nullptr, std::uint32_t min_points = 100);

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace pyrseg::peers
