// OpenCV FileStorage calibration files without OpenCV: cv::FileStorage crashed on a truncated XML prolog, decoded a
// YAML !!binary forever and threw cv::Exception from inside its parsers, so untrusted bytes now only meet one
// maintained parser per format (tinyxml2, libyaml, nlohmann/json), and only the two levels OpenCV's layout puts
// intrinsics in are interpreted.
#include "calibration_file.hpp"

#include <tinyxml2.h>
#include <yaml.h>

#include <algorithm>
#include <charconv>
#include <cstddef>
#include <exception>
#include <nlohmann/json.hpp>
#include <string>

#include "file_util.hpp"

namespace pyrseg::io::detail {
namespace {

// One number filling the whole of `text` but for surrounding whitespace.
std::optional<double> number(std::string_view text) {
    const auto space = [](char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; };
    while (!text.empty() && space(text.front())) text.remove_prefix(1);
    while (!text.empty() && space(text.back())) text.remove_suffix(1);
    if (!text.empty() && text.front() == '+') text.remove_prefix(1);
    double v = 0;
    const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
    if (text.empty() || ec != std::errc() || end != text.data() + text.size()) return std::nullopt;
    return v;
}

// What OpenCV writes for a one-channel element type ("d", "f", "i", ... or "1d").
bool one_channel(std::string_view dt) {
    if (dt.size() == 2 && dt.front() == '1') dt.remove_prefix(1);
    return dt.size() == 1 && std::string_view("ucwsifdh").find(dt.front()) != std::string_view::npos;
}

// A camera matrix: rows 3, cols 3, one channel, nine numbers.
std::optional<Intrinsics> from_matrix(std::optional<double> rows, std::optional<double> cols, std::string_view dt,
                                      const std::vector<double>& data) {
    if (rows != 3.0 || cols != 3.0 || !one_channel(dt) || data.size() != 9) return std::nullopt;
    return Intrinsics{data[0], data[4], data[2], data[5]};
}

std::optional<Intrinsics> from_values(std::optional<double> fx, std::optional<double> fy, std::optional<double> cx,
                                      std::optional<double> cy) {
    if (!fx || !fy || !cx || !cy) return std::nullopt;
    return Intrinsics{*fx, *fy, *cx, *cy};
}

// ---- XML: <opencv_storage> holding one element per node.

std::optional<double> xml_number(const tinyxml2::XMLElement& parent, const char* name) {
    const tinyxml2::XMLElement* e = parent.FirstChildElement(name);
    if (e == nullptr || e->FirstChildElement() != nullptr || e->GetText() == nullptr) return std::nullopt;
    return number(e->GetText());
}

std::optional<Intrinsics> xml_intrinsics(const tinyxml2::XMLElement& e) {
    if (std::optional<Intrinsics> k =
            from_values(xml_number(e, "fx"), xml_number(e, "fy"), xml_number(e, "cx"), xml_number(e, "cy"))) {
        return k;
    }
    const tinyxml2::XMLElement* dt = e.FirstChildElement("dt");
    const tinyxml2::XMLElement* data = e.FirstChildElement("data");
    if (dt == nullptr || dt->GetText() == nullptr || data == nullptr || data->GetText() == nullptr) return std::nullopt;
    std::vector<double> values;
    std::string_view text = data->GetText();
    while (values.size() <= 9) {
        const std::size_t start = text.find_first_not_of(" \t\r\n");
        if (start == std::string_view::npos) break;
        const std::size_t end = std::min(text.find_first_of(" \t\r\n", start), text.size());
        const std::optional<double> v = number(text.substr(start, end - start));
        if (!v) return std::nullopt;
        values.push_back(*v);
        text.remove_prefix(end);
    }
    const std::string_view type = dt->GetText();
    return from_matrix(xml_number(e, "rows"), xml_number(e, "cols"), type, values);
}

CalibrationFile parse_xml(const std::filesystem::path& path, std::string_view text) {
    tinyxml2::XMLDocument doc;
    if (doc.Parse(text.data(), text.size()) != tinyxml2::XML_SUCCESS) {
        fail(ErrorCode::format, path, std::string("is not valid XML: ") + doc.ErrorStr());
    }
    const tinyxml2::XMLElement* root = doc.RootElement();
    if (root == nullptr || std::string_view(root->Name()) != "opencv_storage") {
        fail(ErrorCode::format, path, "is XML without an <opencv_storage> root element (OpenCV's FileStorage layout)");
    }
    CalibrationFile file;
    file.top_level = xml_intrinsics(*root);
    for (const tinyxml2::XMLElement* e = root->FirstChildElement(); e != nullptr; e = e->NextSiblingElement()) {
        file.nodes.push_back({e->Name(), xml_intrinsics(*e)});
    }
    return file;
}

// ---- YAML: a map at the top level; OpenCV's matrices are maps tagged !!opencv-matrix (tags are ignored). libyaml
// hands out events without recursing, so nesting costs heap, bounded by the file size, not stack; nodes below the
// second level are skipped unread, aliases are never resolved.

class YamlEvents {
public:
    YamlEvents(const std::filesystem::path& path, std::string_view text) : path_(path) {
        if (yaml_parser_initialize(&parser_) == 0) fail(ErrorCode::out_of_memory, path, "cannot start a YAML parser");
        yaml_parser_set_input_string(&parser_, reinterpret_cast<const unsigned char*>(text.data()), text.size());
    }
    ~YamlEvents() {
        if (has_event_) yaml_event_delete(&event_);
        yaml_parser_delete(&parser_);
    }
    YamlEvents(const YamlEvents&) = delete;
    YamlEvents& operator=(const YamlEvents&) = delete;

