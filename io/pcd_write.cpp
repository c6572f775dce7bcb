// Writing PCD files the way PCL does: fields x y z [normal_x normal_y normal_z] as F 4 [label and other per-point
// integers as U 4], VERSION 0.7.
#include <bit>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <span>
#include <string>
#include <vector>

#include "file_util.hpp"
#include "lzf_block.hpp"
#include "pyrseg/io.hpp"

namespace pyrseg::io {

namespace {

using detail::fail;

static_assert(std::endian::native == std::endian::little, "PCD binary writing assumes a little-endian host");

// What one point holds, in file order: x y z, then normal_x normal_y normal_z, then the integer fields (label first
// where given: PCL's PointXYZL and PointXYZLNormal name it so; pcl::io::loadPCDFile matches fields by name, so the
// order is free).
struct Layout {
    bool normals = false;
    std::span<const PcdField> integers;
    [[nodiscard]] std::size_t float_fields() const { return normals ? 6 : 3; }
    [[nodiscard]] std::size_t fields() const { return float_fields() + integers.size(); }
    [[nodiscard]] std::size_t point_bytes() const { return 4 * fields(); }
};

// A field name PCL's header reader takes (one token of letters, digits and '_') that no other field has.
void check_fields(const std::filesystem::path& path, std::span<const PcdField> fields) {
    std::vector<std::string> taken = {"x", "y", "z", "normal_x", "normal_y", "normal_z"};
    for (const PcdField& f : fields) {
        const bool word = !f.name.empty() && f.name.find_first_not_of(
                                                 "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTU"
                                                 "VWXYZ0123456789_") == std::string::npos;
        if (!word) fail(ErrorCode::invalid_argument, path, "PCD field name '" + f.name + "' is not one word");
        for (const std::string& t : taken) {
            if (t == f.name) fail(ErrorCode::invalid_argument, path, "PCD field '" + f.name + "' is given twice");
        }
        if (f.values == nullptr) fail(ErrorCode::invalid_argument, path, "PCD field '" + f.name + "' has no values");
        taken.push_back(f.name);
    }
}

std::string header(const PointCloud& cloud, const Layout& layout, const char* data) {
    const std::string n = std::to_string(static_cast<long long>(cloud.width) * cloud.height);
    std::string names = "x y z", sizes = "4 4 4", types = "F F F", counts = "1 1 1";
    if (layout.normals) {
        names += " normal_x normal_y normal_z";
        sizes += " 4 4 4";
        types += " F F F";
        counts += " 1 1 1";
    }
    for (const PcdField& f : layout.integers) {
        names += " " + f.name;
        sizes += " 4";
        types += " U";
        counts += " 1";
    }
    std::string h = "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\n";
    h += "FIELDS " + names + "\nSIZE " + sizes + "\nTYPE " + types + "\nCOUNT " + counts + "\n";
    h += "WIDTH " + std::to_string(cloud.width) + "\nHEIGHT " + std::to_string(cloud.height) + "\n";
    h += "VIEWPOINT 0 0 0 1 0 0 0\nPOINTS " + n + "\nDATA " + data + "\n";
    return h;
}

void append_bytes(std::string& out, const void* data, std::size_t size) {
    out.append(static_cast<const char*>(data), size);
}

void append_float(std::string& out, float v) {
    // PCL reads "nan" (any other spelling, like "-nan", it does not); shortest round-trip digits otherwise.
    if (std::isnan(v)) {
        out += "nan";
        return;
    }
    char buf[32];
    const auto [end, ec] = std::to_chars(buf, buf + sizeof buf, v);
    out.append(buf, end);
}

std::string ascii_body(const PointCloud& cloud, std::size_t n, const Layout& layout) {
    std::string out;
    out.reserve(n * 10 * layout.fields());
    for (std::size_t i = 0; i < n; ++i) {
        for (int c = 0; c < 3; ++c) {
            if (c > 0) out += ' ';
            append_float(out, cloud.points[3 * i + static_cast<std::size_t>(c)]);
        }
        for (int c = 0; layout.normals && c < 3; ++c) {
            out += ' ';
            append_float(out, cloud.normals[3 * i + static_cast<std::size_t>(c)]);
        }
        for (const PcdField& f : layout.integers) {
            char buf[16];
            const auto [end, ec] = std::to_chars(buf, buf + sizeof buf, f.values[i]);
            out += ' ';
            out.append(buf, end);
        }
        out += '\n';
    }
    return out;
}

std::string binary_body(const PointCloud& cloud, std::size_t n, const Layout& layout) {
    std::string out;
    out.reserve(n * layout.point_bytes());
    for (std::size_t i = 0; i < n; ++i) {
        append_bytes(out, &cloud.points[3 * i], 3 * sizeof(float));
        if (layout.normals) append_bytes(out, &cloud.normals[3 * i], 3 * sizeof(float));
        for (const PcdField& f : layout.integers) append_bytes(out, &f.values[i], sizeof(std::uint32_t));
    }
    return out;
}

std::string compressed_body(const std::filesystem::path& path, const PointCloud& cloud, std::size_t n,
                            const Layout& layout) {
    const std::size_t raw_size = n * layout.point_bytes();
    if (raw_size > std::numeric_limits<std::uint32_t>::max()) {
        fail(ErrorCode::invalid_argument, path,
             "cloud too large for DATA binary_compressed (" + std::to_string(raw_size) +
                 " bytes; the format stores sizes in 32 bits): write it as binary");
    }
    // Structure of arrays: all x, then all y, ... (then each integer field's values) as PCL's reader expects.
    std::vector<unsigned char> soa(raw_size);
    unsigned char* block = soa.data();
    for (std::size_t f = 0; f < layout.float_fields(); ++f, block += 4 * n) {
        const std::vector<float>& src = f < 3 ? cloud.points : cloud.normals;
        for (std::size_t i = 0; i < n; ++i) std::memcpy(block + 4 * i, &src[3 * i + f % 3], sizeof(float));
    }
    for (const PcdField& f : layout.integers) {
        std::memcpy(block, f.values, n * sizeof(std::uint32_t));
        block += 4 * n;
    }
    const std::vector<unsigned char> packed = detail::lzf_pack(soa.data(), raw_size);
    if (packed.empty()) fail(ErrorCode::internal, path, "LZF compression failed");
    const auto compressed = static_cast<std::uint32_t>(packed.size());
    const auto uncompressed = static_cast<std::uint32_t>(raw_size);
    std::string out;
    append_bytes(out, &compressed, 4);
    append_bytes(out, &uncompressed, 4);
    append_bytes(out, packed.data(), compressed);
    return out;
}

}  // namespace

void write_pcd(const std::filesystem::path& path, const PointCloud& cloud, std::span<const PcdField> fields,
               PcdEncoding encoding) {
    detail::check_cloud_to_write(path, cloud);
    check_fields(path, fields);
    const auto n = static_cast<std::size_t>(cloud.width) * static_cast<std::size_t>(cloud.height);
    const Layout layout{!cloud.normals.empty(), fields};
    std::string out;
    switch (encoding) {
        case PcdEncoding::ascii:
            out = header(cloud, layout, "ascii") + ascii_body(cloud, n, layout);
            break;
        case PcdEncoding::binary:
            out = header(cloud, layout, "binary") + binary_body(cloud, n, layout);
            break;
        case PcdEncoding::binary_compressed:
            out = header(cloud, layout, "binary_compressed") + compressed_body(path, cloud, n, layout);
            break;
        default:
            fail(ErrorCode::invalid_argument, path, "unknown PcdEncoding");
    }
    detail::write_file(path, out.data(), out.size());
}

void write_pcd(const std::filesystem::path& path, const PointCloud& cloud, const std::uint32_t* labels,
               PcdEncoding encoding) {
    if (labels == nullptr) {
        write_pcd(path, cloud, std::span<const PcdField>{}, encoding);
        return;
    }
    const PcdField label{"label", labels};
    write_pcd(path, cloud, std::span<const PcdField>(&label, 1), encoding);
}

void write_pcd(const std::filesystem::path& path, const PointCloud& cloud, PcdEncoding encoding) {
    write_pcd(path, cloud, std::span<const PcdField>{}, encoding);
}

}  // namespace pyrseg::io
