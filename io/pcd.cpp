// Reading PCD files. The header is checked in full first (pcd_header.cpp); then, before any allocation, the sizes
// it claims are checked against the bytes actually in the file, so a lying header costs an error, not memory.
#include <lzf.h>

#include <algorithm>
#include <bit>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>
#include <string_view>

#include "file_util.hpp"
#include "pcd_header.hpp"
#include "pyrseg/io.hpp"

namespace pyrseg::io {

namespace {

using detail::fail;
using detail::is_space;
using detail::PcdData;
using detail::PcdField;
using detail::PcdHeader;

// PCD binary data is the writer's memory image; every PCD in practice comes from a little-endian machine.
static_assert(std::endian::native == std::endian::little, "PCD binary reading assumes a little-endian host");

// LZF copies at most 264 bytes per 3-byte back reference, so no valid block expands more than 88 times.
constexpr std::uint64_t kMaxLzfRatio = 88;
// A PCD header is a dozen short lines; one of more than this is not a PCD's.
constexpr std::size_t kMaxHeaderBytes = std::size_t{1} << 20;
// Binary data is read in blocks of this size.
constexpr std::size_t kStreamBytes = std::size_t{1} << 20;

float load_float(const unsigned char* p, int size) {
    if (size == 8) {
        double d = 0;
        std::memcpy(&d, p, sizeof d);
        return static_cast<float>(d);
    }
    float f = 0;
    std::memcpy(&f, p, sizeof f);
    return f;
}

// Copies one float field of every point into out[3 * i + component]; stride is the distance between points' values.
void gather(const unsigned char* base, std::uint64_t stride, int size, std::uint64_t n, float* out, int component) {
    for (std::uint64_t i = 0; i < n; ++i) {
        out[3 * i + static_cast<std::uint64_t>(component)] = load_float(base + i * stride, size);
    }
}

// Called only once the sizes the header claims have been checked against the file.
void allocate(const PcdHeader& h, io::PointCloud& cloud) {
    cloud.width = h.width;
    cloud.height = h.height;
    cloud.points.resize(3 * h.points);
    if (h.normal[0] >= 0) cloud.normals.resize(3 * h.points);
}

// Points first .. first + n of DATA binary (array-of-structures), at `data`.
void gather_points(const PcdHeader& h, const unsigned char* data, std::uint64_t first, std::uint64_t n,
                   io::PointCloud& cloud) {
    for (int c = 0; c < 3; ++c) {
        const PcdField& f = h.fields[static_cast<std::size_t>(h.xyz[c])];
        gather(data + f.offset, h.point_size, f.size, n, cloud.points.data() + 3 * first, c);
    }
    if (h.normal[0] < 0) return;
    for (int c = 0; c < 3; ++c) {
        const PcdField& f = h.fields[static_cast<std::size_t>(h.normal[c])];
        gather(data + f.offset, h.point_size, f.size, n, cloud.normals.data() + 3 * first, c);
    }
}

// binary_compressed stores each field's values for all points together.
void gather_soa(const PcdHeader& h, const unsigned char* data, io::PointCloud& cloud) {
    for (int c = 0; c < 3; ++c) {
        const PcdField& f = h.fields[static_cast<std::size_t>(h.xyz[c])];
        gather(data + f.offset * h.points, f.bytes(), f.size, h.points, cloud.points.data(), c);
    }
    if (h.normal[0] < 0) return;
    for (int c = 0; c < 3; ++c) {
        const PcdField& f = h.fields[static_cast<std::size_t>(h.normal[c])];
        gather(data + f.offset * h.points, f.bytes(), f.size, h.points, cloud.normals.data(), c);
    }
}

void read_binary(const PcdHeader& h, detail::InputFile& file, io::PointCloud& cloud) {
    const std::uint64_t left = file.size() - h.data_offset;
    const std::uint64_t needed = h.points * h.point_size;  // < 2^31 * 2^32: no overflow
    if (needed > left) {
        fail(ErrorCode::format, file.path(),
             "DATA binary: " + std::to_string(h.points) + " points of " + std::to_string(h.point_size) +
                 " bytes need " + std::to_string(needed) + " bytes, but only " + std::to_string(left) +
                 " follow the header (truncated file, or wrong WIDTH/HEIGHT/POINTS/SIZE?)");
    }
    // Bytes beyond the data are allowed (PCL's writers padded files to a page boundary) and never read.
    allocate(h, cloud);
    // Streamed a block of points at a time: the data is never held whole beside the cloud.
    const std::uint64_t block = std::max<std::uint64_t>(1, kStreamBytes / h.point_size);
    std::vector<unsigned char> buffer(static_cast<std::size_t>(std::min(block, h.points) * h.point_size));
    file.seek(h.data_offset);
    for (std::uint64_t first = 0; first < h.points; first += block) {
        const std::uint64_t n = std::min(block, h.points - first);
        file.read_exact(buffer.data(), static_cast<std::size_t>(n * h.point_size),
                        "point " + std::to_string(first + n) + " of DATA binary");
        gather_points(h, buffer.data(), first, n, cloud);
    }
}

void read_compressed(const PcdHeader& h, detail::InputFile& file, io::PointCloud& cloud) {
    const std::filesystem::path& path = file.path();
    const std::string what = "DATA binary_compressed: ";
    const std::uint64_t left = file.size() - h.data_offset;
    if (left < 8) {
        fail(ErrorCode::format, path,
             what + "the file ends " + std::to_string(left) +
                 " bytes after the header, before the two block sizes (truncated file?)");
    }
    unsigned char sizes[8];
    file.seek(h.data_offset);
    file.read_exact(sizes, sizeof sizes, "the two block sizes of DATA binary_compressed");
    std::uint32_t compressed = 0, uncompressed = 0;
    std::memcpy(&compressed, sizes, 4);
    std::memcpy(&uncompressed, sizes + 4, 4);
    const std::uint64_t needed = h.points * h.point_size;
    if (uncompressed != needed) {
        fail(ErrorCode::format, path,
             what + "uncompressed size " + std::to_string(uncompressed) + " does not match the " +
                 std::to_string(needed) + " bytes that " + std::to_string(h.points) + " points of " +
                 std::to_string(h.point_size) + " bytes take");
    }
    if (compressed > left - 8) {
        fail(ErrorCode::format, path,
             what + "compressed size " + std::to_string(compressed) + " exceeds the " + std::to_string(left - 8) +
                 " bytes left in the file (truncated file?)");
    }
    if (compressed == 0 || uncompressed > kMaxLzfRatio * compressed) {
        fail(ErrorCode::format, path,
             what + "compressed size " + std::to_string(compressed) + " is too small to hold " +
                 std::to_string(uncompressed) + " bytes of LZF data");
    }
    // Both sizes are now bounded by the file's: the block is in the file, and LZF expands it at most 88-fold.
    std::vector<unsigned char> block(compressed);
    file.read_exact(block.data(), block.size(), "the end of the compressed block");
    std::vector<unsigned char> raw(uncompressed);
    errno = 0;
    const unsigned got = lzf_decompress(block.data(), compressed, raw.data(), uncompressed);
    if (got == 0) {
        fail(ErrorCode::format, path,
             what + (errno == E2BIG ? "LZF data expands past the uncompressed size " + std::to_string(uncompressed)
                                    : std::string("corrupt LZF data")));
    }
    if (got != uncompressed) {
        fail(ErrorCode::format, path,
             what + "LZF data expands to " + std::to_string(got) + " bytes, not the " + std::to_string(uncompressed) +
                 " the header promises");
    }
    block = {};
    allocate(h, cloud);
    gather_soa(h, raw.data(), cloud);
}

enum class Number { ok, not_a_number, out_of_range };

// from_chars accepts nan and inf in any case but no leading '+', which some writers emit.
template <typename T>
Number parse_number(std::string_view token, T& value) {
    if (token.size() > 1 && token[0] == '+' && token[1] != '-') token.remove_prefix(1);
    const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
    if (end != token.data() + token.size()) return Number::not_a_number;
    if (ec == std::errc::result_out_of_range) return Number::out_of_range;
    return ec == std::errc() ? Number::ok : Number::not_a_number;
}

class AsciiReader {
public:
    AsciiReader(const PcdHeader& h, detail::InputFile& file)
        : h_(h),
          data_bytes_(file.size() - h.data_offset),
          path_(file.path()),
          lines_(file, h.data_offset, max_line(h)) {
        check_size();  // first: it also bounds values_per_point, and so targets_, by the file's size
        // Which output float, if any, each value of a line feeds: -1 skip, 0..2 point xyz, 3..5 normal xyz.
        for (std::size_t i = 0; i < h.fields.size(); ++i) {
            int target = -1;
            for (int c = 0; c < 3; ++c) {
                if (h.xyz[c] == static_cast<int>(i)) target = c;
                if (h.normal[c] == static_cast<int>(i)) target = 3 + c;
            }
            for (std::uint64_t k = 0; k < h.fields[i].count; ++k) targets_.push_back({target, &h.fields[i]});
        }
    }

