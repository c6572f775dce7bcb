// PLY clouds through PCL's PLY reader and writer (pcl::PLYReader, pcl::PLYWriter in pcl_io): pyrseg decodes no PLY
// data itself. It does check the file first, because PCL 1.13's reader (Debian builds it with assertions on) does
// not fail cleanly on every file; found by feeding it crafted files:
//   - obj_info num_cols x num_rows smaller than the vertex count: an assertion fails (vertexScalarPropertyCallback),
//     the process aborts; larger than the vertex count: cells that are never written read as zeros;
//   - an obj_info line that starts with whitespace: an assertion fails (objInfoCallback), the process aborts;
//   - a huge element count, or a huge num_cols x num_rows: std::bad_alloc at end_header, before any data is read;
//   - an element with instances but no properties: a loop over every instance that reads nothing (a hang);
//   - uchar colours other than red green blue [alpha] in that order, or list properties in element vertex: values
//     stored at the wrong offsets, or assertions;
//   - a file shorter than its magic: a read of uninitialized memory;
//   - a range_grid vertex index past the vertices: a SIGSEGV (the index wraps PCL's 32-bit bounds check), or a cell
//     read as zeros (an index equal to the vertex count);
//   - an obj_info grid of many cells over a wide vertex: PCL allocates the vertex's size for every cell, twice.
// So the header is parsed here, strictly, to the PLY 1.0 grammar; the bytes the declared elements need at the least
// are checked against the file's size (so PCL's allocations stay within a small multiple of the file's size); the
// organized grid is checked against the vertex count and the file's size; the data is walked as PCL will parse it,
// checking every list against the file and every range_grid index against the vertices; and only then does PCL
// read the file.
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <limits>
#include <string>
#include <string_view>

#include "file_util.hpp"
#include "pyrseg/io.hpp"

#if PYRSEG_HAVE_PLY
#include <pcl/PCLPointCloud2.h>
#include <pcl/console/print.h>
#include <pcl/io/ply_io.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <climits>
#include <cmath>
#include <memory>
#include <new>
#include <optional>
#include <system_error>
#include <vector>
#endif

namespace pyrseg::io {

#if PYRSEG_HAVE_PLY

namespace {

namespace fs = std::filesystem;
using detail::fail;

// A header longer than this is not a point cloud's (PhoXi's, with its camera elements, is under 3 KiB).
constexpr std::size_t kMaxHeaderBytes = std::size_t{1} << 20;
// Element counts beyond this are refused before any arithmetic on them (2^48 instances: far beyond any file).
constexpr std::uint64_t kMaxCount = std::uint64_t{1} << 48;
constexpr std::uint8_t kLabelZeroGray = 128;
// What PCL may allocate for an organized grid per byte of PLY data, beyond a fixed slack: 64 bytes a byte covers a
// grid of 12-byte points even when every cell is empty (one byte in a binary file, two in an ascii one).
constexpr std::uint64_t kGridBytesPerFileByte = 64;
constexpr std::uint64_t kGridBytesSlack = std::uint64_t{16} << 20;

enum class PlyFormat { ascii, binary_little_endian, binary_big_endian };

struct PlyProperty {
    std::string name;
    std::string type;    // the scalar type as written (float, float32, uchar, ...); a list's item type
    int size = 0;        // bytes of the scalar, or of one list item
    int count_size = 0;  // a list's item-count bytes; 0 for a scalar
};

struct PlyElement {
    std::string name;
    std::uint64_t count = 0;
    std::vector<PlyProperty> properties;

    [[nodiscard]] const PlyProperty* find(std::string_view property) const {
        for (const PlyProperty& p : properties) {
            if (p.name == property) return &p;
        }
        return nullptr;
    }
};

struct PlyHeader {
    PlyFormat format = PlyFormat::ascii;
    std::vector<PlyElement> elements;
    std::uint64_t data_offset = 0;         // the first byte after end_header
    std::uint64_t data_bytes = 0;          // the file's bytes after end_header
    int grid_cols = 0, grid_rows = 0;      // obj_info num_cols / num_rows (PCL, Stanford range scans)
    int vendor_cols = 0, vendor_rows = 0;  // "Width = W; Height = H" in an obj_info or comment line (Photoneo)

