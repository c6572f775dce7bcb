#pragma once
// Frames that reach every parallel pass of the CPU backend (fragmented masks, anchored fills, several edge rounds,
// the robust metric's windows, estimated and given normals), and what one thread makes of them: the concurrency
// tests' (test_concurrency.cpp, test_cpu_threads.cpp) common ground.
#include <cstdint>
#include <sstream>
#include <string>
#include <vector>

#include "pyrseg/presets.hpp"
#include "pyrseg/segmenter.hpp"
#include "pyrseg/synthetic.hpp"
#include "support/cpu_targets.hpp"
#include "support/test_frame.hpp"

namespace pyrseg::test {

inline std::vector<TestFrame> thread_test_frames() {
    std::vector<TestFrame> out;
    std::uint64_t seed = 101;
    for (const int width : {97, 160}) {
        const int height = width * 3 / 4;
        for (const bool noisy : {false, true}) {
            for (const bool robust : {false, true}) {
                synthetic::SceneOptions o;
                o.width = width;
                o.height = height;
                o.seed = seed++;
                o.threads = 1;
                o.noise_mm = noisy ? 1.5 : 0.1;  // a fragmented mask at 1.5 mm
                o.sensor = robust ? synthetic::Sensor::kinect_v1 : synthetic::Sensor::structured_light;
                const synthetic::Scene scene = synthetic::generate(o);
                TestFrame f;
                f.w = width;
                f.h = height;
                f.points = scene.points;
                if (!robust && !noisy) f.normals = scene.normals;
                f.params = robust ? sensor_preset(SensorKind::kinect_v1) : Params{};
                std::ostringstream name;
                name << width << "x" << height << (noisy ? "_noisy" : "") << (robust ? "_kinect" : "_paper")
                     << (f.normals.empty() ? "_estimated" : "_given");
                f.name = name.str();
                out.push_back(std::move(f));
            }
        }
    }
    return out;
}

// What one thread (a pool of one) makes of each frame.
inline std::vector<Result> alone(const std::vector<TestFrame>& all) {
    const ScopedEnv one("PYRSEG_THREADS", "1");
    std::vector<Result> out;
    for (const TestFrame& f : all) {
        Segmenter s(f.w, f.h, f.params, "cpu");
        out.push_back(segment_frame(s, f));
    }
    return out;
}

}  // namespace pyrseg::test
