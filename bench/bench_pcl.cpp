// Peer: PCL's organized segmentation as PCL's organized-segmentation demo runs it: integral-image normals, then
// OrganizedConnectedComponentSegmentation with EdgeAwarePlaneComparator (fed the normal estimation's distance map),
// on the same clouds as pyrseg's pipeline/*/estimated_normals (converted to metres, PCL's convention); and the
// labelling alone with the scene's exact normals (no edge map), next to pipeline/*/given_normals. Thresholds follow
// pyrseg's defaults where they mean the same thing: 0.25 rad between normals, 10 mm along them.
#include <benchmark/benchmark.h>

#include <pcl/features/integral_image_normal.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/segmentation/edge_aware_plane_comparator.h>
#include <pcl/segmentation/organized_connected_component_segmentation.h>
#include <cmath>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "bench/bench_scenes.hpp"

namespace pyrseg::bench {
namespace {

using Cloud = pcl::PointCloud<pcl::PointXYZ>;
using Normals = pcl::PointCloud<pcl::Normal>;
using Comparator = pcl::EdgeAwarePlaneComparator<pcl::PointXYZ, pcl::Normal>;

Cloud::Ptr to_pcl(const synthetic::Scene& s) {
    auto cloud = std::make_shared<Cloud>(std::uint32_t(s.width), std::uint32_t(s.height));
    cloud->is_dense = false;
    for (std::size_t i = 0; i < cloud->size(); ++i) {
        (*cloud)[i] = pcl::PointXYZ(s.points[3 * i] * 1e-3f, s.points[3 * i + 1] * 1e-3f, s.points[3 * i + 2] * 1e-3f);
    }
    return cloud;
}

Normals::Ptr scene_normals(const synthetic::Scene& s) {
    auto normals = std::make_shared<Normals>(std::uint32_t(s.width), std::uint32_t(s.height));
    for (std::size_t i = 0; i < normals->size(); ++i) {
        (*normals)[i] = pcl::Normal(s.normals[3 * i], s.normals[3 * i + 1], s.normals[3 * i + 2]);
        (*normals)[i].curvature = 0.0f;
    }
    return normals;
}

// What one PCL frame computes: plane offsets d = -n.p, the comparator, the labelling.
std::size_t segment_with_pcl(const Cloud::ConstPtr& cloud, const Normals::ConstPtr& normals, const float* distance_map,
                             std::shared_ptr<std::vector<float>>& plane_d, pcl::PointCloud<pcl::Label>& labels,
                             std::vector<pcl::PointIndices>& indices) {
    plane_d->resize(cloud->size());
    for (std::size_t i = 0; i < cloud->size(); ++i) {
        (*plane_d)[i] = -(*normals)[i].getNormalVector3fMap().dot((*cloud)[i].getVector3fMap());
    }
    auto comparator = std::make_shared<Comparator>(distance_map);
    comparator->setInputCloud(cloud);
    comparator->setInputNormals(normals);
    comparator->setPlaneCoeffD(plane_d);
    comparator->setAngularThreshold(0.25f);
    comparator->setDistanceThreshold(0.010f, false);
    comparator->setEuclideanDistanceThreshold(0.010f);
    pcl::OrganizedConnectedComponentSegmentation<pcl::PointXYZ, pcl::Label> segmentation(comparator);
    segmentation.setInputCloud(cloud);
    // segment() only resizes the labels it is given, and reads the stale labels of a reused cloud as its own
    // (it crashes on them): every frame starts from empty outputs, as a fresh PCL pipeline would.
    labels.clear();
    indices.clear();
    segmentation.segment(labels, indices);
    std::size_t segments = 0;  // regions of at least 100 points (PCL's organized plane segmentation's default)
    for (const pcl::PointIndices& region : indices) segments += region.indices.size() >= 100 ? 1 : 0;
    return segments;
}

void pcl_segmentation(benchmark::State& state, int width, int height, bool given_normals) {
    const synthetic::Scene& s = scene(width, height);
    const Cloud::ConstPtr cloud = to_pcl(s);
    const Normals::Ptr normals = given_normals ? scene_normals(s) : std::make_shared<Normals>();
    // Without an edge map every point is far from an edge.
    const std::vector<float> no_edges(cloud->size(), std::numeric_limits<float>::max());
    pcl::IntegralImageNormalEstimation<pcl::PointXYZ, pcl::Normal> estimation;
    estimation.setNormalEstimationMethod(estimation.COVARIANCE_MATRIX);
    estimation.setMaxDepthChangeFactor(0.02f);
    estimation.setNormalSmoothingSize(10.0f);
    auto plane_d = std::make_shared<std::vector<float>>();
    pcl::PointCloud<pcl::Label> labels;
    std::vector<pcl::PointIndices> indices;
    std::size_t segments = 0;
    for (auto _ : state) {
        const float* distance_map = no_edges.data();
        if (!given_normals) {
            estimation.setInputCloud(cloud);
            estimation.compute(*normals);
            distance_map = estimation.getDistanceMap();
        }
        segments = segment_with_pcl(cloud, normals, distance_map, plane_d, labels, indices);
        benchmark::DoNotOptimize(labels.data());
    }
    state.counters["segments"] = double(segments);
    state.counters["Mpix/s"] =
        benchmark::Counter(double(width) * height * 1e-6, benchmark::Counter::kIsIterationInvariantRate);
    state.SetBytesProcessed(std::int64_t(state.iterations()) * std::int64_t(width) * height * 12 *
                            (given_normals ? 2 : 1));
}

int register_all() {
    for (const auto& size : kSizes) {
        const int w = size[0];
        const int h = size[1];
        for (const bool given : {false, true}) {
            const std::string name =
                "pcl/organized_edge_aware/" + size_name(w, h) + (given ? "/given_normals" : "/estimated_normals");
            benchmark::RegisterBenchmark(name.c_str(), [=](benchmark::State& st) { pcl_segmentation(st, w, h, given); })
                ->Unit(benchmark::kMillisecond)
                ->UseRealTime();
        }
    }
    benchmark::AddCustomContext("pcl", PCL_VERSION_PRETTY);
    return 0;
}

const int registered = register_all();

}  // namespace
}  // namespace pyrseg::bench
