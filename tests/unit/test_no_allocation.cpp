// "No allocation per frame": after the first frame has sized the Result, segmenting allocates nothing at all.
// Counted with a replaced global operator new (this test binary only).
#include <gtest/gtest.h>

#include <atomic>
#include <cstdint>
#include <cstdlib>
#include <functional>
#include <memory>
#include <new>
#include <string>
#include <vector>

#include "pyrseg/backend.hpp"
#include "pyrseg/error.hpp"
#include "pyrseg/presets.hpp"
#include "pyrseg/scene.hpp"
#include "pyrseg/segmenter.hpp"
#include "pyrseg/synthetic.hpp"

namespace {
std::atomic<bool> counting{false};
std::atomic<long> allocations{0};
// While counting, on the thread that set it: pyrseg's allocation with this number (1 = the first) fails with
// std::bad_alloc, as a large one does when memory runs out (the smaller ones after it, such as the error's message,
// succeed); 0: none fails. Other threads (a driver's compiler threads) are never failed, nor are a driver's own
// allocations: an exception thrown in a Vulkan layer unwinds through the C loader and leaves its lock held (the next
// vkEnumeratePhysicalDevices waits for ever), which is the driver's to handle, not pyrseg's.
thread_local long failing_allocation = 0;
thread_local long pyrseg_allocations = 0;
}  // namespace

// The test binary's own code (pyrseg is linked in statically), from GNU ld's symbols.
extern "C" const char __executable_start;  // NOLINT(bugprone-reserved-identifier)
extern "C" const char etext;

namespace {
bool called_from_this_binary(const void* return_address) {
    const auto* at = static_cast<const char*>(return_address);
    return at >= &__executable_start && at < &etext;
}
}  // namespace

// The replacements are a matched pair over malloc/free; GCC, seeing them inlined, would warn that free() gets a
// pointer from operator new.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
#endif

