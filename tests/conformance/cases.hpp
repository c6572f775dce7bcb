#pragma once
// The conformance scenes: 200 seeded synthetic scenes of many sizes, noise levels, hole fractions and
// parameters, the same list for every backend.
#include <string>
#include <vector>

#include "pyrseg/params.hpp"
#include "pyrseg/synthetic.hpp"

namespace pyrseg::test {

struct ConformanceCase {
    std::string name;  // a gtest-safe name: index, size, normals source
    synthetic::SceneOptions scene;
    Params params;
    bool given_normals = false;  // the scene's exact normals; otherwise the normals pass estimates them
    int color_row_padding = -1;  // >= 0: the frame comes with a colour image, rows padded by this many bytes
};

[[nodiscard]] const std::vector<ConformanceCase>& conformance_cases();
// The robust metric (docs/algorithm.md sections 2b and 8b) and every sensor preset, on scenes of every sensor model.
[[nodiscard]] const std::vector<ConformanceCase>& robust_conformance_cases();
// Robust scenes with the merge (docs/algorithm.md section 5b) on, its parameters varied.
[[nodiscard]] const std::vector<ConformanceCase>& merge_conformance_cases();
// Robust scenes with a colour image (docs/algorithm.md section 2c), the colour term's parameters varied.
[[nodiscard]] const std::vector<ConformanceCase>& color_conformance_cases();

}  // namespace pyrseg::test
