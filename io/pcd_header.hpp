#pragma once
// The PCD v0.7 header: parsed and checked in full before a single byte of point data is touched.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace pyrseg::io::detail {

struct PcdField {
    std::string name;
    char type = 'F';           // F, I or U
    int size = 4;              // bytes per value: 1, 2, 4 or 8
    std::uint64_t count = 1;   // values per point
    std::uint64_t offset = 0;  // bytes before this field in a point; binary_compressed: its block is at offset * points
    [[nodiscard]] std::uint64_t bytes() const { return static_cast<std::uint64_t>(size) * count; }
};

enum class PcdData { ascii, binary, binary_compressed };

struct PcdHeader {
    std::vector<PcdField> fields;
    std::uint64_t point_size = 0;        // bytes per point, all fields
    std::uint64_t values_per_point = 0;  // numbers per ascii line, all fields
    int width = 0, height = 0;
    std::uint64_t points = 0;  // width * height
    PcdData data = PcdData::ascii;
    std::size_t data_offset = 0;   // first byte after the DATA line
    int xyz[3] = {-1, -1, -1};     // indices into fields
    int normal[3] = {-1, -1, -1};  // -1 when the file has no normals
};

// Separators in header lines and ascii data; '\r' included so files with Windows line ends read the same.
inline bool is_space(char c) {
    return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f';
}

// Throws pyrseg::Error (ErrorCode::format) naming the file and the offending line or field. whole_file: `bytes` is the
// whole file, not only its first bytes (a header without DATA is then incomplete rather than too long).
PcdHeader parse_pcd_header(const std::vector<unsigned char>& bytes, const std::filesystem::path& path, bool whole_file);

}  // namespace pyrseg::io::detail
