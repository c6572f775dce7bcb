#include "peers/pcl_lccp.hpp"

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/segmentation/lccp_segmentation.h>
#include <pcl/segmentation/supervoxel_clustering.h>

#include <cmath>
#include <map>
#include <memory>

namespace pyrseg::peers {

std::vector<std::uint32_t> lccp_segment(const float* points_mm, const std::uint8_t* rgb, int width, int height,
                                        const LccpSettings& s) {
    using Point = pcl::PointXYZRGBA;
    const std::size_t pixels = std::size_t(width) * std::size_t(height);
    // The valid points only (PCL's octrees take no NaN), in metres, and which pixel each is.
    auto cloud = std::make_shared<pcl::PointCloud<Point>>();
    std::vector<std::size_t> pixel_of;
    cloud->reserve(pixels);
    pixel_of.reserve(pixels);
    for (std::size_t i = 0; i < pixels; ++i) {
        const float* p = points_mm + 3 * i;
        if (!(std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]) && p[2] > 0)) continue;
        Point q;
        q.x = p[0] / 1000.0f;
        q.y = p[1] / 1000.0f;
        q.z = p[2] / 1000.0f;
        q.r = rgb != nullptr ? rgb[3 * i] : 128;
        q.g = rgb != nullptr ? rgb[3 * i + 1] : 128;
        q.b = rgb != nullptr ? rgb[3 * i + 2] : 128;
        q.a = 255;
        cloud->push_back(q);
        pixel_of.push_back(i);
    }
    std::vector<std::uint32_t> labels(pixels, 0);
    if (cloud->empty()) return labels;

    pcl::SupervoxelClustering<Point> supervoxels(s.voxel_resolution_m, s.seed_resolution_m);
    supervoxels.setUseSingleCameraTransform(s.single_camera_transform);
    supervoxels.setInputCloud(cloud);
    supervoxels.setColorImportance(s.color_importance);
    supervoxels.setSpatialImportance(s.spatial_importance);
    supervoxels.setNormalImportance(s.normal_importance);
    std::map<std::uint32_t, pcl::Supervoxel<Point>::Ptr> clusters;
    supervoxels.extract(clusters);
    std::multimap<std::uint32_t, std::uint32_t> adjacency;
    supervoxels.getSupervoxelAdjacency(adjacency);

    pcl::LCCPSegmentation<Point> lccp;
    lccp.setConcavityToleranceThreshold(s.concavity_tolerance_deg);
    lccp.setSanityCheck(s.sanity_check);
    lccp.setSmoothnessCheck(true, s.voxel_resolution_m, s.seed_resolution_m, s.smoothness_threshold);
    lccp.setKFactor(s.extended_convexity ? 1u : 0u);
    lccp.setMinSegmentSize(s.min_segment_size);
    lccp.setInputSupervoxels(clusters, adjacency);
    lccp.segment();
    // The supervoxel label of each input point, relabelled with its segment.
    const pcl::PointCloud<pcl::PointXYZL>::Ptr labelled = supervoxels.getLabeledCloud();
    lccp.relabelCloud(*labelled);
    // Segment labels as PCL numbers them, renumbered 1..K in order of first pixel.
    std::map<std::uint32_t, std::uint32_t> compact;
    for (std::size_t k = 0; k < labelled->size() && k < pixel_of.size(); ++k) {
        const std::uint32_t l = (*labelled)[k].label;
        if (l == 0) continue;
        const auto [it, added] = compact.try_emplace(l, std::uint32_t(compact.size() + 1));
        labels[pixel_of[k]] = it->second;
    }
    return labels;
}

}  // namespace pyrseg::peers
