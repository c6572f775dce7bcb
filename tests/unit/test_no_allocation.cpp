// "No allocation per frame": after the first frame has sized the Result, segmenting allocates nothing at all.
// Counted with a replaced global operator new (this test binary only).
#include <gtest/gtest.h>

#include <atomic>
#include <cstdint>
#include <cstdlib>
#include <functional>
#include <new>
#include <string>
#include <vector>

#include "pyrseg/backend.hpp"
#include "pyrseg/presets.hpp"
#include "pyrseg/segmenter.hpp"
#include "pyrseg/synthetic.hpp"

namespace {
std::atomic<bool> counting{false};
std::atomic<long> allocations{0};
}  // namespace

// The replacements are a matched pair over malloc/free; GCC, seeing them inlined, would warn that free() gets a
// pointer from operator new.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
#endif

void* operator new(std::size_t size) {
    if (counting.load(std::memory_order_relaxed)) allocations.fetch_add(1, std::memory_order_relaxed);
    if (void* p = std::malloc(size == 0 ? 1 : size)) return p;
    throw std::bad_alloc();
}
void operator delete(void* p) noexcept {
    std::free(p);
}
void operator delete(void* p, std::size_t) noexcept {
    std::free(p);
}

namespace pyrseg {
namespace {

long allocations_during(const std::function<void()>& f) {
    allocations = 0;
    counting = true;
    f();
    counting = false;
    return allocations.load();
}

std::vector<std::string> available() {
    std::vector<std::string> names;
    for (const BackendInfo& b : list_backends()) {
        if (b.available) names.push_back(b.name);
    }
    return names;
}

class NoAllocation : public ::testing::TestWithParam<std::string> {};

TEST_P(NoAllocation, WarmFramesAllocateNothing) {
    if (const char* v = std::getenv("PYRSEG_VULKAN_VALIDATION"); GetParam() == "vulkan" && v != nullptr && *v == '1') {
        GTEST_SKIP() << "the Vulkan validation layer allocates on every call it checks; ctest "
                        "no_allocation_without_validation_layer runs this test without it";
    }
    synthetic::SceneOptions o;
    o.width = 320;
    o.height = 240;
    const synthetic::Scene a = synthetic::generate(o);
    o.seed = 2;
    const synthetic::Scene b = synthetic::generate(o);
    Outputs outputs;
    outputs.raw_labels = outputs.fillable_mask = outputs.normals = outputs.segment_stats = true;
    for (const bool given_normals : {false, true}) {
        Segmenter segmenter(320, 240, {}, GetParam(), outputs);
        Result result;
        const CloudView va{a.points.data(), given_normals ? a.normals.data() : nullptr, 320, 240};
        const CloudView vb{b.points.data(), given_normals ? b.normals.data() : nullptr, 320, 240};
        segmenter.segment(va, result);  // sizes everything
        segmenter.segment(vb, result);  // Result::segments grows to the larger segment count
        EXPECT_EQ(allocations_during([&] {
                      for (int frame = 0; frame < 4; ++frame) segmenter.segment(frame % 2 ? va : vb, result);
                  }),
                  0)
            << (given_normals ? "given normals" : "estimated normals");
        EXPECT_GT(result.segment_count, 1u);
        // The counter does count: a fresh Result must be sized.
        EXPECT_GT(allocations_during([&] {
                      Result fresh;
                      segmenter.segment(va, fresh);
                  }),
                  0);
    }
}

// The same for the robust metric (texels, edge rounds) and for depth frames (their tables and packed samples).
TEST_P(NoAllocation, WarmRobustAndDepthFramesAllocateNothing) {
    if (const char* v = std::getenv("PYRSEG_VULKAN_VALIDATION"); GetParam() == "vulkan" && v != nullptr && *v == '1') {
        GTEST_SKIP() << "the Vulkan validation layer allocates on every call it checks; ctest "
                        "no_allocation_without_validation_layer runs this test without it";
    }
    synthetic::SceneOptions o;
    o.width = 160;
    o.height = 120;
    o.sensor = synthetic::Sensor::kinect_v1;
    const synthetic::Scene a = synthetic::generate(o);
    std::vector<std::uint16_t> depth(std::size_t(o.width) * std::size_t(o.height));
    for (std::size_t i = 0; i < depth.size(); ++i) {
        const float z = a.points[3 * i + 2];
        depth[i] = z > 0 && z < 65535 ? std::uint16_t(z) : 0;
    }
    const DepthView dv{depth.data(), DepthFormat::u16, o.width, o.height, 0, 0.001, a.fx, a.fy, a.cx, a.cy};
    const CloudView cv{a.points.data(), nullptr, o.width, o.height};
    Outputs outputs;
    outputs.raw_labels = outputs.fillable_mask = outputs.normals = outputs.segment_stats = true;
    Segmenter segmenter(o.width, o.height, sensor_preset(SensorKind::kinect_v1), GetParam(), outputs);
    Result result;
    segmenter.segment(cv, result);
    segmenter.segment(dv, result);
    EXPECT_EQ(allocations_during([&] {
                  for (int frame = 0; frame < 4; ++frame) {
                      if (frame % 2 != 0) {
                          segmenter.segment(cv, result);
                      } else {
                          segmenter.segment(dv, result);
                      }
                  }
              }),
              0);
    EXPECT_GT(result.segment_count, 1u);
}

INSTANTIATE_TEST_SUITE_P(Backends, NoAllocation, ::testing::ValuesIn(available()),
                         [](const ::testing::TestParamInfo<std::string>& param_info) { return param_info.param; });

}  // namespace
}  // namespace pyrseg
