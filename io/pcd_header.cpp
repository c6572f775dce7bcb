#include "pcd_header.hpp"

#include <array>
#include <cctype>
#include <charconv>
#include <climits>
#include <cmath>
#include <optional>
#include <string_view>
#include <unordered_set>

#include "file_util.hpp"

namespace pyrseg::io::detail {

namespace {

constexpr std::uint64_t kMaxCount = std::uint64_t{1} << 24;      // values of one field in one point
constexpr std::uint64_t kMaxPointSize = std::uint64_t{1} << 32;  // bytes per point, all fields

std::vector<std::string_view> split(std::string_view line) {
    std::vector<std::string_view> tokens;
    std::size_t i = 0;
    while (i < line.size()) {
        while (i < line.size() && is_space(line[i])) ++i;
        const std::size_t start = i;
        while (i < line.size() && !is_space(line[i])) ++i;
        if (i > start) tokens.push_back(line.substr(start, i - start));
    }
    return tokens;
}

// Header text quoted in messages: short, and printable (detail::printable) so a binary file cannot garble them.
std::string quote(std::string_view text) {
    constexpr std::size_t kMaxLen = 40;
    std::string out = "'";
    out += detail::printable(text.substr(0, kMaxLen));
    out += text.size() > kMaxLen ? "...'" : "'";
    return out;
}

std::optional<std::uint64_t> parse_uint(std::string_view s) {
    std::uint64_t v = 0;
    const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
    if (ec != std::errc() || end != s.data() + s.size()) return std::nullopt;
    return v;
}

// One header line per keyword, as tokens after the keyword; the line number is kept for messages.
struct Line {
    std::vector<std::string_view> values;
    int number = 0;
    bool present = false;
};

class HeaderParser {
public:
    HeaderParser(const std::vector<unsigned char>& bytes, const std::filesystem::path& path, bool whole_file)
        : text_(reinterpret_cast<const char*>(bytes.data()), bytes.size()), path_(path), whole_file_(whole_file) {}

    PcdHeader parse() {
        read_lines();
        PcdHeader h;
        check_version();
        parse_fields(h);
        parse_size(h);
        find_xyz_and_normals(h);
        parse_dimensions(h);
        check_viewpoint();
        parse_data(h);
        return h;
    }

private:
    enum Key { version, fields, size, type, count, width, height, viewpoint, points, data, key_count };
    static constexpr std::array<std::string_view, key_count> kEyNames = {
        "VERSION", "FIELDS", "SIZE", "TYPE", "COUNT", "WIDTH", "HEIGHT", "VIEWPOINT", "POINTS", "DATA"};

    [[noreturn]] void fail(const std::string& what) const { detail::fail(ErrorCode::format, path_, what); }

    void read_lines() {
        std::size_t pos = 0;
        int number = 0;
        while (pos < text_.size()) {
            std::size_t end = text_.find('\n', pos);
            const std::size_t next = end == std::string_view::npos ? text_.size() : end + 1;
            if (end == std::string_view::npos) end = text_.size();
            std::string_view raw = text_.substr(pos, end - pos);
            while (!raw.empty() && is_space(raw.back())) raw.remove_suffix(1);
            pos = next;
            ++number;
            for (const char c : raw) {
                const auto u = static_cast<unsigned char>(c);
                if (u == 0x7f || (u < 0x20 && !is_space(c))) {
                    fail("header line " + std::to_string(number) + " " + quote(raw) +
                         " is not text (not a PCD file, or a truncated header?)");
                }
            }
            const auto tokens = split(raw);
            if (tokens.empty() || tokens[0].front() == '#') continue;
            std::size_t k = 0;
            while (k < key_count && kEyNames[k] != tokens[0]) ++k;
            if (k == key_count) {
                fail("header line " + std::to_string(number) + " " + quote(raw) +
                     " is not a PCD header line (expected VERSION, FIELDS, SIZE, TYPE, COUNT, WIDTH, HEIGHT, "
                     "VIEWPOINT, POINTS or DATA)");
            }
            Line& line = lines_[k];
            if (line.present) {
                fail("header line " + std::to_string(number) + ": second " + std::string(kEyNames[k]) +
                     " line (the first is line " + std::to_string(line.number) + ")");
            }
            line.present = true;
            line.number = number;
            line.values.assign(tokens.begin() + 1, tokens.end());
            if (k == data) {
                data_offset_ = pos;
                return;
            }
        }
        if (!whole_file_) {
            fail("no DATA line in the first " + std::to_string(text_.size()) +
                 " bytes: the header is longer than pyrseg reads (not a PCD file?)");
        }
        fail("no DATA line: the header is incomplete (truncated file, or not a PCD file)");
    }