    const yaml_event_t& next() {
        if (has_event_) yaml_event_delete(&event_);
        has_event_ = false;
        if (yaml_parser_parse(&parser_, &event_) == 0) {
            fail(ErrorCode::format, path_,
                 "is not valid YAML (line " + std::to_string(parser_.problem_mark.line + 1) +
                     "): " + (parser_.problem != nullptr ? parser_.problem : "parse error"));
        }
        has_event_ = true;
        // libyaml spends time in proportion to the open flow collections on every token: stopping at a depth no
        // calibration has keeps "[[[[..." linear (its simple-key look-ahead is bounded, 1024 characters).
        if (event_.type == YAML_MAPPING_START_EVENT || event_.type == YAML_SEQUENCE_START_EVENT) {
            if (++depth_ > kMaxDepth) {
                fail(ErrorCode::format, path_, "is YAML nested deeper than " + std::to_string(kMaxDepth) + " levels");
            }
        } else if (event_.type == YAML_MAPPING_END_EVENT || event_.type == YAML_SEQUENCE_END_EVENT) {
            --depth_;
        }
        return event_;
    }

    // Past the end of the node whose first event is the current one.
    void skip_node() {
        int depth = 0;
        for (const yaml_event_t* e = &event_;; e = &next()) {
            if (e->type == YAML_MAPPING_START_EVENT || e->type == YAML_SEQUENCE_START_EVENT) ++depth;
            if (e->type == YAML_MAPPING_END_EVENT || e->type == YAML_SEQUENCE_END_EVENT) --depth;
            if (depth == 0) return;
        }
    }

private:
    static constexpr int kMaxDepth = kMaxNesting;
    const std::filesystem::path& path_;
    int depth_ = 0;
    yaml_parser_t parser_{};
    yaml_event_t event_{};
    bool has_event_ = false;
};

std::string scalar_text(const yaml_event_t& e) {
    return {reinterpret_cast<const char*>(e.data.scalar.value), e.data.scalar.length};
}

// The scalars of a map that intrinsics may need, and the first ten of its "data" sequence.
struct YamlMap {
    std::vector<std::pair<std::string, std::string>> scalars;
    std::vector<std::string> data;
    bool data_is_list_of_scalars = false;

