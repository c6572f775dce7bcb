#include "peers/pcl_segmentation.hpp"

#include <pcl/features/integral_image_normal.h>
#include <pcl/pcl_config.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/segmentation/edge_aware_plane_comparator.h>
#include <pcl/segmentation/organized_connected_component_segmentation.h>

#include <algorithm>
#include <limits>

namespace pyrseg::peers {

const char* pcl_version() {
    return PCL_VERSION_PRETTY;
}

using Cloud = pcl::PointCloud<pcl::PointXYZ>;
using Normals = pcl::PointCloud<pcl::Normal>;
using Comparator = pcl::EdgeAwarePlaneComparator<pcl::PointXYZ, pcl::Normal>;

struct PclOrganizedSegmentation::Impl {
    Cloud::Ptr cloud = std::make_shared<Cloud>();
    Normals::Ptr normals = std::make_shared<Normals>();
    bool estimate = true;
    std::vector<float> no_edges;  // with given normals there is no edge map: every point is far from an edge
    pcl::IntegralImageNormalEstimation<pcl::PointXYZ, pcl::Normal> estimation;
    std::shared_ptr<std::vector<float>> plane_d = std::make_shared<std::vector<float>>();
    pcl::PointCloud<pcl::Label> labels;
    std::vector<pcl::PointIndices> regions;
};

PclOrganizedSegmentation::PclOrganizedSegmentation() : impl_(std::make_unique<Impl>()) {
    impl_->estimation.setNormalEstimationMethod(impl_->estimation.COVARIANCE_MATRIX);
    impl_->estimation.setMaxDepthChangeFactor(0.02f);
    impl_->estimation.setNormalSmoothingSize(10.0f);
}

PclOrganizedSegmentation::~PclOrganizedSegmentation() = default;

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
    }
}

std::uint32_t PclOrganizedSegmentation::run(std::vector<std::uint32_t>* labels, std::uint32_t min_points) {
    Impl& m = *impl_;
    const float* distance_map = m.no_edges.data();
    if (m.estimate) {
        m.estimation.setInputCloud(m.cloud);
        m.estimation.compute(*m.normals);
        distance_map = m.estimation.getDistanceMap();
    }
    m.plane_d->resize(m.cloud->size());
    for (std::size_t i = 0; i < m.cloud->size(); ++i) {
        (*m.plane_d)[i] = -(*m.normals)[i].getNormalVector3fMap().dot((*m.cloud)[i].getVector3fMap());
    }
    auto comparator = std::make_shared<Comparator>(distance_map);
    comparator->setInputCloud(m.cloud);
    comparator->setInputNormals(m.normals);
    comparator->setPlaneCoeffD(m.plane_d);
    comparator->setAngularThreshold(0.25f);
    comparator->setDistanceThreshold(0.010f, false);
    comparator->setEuclideanDistanceThreshold(0.010f);
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
