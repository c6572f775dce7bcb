// TIFF seeds: the float TIFF through pyrseg's writer, and through libtiff the layouts cameras and datasets use that
// pyrseg cannot write (16-bit samples, tiles, compression, big-endian) and a few it refuses (8-bit, two channels).
#include <tiffio.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <string>
#include <vector>

#include "pyrseg/io.hpp"
#include "tests/fuzz/seeds/seeds.hpp"

namespace fs = std::filesystem;

namespace {

constexpr int kWidth = 8, kHeight = 6;

struct Layout {
    const char* name;
    const char* mode;  // "w", or "wb" for big-endian
    int bits, channels;
    bool tiled;
    std::uint16_t compression;
};

void write_tiff(const fs::path& path, const Layout& l) {
    TIFF* tif = TIFFOpen(path.c_str(), l.mode);
    if (tif == nullptr) throw std::runtime_error("libtiff cannot write " + path.string());
    TIFFSetField(tif, TIFFTAG_IMAGEWIDTH, kWidth);
    TIFFSetField(tif, TIFFTAG_IMAGELENGTH, kHeight);
    TIFFSetField(tif, TIFFTAG_BITSPERSAMPLE, l.bits);
    TIFFSetField(tif, TIFFTAG_SAMPLESPERPIXEL, l.channels);
    TIFFSetField(tif, TIFFTAG_SAMPLEFORMAT, SAMPLEFORMAT_UINT);
    TIFFSetField(tif, TIFFTAG_PHOTOMETRIC, PHOTOMETRIC_MINISBLACK);
    TIFFSetField(tif, TIFFTAG_PLANARCONFIG, PLANARCONFIG_CONTIG);
    TIFFSetField(tif, TIFFTAG_COMPRESSION, l.compression);
    const std::size_t pixel_bytes = static_cast<std::size_t>(l.bits / 8 * l.channels);
    std::vector<std::uint8_t> row(pixel_bytes * kWidth);
    for (std::size_t i = 0; i < row.size(); ++i) row[i] = static_cast<std::uint8_t>(3 + i);
    if (l.tiled) {
        // The smallest tile libtiff allows is 16 x 16: one tile holds the whole image.
        TIFFSetField(tif, TIFFTAG_TILEWIDTH, 16);
        TIFFSetField(tif, TIFFTAG_TILELENGTH, 16);
        std::vector<std::uint8_t> tile(pixel_bytes * 16 * 16, 4);
        TIFFWriteTile(tif, tile.data(), 0, 0, 0, 0);
    } else {
        TIFFSetField(tif, TIFFTAG_ROWSPERSTRIP, 2);
        for (int y = 0; y < kHeight; ++y) TIFFWriteScanline(tif, row.data(), static_cast<std::uint32_t>(y), 0);
    }
    TIFFClose(tif);
}

}  // namespace

namespace pyrseg::fuzz {

void write_tiff_seeds(const fs::path& root) {
    const fs::path dir = root / "fuzz_tiff";
    fs::create_directories(dir);
    std::vector<float> depth(kWidth * kHeight);
    for (std::size_t i = 0; i < depth.size(); ++i) depth[i] = i % 5 == 0 ? 0.0f : 0.5f + 0.01f * static_cast<float>(i);
    io::write_tiff_float(dir / "f32.tif", depth.data(), kWidth, kHeight);
    const Layout layouts[] = {
        {"u16_strips.tif", "w", 16, 1, false, COMPRESSION_NONE},
        {"u16_big_endian.tif", "wb", 16, 1, false, COMPRESSION_NONE},
        {"u16_tiled.tif", "w", 16, 1, true, COMPRESSION_NONE},
        {"u16_deflate.tif", "w", 16, 1, false, COMPRESSION_ADOBE_DEFLATE},
        {"u16_packbits.tif", "w", 16, 1, false, COMPRESSION_PACKBITS},
        {"u8.tif", "w", 8, 1, false, COMPRESSION_NONE},
        {"u16_two_channels.tif", "w", 16, 2, false, COMPRESSION_NONE},
    };
    for (const Layout& l : layouts) write_tiff(dir / l.name, l);
    // The depth harness reads TIFFs too: the same files.
    for (const auto& entry : fs::directory_iterator(dir)) {
        std::ifstream in(entry.path(), std::ios::binary);
        const std::vector<char> bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
        write_seed(root / "fuzz_depth", entry.path().filename().string(), bytes.data(), bytes.size());
    }
}

}  // namespace pyrseg::fuzz