    [[nodiscard]] const PlyElement* find(std::string_view element) const {
        for (const PlyElement& e : elements) {
            if (e.name == element) return &e;
        }
        return nullptr;
    }
};

// The scalar types of PLY 1.0, by their old and their sized names (PCL's parser knows both).
int type_size(std::string_view type) {
    constexpr std::array<std::pair<std::string_view, int>, 16> kTypes = {{{"char", 1},
                                                                          {"int8", 1},
                                                                          {"uchar", 1},
                                                                          {"uint8", 1},
                                                                          {"short", 2},
                                                                          {"int16", 2},
                                                                          {"ushort", 2},
                                                                          {"uint16", 2},
                                                                          {"int", 4},
                                                                          {"int32", 4},
                                                                          {"uint", 4},
                                                                          {"uint32", 4},
                                                                          {"float", 4},
                                                                          {"float32", 4},
                                                                          {"double", 8},
                                                                          {"float64", 8}}};
    for (const auto& [name, size] : kTypes) {
        if (name == type) return size;
    }
    return 0;
}

bool is_floating(std::string_view type) {
    return type == "float" || type == "float32" || type == "double" || type == "float64";
}

bool is_uchar(std::string_view type) {
    return type == "uchar" || type == "uint8";
}

// The item counts PCL's parser reads for list properties.
bool is_list_count_type(std::string_view type) {
    return is_uchar(type) || type == "ushort" || type == "uint16" || type == "uint" || type == "uint32";
}

std::vector<std::string_view> split(std::string_view line) {
    std::vector<std::string_view> tokens;
    std::size_t i = 0;
    while (i < line.size()) {
        while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
        const std::size_t start = i;
        while (i < line.size() && line[i] != ' ' && line[i] != '\t') ++i;
        if (i > start) tokens.push_back(line.substr(start, i - start));
    }
    return tokens;
}

// Whether an ascii token is a value of the scalar type PCL reads it as, exactly: PCL's parser turns a token that is
// not a number into NaN (or 0) and casts what its type cannot hold, so "abc" or 300 for a uchar would be read silently.
// Floating tokens may be nan or inf (PCL writes invalid points so); float32 ones must otherwise fit a float.
bool is_ascii_value(std::string_view token, std::string_view type) {
    if (token.size() > 1 && token[0] == '+' && token[1] != '-') token.remove_prefix(1);
    const char* const end = token.data() + token.size();
    if (is_floating(type)) {
        double v = 0;
        const auto [at, ec] = std::from_chars(token.data(), end, v);
        if (ec != std::errc() || at != end) return false;
        return type_size(type) == 8 || !std::isfinite(v) || std::fabs(v) <= double(std::numeric_limits<float>::max());
    }
    long long v = 0;
    const auto [at, ec] = std::from_chars(token.data(), end, v);
    if (ec != std::errc() || at != end) return false;
    const int bits = 8 * type_size(type);
    const bool is_signed =
        type == "char" || type == "int8" || type == "short" || type == "int16" || type == "int" || type == "int32";
    const long long low = is_signed ? -(1LL << (bits - 1)) : 0;
    const long long high = is_signed ? (1LL << (bits - 1)) - 1 : (1LL << bits) - 1;
    return v >= low && v <= high;
}

template <typename T>
bool parse_unsigned(std::string_view token, T& value) {
    if (token.empty() || token[0] < '0' || token[0] > '9') return false;  // no sign, no space
    const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
    return ec == std::errc() && end == token.data() + token.size();
}

// "Width = 2064" in a Photoneo header line ("Photoneo PLY PointCloud ( Width = 2064; Height = 1544)"): the number
// after `key`, spaces and '=' (key matched without regard to case); 0 when absent.
int dimension_after(std::string_view line, std::string_view key) {
    std::string lower(line);
    std::transform(lower.begin(), lower.end(), lower.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    std::size_t at = lower.find(key);
    if (at == std::string::npos) return 0;
    at += key.size();
    while (at < lower.size() && (lower[at] == ' ' || lower[at] == '\t')) ++at;
    if (at >= lower.size() || lower[at] != '=') return 0;
    ++at;
    while (at < lower.size() && (lower[at] == ' ' || lower[at] == '\t')) ++at;
    std::size_t end = at;
    while (end < lower.size() && lower[end] >= '0' && lower[end] <= '9') ++end;
    int value = 0;
    if (!parse_unsigned(std::string_view(lower).substr(at, end - at), value)) return 0;
    return value;
}

struct FileCloser {
    void operator()(std::FILE* f) const noexcept { std::fclose(f); }
};

// The first bytes of the file (up to kMaxHeaderBytes, no more than it holds) and its size.
std::string read_head(const fs::path& path, std::uint64_t& file_size) {
    detail::InputFile file(path);
    file_size = file.size();
    const std::vector<unsigned char> head = detail::read_head(file, kMaxHeaderBytes);
    return {head.begin(), head.end()};
}

class HeaderParser {
public:
    HeaderParser(const fs::path& path, std::string_view head) : path_(path), head_(head) {}

    PlyHeader parse(std::uint64_t file_size) {
        std::string_view line;
        if (!next_line(line) || line != "ply") {
            fail(ErrorCode::format, path_,
                 head_.empty() ? std::string("empty file, not a PLY file")
                               : std::string("not a PLY file: the first line is not 'ply'"));
        }
        bool format_seen = false, ended = false;
        while (!ended && next_line(line)) {
            if (!line.empty() && (line[0] == ' ' || line[0] == '\t')) error("starts with whitespace");
            const std::vector<std::string_view> t = split(line);
            if (t.empty()) continue;  // PCL skips blank header lines
            if (t[0] == "comment") {
                vendor_grid(line);
            } else if (t[0] == "obj_info") {
                obj_info(t, line);
            } else if (t[0] == "format") {
                if (format_seen) error("a second format line");
                format(t);
                format_seen = true;
            } else if (t[0] == "element") {
                element(t);
            } else if (t[0] == "property") {
                property(t);
            } else if (t[0] == "end_header") {
                if (t.size() != 1) error("end_header followed by more text");
                ended = true;
            } else {
                error("unknown keyword '" + std::string(t[0]) + "'");
            }
        }
        if (!ended) {
            fail(ErrorCode::format, path_,
                 head_.size() >= kMaxHeaderBytes
                     ? "no end_header line in the first " + std::to_string(kMaxHeaderBytes) + " bytes"
                     : std::string("the header has no end_header line (truncated file?)"));
        }
        if (!format_seen) fail(ErrorCode::format, path_, "the header has no format line");
        if ((h_.grid_cols > 0) != (h_.grid_rows > 0)) {
            fail(ErrorCode::format, path_, "obj_info gives only one of num_cols and num_rows");
        }
        h_.data_offset = pos_;
        h_.data_bytes = file_size > pos_ ? file_size - pos_ : 0;
        return h_;
    }

private:
    // The next '\n'-terminated line without its '\r'; false when no complete line is left.
    bool next_line(std::string_view& line) {
        const std::size_t nl = head_.find('\n', pos_);
        if (nl == std::string_view::npos) return false;
        line = head_.substr(pos_, nl - pos_);
        if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
        pos_ = nl + 1;
        ++line_number_;
        return true;
    }

    [[noreturn]] void error(const std::string& what) const {
        fail(ErrorCode::format, path_, "PLY header line " + std::to_string(line_number_) + ": " + what);
    }

    void format(const std::vector<std::string_view>& t) {
        if (t.size() != 3) error("expected 'format ascii|binary_little_endian|binary_big_endian 1.0'");
        if (t[1] == "ascii") {
            h_.format = PlyFormat::ascii;
        } else if (t[1] == "binary_little_endian") {
            h_.format = PlyFormat::binary_little_endian;
        } else if (t[1] == "binary_big_endian") {
            h_.format = PlyFormat::binary_big_endian;
        } else {
            error("unknown format '" + std::string(t[1]) + "'");
        }
        if (t[2] != "1.0") error("PLY version '" + std::string(t[2]) + "' (only 1.0 exists)");
    }

    void element(const std::vector<std::string_view>& t) {
        if (t.size() != 3) error("expected 'element NAME COUNT'");
        if (h_.find(t[1]) != nullptr) error("a second element '" + std::string(t[1]) + "'");
        PlyElement e;
        e.name = std::string(t[1]);
        if (!parse_unsigned(t[2], e.count) || e.count > kMaxCount) {
            error("element '" + e.name + "': count '" + std::string(t[2]) + "' is not a count");
        }
        h_.elements.push_back(std::move(e));
    }

    void property(const std::vector<std::string_view>& t) {
        if (h_.elements.empty()) error("a property before any element");
        PlyElement& e = h_.elements.back();
        PlyProperty p;
        if (t.size() == 5 && t[1] == "list") {
            if (!is_list_count_type(t[2])) error("unsupported list count type '" + std::string(t[2]) + "'");
            p.count_size = type_size(t[2]);
            p.type = std::string(t[3]);
            p.name = std::string(t[4]);
        } else if (t.size() == 3 && t[1] != "list") {
            p.type = std::string(t[1]);
            p.name = std::string(t[2]);
        } else {
            error("expected 'property TYPE NAME' or 'property list COUNT_TYPE TYPE NAME'");
        }
        p.size = type_size(p.type);
        if (p.size == 0) error("unknown property type '" + p.type + "'");
        if (e.find(p.name) != nullptr) error("a second property '" + p.name + "' in element '" + e.name + "'");
        e.properties.push_back(std::move(p));
    }

    void obj_info(const std::vector<std::string_view>& t, std::string_view line) {
        if (t.size() >= 2 && (t[1] == "num_cols" || t[1] == "num_rows")) {
            int value = 0;
            if (t.size() != 3 || !parse_unsigned(t[2], value) || value < 1) {
                error("obj_info " + std::string(t[1]) + " needs one positive integer");
            }
            (t[1] == "num_cols" ? h_.grid_cols : h_.grid_rows) = value;
            return;
        }
        vendor_grid(line);
    }

    void vendor_grid(std::string_view line) {
        const int w = dimension_after(line, "width");
        const int h = dimension_after(line, "height");
        if (w > 0 && h > 0) {
            h_.vendor_cols = w;
            h_.vendor_rows = h;
        }
    }

    const fs::path& path_;
    std::string_view head_;
    std::size_t pos_ = 0;
    int line_number_ = 0;
    PlyHeader h_;
};

// PCL stores uchar red green blue (or diffuse_*) in one float 'rgb' field as it meets red, and only in that order.
void check_colours(const PlyElement& vertex, const fs::path& path) {
    const auto& props = vertex.properties;
    std::vector<std::size_t> colour;
    for (std::size_t i = 0; i < props.size(); ++i) {
        const std::string& n = props[i].name;
        if (is_uchar(props[i].type) && (n == "red" || n == "green" || n == "blue" || n == "diffuse_red" ||
                                        n == "diffuse_green" || n == "diffuse_blue" || n == "alpha")) {
            colour.push_back(i);
        }
    }
    if (colour.empty()) return;
    const std::size_t first = colour[0];
    const std::string prefix = props[first].name == "diffuse_red" ? "diffuse_" : "";
    const std::array<std::string, 4> expected = {prefix + "red", prefix + "green", prefix + "blue", "alpha"};
    bool ok = colour.size() >= 3 && colour.size() <= 4;
    for (std::size_t k = 0; ok && k < colour.size(); ++k) {
        ok = colour[k] == first + k && props[colour[k]].name == expected[k];
    }
    if (!ok) {
        fail(ErrorCode::format, path,
             "element vertex: uchar colour properties must be red green blue [alpha] (or diffuse_red ...), "
             "consecutive and in that order, as PCL's PLY reader reads them");
    }
}

// At least how many data bytes the declared elements take: binary, every scalar plus every list's item count;
// ascii, one character and one separator per value (the file's last value may lack its separator).
void check_data_size(const PlyHeader& h, const fs::path& path) {
    const bool ascii = h.format == PlyFormat::ascii;
    const std::uint64_t room = h.data_bytes + (ascii ? 1 : 0);
    std::uint64_t need = 0;
    for (const PlyElement& e : h.elements) {
        if (e.count == 0) continue;
        if (e.properties.empty()) {
            fail(ErrorCode::format, path,
                 "element '" + e.name + "' has " + std::to_string(e.count) + " instances but no properties");
        }
        std::uint64_t per = 0;
        for (const PlyProperty& p : e.properties) {
            per += ascii ? 2 : static_cast<std::uint64_t>(p.count_size > 0 ? p.count_size : p.size);
        }
        // Divided first: a large count times a wide element could overflow 64 bits.
        if (e.count > (room - need) / per) {
            fail(ErrorCode::format, path,
                 "element '" + e.name + "' declares " + std::to_string(e.count) + " instances of at least " +
                     std::to_string(per) + " bytes each, more than the " + std::to_string(h.data_bytes) + " bytes of " +
                     (ascii ? "ascii" : "binary") + " data after the header hold (truncated file?)");
        }
        need += e.count * per;
    }
}

std::string grid_text(int cols, int rows) {
    return std::to_string(cols) + " x " + std::to_string(rows);
}

[[noreturn]] void not_organized(const fs::path& path, std::uint64_t vertices, const std::string& why) {
    fail(ErrorCode::format, path,
         "PLY cloud is not organized (" + std::to_string(vertices) + " vertices, " + why +
             "); pyrseg needs an organized cloud as structured-light scanners export it");
}

// Everything PCL's reader needs to be safe from, and what pyrseg itself needs: x y z, an organized grid.
void check_header(const PlyHeader& h, const fs::path& path) {
    const PlyElement* vertex = h.find("vertex");
    if (vertex == nullptr) fail(ErrorCode::format, path, "no element vertex in the PLY header");
    for (const PlyProperty& p : vertex->properties) {
        if (p.count_size > 0) {
            fail(ErrorCode::format, path,
                 "element vertex: list property '" + p.name + "' is not supported (only scalar vertex properties)");
        }
    }
    for (const char* axis : {"x", "y", "z"}) {
        const PlyProperty* p = vertex->find(axis);
        if (p == nullptr) fail(ErrorCode::format, path, std::string("element vertex has no property ") + axis);
        if (!is_floating(p->type)) {
            fail(ErrorCode::format, path,
                 std::string("element vertex: property ") + axis + " is " + p->type + ", not float or double");
        }
    }
    check_colours(*vertex, path);
    check_data_size(h, path);

    const PlyElement* range_grid = h.find("range_grid");
    if (h.grid_cols > 0) {
        const std::uint64_t cells = std::uint64_t(h.grid_cols) * std::uint64_t(h.grid_rows);
        if (cells > std::uint64_t(INT_MAX)) {
            fail(ErrorCode::format, path, "obj_info grid " + grid_text(h.grid_cols, h.grid_rows) + " is too large");
        }
        if (range_grid != nullptr && range_grid->count != cells) {
            fail(ErrorCode::format, path,
                 "element range_grid has " + std::to_string(range_grid->count) + " cells, but obj_info num_cols/" +
                     "num_rows give " + grid_text(h.grid_cols, h.grid_rows));
        }
        if (range_grid != nullptr ? vertex->count > cells : vertex->count != cells) {
            fail(ErrorCode::format, path,
                 "obj_info num_cols/num_rows give a " + grid_text(h.grid_cols, h.grid_rows) + " grid (" +
                     std::to_string(cells) + " points), but element vertex has " + std::to_string(vertex->count));
        }
        return;
    }
    if (range_grid != nullptr) not_organized(path, vertex->count, "a range_grid but no obj_info num_cols/num_rows");
    if (h.vendor_cols > 0) {
        const std::uint64_t cells = std::uint64_t(h.vendor_cols) * std::uint64_t(h.vendor_rows);
        if (vertex->count != cells) {
            fail(ErrorCode::format, path,
                 "the header gives Width = " + std::to_string(h.vendor_cols) +
                     ", Height = " + std::to_string(h.vendor_rows) + " (" + std::to_string(cells) +
                     " points), but element vertex has " + std::to_string(vertex->count) + " (an unorganized export?)");
        }
        return;
    }
    const PlyElement* camera = h.find("camera");
    const bool viewport =
        camera != nullptr && camera->find("viewportx") != nullptr && camera->find("viewporty") != nullptr;
    if (!viewport) not_organized(path, vertex->count, "no obj_info num_cols/num_rows grid");
    if (vertex->count > std::uint64_t(INT_MAX)) fail(ErrorCode::format, path, "too many vertices");
}

// PCL copies range_grid cells from vertex index * point_step and checks that against its data in 32-bit unsigned
// arithmetic, so an index past the vertices either wraps to a crash (-1, or 1431655765 with 12-byte points) or
// reads a cell it zero-filled (an index equal to the vertex count). Every index is therefore checked here, in the
// data, before PCL reads the file: the data is walked as PCL's parser walks it (elements in header order; binary:
// each property's bytes, each list's count then its items; ascii: one line per instance), which also checks that
// every list fits in the file. Reading PLY without PCL would avoid the walk, but PCL also decodes colours, normals,
// cameras and every PLY dialect pyrseg accepts; the walk costs a seek per element without lists or a grid, and a
// pass over the grid (a few bytes per cell) otherwise.
class DataWalker {
public:
    DataWalker(const PlyHeader& h, const fs::path& path) : h_(h), file_(path) {
        const PlyElement* vertex = h.find("vertex");
        vertices_ = vertex != nullptr ? vertex->count : 0;
    }

    void walk() {
        for (const PlyElement& e : h_.elements) {
            for (const PlyProperty& p : e.properties) {
                // PCL converts float indices to int: NaN or 1e30 would be undefined behaviour.
                if (is_grid_index(e, p) && is_floating(p.type)) {
                    fail(ErrorCode::format, file_.path(),
                         "element range_grid: list '" + p.name + "' holds " + p.type + ", not integer vertex indices");
                }
            }
        }
        if (h_.format == PlyFormat::ascii) {
            walk_ascii();
        } else {
            walk_binary();
        }
    }

private:
    [[noreturn]] void error(const PlyElement& e, std::uint64_t instance, const std::string& what) const {
        fail(ErrorCode::format, file_.path(),
             "PLY data: element '" + e.name + "' instance " + std::to_string(instance) + ": " + what);
    }

    static bool is_grid_index(const PlyElement& e, const PlyProperty& p) {
        return e.name == "range_grid" && p.count_size > 0 && (p.name == "vertex_indices" || p.name == "vertex_index");
    }

    void check_index(const PlyElement& e, std::uint64_t instance, long long index) const {
        if (index < 0 || static_cast<std::uint64_t>(index) >= vertices_) {
            error(e, instance,
                  "range_grid vertex index " + std::to_string(index) + " is not one of the " +
                      std::to_string(vertices_) + " vertices");
        }
    }

    // ---- binary

    // `n` bytes at the current position (a view into the buffer, valid until the next call).
    const unsigned char* take(std::size_t n, const PlyElement& e, std::uint64_t instance) {
        if (n > end_ - begin_) {
            std::memmove(buffer_.data(), buffer_.data() + begin_, end_ - begin_);
            end_ -= begin_;
            begin_ = 0;
            if (buffer_.size() < n) buffer_.resize(n);
            end_ += file_.read_some(buffer_.data() + end_, buffer_.size() - end_);
            if (n > end_) error(e, instance, "the file ends inside it (truncated file?)");
        }
        const unsigned char* p = buffer_.data() + begin_;
        begin_ += n;
        offset_ += n;
        return p;
    }

    std::uint64_t unsigned_value(const unsigned char* p, int size) const {
        std::uint64_t v = 0;
        for (int i = 0; i < size; ++i) {
            const int byte = h_.format == PlyFormat::binary_big_endian ? i : size - 1 - i;
            v = v << 8 | p[byte];
        }
        return v;
    }

    long long integer_value(const unsigned char* p, const PlyProperty& prop) const {
        const std::uint64_t v = unsigned_value(p, prop.size);
        const bool is_signed = prop.type == "char" || prop.type == "int8" || prop.type == "short" ||
                               prop.type == "int16" || prop.type == "int" || prop.type == "int32";
        if (!is_signed) return static_cast<long long>(v);
        const int bits = 8 * prop.size;
        const std::uint64_t sign = std::uint64_t{1} << (bits - 1);
        return static_cast<long long>(v ^ sign) - static_cast<long long>(sign);
    }

    void walk_binary() {
        const std::uint64_t end = h_.data_offset + h_.data_bytes;
        offset_ = h_.data_offset;
        file_.seek(offset_);
        for (const PlyElement& e : h_.elements) {
            bool lists = false;
            std::uint64_t per = 0;
            for (const PlyProperty& p : e.properties) {
                lists = lists || p.count_size > 0;
                per += static_cast<std::uint64_t>(p.size);
            }
            if (!lists) {
                // check_data_size has bounded count * per by the file's size.
                offset_ += e.count * per;
                if (offset_ > end) error(e, 0, "the file ends inside this element (truncated file?)");
                file_.seek(offset_);
                begin_ = end_ = 0;
                continue;
            }
            for (std::uint64_t i = 0; i < e.count; ++i) {
                for (const PlyProperty& p : e.properties) {
                    if (p.count_size == 0) {
                        (void)take(static_cast<std::size_t>(p.size), e, i);
                        continue;
                    }
                    const std::uint64_t items =
                        unsigned_value(take(static_cast<std::size_t>(p.count_size), e, i), p.count_size);
                    const std::uint64_t left = end > offset_ ? end - offset_ : 0;
                    if (items > left / static_cast<std::uint64_t>(p.size)) {
                        error(e, i,
                              "list '" + p.name + "' of " + std::to_string(items) + " items runs past the end of " +
                                  "the file (truncated file?)");
                    }
                    for (std::uint64_t k = 0; k < items; ++k) {
                        const unsigned char* item = take(static_cast<std::size_t>(p.size), e, i);
                        if (is_grid_index(e, p)) check_index(e, i, integer_value(item, p));
                    }
                }
            }
        }
    }

    // ---- ascii

    void walk_ascii() {
        detail::LineReader lines(file_, h_.data_offset, kMaxAsciiLine);
        std::string_view line;
        for (const PlyElement& e : h_.elements) {
            for (std::uint64_t i = 0; i < e.count; ++i) {
                if (!lines.next(line)) {
                    error(e, i,
                          lines.too_long() ? "a line longer than " + std::to_string(kMaxAsciiLine) + " bytes"
                                           : std::string("the file ends before it (truncated file?)"));
                }
                check_ascii_line(e, i, line);
            }
        }
    }

    // Every value of the line is one of its property's type (is_ascii_value); every list fits the line; every
    // range_grid index is one of the vertices.
    void check_ascii_line(const PlyElement& e, std::uint64_t instance, std::string_view line) const {
        std::vector<std::string_view> tokens = split(line);
        for (std::string_view& t : tokens) {
            while (!t.empty() && (t.back() == '\r' || t.front() == '\r')) {
                t = t.back() == '\r' ? t.substr(0, t.size() - 1) : t.substr(1);
            }
        }
        std::erase_if(tokens, [](std::string_view t) { return t.empty(); });
        std::size_t at = 0;
        auto integer = [&](const std::string& what) {
            if (at >= tokens.size()) error(e, instance, "the line ends before " + what);
            const std::string_view t = tokens[at++];
            long long v = 0;
            const auto [end, ec] = std::from_chars(t.data(), t.data() + t.size(), v);
            if (ec != std::errc() || end != t.data() + t.size()) {
                error(e, instance, what + " '" + std::string(t.substr(0, 32)) + "' is not an integer");
            }
            return v;
        };
        auto value = [&](const PlyProperty& p) {
            if (at >= tokens.size()) error(e, instance, "the line ends before property '" + p.name + "'");
            const std::string_view t = tokens[at++];
            if (!is_ascii_value(t, p.type)) {
                error(e, instance,
                      "property '" + p.name + "': '" + detail::printable(t.substr(0, 32)) + "' is not a " + p.type +
                          " value");
            }
        };
        for (const PlyProperty& p : e.properties) {
            if (p.count_size == 0) {
                value(p);
                continue;
            }
            const long long items = integer("the item count of list '" + p.name + "'");
            if (items < 0 || static_cast<std::uint64_t>(items) > tokens.size() - std::min(at, tokens.size())) {
                error(e, instance,
                      "list '" + p.name + "' claims " + std::to_string(items) + " items, the line has fewer");
            }
            for (long long k = 0; k < items; ++k) {
                if (is_grid_index(e, p)) {
                    check_index(e, instance, integer("a range_grid vertex index"));
                } else {
                    value(p);
                }
            }
        }
    }

    // PLY ascii lines are a few dozen numbers; this only stops a line of gigabytes from being buffered.
    static constexpr std::size_t kMaxAsciiLine = std::size_t{16} << 20;

    const PlyHeader& h_;
    detail::InputFile file_;
    std::uint64_t vertices_ = 0;
    std::vector<unsigned char> buffer_ = std::vector<unsigned char>(std::size_t{1} << 16);
    std::size_t begin_ = 0, end_ = 0;
    std::uint64_t offset_ = 0;
};

// PCL allocates its point size (point_step) for every cell of an obj_info grid, twice (while reading, then for the
// range_grid copy); a cell of a range_grid takes as little as one byte of the file. Bounded here by the file's size.
void check_grid_memory(const PlyHeader& h, const fs::path& path) {
    const PlyElement* vertex = h.find("vertex");
    if (h.grid_cols == 0 || vertex == nullptr) return;
    std::uint64_t point_step = 0;  // at least PCL's: uchar colours and intensity become 4-byte floats
    for (const PlyProperty& p : vertex->properties) point_step += std::max(p.size, 4);
    const std::uint64_t cells = std::uint64_t(h.grid_cols) * std::uint64_t(h.grid_rows);  // <= INT_MAX
    const std::uint64_t needed = 2 * cells * point_step;  // point_step <= 8 * (1 MiB header): no overflow
    const std::uint64_t allowed = kGridBytesPerFileByte * h.data_bytes + kGridBytesSlack;
    if (needed > allowed) {
        fail(ErrorCode::format, path,
             "an obj_info grid of " + grid_text(h.grid_cols, h.grid_rows) + " cells of " + std::to_string(point_step) +
                 "-byte points takes " + std::to_string(needed) + " bytes to read, more than the " +
                 std::to_string(h.data_bytes) + " bytes of data in the file can describe");
    }
}

// PCL prints its errors and warnings on the console: quiet while pyrseg calls it, so only pyrseg's exception speaks.
class QuietPcl {
public:
    QuietPcl() : saved_(pcl::console::getVerbosityLevel()) { pcl::console::setVerbosityLevel(pcl::console::L_ALWAYS); }
    ~QuietPcl() { pcl::console::setVerbosityLevel(saved_); }
    QuietPcl(const QuietPcl&) = delete;
    QuietPcl& operator=(const QuietPcl&) = delete;

private:
    pcl::console::VERBOSITY_LEVEL saved_;
};

struct FloatField {
    std::uint32_t offset = 0;
    bool is_double = false;
};

std::optional<FloatField> float_field(const pcl::PCLPointCloud2& cloud, std::string_view name) {
    for (const pcl::PCLPointField& f : cloud.fields) {
        if (f.name != name) continue;
        const bool is_double = f.datatype == pcl::PCLPointField::FLOAT64;
        if (f.count != 1 || (f.datatype != pcl::PCLPointField::FLOAT32 && !is_double)) return std::nullopt;
        if (std::uint64_t(f.offset) + (is_double ? 8 : 4) > cloud.point_step) return std::nullopt;
        return FloatField{f.offset, is_double};
    }
    return std::nullopt;
}

void gather(const pcl::PCLPointCloud2& cloud, const FloatField& field, std::size_t n, std::vector<float>& out,
            std::size_t component) {
    const std::uint8_t* base = cloud.data.data() + field.offset;
    for (std::size_t i = 0; i < n; ++i) {
        const std::uint8_t* p = base + i * cloud.point_step;
        float value = 0;
        if (field.is_double) {
            double d = 0;
            std::memcpy(&d, p, sizeof d);
            value = static_cast<float>(d);
        } else {
            std::memcpy(&value, p, sizeof value);
        }
        out[3 * i + component] = value;
    }
}

PointCloud to_cloud(const pcl::PCLPointCloud2& blob, const PlyHeader& h, const fs::path& path) {
    // PCL's grid: obj_info (kept through range_grid) or the camera element's viewport; else Photoneo's header line.
    std::uint64_t width = blob.width, height = blob.height;
    if (height <= 1 && h.grid_cols == 0 && h.vendor_cols > 0) {
        width = std::uint64_t(h.vendor_cols);
        height = std::uint64_t(h.vendor_rows);
    }
    const std::uint64_t points = width * height;  // both < 2^32
    if (height <= 1) not_organized(path, points, "a grid of " + std::to_string(width) + " x " + std::to_string(height));
    if (points > std::uint64_t(INT_MAX) || blob.point_step == 0 ||
        blob.data.size() != points * std::uint64_t(blob.point_step)) {
        fail(ErrorCode::format, path,
             "the " + std::to_string(width) + " x " + std::to_string(height) + " grid (from obj_info or the camera " +
                 "element's viewportx/viewporty) does not match the " +
                 std::to_string(blob.point_step > 0 ? blob.data.size() / blob.point_step : 0) + " points read");
    }
    std::array<std::optional<FloatField>, 3> xyz = {float_field(blob, "x"), float_field(blob, "y"),
                                                    float_field(blob, "z")};
    std::array<std::optional<FloatField>, 3> normal = {float_field(blob, "normal_x"), float_field(blob, "normal_y"),
                                                       float_field(blob, "normal_z")};
    if (!xyz[0] || !xyz[1] || !xyz[2]) fail(ErrorCode::format, path, "PCL's PLY reader found no float x, y and z");
    const bool normals = normal[0] && normal[1] && normal[2];
    PointCloud cloud;
    cloud.width = static_cast<int>(width);
    cloud.height = static_cast<int>(height);
    const auto n = static_cast<std::size_t>(points);
    cloud.points.resize(3 * n);
    for (std::size_t c = 0; c < 3; ++c) gather(blob, *xyz[c], n, cloud.points, c);
    if (normals) {
        cloud.normals.resize(3 * n);
        for (std::size_t c = 0; c < 3; ++c) gather(blob, *normal[c], n, cloud.normals, c);
    }
    return cloud;
}

void add_field(pcl::PCLPointCloud2& blob, const char* name) {
    pcl::PCLPointField f;
    f.name = name;
    f.offset = blob.point_step;
    f.datatype = pcl::PCLPointField::FLOAT32;
    f.count = 1;
    blob.fields.push_back(f);
    blob.point_step += 4;
}

// PCL's writer reports no write error: a file a full disk cut short comes back with status 0. So what it wrote is
// read back through the reader's own header and data checks (the walk finds a file that ends inside an element),
// and an ascii file must end with its last line's newline.
void check_written(const fs::path& written, const fs::path& named) {
    try {
        std::uint64_t file_size = 0;
        const std::string head = read_head(written, file_size);
        const PlyHeader header = HeaderParser(written, head).parse(file_size);
        check_data_size(header, written);
        DataWalker(header, written).walk();
        if (header.format == PlyFormat::ascii && header.data_bytes > 0) {
            detail::InputFile file(written);
            char last = 0;
            file.seek(file.size() - 1);
            file.read_exact(&last, 1, "its last byte");
            if (last != '\n') fail(ErrorCode::format, written, "the last line has no newline");
        }
    } catch (const Error& e) {
        // The temporary file's name means nothing to the caller: the reason after it is what counts.
        std::string reason = e.what();
        const std::string prefix = written.string() + ": ";
        if (const std::size_t at = reason.find(prefix); at != std::string::npos) reason.erase(0, at + prefix.size());
        fail(ErrorCode::io, named, "write error: PCL's PLY writer left an incomplete file (a full disk?): " + reason);
    }
}

PointCloud read_ply_file(const std::filesystem::path& path) {
    std::uint64_t file_size = 0;
    const std::string head = read_head(path, file_size);
    const PlyHeader header = HeaderParser(path, head).parse(file_size);
    check_header(header, path);
    check_grid_memory(header, path);
    DataWalker(header, path).walk();

    pcl::PCLPointCloud2 blob;
    int status = -1;
    {
        const QuietPcl quiet;
        pcl::PLYReader reader;
        Eigen::Vector4f origin;
        Eigen::Quaternionf orientation;
        int version = 0;
        try {
            status = reader.read(path.string(), blob, origin, orientation, version, 0);
        } catch (const std::bad_alloc&) {
            fail(ErrorCode::out_of_memory, path, "out of memory reading the PLY data");
        } catch (const std::exception& e) {
            fail(ErrorCode::format, path, std::string("PCL's PLY reader failed: ") + e.what());
        }
    }
    if (status != 0) {
        fail(ErrorCode::format, path,
             std::string("PCL's PLY reader could not read the ") +
                 (header.format == PlyFormat::ascii ? "ascii" : "binary") +
                 " data after the header (truncated or corrupt file?)");
    }
    return to_cloud(blob, header, path);
}

}  // namespace

PointCloud read_ply(const std::filesystem::path& path) {
    return detail::guard_reader(path, [&] { return read_ply_file(path); });
}

void write_ply(const std::filesystem::path& path, const PointCloud& cloud, const std::uint32_t* labels, bool binary) {
    detail::check_cloud_to_write(path, cloud);
    const auto n = static_cast<std::size_t>(cloud.width) * static_cast<std::size_t>(cloud.height);
    const bool normals = !cloud.normals.empty();
    pcl::PCLPointCloud2 blob;
    blob.width = static_cast<std::uint32_t>(cloud.width);
    blob.height = static_cast<std::uint32_t>(cloud.height);
    blob.is_dense = false;
    for (const char* name : {"x", "y", "z"}) add_field(blob, name);
    if (normals) {
        for (const char* name : {"normal_x", "normal_y", "normal_z"}) add_field(blob, name);
    }
    const std::uint32_t rgb_offset = blob.point_step;
    if (labels != nullptr) add_field(blob, "rgb");  // PCL writes a float 'rgb' (0x00RRGGBB) as uchar red green blue
    blob.row_step = blob.point_step * blob.width;
    blob.data.resize(n * blob.point_step);
    for (std::size_t i = 0; i < n; ++i) {
        std::uint8_t* p = blob.data.data() + i * blob.point_step;
        const float* xyz = &cloud.points[3 * i];
        // PCL's range grid looks at x alone: a point with any non-finite coordinate becomes a gap (NaN NaN NaN).
        if (std::isfinite(xyz[0]) && std::isfinite(xyz[1]) && std::isfinite(xyz[2])) {
            std::memcpy(p, xyz, 3 * sizeof(float));
        } else {
            const std::array<float, 3> gap = {std::numeric_limits<float>::quiet_NaN(),
                                              std::numeric_limits<float>::quiet_NaN(),
                                              std::numeric_limits<float>::quiet_NaN()};
            std::memcpy(p, gap.data(), sizeof gap);
        }
        if (normals) std::memcpy(p + 12, &cloud.normals[3 * i], 3 * sizeof(float));
        if (labels != nullptr) {
            const std::array<std::uint8_t, 3> c =
                labels[i] == 0 ? std::array<std::uint8_t, 3>{kLabelZeroGray, kLabelZeroGray, kLabelZeroGray}
                               : label_color(labels[i]);
            const std::uint32_t packed = std::uint32_t{c[0]} << 16 | std::uint32_t{c[1]} << 8 | std::uint32_t{c[2]};
            std::memcpy(p + rgb_offset, &packed, sizeof packed);
        }
    }
    detail::write_atomically(path, [&](const std::filesystem::path& temporary) {
        // Open it here first: PCL's failure to would be silent, and this way the message carries the reason.
        errno = 0;
        {
            const std::unique_ptr<std::FILE, FileCloser> probe(std::fopen(temporary.c_str(), "wb"));
            if (!probe) {
                fail(ErrorCode::io, path,
                     "cannot open for writing: " + std::error_code(errno, std::generic_category()).message());
            }
        }
        int status = -1;
        {
            const QuietPcl quiet;
            pcl::PLYWriter writer;
            const Eigen::Vector4f origin = Eigen::Vector4f::Zero();
            const Eigen::Quaternionf orientation = Eigen::Quaternionf::Identity();
            // use_camera = false: obj_info num_cols/num_rows and a range_grid element keep the grid, and only
            // points with finite x y z become vertices. (PCL 1.13 writes those ascii values with 6 significant
            // digits: the precision argument does not reach its range-grid path. Binary is exact.)
            try {
                status = binary ? writer.writeBinary(temporary.string(), blob, origin, orientation, false)
                                : writer.writeASCII(temporary.string(), blob, origin, orientation, 9, false);
            } catch (const std::exception& e) {
                fail(ErrorCode::io, path, std::string("PCL's PLY writer failed: ") + e.what());
            }
        }
        if (status != 0) fail(ErrorCode::io, path, "PCL's PLY writer could not write the file");
        check_written(temporary, path);
    });
}

#else  // !PYRSEG_HAVE_PLY

namespace {
constexpr const char* kNoPly =
    "pyrseg was built without PLY support (it reads and writes PLY with PCL's io module; install libpcl-dev and "
    "rebuild)";
}  // namespace

PointCloud read_ply(const std::filesystem::path& path) {
    detail::fail(ErrorCode::format, path, kNoPly);
}

void write_ply(const std::filesystem::path& path, const PointCloud& /*cloud*/, const std::uint32_t* /*labels*/,
               bool /*binary*/) {
    detail::fail(ErrorCode::format, path, kNoPly);
}

#endif  // PYRSEG_HAVE_PLY

}  // namespace pyrseg::io
