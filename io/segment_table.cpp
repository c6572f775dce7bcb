// Per-segment statistics as CSV or JSON (nlohmann/json).
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <string>

#include "file_util.hpp"
#include "pyrseg/io.hpp"

namespace pyrseg::io {
namespace {

// Shortest text that reads back as the same double; empty for NaN (a mask has no geometry).
std::string csv_number(double v) {
    if (std::isnan(v)) return {};
    return nlohmann::json(v).dump();
}

std::string to_csv(const std::vector<SegmentStats>& segments) {
    std::string out =
        "label,pixel_count,fillable_count,x_min,y_min,x_max,y_max,centroid_x,centroid_y,centroid_z,"
        "normal_x,normal_y,normal_z,z_min,z_max,plane_nx,plane_ny,plane_nz,plane_offset,plane_rms,curvature,planar,"
        "axis0_x,axis0_y,axis0_z,axis1_x,axis1_y,axis1_z,axis2_x,axis2_y,axis2_z,extent0,extent1,extent2\n";
    for (const SegmentStats& s : segments) {
        out += std::to_string(s.label) + ',' + std::to_string(s.pixel_count) + ',' + std::to_string(s.fillable_count) +
               ',' + std::to_string(s.x_min) + ',' + std::to_string(s.y_min) + ',' + std::to_string(s.x_max) + ',' +
               std::to_string(s.y_max);
        for (const double v : s.centroid) out += ',' + csv_number(v);
        for (const double v : s.mean_normal) out += ',' + csv_number(v);
        out += ',' + csv_number(s.z_min) + ',' + csv_number(s.z_max);
        for (const double v : s.plane_normal) out += ',' + csv_number(v);
        out += ',' + csv_number(s.plane_offset) + ',' + csv_number(s.plane_rms) + ',' + csv_number(s.curvature) + ',' +
               (std::isnan(s.plane_rms) ? ""
                : s.planar              ? "1"
                                        : "0");
        for (const auto& axis : s.axes) {
            for (const double v : axis) out += ',' + csv_number(v);
        }
        for (const double v : s.extents) out += ',' + csv_number(v);
        out += '\n';
    }
    return out;
}

nlohmann::json number(double v) {
    return std::isnan(v) ? nlohmann::json(nullptr) : nlohmann::json(v);
}

nlohmann::json vector3(const std::array<double, 3>& v) {
    nlohmann::json a = nlohmann::json::array();
    for (const double c : v) a.push_back(number(c));
    return a;
}

std::string to_json(const std::vector<SegmentStats>& segments, const SegmentTable& frame) {
    nlohmann::json doc;
    doc["source"] = frame.source;
    doc["width"] = frame.width;
    doc["height"] = frame.height;
    doc["unit_mm"] = frame.unit_mm;
    doc["segment_count"] = segments.size();
    nlohmann::json list = nlohmann::json::array();
    for (const SegmentStats& s : segments) {
        list.push_back({{"label", s.label},
                        {"pixel_count", s.pixel_count},
                        {"fillable_count", s.fillable_count},
                        {"bbox", {s.x_min, s.y_min, s.x_max, s.y_max}},
                        {"centroid", vector3(s.centroid)},
                        {"mean_normal", vector3(s.mean_normal)},
                        {"depth_range", {number(s.z_min), number(s.z_max)}},
                        {"plane",
                         {{"normal", vector3(s.plane_normal)},
                          {"offset", number(s.plane_offset)},
                          {"rms", number(s.plane_rms)},
                          {"curvature", number(s.curvature)},
                          {"planar", s.planar}}},
                        {"box",
                         {{"centre", vector3(s.centroid)},
                          {"axes", {vector3(s.axes[0]), vector3(s.axes[1]), vector3(s.axes[2])}},
                          {"extents", vector3(s.extents)}}}});
    }
    doc["segments"] = std::move(list);
    return doc.dump(1) + "\n";
}

}  // namespace

void write_segment_stats(const std::filesystem::path& path, const std::vector<SegmentStats>& segments,
                         const SegmentTable& frame) {
    const std::string text = detail::lower_extension(path) == ".csv" ? to_csv(segments) : to_json(segments, frame);
    detail::write_file(path, text.data(), text.size());
}

}  // namespace pyrseg::io