    void read(io::PointCloud& cloud) {
        allocate(h_, cloud);
        for (std::uint64_t i = 0; i < h_.points; ++i) {
            const std::string_view line = next_line();
            if (line.data() == nullptr) {
                fail("the file ends after " + std::to_string(i) + " of " + std::to_string(h_.points) +
                     " points (truncated file, or wrong WIDTH/HEIGHT/POINTS?)");
            }
            parse_line(line, i, cloud);
        }
        if (next_line().data() != nullptr) {
            fail("more lines than the " + std::to_string(h_.points) +
                 " points the header announces (wrong WIDTH/HEIGHT/POINTS?)");
        }
    }

private:
    [[noreturn]] void fail(const std::string& what) const {
        detail::fail(ErrorCode::format, path_, "DATA ascii: " + what);
    }

    // Each point takes at least one character per value plus a separator, so a short file cannot make us allocate.
    void check_size() const {
        const std::uint64_t per_point = 2 * h_.values_per_point;  // values_per_point <= 2^32
        if (h_.points > (std::numeric_limits<std::uint64_t>::max() - 1) / per_point ||
            h_.points * per_point - 1 > data_bytes_) {
            fail(std::to_string(h_.points) + " points of " + std::to_string(h_.values_per_point) +
                 " values cannot fit in the " + std::to_string(data_bytes_) +
                 " bytes after the header (truncated file, or wrong WIDTH/HEIGHT/POINTS?)");
        }
    }

