#pragma once
// PCL's organized segmentation, the peer pyrseg is measured against (bench/) and scored against (pyrseg eval):
// OrganizedConnectedComponentSegmentation with EdgeAwarePlaneComparator, as PCL's organized-segmentation demo runs
// it, with integral-image normals unless normals are given. The default settings (PclSettings{}) are the ones the
// benchmarks time: covariance normals, smoothing 10, depth change 0.02; thresholds that follow pyrseg's defaults
// where they mean the same thing: 0.25 rad between normals, 10 mm along them; regions of at least 100 points.
// `pyrseg eval` tunes them per sensor model. PCL's headers stay in the .cpp.
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace pyrseg::peers {

// The PCL version this was built with ("1.13.0").
[[nodiscard]] const char* pcl_version();

// pcl::IntegralImageNormalEstimation's methods.
enum class PclNormalMethod : std::uint8_t { covariance_matrix, average_3d_gradient, average_depth_change };
// "covariance", "average-3d-gradient", "average-depth-change".
[[nodiscard]] const char* pcl_normal_method_name(PclNormalMethod method);

struct PclSettings {
    // Integral-image normal estimation (unused when normals are given).
    PclNormalMethod normal_method = PclNormalMethod::covariance_matrix;
    float normal_smoothing_size = 10.0f;    // setNormalSmoothingSize, pixels
    float max_depth_change_factor = 0.02f;  // setMaxDepthChangeFactor (PCL's units: metres)
    // EdgeAwarePlaneComparator.
    float angular_threshold_rad = 0.25f;  // setAngularThreshold: largest angle between neighbouring normals
    float distance_threshold_mm = 10.0f;  // setDistanceThreshold (plane offsets) and setEuclideanDistanceThreshold
    // Regions kept (PCL's organized plane segmentation's default is 100 points); the rest count as no region.
    std::uint32_t min_region_points = 100;
    friend bool operator==(const PclSettings&, const PclSettings&) = default;
};
// One line: "covariance normals, smoothing 10, depth change 0.02, 0.25 rad, 10 mm, >= 100 points".
[[nodiscard]] std::string describe(const PclSettings& settings);

class PclOrganizedSegmentation {
public:
    explicit PclOrganizedSegmentation(const PclSettings& settings = {});
    ~PclOrganizedSegmentation();
    PclOrganizedSegmentation(const PclOrganizedSegmentation&) = delete;
    PclOrganizedSegmentation& operator=(const PclOrganizedSegmentation&) = delete;

    // Applies to the next run(), estimate_normals() or segment().
    void set_settings(const PclSettings& settings);
    [[nodiscard]] const PclSettings& settings() const;

    // The frame: packed xyz in millimetres (NaN: no data), converted to PCL's metres; normals packed, or null to
    // estimate them in run(). The conversion is not part of run(), so that benchmarks time PCL alone.
    void set_cloud(const float* points_mm, const float* normals, int width, int height);

    // Segments the frame set last: estimate_normals(), then segment().
    std::uint32_t run(std::vector<std::uint32_t>* labels = nullptr);

    // The two halves of run(), so that a search over the comparator's settings estimates normals once per
    // normal setting. estimate_normals() estimates them with the current settings (nothing when normals were
    // given); segment() labels the frame on the normals estimated last (or given) with the current comparator
    // settings. Returns the regions of at least min_region_points points; when labels is given, writes W*H labels
    // 1..count for those regions (0: no region, or a smaller one), in order of each region's first pixel.
    void estimate_normals();
    std::uint32_t segment(std::vector<std::uint32_t>* labels = nullptr);

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace pyrseg::peers
