#include "peers/pcl_planes.hpp"

#include <pcl/features/integral_image_normal.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/segmentation/organized_multi_plane_segmentation.h>

namespace pyrseg::peers {

std::vector<PclPlane> pcl_multi_plane(const float* points_mm, int width, int height, const PclPlaneSettings& settings) {
    auto cloud = std::make_shared<pcl::PointCloud<pcl::PointXYZ>>(std::uint32_t(width), std::uint32_t(height));
    cloud->is_dense = false;
    for (std::size_t i = 0; i < cloud->size(); ++i) {
        (*cloud)[i] =
            pcl::PointXYZ(points_mm[3 * i] * 1e-3f, points_mm[3 * i + 1] * 1e-3f, points_mm[3 * i + 2] * 1e-3f);
    }
    auto normals = std::make_shared<pcl::PointCloud<pcl::Normal>>();
    pcl::IntegralImageNormalEstimation<pcl::PointXYZ, pcl::Normal> estimation;
    switch (settings.normals.normal_method) {
        case PclNormalMethod::covariance_matrix:
            estimation.setNormalEstimationMethod(estimation.COVARIANCE_MATRIX);
            break;
        case PclNormalMethod::average_3d_gradient:
            estimation.setNormalEstimationMethod(estimation.AVERAGE_3D_GRADIENT);
            break;
        case PclNormalMethod::average_depth_change:
            estimation.setNormalEstimationMethod(estimation.AVERAGE_DEPTH_CHANGE);
            break;
    }
    estimation.setMaxDepthChangeFactor(settings.normals.max_depth_change_factor);
    estimation.setNormalSmoothingSize(settings.normals.normal_smoothing_size);
    estimation.setInputCloud(cloud);
    estimation.compute(*normals);

    pcl::OrganizedMultiPlaneSegmentation<pcl::PointXYZ, pcl::Normal, pcl::Label> segmentation;
    segmentation.setMinInliers(settings.min_inliers);
    segmentation.setAngularThreshold(settings.angular_threshold_rad);
    segmentation.setDistanceThreshold(settings.distance_threshold_mm / 1000.0f);
    segmentation.setMaximumCurvature(settings.maximum_curvature);
    segmentation.setInputNormals(normals);
    segmentation.setInputCloud(cloud);
    std::vector<pcl::ModelCoefficients> models;
    std::vector<pcl::PointIndices> inliers;
    segmentation.segment(models, inliers);

    std::vector<PclPlane> planes(models.size());
    for (std::size_t k = 0; k < models.size(); ++k) {
        const std::vector<float>& v = models[k].values;
        planes[k].normal = {v[0], v[1], v[2]};
        planes[k].offset_mm = double(v[3]) * 1000.0;
        planes[k].inliers.assign(inliers[k].indices.begin(), inliers[k].indices.end());
    }
    return planes;
}

}  // namespace pyrseg::peers