    // The longest data line accepted: 64 characters per value (a double takes at most 24) and some slack for
    // spaces; longer lines are not a point's.
    static std::size_t max_line(const PcdHeader& h) {
        return static_cast<std::size_t>(
            std::min<std::uint64_t>(64 * h.values_per_point + 4096, std::uint64_t{1} << 40));
    }

    // The next non-blank line, or a null view at the end of the data.
    std::string_view next_line() {
        std::string_view line;
        while (lines_.next(line)) {
            ++line_number_;
            for (const char c : line) {
                if (!is_space(c)) return line;
            }
        }
        if (lines_.too_long()) {
            fail("data line " + std::to_string(line_number_ + 1) + " is longer than " + std::to_string(max_line(h_)) +
                 " bytes, too long for a point of " + std::to_string(h_.values_per_point) + " values");
        }
        return {};
    }

    void parse_line(std::string_view line, std::uint64_t point, io::PointCloud& cloud) const {
        std::size_t value = 0;
        std::size_t i = 0;
        while (true) {
            while (i < line.size() && is_space(line[i])) ++i;
            if (i == line.size()) break;
            const std::size_t start = i;
            while (i < line.size() && !is_space(line[i])) ++i;
            const std::string_view token = line.substr(start, i - start);
            if (value >= targets_.size()) {
                fail("data line " + std::to_string(line_number_) + " (point " + std::to_string(point) +
                     ") has more than the " + std::to_string(targets_.size()) + " values the fields need");
            }
            store(token, targets_[value], point, cloud);
            ++value;
        }
        if (value != targets_.size()) {
            fail("data line " + std::to_string(line_number_) + " (point " + std::to_string(point) + ") has " +
                 std::to_string(value) + " values, the fields need " + std::to_string(targets_.size()));
        }
    }

    struct Target {
        int index;
        const PcdField* field;
    };

    void store(std::string_view token, const Target& t, std::uint64_t point, io::PointCloud& cloud) const {
        Number parsed = Number::ok;
        float f = 0;
        if (t.index >= 0 && t.field->size == 4) {
            parsed = parse_number(token, f);
        } else {
            // Skipped fields are still checked: garbage anywhere means the file is not what it claims to be.
            // Doubles parse every integer PCL writes (it writes rgb as an unsigned integer despite TYPE F).
            double d = 0;
            parsed = parse_number(token, d);
            // A double point field's value must fit the float it is stored in (the conversion is undefined else).
            if (parsed == Number::ok && t.index >= 0 && std::isfinite(d) &&
                std::fabs(d) > double(std::numeric_limits<float>::max())) {
                parsed = Number::out_of_range;
            }
            if (parsed == Number::ok && t.index >= 0) f = static_cast<float>(d);
        }
        if (parsed != Number::ok) {
            const std::string shown = detail::printable(token.substr(0, 32));
            fail("data line " + std::to_string(line_number_) + " (point " + std::to_string(point) + "): '" + shown +
                 "' in field '" + t.field->name + "' " +
                 (parsed == Number::out_of_range
                      ? "is outside float32's range (about 1.2e-38 to 3.4e38 in magnitude, or 0)"
                      : "is not a number"));
        }
        if (t.index < 0) return;
        auto& out = t.index < 3 ? cloud.points : cloud.normals;
        out[3 * point + static_cast<std::uint64_t>(t.index % 3)] = f;
    }

    const PcdHeader& h_;
    std::uint64_t data_bytes_;
    const std::filesystem::path& path_;
    detail::LineReader lines_;
    std::vector<Target> targets_;
    std::uint64_t line_number_ = 0;  // counted from the first line after DATA
};

}  // namespace

PointCloud read_pcd(const std::filesystem::path& path) {
    return detail::guard_reader(path, [&] {
        detail::InputFile file(path);
        // The header from the file's first bytes: a file that is not a PCD is refused without reading it whole.
        const std::vector<unsigned char> head = detail::read_head(file, kMaxHeaderBytes);
        const PcdHeader h = detail::parse_pcd_header(head, path, head.size() == file.size());
        if (head.size() < file.size() && h.data_offset == head.size() && head.back() != '\n') {
            fail(ErrorCode::format, path,
                 "the header is longer than " + std::to_string(kMaxHeaderBytes) + " bytes (not a PCD file?)");
        }
        PointCloud cloud;
        switch (h.data) {
            case PcdData::binary:
                read_binary(h, file, cloud);
                break;
            case PcdData::binary_compressed:
                read_compressed(h, file, cloud);
                break;
            case PcdData::ascii:
                AsciiReader(h, file).read(cloud);
                break;
        }
        return cloud;
    });
}

}  // namespace pyrseg::io