    const Line& required(Key k) const {
        if (!lines_[k].present) fail("missing " + std::string(kEyNames[k]) + " line in the header");
        return lines_[k];
    }

    // The single value of a one-value line (WIDTH 640).
    std::string_view single(Key k) const {
        const Line& line = required(k);
        if (line.values.size() != 1) {
            fail(std::string(kEyNames[k]) + " needs exactly one value, line " + std::to_string(line.number) + " has " +
                 std::to_string(line.values.size()));
        }
        return line.values[0];
    }

    void check_version() const {
        const std::string_view v = single(version);
        // PCL writes 0.7 (older releases .7); 0.6 differs only by lacking VIEWPOINT, which is ignored anyway.
        if (v != "0.7" && v != ".7" && v != "0.6" && v != ".6") {
            fail("VERSION " + quote(v) + " is not supported (pyrseg reads PCD 0.7)");
        }
    }

    void parse_fields(PcdHeader& h) const {
        const Line& line = required(fields);
        if (line.values.empty()) fail("FIELDS lists no fields");
        // A set, not a scan of the names so far: a megabyte of FIELDS names is then read in linear time.
        std::unordered_set<std::string_view> seen;
        for (const auto name : line.values) {
            // PCL names every padding field "_", so only real names must be unique.
            if (name != "_" && !seen.insert(name).second) fail("FIELDS lists field " + quote(name) + " twice");
            h.fields.push_back(PcdField{std::string(name)});
        }
    }

    // SIZE, TYPE and COUNT each need one entry per field.
    const std::vector<std::string_view>& per_field(Key k, const PcdHeader& h) const {
        const Line& line = lines_[k];
        const auto n = h.fields.size();
        if (line.values.size() < n) {
            fail(std::string(kEyNames[k]) + " has no entry for field " + quote(h.fields[line.values.size()].name) +
                 " (" + std::to_string(line.values.size()) + " entries for " + std::to_string(n) + " FIELDS)");
        }
        if (line.values.size() > n) {
            fail(std::string(kEyNames[k]) + " has " + std::to_string(line.values.size()) + " entries for " +
                 std::to_string(n) + " FIELDS");
        }
        return line.values;
    }

    void parse_size(PcdHeader& h) const {
        required(size);
        required(type);
        const auto& sizes = per_field(size, h);
        const auto& types = per_field(type, h);
        const bool has_count = lines_[count].present;
        const std::vector<std::string_view> no_counts;
        const auto& counts = has_count ? per_field(count, h) : no_counts;

        std::uint64_t offset = 0;
        for (std::size_t i = 0; i < h.fields.size(); ++i) {
            PcdField& f = h.fields[i];
            const std::string field = "field " + quote(f.name) + ": ";
            const auto sz = parse_uint(sizes[i]);
            if (!sz || (*sz != 1 && *sz != 2 && *sz != 4 && *sz != 8)) {
                fail(field + "SIZE " + quote(sizes[i]) + " is not 1, 2, 4 or 8");
            }
            f.size = static_cast<int>(*sz);
            if (types[i].size() != 1) fail(field + "TYPE " + quote(types[i]) + " is not F, I or U");
            f.type = static_cast<char>(std::toupper(static_cast<unsigned char>(types[i][0])));
            if (f.type != 'F' && f.type != 'I' && f.type != 'U') {
                fail(field + "TYPE " + quote(types[i]) + " is not F, I or U");
            }
            if (f.type == 'F' && f.size != 4 && f.size != 8) {
                fail(field + "TYPE F with SIZE " + std::to_string(f.size) + " is not supported (only 4 or 8)");
            }
            if (has_count) {
                const auto c = parse_uint(counts[i]);
                if (!c || *c < 1 || *c > kMaxCount) {
                    fail(field + "COUNT " + quote(counts[i]) + " is not a number from 1 to " +
                         std::to_string(kMaxCount));
                }
                f.count = *c;
            }
            f.offset = offset;
            // No overflow: offset <= 2^32 here and one field adds at most 8 * 2^24 bytes.
            offset += f.bytes();
            h.values_per_point += f.count;
            if (offset > kMaxPointSize) {
                fail("points of more than " + std::to_string(kMaxPointSize) + " bytes are not supported");
            }
        }
        h.point_size = offset;
    }

