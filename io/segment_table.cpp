// Per-segment statistics as CSV or JSON (nlohmann/json).
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <string>

#include "file_util.hpp"
#include "pyrseg/io.hpp"

namespace pyrseg::io {
namespace {

bool ends_with_csv(const std::filesystem::path& path) {
    std::string ext = path.extension().string();
    for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
    return ext == ".csv";
}

// Shortest text that reads back as the same double; empty for NaN (a mask has no geometry).
std::string csv_number(double v) {
    if (std::isnan(v)) return {};
    return nlohmann::json(v).dump();
}

std::string to_csv(const std::vector<SegmentStats>& segments) {
    std::string out =
        "label,pixel_count,x_min,y_min,x_max,y_max,centroid_x,centroid_y,centroid_z,normal_x,normal_y,normal_z\n";
    for (const SegmentStats& s : segments) {
        out += std::to_string(s.label) + ',' + std::to_string(s.pixel_count) + ',' + std::to_string(s.x_min) + ',' +
               std::to_string(s.y_min) + ',' + std::to_string(s.x_max) + ',' + std::to_string(s.y_max);
        for (const double v : s.centroid) out += ',' + csv_number(v);
        for (const double v : s.mean_normal) out += ',' + csv_number(v);
        out += '\n';
    }
    return out;
}

nlohmann::json vector3(const std::array<double, 3>& v) {
    nlohmann::json a = nlohmann::json::array();
    for (const double c : v) a.push_back(std::isnan(c) ? nlohmann::json(nullptr) : nlohmann::json(c));
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
                        {"bbox", {s.x_min, s.y_min, s.x_max, s.y_max}},
                        {"centroid", vector3(s.centroid)},
                        {"mean_normal", vector3(s.mean_normal)}});
    }
    doc["segments"] = std::move(list);
    return doc.dump(1) + "\n";
}

}  // namespace

void write_segment_stats(const std::filesystem::path& path, const std::vector<SegmentStats>& segments,
                         const SegmentTable& frame) {
    const std::string text = ends_with_csv(path) ? to_csv(segments) : to_json(segments, frame);
    detail::write_file(path, text.data(), text.size());
}

}  // namespace pyrseg::io
