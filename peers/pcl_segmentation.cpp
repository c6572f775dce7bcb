#include "peers/pcl_segmentation.hpp"

#include <pcl/features/integral_image_normal.h>
#include <pcl/pcl_config.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/segmentation/edge_aware_plane_comparator.h>
#include <pcl/segmentation/organized_connected_component_segmentation.h>

#include <algorithm>
#include <cstdio>
#include <limits>

namespace pyrseg::peers {

const char* pcl_version() {
    return PCL_VERSION_PRETTY;
}

const char* pcl_normal_method_name(PclNormalMethod method) {
    switch (method) {
        case PclNormalMethod::covariance_matrix:
            return "covariance";
        case PclNormalMethod::average_3d_gradient:
            return "average-3d-gradient";
        case PclNormalMethod::average_depth_change:
            return "average-depth-change";
    }
    return "unknown";
}

std::string describe(const PclSettings& s) {
    char text[200];
    std::snprintf(text, sizeof text, "%s normals, smoothing %g, depth change %g, %g rad, %g mm, >= %u points",
                  pcl_normal_method_name(s.normal_method), double(s.normal_smoothing_size),
                  double(s.max_depth_change_factor), double(s.angular_threshold_rad), double(s.distance_threshold_mm),
                  unsigned(s.min_region_points));
    return text;
}

using Cloud = pcl::PointCloud<pcl::PointXYZ>;
using Normals = pcl::PointCloud<pcl::Normal>;
using Comparator = pcl::EdgeAwarePlaneComparator<pcl::PointXYZ, pcl::Normal>;

struct PclOrganizedSegmentation::Impl {
    PclSettings settings;
    Cloud::Ptr cloud = std::make_shared<Cloud>();
    Normals::Ptr normals = std::make_shared<Normals>();
    bool estimate = true;
    std::vector<float> no_edges;          // with given normals there is no edge map: every point is far from an edge
    const float* distance_map = nullptr;  // of the normals estimated last (or no_edges)
    pcl::IntegralImageNormalEstimation<pcl::PointXYZ, pcl::Normal> estimation;
    std::shared_ptr<std::vector<float>> plane_d = std::make_shared<std::vector<float>>();
    pcl::PointCloud<pcl::Label> labels;
    std::vector<pcl::PointIndices> regions;
};

PclOrganizedSegmentation::PclOrganizedSegmentation(const PclSettings& settings) : impl_(std::make_unique<Impl>()) {
    set_settings(settings);
}

PclOrganizedSegmentation::~PclOrganizedSegmentation() = default;

void PclOrganizedSegmentation::set_settings(const PclSettings& settings) {
    Impl& m = *impl_;
    m.settings = settings;
    switch (settings.normal_method) {
        case PclNormalMethod::covariance_matrix:
            m.estimation.setNormalEstimationMethod(m.estimation.COVARIANCE_MATRIX);
            break;
        case PclNormalMethod::average_3d_gradient:
            m.estimation.setNormalEstimationMethod(m.estimation.AVERAGE_3D_GRADIENT);
            break;
        case PclNormalMethod::average_depth_change:
            m.estimation.setNormalEstimationMethod(m.estimation.AVERAGE_DEPTH_CHANGE);
            break;
    }
    m.estimation.setMaxDepthChangeFactor(settings.max_depth_change_factor);
    m.estimation.setNormalSmoothingSize(settings.normal_smoothing_size);
}

const PclSettings& PclOrganizedSegmentation::settings() const {
    return impl_->settings;
}

void PclOrganizedSegmentation::set_cloud(const float* points_mm, const float* normals, int width, int height) {
    Impl& m = *impl_;
    m.cloud->resize(std::uint32_t(width), std::uint32_t(height));
    m.cloud->is_dense = false;
    for (std::size_t i = 0; i < m.cloud->size(); ++i) {
        (*m.cloud)[i] =
            pcl::PointXYZ(points_mm[3 * i] * 1e-3f, points_mm[3 * i + 1] * 1e-3f, points_mm[3 * i + 2] * 1e-3f);
    }
    m.estimate = normals == nullptr;
    if (!m.estimate) {
        m.normals->resize(std::uint32_t(width), std::uint32_t(height));
        for (std::size_t i = 0; i < m.normals->size(); ++i) {
            (*m.normals)[i] = pcl::Normal(normals[3 * i], normals[3 * i + 1], normals[3 * i + 2]);
            (*m.normals)[i].curvature = 0.0f;
        }
        m.no_edges.assign(m.cloud->size(), std::numeric_limits<float>::max());
        m.distance_map = m.no_edges.data();
    } else {
        m.distance_map = nullptr;
    }
}

std::uint32_t PclOrganizedSegmentation::run(std::vector<std::uint32_t>* labels) {
    estimate_normals();
    return segment(labels);
}

void PclOrganizedSegmentation::estimate_normals() {
    Impl& m = *impl_;
    if (!m.estimate) return;
    m.estimation.setInputCloud(m.cloud);
    m.estimation.compute(*m.normals);
    m.distance_map = m.estimation.getDistanceMap();
}

std::uint32_t PclOrganizedSegmentation::segment(std::vector<std::uint32_t>* labels) {
    Impl& m = *impl_;
    if (m.distance_map == nullptr) estimate_normals();
    const float* distance_map = m.distance_map;
    const std::uint32_t min_points = m.settings.min_region_points;
    m.plane_d->resize(m.cloud->size());
    for (std::size_t i = 0; i < m.cloud->size(); ++i) {
        (*m.plane_d)[i] = -(*m.normals)[i].getNormalVector3fMap().dot((*m.cloud)[i].getVector3fMap());
    }
    auto comparator = std::make_shared<Comparator>(distance_map);
    comparator->setInputCloud(m.cloud);
    comparator->setInputNormals(m.normals);
    comparator->setPlaneCoeffD(m.plane_d);
    // Millimetres to PCL's metres by a division, so that the default 10 mm is exactly the 0.010f it always was.
    const float distance_m = m.settings.distance_threshold_mm / 1000.0f;
    comparator->setAngularThreshold(m.settings.angular_threshold_rad);
    comparator->setDistanceThreshold(distance_m, false);
    comparator->setEuclideanDistanceThreshold(distance_m);
    pcl::OrganizedConnectedComponentSegmentation<pcl::PointXYZ, pcl::Label> segmentation(comparator);
    segmentation.setInputCloud(m.cloud);
    // segment() only resizes the labels it is given, and reads the stale labels of a reused cloud as its own (it
    // crashes on them): every frame starts from empty outputs, as a fresh PCL pipeline would.
    m.labels.clear();
    m.regions.clear();
    segmentation.segment(m.labels, m.regions);
    std::vector<const pcl::PointIndices*> kept;
    for (const pcl::PointIndices& region : m.regions) {
        if (region.indices.size() >= min_points) kept.push_back(&region);
    }
    if (labels == nullptr) return std::uint32_t(kept.size());
    // Regions in order of their first pixel, so that labels do not depend on PCL's numbering.
    std::uint32_t count = 0;
    labels->assign(m.cloud->size(), 0);
    std::sort(kept.begin(), kept.end(), [](const pcl::PointIndices* a, const pcl::PointIndices* b) {
        return *std::min_element(a->indices.begin(), a->indices.end()) <
               *std::min_element(b->indices.begin(), b->indices.end());
    });
    for (const pcl::PointIndices* region : kept) {
        ++count;
        for (const auto index : region->indices) (*labels)[std::size_t(index)] = count;
    }
    return count;
}

}  // namespace pyrseg::peers