    void find_xyz_and_normals(PcdHeader& h) const {
        constexpr std::array<const char*, 3> kXyzNames = {"x", "y", "z"};
        constexpr std::array<const char*, 3> kNormalNames = {"normal_x", "normal_y", "normal_z"};
        auto find = [&](const char* name) {
            for (std::size_t i = 0; i < h.fields.size(); ++i) {
                if (h.fields[i].name == name) return static_cast<int>(i);
            }
            return -1;
        };
        auto check_float = [&](int i) {
            const PcdField& f = h.fields[static_cast<std::size_t>(i)];
            if (f.type != 'F' || f.count != 1) {
                fail("field " + quote(f.name) + " must be TYPE F (SIZE 4 or 8) with COUNT 1, not TYPE " +
                     std::string(1, f.type) + " SIZE " + std::to_string(f.size) + " COUNT " + std::to_string(f.count));
            }
        };
        for (int c = 0; c < 3; ++c) {
            h.xyz[c] = find(kXyzNames[static_cast<std::size_t>(c)]);
            if (h.xyz[c] < 0) {
                fail(std::string("no field '") + kXyzNames[static_cast<std::size_t>(c)] +
                     "': pyrseg needs fields x, y and z");
            }
            check_float(h.xyz[c]);
        }
        int found = 0;
        for (int c = 0; c < 3; ++c) {
            h.normal[c] = find(kNormalNames[static_cast<std::size_t>(c)]);
            found += h.normal[c] >= 0 ? 1 : 0;
        }
        if (found != 0 && found != 3) {
            std::string missing;
            for (int c = 0; c < 3; ++c) {
                if (h.normal[c] < 0) missing += std::string(missing.empty() ? "" : " ") + kNormalNames[c];
            }
            fail("normals need all of normal_x normal_y normal_z; missing " + missing);
        }
        if (found == 0) return;
        for (const int i : h.normal) check_float(i);
    }

    void parse_dimensions(PcdHeader& h) const {
        auto dim = [&](Key k) {
            const std::string_view v = single(k);
            const auto n = parse_uint(v);
            if (!n) fail(std::string(kEyNames[k]) + " " + quote(v) + " is not a non-negative integer");
            return *n;
        };
        const std::uint64_t w = dim(width);
        const std::uint64_t hgt = dim(height);
        const std::uint64_t n = dim(points);
        if (w == 0 || hgt == 0) {
            fail("empty cloud (WIDTH " + std::to_string(w) + ", HEIGHT " + std::to_string(hgt) + ")");
        }
        if (hgt == 1) {
            fail("unorganized cloud (HEIGHT 1): pyrseg needs an organized cloud (HEIGHT > 1, one point per pixel)");
        }
        constexpr std::uint64_t kMaxPoints = INT_MAX;
        if (w > kMaxPoints || hgt > kMaxPoints || w * hgt > kMaxPoints) {
            fail("WIDTH " + std::to_string(w) + " x HEIGHT " + std::to_string(hgt) +
                 " is more points than pyrseg supports (2^31 - 1)");
        }
        if (n != w * hgt) {
            fail("POINTS " + std::to_string(n) + " does not match WIDTH " + std::to_string(w) + " x HEIGHT " +
                 std::to_string(hgt) + " = " + std::to_string(w * hgt) +
                 " (an organized cloud has one point per pixel)");
        }
        h.width = static_cast<int>(w);
        h.height = static_cast<int>(hgt);
        h.points = n;
    }

    void check_viewpoint() const {
        const Line& line = lines_[viewpoint];
        if (!line.present) return;
        // Ignored, but a malformed one means the header is not what it claims to be.
        bool ok = line.values.size() == 7;
        for (const auto v : line.values) {
            double d = 0;
            const auto [end, ec] = std::from_chars(v.data(), v.data() + v.size(), d);
            ok = ok && ec == std::errc() && end == v.data() + v.size() && std::isfinite(d);
        }
        if (!ok) fail("VIEWPOINT needs 7 finite numbers (tx ty tz qw qx qy qz), line " + std::to_string(line.number));
    }

    void parse_data(PcdHeader& h) const {
        const std::string_view v = single(data);
        std::string lower(v);
        for (char& c : lower) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
        if (lower == "ascii") {
            h.data = PcdData::ascii;
        } else if (lower == "binary") {
            h.data = PcdData::binary;
        } else if (lower == "binary_compressed") {
            h.data = PcdData::binary_compressed;
        } else {
            fail("DATA " + quote(v) + " is not ascii, binary or binary_compressed");
        }
        h.data_offset = data_offset_;
    }

    std::string_view text_;
    const std::filesystem::path& path_;
    std::array<Line, key_count> lines_{};
    std::size_t data_offset_ = 0;
    bool whole_file_ = true;
};

}  // namespace

PcdHeader parse_pcd_header(const std::vector<unsigned char>& bytes, const std::filesystem::path& path,
                           bool whole_file) {
    return HeaderParser(bytes, path, whole_file).parse();
}

}  // namespace pyrseg::io::detail
