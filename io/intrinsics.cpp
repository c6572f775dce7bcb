// Pinhole intrinsics: from "fx,fy,cx,cy", or from an OpenCV FileStorage calibration file read by OpenCV itself.
#include <opencv2/core.hpp>

#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include "file_util.hpp"
#include "pyrseg/io.hpp"

namespace pyrseg::io {
namespace {

using detail::fail;

bool plausible(const Intrinsics& k) {
    return k.fx > 0 && k.fy > 0 && std::isfinite(k.fx) && std::isfinite(k.fy) && std::isfinite(k.cx) &&
           std::isfinite(k.cy);
}

// A 3x3 camera matrix node, or a map with fx fy cx cy; false when the node is neither.
bool from_node(const cv::FileNode& node, Intrinsics& k) {
    if (node.isMap() && !node["fx"].empty() && !node["fy"].empty() && !node["cx"].empty() && !node["cy"].empty()) {
        k = {double(node["fx"]), double(node["fy"]), double(node["cx"]), double(node["cy"])};
        return true;
    }
    cv::Mat m;
    try {
        node >> m;
    } catch (const cv::Exception&) {
        return false;
    }
    if (m.rows != 3 || m.cols != 3 || m.channels() != 1) return false;
    m.convertTo(m, CV_64F);
    k = {m.at<double>(0, 0), m.at<double>(1, 1), m.at<double>(0, 2), m.at<double>(1, 2)};
    return true;
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
    (void)detail::read_file(path);  // a clear io error for a missing file, a directory or a FIFO
    cv::FileStorage fs;
    try {
        if (!fs.open(path.string(), cv::FileStorage::READ))
            fail(ErrorCode::format, path, "not an OpenCV FileStorage file");
    } catch (const cv::Exception& e) {
        fail(ErrorCode::format, path, std::string("not an OpenCV FileStorage file (") + e.err + ")");
    }
    Intrinsics k;
    const cv::FileNode root = fs.root();
    if (!node_name.empty()) {
        const cv::FileNode node = fs[node_name];
        if (node.empty()) fail(ErrorCode::format, path, "has no node '" + node_name + "'");
        if (!from_node(node, k)) {
            fail(ErrorCode::format, path, "node '" + node_name + "' is neither a 3x3 camera matrix nor fx fy cx cy");
        }
    } else if (!from_node(root, k)) {
        std::vector<std::string> matrices;
        for (const cv::FileNode& child : root) {
            Intrinsics candidate;
            if (from_node(child, candidate)) {
                matrices.push_back(child.name());
                k = candidate;
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
