// pyrseg_fuzz_seeds ROOT: writes a small valid seed corpus for every harness into ROOT/<harness>/, with pyrseg's own
// writers where it has them, so that the corpora follow the formats as pyrseg writes them and nothing binary is
// committed. scripts/fuzz.sh runs it before fuzzing.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "pyrseg/io.hpp"
#include "tests/fuzz/ply_headers.hpp"
#include "tests/fuzz/seeds/seeds.hpp"

namespace fs = std::filesystem;
namespace io = pyrseg::io;

namespace pyrseg::fuzz {

void write_seed(const fs::path& dir, const std::string& name, const void* data, std::size_t size) {
    fs::create_directories(dir);
    std::ofstream out(dir / name, std::ios::binary);
    out.write(static_cast<const char*>(data), static_cast<std::streamsize>(size));
    if (!out) throw std::runtime_error("cannot write " + (dir / name).string());
}

}  // namespace pyrseg::fuzz

namespace {

using pyrseg::fuzz::write_seed;

// A plane 1 m away with a box on it, holes (NaN) where `holes` says: the shapes real scans have, in a few cells.
io::PointCloud make_cloud(int width, int height, bool normals, bool holes) {
    io::PointCloud cloud;
    cloud.width = width;
    cloud.height = height;
    for (int y = 0; y < height; ++y) {
        for (int x = 0; x < width; ++x) {
            const bool box = x > width / 3 && x < 2 * width / 3 && y > height / 3;
            const float z = box ? 0.9f : 1.0f + 0.01f * static_cast<float>(y);
            const bool hole = holes && (x + 2 * y) % 7 == 3;
            const float nan = std::numeric_limits<float>::quiet_NaN();
            cloud.points.insert(cloud.points.end(),
                                {hole ? nan : 0.002f * static_cast<float>(x - width / 2) * z,
                                 hole ? nan : 0.002f * static_cast<float>(y - height / 2) * z, hole ? nan : z});
            if (normals) cloud.normals.insert(cloud.normals.end(), {0.0f, box ? 0.0f : -0.1f, -1.0f});
        }
    }
    return cloud;
}

std::vector<std::uint32_t> make_labels(int width, int height) {
    std::vector<std::uint32_t> labels(static_cast<std::size_t>(width) * static_cast<std::size_t>(height));
    for (std::size_t i = 0; i < labels.size(); ++i) labels[i] = static_cast<std::uint32_t>(i % 3);
    return labels;
}

// The writers replace files atomically through a temporary beside them: write into the folder directly.
void pcd_seeds(const fs::path& dir) {
    fs::create_directories(dir);
    const struct {
        io::PcdEncoding encoding;
        const char* name;
    } encodings[] = {{io::PcdEncoding::ascii, "ascii"},
                     {io::PcdEncoding::binary, "binary"},
                     {io::PcdEncoding::binary_compressed, "binary_compressed"}};
    for (const auto& e : encodings) {
        for (const bool normals : {false, true}) {
            const io::PointCloud cloud = make_cloud(6, 4, normals, true);
            const std::string base = std::string(e.name) + (normals ? "_normals" : "");
            io::write_pcd(dir / (base + ".pcd"), cloud, e.encoding);
            const std::vector<std::uint32_t> labels = make_labels(cloud.width, cloud.height);
            io::write_pcd(dir / (base + "_labels.pcd"), cloud, labels.data(), e.encoding);
        }
    }
}

void ply_seeds(const fs::path& dir) {
    fs::create_directories(dir);
    for (const bool binary : {false, true}) {
        for (const bool holes : {false, true}) {
            for (const bool normals : {false, true}) {
                const io::PointCloud cloud = make_cloud(5, 3, normals, holes);
                const std::string base = std::string(binary ? "binary" : "ascii") + (holes ? "_range_grid" : "") +
                                         (normals ? "_normals" : "");
                io::write_ply(dir / (base + ".ply"), cloud, nullptr, binary);
                const std::vector<std::uint32_t> labels = make_labels(cloud.width, cloud.height);
                io::write_ply(dir / (base + "_labels.ply"), cloud, labels.data(), binary);
            }
        }
    }
}

// Bodies for fuzz_ply_body's headers: the selector byte, then data that header describes.
void append_float(std::string& out, float v, bool big_endian) {
    unsigned char b[4];
    std::memcpy(b, &v, 4);
    if (big_endian) std::swap(b[0], b[3]), std::swap(b[1], b[2]);
    out.append(reinterpret_cast<const char*>(b), 4);
}

void ply_body_seeds(const fs::path& dir) {
    const auto& headers = pyrseg::fuzz::kPlyHeaders;
    for (std::size_t h = 0; h < headers.size(); ++h) {
        const std::string_view name = headers[h].name;
        const bool ascii = name.starts_with("ascii");
        const bool grid = name.ends_with("range_grid");
        const bool big = name.starts_with("binary_be");
        const int values_per_vertex = name.ends_with("normals") ? 6 : 3;
        const int vertices = grid ? 10 : 12;
        std::string body(1, static_cast<char>(h));
        for (int v = 0; v < vertices; ++v) {
            for (int c = 0; c < values_per_vertex; ++c) {
                const float value = c == 2 ? 1.0f + 0.01f * static_cast<float>(v) : 0.01f * static_cast<float>(v);
                if (ascii) {
                    body += std::to_string(value) + (c + 1 == values_per_vertex ? "\n" : " ");
                } else {
                    append_float(body, value, big);
                }
            }
        }
        if (grid) {
            // Cells 3 and 8 are gaps; the others map to the vertices in order.
            int next = 0;
            for (int cell = 0; cell < 12; ++cell) {
                const bool gap = cell == 3 || cell == 8;
                if (ascii) {
                    body += gap ? std::string("0\n") : "1 " + std::to_string(next++) + "\n";
                } else {
                    body.push_back(static_cast<char>(gap ? 0 : 1));
                    if (!gap) {
                        const std::int32_t index = next++;
                        body.append(reinterpret_cast<const char*>(&index), 4);
                    }
                }
            }
        }
        write_seed(dir, std::string(name) + ".body", body);
    }
}

// A .npy file of any dtype and shape, for the dtypes and versions pyrseg's writers do not produce.
std::string npy_file(const std::string& dtype, const std::string& shape, std::size_t data_bytes, int major) {
    std::string header = "{'descr': '" + dtype + "', 'fortran_order': False, 'shape': " + shape + ", }";
    const std::size_t prefix = major == 1 ? 10 : 12;
    while ((prefix + header.size() + 1) % 64 != 0) header.push_back(' ');
    header.push_back('\n');
    std::string out = "\x93NUMPY";
    out.push_back(static_cast<char>(major));
    out.push_back('\0');
    const std::size_t len = header.size();
    for (std::size_t i = 0; i < (major == 1 ? 2u : 4u); ++i) out.push_back(static_cast<char>((len >> (8 * i)) & 0xff));
    out += header;
    for (std::size_t i = 0; i < data_bytes; ++i) out.push_back(static_cast<char>(i * 7));
    return out;
}

void npy_seeds(const fs::path& dir) {
    fs::create_directories(dir);
    const int w = 4, h = 3;
    const std::vector<std::uint32_t> labels = make_labels(w, h);
    io::write_npy(dir / "u4.npy", labels.data(), h, w);
    const std::vector<std::uint8_t> mask(labels.begin(), labels.end());
    io::write_npy(dir / "u1.npy", mask.data(), h, w);
    const io::PointCloud cloud = make_cloud(w, h, true, true);
    io::write_npy(dir / "f4_points.npy", cloud.points.data(), h, w, 3);
    std::vector<float> six;
    for (std::size_t i = 0; i < cloud.points.size(); i += 3) {
        six.insert(six.end(), cloud.points.begin() + static_cast<std::ptrdiff_t>(i),
                   cloud.points.begin() + static_cast<std::ptrdiff_t>(i + 3));
        six.insert(six.end(), cloud.normals.begin() + static_cast<std::ptrdiff_t>(i),
                   cloud.normals.begin() + static_cast<std::ptrdiff_t>(i + 3));
    }
    io::write_npy(dir / "f4_points_normals.npy", six.data(), h, w, 6);
    std::vector<float> depth(static_cast<std::size_t>(w * h), 1.25f);
    io::write_npy(dir / "f4_depth.npy", depth.data(), h, w, 1);
    write_seed(dir, "f8_points.npy", npy_file("<f8", "(3, 4, 3)", 8 * 36, 1));
    write_seed(dir, "u2_depth.npy", npy_file("<u2", "(3, 4)", 2 * 12, 1));
    write_seed(dir, "i4_v2.npy", npy_file("<i4", "(2, 2)", 16, 2));
    write_seed(dir, "b1_v3.npy", npy_file("|b1", "(5,)", 5, 3));
    write_seed(dir, "c8_0d.npy", npy_file("<c8", "()", 8, 1));
}

void png_seeds(const fs::path& dir) {
    fs::create_directories(dir);
    const int w = 5, h = 4;
    std::vector<std::uint16_t> gray16(static_cast<std::size_t>(w * h));
    for (std::size_t i = 0; i < gray16.size(); ++i) gray16[i] = static_cast<std::uint16_t>(i % 4 == 0 ? 0 : 900 + i);
    io::write_png_gray16(dir / "gray16.png", gray16.data(), w, h);
    const std::vector<std::uint8_t> gray8(gray16.begin(), gray16.end());
    io::write_png_gray8(dir / "gray8.png", gray8.data(), w, h);
    const std::vector<std::uint8_t> rgb = io::colorize_labels(make_labels(w, h).data(), w, h);
    io::write_png_rgb(dir / "rgb.png", rgb.data(), w, h);
}

std::vector<char> slurp(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

}  // namespace

int main(int argc, char** argv) {
    if (argc != 2) {
        std::fprintf(stderr, "usage: pyrseg_fuzz_seeds ROOT  (writes ROOT/<harness>/ seed files)\n");
        return 2;
    }
    try {
        const fs::path root = argv[1];
        pcd_seeds(root / "fuzz_pcd");
        ply_seeds(root / "fuzz_ply");
        ply_body_seeds(root / "fuzz_ply_body");
        npy_seeds(root / "fuzz_npy");
        png_seeds(root / "fuzz_png");
        pyrseg::fuzz::write_tiff_seeds(root);
        // The depth harness reads both: its corpus is the 16-bit PNG and the TIFFs.
        const std::vector<char> gray16 = slurp(root / "fuzz_png" / "gray16.png");
        write_seed(root / "fuzz_depth", "gray16.png", gray16.data(), gray16.size());
        pyrseg::fuzz::write_text_seeds(root);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "pyrseg_fuzz_seeds: %s\n", e.what());
        return 1;
    }
    return 0;
}
