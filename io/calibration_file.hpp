#pragma once
// The top level of a calibration file in OpenCV's FileStorage layout (XML, YAML or JSON), as far as pinhole
// intrinsics go, read with tinyxml2, libyaml and nlohmann/json instead of cv::FileStorage.
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "pyrseg/io.hpp"

namespace pyrseg::io::detail {

// One node under the top level; `intrinsics` when it is a single-channel 3x3 matrix or a map with fx fy cx cy.
struct CalibrationNode {
    std::string name;
    std::optional<Intrinsics> intrinsics;
};

struct CalibrationFile {
    std::optional<Intrinsics> top_level;  // the top level itself holds fx fy cx cy
    std::vector<CalibrationNode> nodes;   // in file order
};

// Calibration files are a few kilobytes; anything much larger is refused before a parser sees it.
inline constexpr std::size_t kMaxCalibrationBytes = std::size_t{1} << 20;
// Nesting deeper than any calibration has is refused: JSON before parsing, YAML as libyaml reports it (tinyxml2
// stops at 100 elements itself).
inline constexpr int kMaxNesting = 64;

// The format is chosen from the content ('<' XML, '{' JSON, anything else YAML). ErrorCode::format naming `path`
// on any malformed, unsupported or too deeply nested content; no other exception leaves it.
CalibrationFile parse_calibration(const std::filesystem::path& path, std::string_view text);

}  // namespace pyrseg::io::detail