    [[nodiscard]] std::optional<double> value(std::string_view key) const {
        for (const auto& [k, v] : scalars) {
            if (k == key) return number(v);
        }
        return std::nullopt;
    }
    [[nodiscard]] std::optional<Intrinsics> intrinsics() const {
        if (std::optional<Intrinsics> k = from_values(value("fx"), value("fy"), value("cx"), value("cy"))) return k;
        const auto dt = std::find_if(scalars.begin(), scalars.end(), [](const auto& kv) { return kv.first == "dt"; });
        if (dt == scalars.end() || !data_is_list_of_scalars || data.size() != 9) return std::nullopt;
        std::vector<double> values;
        for (const std::string& text : data) {
            const std::optional<double> v = number(text);
            if (!v) return std::nullopt;
            values.push_back(*v);
        }
        return from_matrix(value("rows"), value("cols"), dt->second, values);
    }
};

// The map whose MAPPING_START is the current event; with `nodes`, each of its entries' values is read as a map too
// (the top level), else skipped.
YamlMap read_yaml_map(YamlEvents& events, std::vector<CalibrationNode>* nodes) {
    YamlMap map;
    for (;;) {
        const yaml_event_t& key = events.next();
        if (key.type == YAML_MAPPING_END_EVENT) return map;
        std::string name;
        if (key.type == YAML_SCALAR_EVENT) {
            name = scalar_text(key);
        } else {
            events.skip_node();
        }
        const yaml_event_t& value = events.next();
        if (value.type == YAML_SCALAR_EVENT) {
            if (map.scalars.size() < 64) map.scalars.emplace_back(name, scalar_text(value));
            if (nodes != nullptr) nodes->push_back({name, std::nullopt});
        } else if (value.type == YAML_MAPPING_START_EVENT && nodes != nullptr) {
            nodes->push_back({name, read_yaml_map(events, nullptr).intrinsics()});
        } else if (value.type == YAML_SEQUENCE_START_EVENT && nodes == nullptr && name == "data") {
            map.data_is_list_of_scalars = true;
            for (const yaml_event_t* e = &events.next(); e->type != YAML_SEQUENCE_END_EVENT; e = &events.next()) {
                if (e->type == YAML_SCALAR_EVENT) {
                    if (map.data.size() < 10) map.data.push_back(scalar_text(*e));
                } else {
                    map.data_is_list_of_scalars = false;
                    events.skip_node();
                }
            }
        } else {
            if (nodes != nullptr) nodes->push_back({name, std::nullopt});
            events.skip_node();
        }
    }
}

CalibrationFile parse_yaml(const std::filesystem::path& path, std::string_view text) {
    std::string yaml(text);
    // OpenCV's "%YAML:1.0" is no YAML directive: blank it, keeping the line numbers of messages.
    if (yaml.starts_with("%YAML:")) yaml.replace(0, std::min(yaml.find('\n'), yaml.size()), "");
    YamlEvents events(path, yaml);
    yaml_event_type_t type = events.next().type;  // the stream's start
    while (type == YAML_STREAM_START_EVENT || type == YAML_DOCUMENT_START_EVENT) type = events.next().type;
    if (type != YAML_MAPPING_START_EVENT) {
        fail(ErrorCode::format, path,
             "is not a calibration file: expected XML (<opencv_storage>), or YAML or JSON with a map at the top level");
    }
    CalibrationFile file;
    file.top_level = read_yaml_map(events, &file.nodes).intrinsics();
    // The rest of the document must parse too: a file cut short is an error, not a partial calibration.
    while (type != YAML_DOCUMENT_END_EVENT && type != YAML_STREAM_END_EVENT) type = events.next().type;
    return file;
}

// ---- JSON: an object at the top level.

// Deepest nesting of arrays and objects, outside strings: nlohmann/json builds (and destroys) what it parses.
int json_depth(std::string_view text) {
    int depth = 0;
    int deepest = 0;
    bool in_string = false;
    for (std::size_t i = 0; i < text.size(); ++i) {
        const char c = text[i];
        if (in_string) {
            if (c == '\\') {
                ++i;
            } else if (c == '"') {
                in_string = false;
            }
        } else if (c == '"') {
            in_string = true;
        } else if (c == '[' || c == '{') {
            deepest = std::max(deepest, ++depth);
        } else if (c == ']' || c == '}') {
            --depth;
        }
    }
    return deepest;
}

std::optional<double> json_number(const nlohmann::json& object, const char* key) {
    const auto it = object.find(key);
    if (it == object.end() || !it->is_number()) return std::nullopt;
    return it->get<double>();
}

std::optional<Intrinsics> json_intrinsics(const nlohmann::json& node) {
    if (!node.is_object()) return std::nullopt;
    if (std::optional<Intrinsics> k = from_values(json_number(node, "fx"), json_number(node, "fy"),
                                                  json_number(node, "cx"), json_number(node, "cy"))) {
        return k;
    }
    const auto dt = node.find("dt");
    const auto data = node.find("data");
    if (dt == node.end() || !dt->is_string() || data == node.end() || !data->is_array() || data->size() != 9) {
        return std::nullopt;
    }
    std::vector<double> values;
    for (const nlohmann::json& v : *data) {
        if (!v.is_number()) return std::nullopt;
        values.push_back(v.get<double>());
    }
    return from_matrix(json_number(node, "rows"), json_number(node, "cols"), dt->get_ref<const std::string&>(), values);
}

CalibrationFile parse_json(const std::filesystem::path& path, std::string_view text) {
    if (json_depth(text) > kMaxNesting) {
        fail(ErrorCode::format, path, "is JSON nested deeper than " + std::to_string(kMaxNesting) + " levels");
    }
    const nlohmann::json root = nlohmann::json::parse(text.begin(), text.end(), nullptr, false);
    if (root.is_discarded()) fail(ErrorCode::format, path, "is not valid JSON");
    if (!root.is_object()) fail(ErrorCode::format, path, "is JSON without an object at the top level");
    CalibrationFile file;
    file.top_level = json_intrinsics(root);
    for (const auto& [name, value] : root.items()) file.nodes.push_back({name, json_intrinsics(value)});
    return file;
}

}  // namespace

CalibrationFile parse_calibration(const std::filesystem::path& path, std::string_view text) {
    if (text.size() > kMaxCalibrationBytes) {
        fail(ErrorCode::format, path,
             "is " + std::to_string(text.size()) + " bytes; a calibration file is at most " +
                 std::to_string(kMaxCalibrationBytes));
    }
    if (text.starts_with("\x1f\x8b")) fail(ErrorCode::format, path, "is compressed (gzip): unpack it first");
    if (text.starts_with("\xEF\xBB\xBF")) text.remove_prefix(3);
    const std::size_t first = text.find_first_not_of(" \t\r\n");
    const char lead = first == std::string_view::npos ? '\0' : text[first];
    try {
        if (lead == '<') return parse_xml(path, text);
        if (lead == '{' || lead == '[') return parse_json(path, text);
        return parse_yaml(path, text);
    } catch (const Error&) {
        throw;
    } catch (const std::exception& e) {
        // Whatever the standard library may still throw (bad_alloc): never a foreign exception.
        fail(ErrorCode::format, path, std::string("cannot be read as a calibration file: ") + e.what());
    }
}

}  // namespace pyrseg::io::detail
