#include "tools/pcl_peer.hpp"

#include <algorithm>
#include <cstdio>

#include "pyrseg/error.hpp"
#ifdef PYRSEG_HAVE_PCL_PEER
#include "peers/pcl_segmentation.hpp"
#endif

namespace pyrseg::cli {

std::vector<peers::LccpSettings> lccp_grid() {
    std::vector<peers::LccpSettings> grid;
    for (const float seed : {0.02f, 0.03f}) {
        for (const float concavity : {10.0f, 20.0f}) {
            for (const float colour : {0.0f, 0.2f}) {
                peers::LccpSettings s;
                s.seed_resolution_m = seed;
                s.concavity_tolerance_deg = concavity;
                s.color_importance = colour;
                grid.push_back(s);
            }
        }
    }
    return grid;
}

#ifdef PYRSEG_HAVE_PCL_PEER
namespace {

// The settings `pyrseg eval` chose for each sensor model by its grid search (docs/quality.md, "PCL's settings
// chosen by the tuning"); PCL's defaults (the benchmarks') when no sensor is named.
peers::PclSettings settings_for(std::optional<SensorKind> kind) {
    peers::PclSettings s;
    if (!kind) return s;
    s.max_depth_change_factor = 0.1f;
    s.distance_threshold_mm = 80.0f;
    switch (*kind) {
        case SensorKind::structured_light:
            s.max_depth_change_factor = 0.05f;
            s.angular_threshold_rad = 0.08f;
            break;
        case SensorKind::kinect_v1:
            s.normal_smoothing_size = 20.0f;
            s.angular_threshold_rad = 0.4f;
            break;
        case SensorKind::realsense_d435:
            s.normal_smoothing_size = 30.0f;
            s.angular_threshold_rad = 0.08f;
            break;
        case SensorKind::azure_kinect:
            s.angular_threshold_rad = 0.15f;
            break;
    }
    return s;
}

}  // namespace

std::string pcl_peer_missing() {
    return {};
}

PclRun pcl_segment(const io::PointCloud& cloud, double unit_mm, std::optional<SensorKind> kind) {
    std::vector<float> points_mm(cloud.points.size());
    for (std::size_t i = 0; i < points_mm.size(); ++i) points_mm[i] = float(double(cloud.points[i]) * unit_mm);
    const peers::PclSettings settings = settings_for(kind);
    peers::PclOrganizedSegmentation pcl;
    pcl.set_settings(settings);
    pcl.set_cloud(points_mm.data(), nullptr, cloud.width, cloud.height);
    PclRun run;
    run.regions = pcl.run(&run.labels);
    run.settings = std::string("PCL ") + peers::pcl_version() + ", " + peers::describe(settings) +
                   (kind ? std::string(" (tuned for ") + sensor_kind_name(*kind) + ")" : " (PCL's defaults)");
    return run;
}

PclRun lccp_segment(const io::PointCloud& cloud_mm, const std::uint8_t* rgb, const peers::LccpSettings& settings) {
    PclRun run;
    run.labels = peers::lccp_segment(cloud_mm.points.data(), rgb, cloud_mm.width, cloud_mm.height, settings);
    for (const std::uint32_t l : run.labels) run.regions = std::max(run.regions, l);
    run.settings = std::string("PCL ") + peers::pcl_version() + " supervoxels + LCCP, " + peers::describe(settings);
    return run;
}
std::vector<peers::PclPlane> pcl_planes(const io::PointCloud& cloud_mm, std::optional<SensorKind> kind,
                                        float maximum_curvature, std::string* settings) {
    peers::PclPlaneSettings s;
    s.normals = settings_for(kind);
    s.angular_threshold_rad = s.normals.angular_threshold_rad;
    s.distance_threshold_mm = s.normals.distance_threshold_mm;
    s.maximum_curvature = maximum_curvature;
    s.min_inliers = 100;
    if (settings != nullptr) {
        char text[160];
        std::snprintf(text, sizeof text, ", %g rad, %g mm, curvature <= %g, >= %u inliers",
                      double(s.angular_threshold_rad), double(s.distance_threshold_mm), double(s.maximum_curvature),
                      unsigned(s.min_inliers));
        *settings = std::string("PCL ") + peers::pcl_version() + " OrganizedMultiPlaneSegmentation, " +
                    peers::pcl_normal_method_name(s.normals.normal_method) + " normals, smoothing " +
                    std::to_string(int(s.normals.normal_smoothing_size)) + text;
    }
    return peers::pcl_multi_plane(cloud_mm.points.data(), cloud_mm.width, cloud_mm.height, s);
}
#else
std::vector<peers::PclPlane> pcl_planes(const io::PointCloud& /*cloud_mm*/, std::optional<SensorKind> /*kind*/,
                                        float /*maximum_curvature*/, std::string* /*settings*/) {
    throw Error(ErrorCode::invalid_argument, "OrganizedMultiPlaneSegmentation: " + pcl_peer_missing());
}

PclRun lccp_segment(const io::PointCloud& /*cloud_mm*/, const std::uint8_t* /*rgb*/,
                    const peers::LccpSettings& /*settings*/) {
    throw Error(ErrorCode::invalid_argument, "LCCP: " + pcl_peer_missing());
}

std::string pcl_peer_missing() {
    return "this build has no PCL peer (pyrseg is built with it when libpcl-dev is installed)";
}

PclRun pcl_segment(const io::PointCloud& /*cloud*/, double /*unit_mm*/, std::optional<SensorKind> /*kind*/) {
    throw Error(ErrorCode::invalid_argument, "--pcl-png: " + pcl_peer_missing());
}
#endif

}  // namespace pyrseg::cli
