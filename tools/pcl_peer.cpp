#include "tools/pcl_peer.hpp"

#include "pyrseg/error.hpp"
#ifdef PYRSEG_HAVE_PCL_PEER
#include "peers/pcl_segmentation.hpp"
#endif

namespace pyrseg::cli {

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
#else
std::string pcl_peer_missing() {
    return "this build has no PCL peer (pyrseg is built with it when libpcl-dev is installed)";
}

PclRun pcl_segment(const io::PointCloud& /*cloud*/, double /*unit_mm*/, std::optional<SensorKind> /*kind*/) {
    throw Error(ErrorCode::invalid_argument, "--pcl-png: " + pcl_peer_missing());
}
#endif

}  // namespace pyrseg::cli
