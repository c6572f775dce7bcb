// The Segmenter's contract with its caller: frames of any layout, reuse without reallocation, backend choice.
#include <gtest/gtest.h>

#include <cstdlib>
#include <string>
#include <vector>

#include "pyrseg/backend.hpp"
#include "pyrseg/error.hpp"
#include "pyrseg/segmenter.hpp"
#include "pyrseg/synthetic.hpp"

namespace pyrseg {
namespace {

synthetic::Scene scene(int w, int h, std::uint64_t seed) {
    synthetic::SceneOptions o;
    o.width = w;
    o.height = h;
    o.seed = seed;
    return synthetic::generate(o);
}

TEST(Segmenter, StridedAndPaddedLayoutsGiveTheSameLabelsAsPacked) {
    const synthetic::Scene s = scene(160, 120, 3);
    // PCL-style: x y z pad nx ny nz pad, rows padded to 170 points.
    const std::size_t stride = 170;
    std::vector<float> padded(stride * 120 * 8, -123.0f);
    for (std::size_t y = 0; y < 120; ++y) {
        for (std::size_t x = 0; x < 160; ++x) {
            for (std::size_t c = 0; c < 3; ++c) {
                padded[(y * stride + x) * 8 + c] = s.points[3 * (y * 160 + x) + c];
                padded[(y * stride + x) * 8 + 4 + c] = s.normals[3 * (y * 160 + x) + c];
            }
        }
    }
    for (const bool with_normals : {true, false}) {
        Segmenter seg(160, 120, {}, "cpu");
        CloudView packed{s.points.data(), with_normals ? s.normals.data() : nullptr, 160, 120, 0, 3};
        CloudView strided{padded.data(), with_normals ? padded.data() + 4 : nullptr, 160, 120, stride, 8};
        const Result a = seg.segment(packed);
        const Result b = seg.segment(strided);
        EXPECT_GT(a.segment_count, 1u);
        EXPECT_EQ(a.labels, b.labels);
    }
}

TEST(Segmenter, ReusesItsResultBuffersFrameAfterFrame) {
    const synthetic::Scene a = scene(200, 150, 1);
    const synthetic::Scene b = scene(200, 150, 2);
    Outputs o;
    o.raw_labels = o.fillable_mask = o.normals = true;
    Segmenter seg(200, 150, {}, "cpu", o);
    Result r;
    seg.segment(CloudView{a.points.data(), nullptr, 200, 150}, r);
    const void* labels = r.labels.data();
    const void* raw = r.raw_labels.data();
    const void* mask = r.fillable_mask.data();
    const void* normals = r.normals.data();
    for (int frame = 0; frame < 3; ++frame) {
        seg.segment(CloudView{(frame % 2 ? a : b).points.data(), nullptr, 200, 150}, r);
        EXPECT_EQ(labels, r.labels.data());
        EXPECT_EQ(raw, r.raw_labels.data());
        EXPECT_EQ(mask, r.fillable_mask.data());
        EXPECT_EQ(normals, r.normals.data());
    }
}

TEST(Segmenter, ReportsTimingsOfEveryPass) {
    const synthetic::Scene a = scene(64, 48, 1);
    Segmenter seg(64, 48, {}, "cpu");
    (void)seg.segment(CloudView{a.points.data(), nullptr, 64, 48});
    std::vector<std::string> passes;
    for (const PassTiming& t : seg.last_timings()) {
        passes.emplace_back(t.pass);
        EXPECT_GE(t.milliseconds, 0.0);
    }
    // The CPU's vector rows run normals, quantize and metric as one pass (PYRSEG_CPU_SIMD=scalar: three).
    const char* simd = std::getenv("PYRSEG_CPU_SIMD");
    std::vector<std::string> expected = {"points_to_mask"};
    if (simd != nullptr && std::string(simd) == "scalar") expected = {"normals", "quantize", "metric"};
    for (const char* pass : {"mip", "labels", "fill", "final_fill", "edges", "compact", "upload", "download"})
        expected.emplace_back(pass);
    EXPECT_EQ(passes, expected);
}

TEST(Backends, CpuIsAlwaysAvailableAndLast) {
    const std::vector<BackendInfo> all = list_backends();
    ASSERT_FALSE(all.empty());
    EXPECT_EQ(all.back().name, "cpu");
    EXPECT_TRUE(all.back().available);
    EXPECT_FALSE(all.back().devices.empty());
    for (const BackendInfo& b : all) {
        if (!b.available) {
            EXPECT_FALSE(b.reason.empty()) << b.name;
        }
    }
}

TEST(Backends, EnvironmentVariableChoosesWhenNoNameIsGiven) {
    ASSERT_EQ(setenv("PYRSEG_BACKEND", "cpu", 1), 0);
    EXPECT_EQ(resolve_backend_name(""), "cpu");
    ASSERT_EQ(setenv("PYRSEG_BACKEND", "bogus", 1), 0);
    EXPECT_THROW((void)resolve_backend_name(""), Error);
    try {
        (void)resolve_backend_name("");
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("PYRSEG_BACKEND"), std::string::npos) << e.what();
    }
    EXPECT_EQ(resolve_backend_name("cpu"), "cpu");  // an explicit name wins
    ASSERT_EQ(unsetenv("PYRSEG_BACKEND"), 0);
    EXPECT_FALSE(resolve_backend_name("auto").empty());
}

TEST(Backends, AutoNeverPicksACpuEmulationOverTheCpuBackend) {
    // lavapipe and PoCL's CPU device are the API in software on the host: slower than the native backend.
    const std::vector<BackendInfo> all = list_backends();
    const BackendChoice choice = choose_backend("auto");
    std::string first_real;
    for (const BackendInfo& b : all) {
        if (b.available && !b.emulated && first_real.empty()) first_real = b.name;
        if (b.name == "cpu") {
            EXPECT_FALSE(b.emulated);
        }
        if (b.emulated) {
            EXPECT_TRUE(b.available) << b.name;
            EXPECT_FALSE(b.emulated_device.empty()) << b.name;
            EXPECT_NE(choice.reason.find(b.name + "'s device"), std::string::npos) << choice.reason;
        }
    }
    EXPECT_EQ(choice.name, first_real) << choice.reason;
    EXPECT_EQ(choice.reason.rfind("auto: ", 0), 0u) << choice.reason;
    // Named, an emulated backend still runs: the choice is only auto's.
    for (const BackendInfo& b : all) {
        if (b.emulated) {
            EXPECT_EQ(choose_backend(b.name).name, b.name);
        }
    }
    EXPECT_EQ(choose_backend("cpu").reason, "requested");
}

}  // namespace
}  // namespace pyrseg
