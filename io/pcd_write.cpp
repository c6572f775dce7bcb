// Writing PCD files the way PCL does: fields x y z [normal_x normal_y normal_z], all F 4, VERSION 0.7.
#include <bit>
#include <charconv>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>

#include "file_util.hpp"
#include "lzf_block.hpp"
#include "pyrseg/io.hpp"

namespace pyrseg::io {

namespace {

using detail::fail;

static_assert(std::endian::native == std::endian::little, "PCD binary writing assumes a little-endian host");

std::string header(const PointCloud& cloud, bool normals, const char* data) {
    const std::string n = std::to_string(static_cast<long long>(cloud.width) * cloud.height);
    std::string h = "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\n";
    h += normals ? "FIELDS x y z normal_x normal_y normal_z\nSIZE 4 4 4 4 4 4\nTYPE F F F F F F\nCOUNT 1 1 1 1 1 1\n"
                 : "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n";
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

std::string ascii_body(const PointCloud& cloud, std::size_t n, bool normals) {
    std::string out;
    out.reserve(n * (normals ? 60 : 30));
    for (std::size_t i = 0; i < n; ++i) {
        for (int c = 0; c < 3; ++c) {
            if (c > 0) out += ' ';
            append_float(out, cloud.points[3 * i + static_cast<std::size_t>(c)]);
        }
        for (int c = 0; normals && c < 3; ++c) {
            out += ' ';
            append_float(out, cloud.normals[3 * i + static_cast<std::size_t>(c)]);
        }
        out += '\n';
    }
    return out;
}

std::string binary_body(const PointCloud& cloud, std::size_t n, bool normals) {
    std::string out;
    out.reserve(n * (normals ? 24 : 12));
    for (std::size_t i = 0; i < n; ++i) {
        append_bytes(out, &cloud.points[3 * i], 3 * sizeof(float));
        if (normals) append_bytes(out, &cloud.normals[3 * i], 3 * sizeof(float));
    }
    return out;
}

std::string compressed_body(const std::filesystem::path& path, const PointCloud& cloud, std::size_t n, bool normals) {
    const std::size_t fields = normals ? 6 : 3;
    const std::size_t raw_size = n * fields * sizeof(float);
    if (raw_size > std::numeric_limits<std::uint32_t>::max()) {
        fail(ErrorCode::invalid_argument, path,
             "cloud too large for DATA binary_compressed (" + std::to_string(raw_size) +
                 " bytes; the format stores sizes in 32 bits): write it as binary");
    }
    // Structure of arrays: all x, then all y, ... as PCL's reader expects.
    std::vector<float> soa(n * fields);
    for (std::size_t f = 0; f < fields; ++f) {
        const std::vector<float>& src = f < 3 ? cloud.points : cloud.normals;
        for (std::size_t i = 0; i < n; ++i) soa[f * n + i] = src[3 * i + f % 3];
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

void write_pcd(const std::filesystem::path& path, const PointCloud& cloud, PcdEncoding encoding) {
    detail::check_cloud_to_write(path, cloud);
    const auto n = static_cast<std::size_t>(cloud.width) * static_cast<std::size_t>(cloud.height);
    const bool normals = !cloud.normals.empty();
    std::string out;
    switch (encoding) {
        case PcdEncoding::ascii:
            out = header(cloud, normals, "ascii") + ascii_body(cloud, n, normals);
            break;
        case PcdEncoding::binary:
            out = header(cloud, normals, "binary") + binary_body(cloud, n, normals);
            break;
        case PcdEncoding::binary_compressed:
            out = header(cloud, normals, "binary_compressed") + compressed_body(path, cloud, n, normals);
            break;
        default:
            fail(ErrorCode::invalid_argument, path, "unknown PcdEncoding");
    }
    detail::write_file(path, out.data(), out.size());
}

}  // namespace pyrseg::io
