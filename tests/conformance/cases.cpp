#include "conformance/cases.hpp"

#include <cstdint>
#include <iterator>
#include <limits>
#include <string>

#include "pyrseg/presets.hpp"

namespace pyrseg::test {
namespace {

// A tiny deterministic generator so that the case list is the same on every platform.
class CaseRng {
public:
    explicit CaseRng(std::uint64_t seed) : state_(seed) {}
    std::uint64_t next() {
        state_ += 0x9E3779B97F4A7C15ull;
        std::uint64_t z = state_;
        z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
        z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
        return z ^ (z >> 31);
    }
    int range(int lo, int hi) { return lo + int(next() % std::uint64_t(hi - lo + 1)); }
    bool chance(int percent) { return range(1, 100) <= percent; }
    template <class T, std::size_t N>
    T pick(const T (&values)[N]) {
        return values[next() % N];
    }

private:
    std::uint64_t state_;
};

constexpr int kCaseCount = 200;

ConformanceCase make_case(int index, int width, int height, CaseRng& rng, bool vary_params) {
    ConformanceCase c;
    c.scene.width = width;
    c.scene.height = height;
    c.scene.seed = std::uint64_t(1000 + index);
    c.scene.object_count = rng.range(0, 16);
    c.scene.noise_mm = rng.pick({0.0, 0.05, 0.1, 0.3, 1.0});
    c.scene.hole_fraction = rng.pick({0.0, 0.0, 0.01, 0.05, 0.2});
    c.scene.touching = rng.chance(75);
    c.scene.bin = rng.chance(70);
    c.given_normals = rng.chance(40);
    if (vary_params) {
        c.params.ct = rng.pick({0.1, 0.25, 0.25, 0.4, 1.0, 3.5});
        c.params.dt = rng.pick({0.5, 4.0, 10.0, 10.0, 50.0, std::numeric_limits<double>::infinity()});
        if (rng.chance(30)) c.params.bridge_levels = rng.range(1, 4);
        if (rng.chance(30)) c.params.unjoinable_gap = rng.range(1, 3);
        c.params.label_edges = rng.chance(70);
        c.params.compact = rng.chance(80);
        c.params.normal_radius = rng.pick({1, 1, 2, 3});
    }
    c.name = "case" + std::to_string(index) + "_" + std::to_string(width) + "x" + std::to_string(height) +
             (c.given_normals ? "_given_normals" : "_estimated_normals");
    return c;
}

std::vector<ConformanceCase> build_cases() {
    std::vector<ConformanceCase> cases;
    CaseRng rng(20261122);
    // The sizes that matter: degenerate strips, the fallback boundary (8 vs 9), odd sizes, camera frames.
    const int fixed[][2] = {{1, 1},     {1, 7},      {7, 1},       {8, 8}, {9, 9},  {33, 17}, {640, 480},
                            {640, 480}, {1031, 772}, {2064, 1544}, {2, 2}, {16, 1}, {1, 16},  {17, 9}};
    for (const auto& size : fixed) {
        const bool vary = int(cases.size()) % 2 == 1;
        cases.push_back(make_case(int(cases.size()), size[0], size[1], rng, vary));
    }
    // Some camera-like frames with varied parameters.
    const int frames[][2] = {{320, 240}, {160, 120}, {400, 300}, {256, 212}};
    for (int i = 0; i < 12; ++i) {
        const auto& size = frames[i % 4];
        cases.push_back(make_case(int(cases.size()), size[0], size[1], rng, true));
    }
    while (int(cases.size()) < kCaseCount) {
        const int w = rng.chance(20) ? rng.range(1, 12) : rng.range(9, 160);
        const int h = rng.chance(20) ? rng.range(1, 12) : rng.range(9, 120);
        cases.push_back(make_case(int(cases.size()), w, h, rng, rng.chance(60)));
    }
    return cases;
}

constexpr int kRobustCaseCount = 48;

ConformanceCase make_robust_case(int index, int width, int height, CaseRng& rng) {
    ConformanceCase c;
    c.scene.width = width;
    c.scene.height = height;
    c.scene.seed = std::uint64_t(5000 + index);
    c.scene.object_count = rng.range(0, 16);
    c.scene.sensor = rng.pick({synthetic::Sensor::structured_light, synthetic::Sensor::kinect_v1,
                               synthetic::Sensor::realsense_d435, synthetic::Sensor::azure_kinect});
    c.scene.camera_distance_mm = rng.pick({600.0, 1200.0, 1200.0, 2500.0});
    c.scene.hole_fraction = rng.pick({0.0, 0.01, 0.05});
    c.scene.touching = rng.chance(75);
    c.scene.bin = rng.chance(70);
    c.given_normals = rng.chance(20);
    // A preset as users pick it, or the robust metric's parameters over their whole ranges.
    const int preset = rng.range(0, 5);
    if (preset < int(sensor_kinds().size())) {
        c.params = sensor_preset(sensor_kinds()[std::size_t(preset)]);
    } else {
        c.params.metric = Metric::robust;
        c.params.ct = rng.pick({0.05, 0.2, 0.3, 0.6, 3.5});
        c.params.dt = rng.pick({0.0, 2.0, 5.0, 20.0, std::numeric_limits<double>::infinity()});
        c.params.normal_radius = rng.pick({1, 1, 2, 5});
        c.params.normal_window = rng.range(1, kMaxNormalWindow);
        c.params.curvature_stride = rng.pick({1, 2, 4, 6, 13, kMaxCurvatureStride});
        c.params.dt_per_m2 = rng.pick({0.0, 0.0, 3.0, 10.0, 1e6});
        c.params.ct_growth_per_m2 = rng.pick({0.0, 0.0, 0.2, 1.0, 1e9});
        if (rng.chance(20)) c.params.unit_mm = rng.pick({0.5, 3.0});
    }
    if (rng.chance(20)) c.params.bridge_levels = rng.range(1, 3);
    c.params.label_edges = rng.chance(80);
    if (rng.chance(50)) c.params.edge_rounds = rng.pick({2, 3, 8, kMaxEdgeRounds});
    c.name = "robust" + std::to_string(index) + "_" + std::to_string(width) + "x" + std::to_string(height) + "_" +
             synthetic::sensor_name(c.scene.sensor) + (c.given_normals ? "_given_normals" : "_estimated_normals");
    for (char& ch : c.name) ch = ch == '-' ? '_' : ch;
    return c;
}

// The edge rounds' depth test (docs/algorithm.md section 5, step 6c) over its range, from a stream of its own so that
// the scenes and the other parameters stay those of the cases before it; presets keep their own share half the time.
std::vector<ConformanceCase> build_robust_cases() {
    std::vector<ConformanceCase> cases;
    CaseRng rng(20261130);
    CaseRng step_rng(20261207);
    const auto vary_step = [&](ConformanceCase c) {
        if (step_rng.chance(50)) c.params.edge_max_depth_step = step_rng.pick({0.0, 1e-6, 0.005, 0.02, 0.1, 1.0});
        return c;
    };
    const int fixed[][2] = {{1, 1}, {3, 9}, {9, 3}, {15, 15}, {640, 480}, {2064, 1544}, {33, 17}, {64, 1}};
    for (const auto& size : fixed) {
        cases.push_back(vary_step(make_robust_case(int(cases.size()), size[0], size[1], rng)));
    }
    while (int(cases.size()) < kRobustCaseCount) {
        const int w = rng.chance(15) ? rng.range(1, 16) : rng.range(9, 200);
        const int h = rng.chance(15) ? rng.range(1, 16) : rng.range(9, 150);
        cases.push_back(vary_step(make_robust_case(int(cases.size()), w, h, rng)));
    }
    return cases;
}

constexpr int kMergeCaseCount = 32;

// The robust scenes with the merge on (docs/algorithm.md section 5b), its parameters over their ranges: a stream of
// its own, so that the robust cases stay what they were.
std::vector<ConformanceCase> build_merge_cases() {
    std::vector<ConformanceCase> cases;
    CaseRng rng(20261203);
    const int fixed[][2] = {{9, 9}, {33, 17}, {640, 480}, {2064, 1544}, {200, 150}, {64, 1}};
    for (int i = 0; i < kMergeCaseCount; ++i) {
        const bool sized = i < int(std::size(fixed));
        const int w = sized ? fixed[i][0] : rng.range(9, 200);
        const int h = sized ? fixed[i][1] : rng.range(9, 150);
        ConformanceCase c = make_robust_case(1000 + i, w, h, rng);
        c.params.merge = true;
        if (rng.chance(60)) {
            c.params.merge_reach = rng.pick({1, 2, 3, 5, kMaxMergeReach});
            c.params.merge_tolerance_mm = rng.pick({0.0, 0.5, 1.5, 4.0, 50.0});
            c.params.merge_tolerance_per_m2 = rng.pick({0.0, 0.0, 2.0, 1e4});
            c.params.merge_min_crossings = rng.pick({1, 4, 16, 200});
            c.params.merge_max_bad_share = rng.pick({0.0, 0.05, 0.2, 0.5, 1.0});
        }
        c.name = "merge" + c.name.substr(std::string("robust").size());
        cases.push_back(c);
    }
    return cases;
}

constexpr int kColorCaseCount = 24;

// Robust scenes with a colour image (docs/algorithm.md section 2c), the merge on in half of them; the colour term's
// parameters over their ranges, from a stream of their own, and its curvature gate from another (so that the scenes
// and the other parameters stay those of the cases before the gate).
std::vector<ConformanceCase> build_color_cases() {
    std::vector<ConformanceCase> cases;
    CaseRng rng(20261204);
    CaseRng gate_rng(20261206);
    const int fixed[][2] = {{1, 1}, {3, 9}, {33, 17}, {640, 480}, {2064, 1544}, {64, 1}};
    for (int i = 0; i < kColorCaseCount; ++i) {
        const bool sized = i < int(std::size(fixed));
        const int w = sized ? fixed[i][0] : rng.range(9, 200);
        const int h = sized ? fixed[i][1] : rng.range(9, 150);
        ConformanceCase c = make_robust_case(2000 + i, w, h, rng);
        c.params.merge = rng.chance(50);
        c.params.color_edge_threshold = rng.pick({0, 20, 60, 120, 300, 764, kMaxColorEdgeThreshold});
        c.params.color_edge_stride = rng.pick({1, 1, 2, 3, kMaxColorEdgeStride});
        c.color_row_padding = rng.pick({0, 0, 1, 5});
        c.params.color_edge_curvature_share = gate_rng.pick({0.0, 0.02, 0.1, 0.25, 0.25, 0.5, 0.999, 1.0});
        c.name = "color" + c.name.substr(std::string("robust").size());
        cases.push_back(c);
    }
    return cases;
}

}  // namespace

const std::vector<ConformanceCase>& color_conformance_cases() {
    static const std::vector<ConformanceCase> cases = build_color_cases();
    return cases;
}

const std::vector<ConformanceCase>& merge_conformance_cases() {
    static const std::vector<ConformanceCase> cases = build_merge_cases();
    return cases;
}

const std::vector<ConformanceCase>& robust_conformance_cases() {
    static const std::vector<ConformanceCase> cases = build_robust_cases();
    return cases;
}

const std::vector<ConformanceCase>& conformance_cases() {
    static const std::vector<ConformanceCase> cases = build_cases();
    return cases;
}

}  // namespace pyrseg::test