void* operator new(std::size_t size) {
    if (counting.load(std::memory_order_relaxed)) {
        allocations.fetch_add(1, std::memory_order_relaxed);
        if (failing_allocation > 0 && called_from_this_binary(__builtin_return_address(0)) &&
            ++pyrseg_allocations == failing_allocation)
            throw std::bad_alloc();
    }
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

// What `f` throws when the host's memory runs out at its n-th allocation: "" for nothing, else the pyrseg::Error's
// code name or "bad_alloc".
std::string when_memory_runs_out_at(long n, const std::function<void()>& f) {
    allocations = 0;
    pyrseg_allocations = 0;
    failing_allocation = n;
    counting = true;
    std::string outcome;
    try {
        f();
    } catch (const Error& e) {
        outcome = to_string(e.code());
    } catch (const std::bad_alloc&) {
        outcome = "bad_alloc";
    }
    counting = false;
    failing_allocation = 0;
    return outcome;
}

// The Vulkan validation layer allocates on every call it checks: warm frames are counted without it.
bool under_validation_layer(const std::string& backend) {
    const char* v = std::getenv("PYRSEG_VULKAN_VALIDATION");
    return backend == "vulkan" && v != nullptr && *v == '1';
}
constexpr const char* kValidationLayerSkip =
    "the Vulkan validation layer allocates on every call it checks; ctest no_allocation_without_validation_layer "
    "runs this test without it";

// The host's memory running out, anywhere in making a Segmenter or in a frame, is pyrseg::Error(out_of_memory) on
// every backend (OpenCL's let std::bad_alloc through: Python saw a bare MemoryError).
TEST_P(NoAllocation, HostMemoryRunningOutIsOutOfMemory) {
    synthetic::SceneOptions o;
    o.width = 64;
    o.height = 48;
    const synthetic::Scene scene = synthetic::generate(o);
    const CloudView cv{scene.points.data(), nullptr, o.width, o.height};
    Outputs outputs;
    outputs.raw_labels = outputs.fillable_mask = outputs.normals = outputs.segment_stats = outputs.segment_graph = true;
    int failed_makes = 0;
    int failed_frames = 0;
    for (long n = 1; n <= 120; ++n) {  // every allocation of a small frame's setup, one at a time
        SCOPED_TRACE("allocation " + std::to_string(n));
        const std::string made =
            when_memory_runs_out_at(n, [&] { Segmenter s(o.width, o.height, Params{}, GetParam(), outputs); });
        EXPECT_TRUE(made.empty() || made == to_string(ErrorCode::out_of_memory)) << "making the Segmenter: " << made;
        failed_makes += made.empty() ? 0 : 1;
        Segmenter segmenter(o.width, o.height, Params{}, GetParam(), outputs);
        const std::string framed = when_memory_runs_out_at(n, [&] {
            Result fresh;  // sized by the frame: its vectors are what the frame allocates
            segmenter.segment(cv, fresh);
        });
        EXPECT_TRUE(framed.empty() || framed == to_string(ErrorCode::out_of_memory)) << "a frame: " << framed;
        failed_frames += framed.empty() ? 0 : 1;
        Result after;
        EXPECT_NO_THROW(segmenter.segment(cv, after)) << "the Segmenter must work once memory is back";
    }
    // The injection reached pyrseg's allocations: the first ones of making a Segmenter and of a fresh frame fail.
    EXPECT_GE(failed_makes, 1);
    EXPECT_GE(failed_frames, 1);
}

TEST_P(NoAllocation, WarmFramesAllocateNothing) {
    if (under_validation_layer(GetParam())) GTEST_SKIP() << kValidationLayerSkip;
    synthetic::SceneOptions o;
    o.width = 320;
    o.height = 240;
    const synthetic::Scene a = synthetic::generate(o);
    o.seed = 2;
    const synthetic::Scene b = synthetic::generate(o);
    Outputs outputs;
    outputs.raw_labels = outputs.fillable_mask = outputs.normals = outputs.segment_stats = outputs.segment_graph = true;
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

// Tracks (docs/algorithm.md section 11) over a stream that alternates between two scenes: every frame makes new
// tracks and hides others, and once the hidden ones are dropped as fast as new ones come, the stream's tracks, the
// overlap pairs and the id image live in what the first frames sized.
TEST_P(NoAllocation, WarmTrackedFramesAllocateNothing) {
    synthetic::SceneOptions o;
    o.width = 320;
    o.height = 240;
    const synthetic::Scene a = synthetic::generate(o);
    o.seed = 2;
    const synthetic::Scene b = synthetic::generate(o);
    Outputs outputs;
    outputs.segment_tracks = outputs.track_ids = true;
    Params params;
    params.track_hold_frames = 2;
    if (under_validation_layer(GetParam())) GTEST_SKIP() << kValidationLayerSkip;
    auto segmenter = std::make_unique<Segmenter>(320, 240, params, GetParam(), outputs);
    Result result;
    const CloudView va{a.points.data(), nullptr, 320, 240};
    const CloudView vb{b.points.data(), nullptr, 320, 240};
    for (int frame = 0; frame < 8; ++frame) segmenter->segment(frame % 2 ? va : vb, result);
    EXPECT_EQ(allocations_during([&] {
                  for (int frame = 0; frame < 4; ++frame) segmenter->segment(frame % 2 ? va : vb, result);
              }),
              0);
    EXPECT_GT(result.tracks.size(), 1u);
}

// The scene of a warm frame (describe_scene and fit_object_boxes into a Scene that has seen as many segments)
// allocates nothing; a fresh Scene does.
TEST(NoAllocationScene, WarmScenesAllocateNothing) {
    synthetic::SceneOptions o;
    o.width = 320;
    o.height = 240;
    o.bin = false;
    const synthetic::Scene a = synthetic::generate(o);
    o.seed = 2;
    const synthetic::Scene b = synthetic::generate(o);
    Outputs outputs;
    outputs.segment_stats = outputs.fillable_mask = true;
    Segmenter segmenter(320, 240, {}, "cpu", outputs);
    const Result ra = segmenter.segment(CloudView{a.points.data(), a.normals.data(), 320, 240});
    const Result rb = segmenter.segment(CloudView{b.points.data(), b.normals.data(), 320, 240});
    Scene scene;
    const auto describe = [&](const synthetic::Scene& s, const Result& r) {
        describe_scene(r.segments, segmenter.params(), SceneParams{}, scene);
        fit_object_boxes(s.points, r.labels, r.fillable_mask, scene);
    };
    describe(a, ra);
    describe(b, rb);
    ASSERT_FALSE(scene.supports.empty());
    ASSERT_FALSE(scene.objects.empty());
    EXPECT_EQ(allocations_during([&] {
                  for (int frame = 0; frame < 4; ++frame) frame % 2 ? describe(a, ra) : describe(b, rb);
              }),
              0);
    EXPECT_GT(allocations_during([&] {
                  Scene fresh;
                  describe_scene(ra.segments, segmenter.params(), SceneParams{}, fresh);
              }),
              0);
}

// The same for the robust metric (texels, edge rounds) and for depth frames (their tables and packed samples).
TEST_P(NoAllocation, WarmRobustAndDepthFramesAllocateNothing) {
    if (under_validation_layer(GetParam())) GTEST_SKIP() << kValidationLayerSkip;
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
    outputs.raw_labels = outputs.fillable_mask = outputs.normals = outputs.segment_stats = outputs.segment_graph = true;
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

// Frames with a colour image (the colour edge term), clouds and depth images, with and without colour in turn.
TEST_P(NoAllocation, WarmColourFramesAllocateNothing) {
    if (under_validation_layer(GetParam())) GTEST_SKIP() << kValidationLayerSkip;
    synthetic::SceneOptions o;
    o.width = 160;
    o.height = 120;
    o.sensor = synthetic::Sensor::kinect_v1;
    const synthetic::Scene a = synthetic::generate(o);
    std::vector<std::uint16_t> depth(std::size_t(o.width) * std::size_t(o.height));
    std::vector<std::uint8_t> rgb(3 * depth.size());
    for (std::size_t i = 0; i < depth.size(); ++i) {
        const float z = a.points[3 * i + 2];
        depth[i] = z > 0 && z < 65535 ? std::uint16_t(z) : 0;
        for (std::size_t c = 0; c < 3; ++c) rgb[3 * i + c] = std::uint8_t((a.object_id[i] * 2654435761u) >> (8 * c));
    }
    DepthView dv{depth.data(), DepthFormat::u16, o.width, o.height, 0, 0.001, a.fx, a.fy, a.cx, a.cy};
    dv.color = rgb.data();
    CloudView cv{a.points.data(), nullptr, o.width, o.height};
    cv.color = rgb.data();
    CloudView plain{a.points.data(), nullptr, o.width, o.height};
    Params params = sensor_preset(SensorKind::kinect_v1);
    params.color_edge_threshold = 60;
    Segmenter segmenter(o.width, o.height, params, GetParam());
    Result result;
    segmenter.segment(cv, result);
    segmenter.segment(dv, result);
    segmenter.segment(plain, result);
    EXPECT_EQ(allocations_during([&] {
                  for (int frame = 0; frame < 6; ++frame) {
                      if (frame % 3 == 0) segmenter.segment(cv, result);
                      if (frame % 3 == 1) segmenter.segment(dv, result);
                      if (frame % 3 == 2) segmenter.segment(plain, result);
                  }
              }),
              0);
    EXPECT_GT(result.segment_count, 1u);
}

INSTANTIATE_TEST_SUITE_P(Backends, NoAllocation, ::testing::ValuesIn(available()),
                         [](const ::testing::TestParamInfo<std::string>& param_info) { return param_info.param; });

}  // namespace
}  // namespace pyrseg
