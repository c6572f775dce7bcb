// Peer: PCL's organized segmentation as PCL's organized-segmentation demo runs it: integral-image normals, then
// OrganizedConnectedComponentSegmentation with EdgeAwarePlaneComparator (fed the normal estimation's distance map),
// on the same clouds as pyrseg's pipeline/*/estimated_normals (converted to metres, PCL's convention). Thresholds
// follow pyrseg's defaults where they mean the same thing: 0.25 rad between normals, 10 mm along them.
// Left out: PCL's labelling with the scene's exact normals and no edge map crashes inside
// OrganizedConnectedComponentSegmentation::segment() (PCL 1.13) on these scenes; not chased further.
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

bool on_border(const synthetic::Scene& s, std::size_t i) {
    const std::size_t x = i % std::size_t(s.width);
    const std::size_t y = i / std::size_t(s.width);
    return x == 0 || y == 0 || x + 1 == std::size_t(s.width) || y + 1 == std::size_t(s.height);
}

// The outermost pixels are left out, as PCL's integral-image normals leave them out anyway (a region touching the
// image border was one suspect for the crash above).
Cloud::Ptr to_pcl(const synthetic::Scene& s) {
    auto cloud = std::make_shared<Cloud>(std::uint32_t(s.width), std::uint32_t(s.height));
    cloud->is_dense = false;
    const float nan = std::numeric_limits<float>::quiet_NaN();
    for (std::size_t i = 0; i < cloud->size(); ++i) {
        (*cloud)[i] = on_border(s, i) ? pcl::PointXYZ(nan, nan, nan)
                                      : pcl::PointXYZ(s.points[3 * i] * 1e-3f, s.points[3 * i + 1] * 1e-3f,
                                                      s.points[3 * i + 2] * 1e-3f);
    }
    return cloud;
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
    segmentation.segment(labels, indices);
    std::size_t segments = 0;  // regions of at least 100 points (PCL's organized plane segmentation's default)
    for (const pcl::PointIndices& region : indices) segments += region.indices.size() >= 100 ? 1 : 0;
    return segments;
}

void pcl_segmentation(benchmark::State& state, int width, int height) {
    const synthetic::Scene& s = scene(width, height);
    const Cloud::ConstPtr cloud = to_pcl(s);
    auto normals = std::make_shared<Normals>();
    pcl::IntegralImageNormalEstimation<pcl::PointXYZ, pcl::Normal> estimation;
    estimation.setNormalEstimationMethod(estimation.COVARIANCE_MATRIX);
    estimation.setMaxDepthChangeFactor(0.02f);
    estimation.setNormalSmoothingSize(10.0f);
    auto plane_d = std::make_shared<std::vector<float>>();
    pcl::PointCloud<pcl::Label> labels;
    std::vector<pcl::PointIndices> indices;
    std::size_t segments = 0;
    for (auto _ : state) {
        estimation.setInputCloud(cloud);
        estimation.compute(*normals);
        segments = segment_with_pcl(cloud, normals, estimation.getDistanceMap(), plane_d, labels, indices);
        benchmark::DoNotOptimize(labels.data());
    }
    state.counters["segments"] = double(segments);
    state.counters["Mpix/s"] =
        benchmark::Counter(double(width) * height * 1e-6, benchmark::Counter::kIsIterationInvariantRate);
    state.SetBytesProcessed(std::int64_t(state.iterations()) * std::int64_t(width) * height * 12);
}

int register_all() {
    for (const auto& size : kSizes) {
        const int w = size[0];
        const int h = size[1];
        const std::string name = "pcl/organized_edge_aware/" + size_name(w, h) + "/estimated_normals";
        benchmark::RegisterBenchmark(name.c_str(), [=](benchmark::State& st) { pcl_segmentation(st, w, h); })
            ->Unit(benchmark::kMillisecond)
            ->UseRealTime();
    }
    benchmark::AddCustomContext("pcl", PCL_VERSION_PRETTY);
    return 0;
}

const int registered = register_all();

}  // namespace
}  // namespace pyrseg::bench
