// Pinhole intrinsics: from "fx,fy,cx,cy", or from a calibration file in OpenCV's FileStorage layout
// (calibration_file.cpp reads it, without OpenCV).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include "calibration_file.hpp"
#include "file_util.hpp"
#include "pyrseg/io.hpp"

namespace pyrseg::io {
namespace {

using detail::fail;

bool plausible(const Intrinsics& k) {
    return k.fx > 0 && k.fy > 0 && std::isfinite(k.fx) && std::isfinite(k.fy) && std::isfinite(k.cx) &&
           std::isfinite(k.cy);
}

}  // namespace

Intrinsics parse_intrinsics(const std::string& text) {
    std::vector<double> values;
    std::stringstream in(text);
    std::string item;
    while (std::getline(in, item, ',')) {
        std::size_t used = 0;
        double v = 0;
        try {
            v = std::stod(item, &used);
        } catch (const std::exception&) {
            used = 0;
        }
        if (used == 0 || used != item.size()) {
            std::string message = "intrinsics '" + text;
            message += "': '" + item;
            message += "' is not a number";
            throw Error(ErrorCode::invalid_argument, message);
        }
        values.push_back(v);
    }
    if (values.size() != 4) {
        throw Error(ErrorCode::invalid_argument, "intrinsics '" + text + "': expected four numbers fx,fy,cx,cy");
    }
    const Intrinsics k{values[0], values[1], values[2], values[3]};
    if (!plausible(k)) {
        throw Error(ErrorCode::invalid_argument, "intrinsics '" + text + "': fx and fy must be > 0, all finite");
    }
    return k;
}

Intrinsics read_intrinsics(const std::filesystem::path& path, const std::string& node_name) {
    std::error_code ec;
    const std::uintmax_t size = std::filesystem::file_size(path, ec);
    // Refused before reading: a multi-gigabyte "calibration" would otherwise be read whole first.
    if (!ec && size > detail::kMaxCalibrationBytes) {
        fail(ErrorCode::format, path,
             "is " + std::to_string(size) + " bytes; a calibration file is at most " +
                 std::to_string(detail::kMaxCalibrationBytes));
    }
    const std::vector<unsigned char> bytes = detail::read_file(path);  // io errors: missing, directory, FIFO
    const detail::CalibrationFile file =
        detail::parse_calibration(path, std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()));
    Intrinsics k;
    if (!node_name.empty()) {
        const auto node = std::find_if(file.nodes.begin(), file.nodes.end(),
                                       [&](const detail::CalibrationNode& n) { return n.name == node_name; });
        if (node == file.nodes.end()) fail(ErrorCode::format, path, "has no node '" + node_name + "'");
        if (!node->intrinsics) {
            fail(ErrorCode::format, path, "node '" + node_name + "' is neither a 3x3 camera matrix nor fx fy cx cy");
        }
        k = *node->intrinsics;
    } else if (file.top_level) {
        k = *file.top_level;
    } else {
        std::vector<std::string> matrices;
        for (const detail::CalibrationNode& n : file.nodes) {
            if (n.intrinsics) {
                matrices.push_back(n.name);
                k = *n.intrinsics;
            }
        }
        if (matrices.size() != 1) {
            std::string names;
            for (const std::string& n : matrices) names += (names.empty() ? "" : ", ") + n;
            fail(ErrorCode::format, path,
                 matrices.empty() ? "holds no 3x3 camera matrix and no fx fy cx cy"
                                  : "holds several 3x3 matrices (" + names + "): name one, as FILE:NODE");
        }
    }
    if (!plausible(k)) fail(ErrorCode::format, path, "intrinsics with fx or fy not > 0, or not finite");
    return k;
}

}  // namespace pyrseg::io
