#pragma once
// A named test frame (an organized cloud, its normals or none, its parameters) and what a cpu Segmenter makes of
// it: the CPU backend's whole-frame tests generate different frames but segment them the same way.
#include <string>
#include <vector>

#include "pyrseg/segmenter.hpp"
#include "support/cpu_targets.hpp"

namespace pyrseg::test {

struct TestFrame {
    std::string name;
    int w = 0, h = 0;
    std::vector<float> points;
    std::vector<float> normals;  // empty: estimated
    Params params;

    [[nodiscard]] CloudView view() const {
        return CloudView{points.data(), normals.empty() ? nullptr : normals.data(), w, h};
    }
};

inline Result segment_frame(Segmenter& segmenter, const TestFrame& f) {
    Result result;
    segmenter.segment(f.view(), result);
    return result;
}

// On a new cpu Segmenter whose kernels are those of the Highway target named `target` ("scalar": the shared scalar
// functions), as PYRSEG_CPU_SIMD chooses them.
inline Result segment_on_target(const std::string& target, const TestFrame& f, const Outputs& outputs) {
    const ScopedEnv env("PYRSEG_CPU_SIMD", target);
    Segmenter segmenter(f.w, f.h, f.params, "cpu", outputs);
    return segment_frame(segmenter, f);
}

}  // namespace pyrseg::test
