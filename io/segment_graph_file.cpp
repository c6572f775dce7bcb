// The segment graph as CSV or JSON (nlohmann/json).
#include <nlohmann/json.hpp>
#include <string>

#include "file_util.hpp"
#include "pyrseg/io.hpp"

namespace pyrseg::io {
namespace {

std::string to_csv(const std::vector<SegmentEdge>& graph) {
    std::string out = "a,b,length,flat,convex,concave,step\n";
    for (const SegmentEdge& e : graph) {
        out += std::to_string(e.a) + ',' + std::to_string(e.b) + ',' + std::to_string(e.length) + ',' +
               std::to_string(e.flat) + ',' + std::to_string(e.convex) + ',' + std::to_string(e.concave) + ',' +
               std::to_string(e.step) + '\n';
    }
    return out;
}

std::string to_json(const std::vector<SegmentEdge>& graph, const SegmentTable& frame) {
    nlohmann::json doc;
    doc["source"] = frame.source;
    doc["width"] = frame.width;
    doc["height"] = frame.height;
    doc["edge_count"] = graph.size();
    nlohmann::json list = nlohmann::json::array();
    for (const SegmentEdge& e : graph) {
        list.push_back({{"a", e.a},
                        {"b", e.b},
                        {"length", e.length},
                        {"flat", e.flat},
                        {"convex", e.convex},
                        {"concave", e.concave},
                        {"step", e.step}});
    }
    doc["edges"] = std::move(list);
    return doc.dump(1) + "\n";
}

}  // namespace

void write_segment_graph(const std::filesystem::path& path, const std::vector<SegmentEdge>& graph,
                         const SegmentTable& frame) {
    const std::string text = detail::lower_extension(path) == ".csv" ? to_csv(graph) : to_json(graph, frame);
    detail::write_file(path, text.data(), text.size());
}

}  // namespace pyrseg::io
