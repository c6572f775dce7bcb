// Depth images in (16-bit PNG through the PNG reader, TIFF through libtiff) and their back-projection.
#include <tiffio.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <string>

#include "file_util.hpp"
#include "pyrseg/depth.hpp"
#include "pyrseg/io.hpp"

namespace pyrseg::io {
namespace {

using detail::fail;

DepthImage from_png(const std::filesystem::path& path) {
    const Image png = read_png(path);
    if (png.channels != 1 || png.bit_depth != 16) {
        fail(ErrorCode::format, path,
             "not a depth image: a depth PNG is 16-bit grayscale, this one has " + std::to_string(png.channels) +
                 " channel(s) of " + std::to_string(png.bit_depth) + " bits");
    }
    DepthImage out{png.width, png.height, {}, false};
    out.depth.resize(std::size_t(png.width) * std::size_t(png.height));
    for (std::size_t i = 0; i < out.depth.size(); ++i) {
        std::uint16_t v = 0;
        std::memcpy(&v, png.data.data() + 2 * i, 2);
        out.depth[i] = float(v);
    }
    return out;
}

// libtiff reports through handlers; they are silenced so that its errors surface as one pyrseg::Error.
struct TiffCloser {
    void operator()(TIFF* t) const { TIFFClose(t); }
};

// How many bytes one byte of a strip can decode to, for the codecs whose bound is known; 0 for the others.
std::uint64_t max_expansion(std::uint16_t compression) {
    switch (compression) {
        case COMPRESSION_NONE:
            return 1;
        case COMPRESSION_PACKBITS:
            return 64;  // a 2-byte run of 128 bytes
        case COMPRESSION_LZW:
            return 4096;  // a 9- to 12-bit code stands for at most 4096 bytes
        case COMPRESSION_ADOBE_DEFLATE:
        case COMPRESSION_DEFLATE:
            return 1032;  // deflate's limit
        default:
            return 0;
    }
}

// The strips must lie inside the file and, where the codec's expansion is bounded, be able to hold the image;
// checked before anything the size of the image is allocated.
void check_strips(TIFF* tiff, const std::filesystem::path& path, std::uint64_t file_size, std::uint64_t image_bytes) {
    const std::uint32_t strips = TIFFNumberOfStrips(tiff);
    if (strips == 0) fail(ErrorCode::format, path, "TIFF without strips");
    std::uint64_t stored = 0;
    for (std::uint32_t s = 0; s < strips; ++s) {
        int error = 0;
        const std::uint64_t offset = TIFFGetStrileOffsetWithErr(tiff, s, &error);
        const std::uint64_t bytes = error == 0 ? TIFFGetStrileByteCountWithErr(tiff, s, &error) : 0;
        if (error != 0 || bytes == 0 || offset > file_size || bytes > file_size - offset) {
            fail(ErrorCode::format, path,
                 "TIFF strip " + std::to_string(s) + " of " + std::to_string(strips) + " (" + std::to_string(bytes) +
                     " bytes at offset " + std::to_string(offset) + ") is not inside the file of " +
                     std::to_string(file_size) + " bytes (truncated file?)");
        }
        stored += bytes;  // at most 65536 strips (one per row) of at most file_size bytes: no overflow
    }
    std::uint16_t compression = COMPRESSION_NONE;
    TIFFGetFieldDefaulted(tiff, TIFFTAG_COMPRESSION, &compression);
    const std::uint64_t ratio = max_expansion(compression);
    if (ratio > 0 && stored < (image_bytes + ratio - 1) / ratio) {
        fail(ErrorCode::format, path,
             "the TIFF's strips hold " + std::to_string(stored) + " bytes" +
                 (compression == COMPRESSION_NONE ? std::string()
                                                  : " (expanding at most " + std::to_string(ratio) + "-fold)") +
                 ", too few for the " + std::to_string(image_bytes) + " bytes of its image (truncated file?)");
    }
}

DepthImage from_tiff(const std::filesystem::path& path) {
    // A clear io error for a missing file, a directory or a FIFO, and the size the strips are checked against.
    const std::uint64_t file_size = detail::InputFile(path).size();
    TIFFSetErrorHandler(nullptr);
    TIFFSetWarningHandler(nullptr);
    const std::unique_ptr<TIFF, TiffCloser> tiff(TIFFOpen(path.c_str(), "r"));
    if (!tiff) fail(ErrorCode::format, path, "not a readable TIFF file");
    std::uint32_t width = 0;
    std::uint32_t height = 0;
    std::uint16_t samples = 1;
    std::uint16_t bits = 0;
    std::uint16_t format = SAMPLEFORMAT_UINT;
    if (TIFFGetField(tiff.get(), TIFFTAG_IMAGEWIDTH, &width) != 1 ||
        TIFFGetField(tiff.get(), TIFFTAG_IMAGELENGTH, &height) != 1) {
        fail(ErrorCode::format, path, "TIFF without image width or length");
    }
    TIFFGetFieldDefaulted(tiff.get(), TIFFTAG_SAMPLESPERPIXEL, &samples);
    TIFFGetFieldDefaulted(tiff.get(), TIFFTAG_BITSPERSAMPLE, &bits);
    TIFFGetFieldDefaulted(tiff.get(), TIFFTAG_SAMPLEFORMAT, &format);
    const bool is_float = format == SAMPLEFORMAT_IEEEFP && bits == 32;
    const bool is_u16 = format == SAMPLEFORMAT_UINT && bits == 16;
    if (samples != 1 || !(is_float || is_u16)) {
        fail(ErrorCode::format, path,
             "not a depth image: a depth TIFF has one channel of 32-bit float or 16-bit unsigned samples, this one "
             "has " +
                 std::to_string(samples) + " channel(s) of " + std::to_string(bits) + "-bit " +
                 (format == SAMPLEFORMAT_IEEEFP ? "float"
                  : format == SAMPLEFORMAT_INT  ? "signed"
                                                : "unsigned") +
                 " samples");
    }
    detail::check_image_size(path, "TIFF", width, height);
    if (TIFFIsTiled(tiff.get())) fail(ErrorCode::format, path, "unsupported TIFF layout (tiled)");
    const tmsize_t line = TIFFScanlineSize(tiff.get());
    if (line != tmsize_t(width) * (bits / 8)) fail(ErrorCode::format, path, "unsupported TIFF layout (tiled?)");
    check_strips(tiff.get(), path, file_size, std::uint64_t(line) * height);
    DepthImage out{int(width), int(height), {}, is_float};
    // Grown row by row as rows decode: an image whose codec's expansion is unbounded costs memory only for data
    // that is really there.
    out.depth.reserve(std::min<std::size_t>(std::size_t(width) * height, std::size_t{1} << 22));
    std::vector<unsigned char> row(static_cast<std::size_t>(line));
    for (std::uint32_t y = 0; y < height; ++y) {
        if (TIFFReadScanline(tiff.get(), row.data(), y, 0) != 1) {
            fail(ErrorCode::format, path, "TIFF data ends early (row " + std::to_string(y) + " unreadable)");
        }
        out.depth.resize(out.depth.size() + width);
        float* dst = out.depth.data() + std::size_t(y) * width;
        for (std::uint32_t x = 0; x < width; ++x) {
            if (is_float) {
                std::memcpy(dst + x, row.data() + 4 * std::size_t(x), 4);
            } else {
                std::uint16_t v = 0;
                std::memcpy(&v, row.data() + 2 * std::size_t(x), 2);
                dst[x] = float(v);
            }
        }
    }
    return out;
}

}  // namespace

DepthImage read_depth_image(const std::filesystem::path& path) {
    const std::string ext = detail::lower_extension(path);
    if (ext == ".png") return detail::guard_reader(path, [&] { return from_png(path); });
    if (ext == ".tif" || ext == ".tiff") return detail::guard_reader(path, [&] { return from_tiff(path); });
    fail(ErrorCode::format, path, "unsupported depth image format '" + ext + "' (16-bit .png, or .tif/.tiff)");
}

void write_tiff_float(const std::filesystem::path& path, const float* depth, int width, int height) {
    if (depth == nullptr || width <= 0 || height <= 0) {
        fail(ErrorCode::invalid_argument, path, "write_tiff_float needs data and a positive size");
    }
    TIFFSetErrorHandler(nullptr);
    TIFFSetWarningHandler(nullptr);
    // Into a temporary file renamed over `path` once complete: a failure leaves the old file or none.
    detail::write_atomically(path, [&](const std::filesystem::path& temporary) {
        const std::unique_ptr<TIFF, TiffCloser> tiff(TIFFOpen(temporary.c_str(), "w"));
        if (!tiff) fail(ErrorCode::io, path, "cannot open for writing");
        TIFFSetField(tiff.get(), TIFFTAG_IMAGEWIDTH, std::uint32_t(width));
        TIFFSetField(tiff.get(), TIFFTAG_IMAGELENGTH, std::uint32_t(height));
        TIFFSetField(tiff.get(), TIFFTAG_SAMPLESPERPIXEL, std::uint16_t(1));
        TIFFSetField(tiff.get(), TIFFTAG_BITSPERSAMPLE, std::uint16_t(32));
        TIFFSetField(tiff.get(), TIFFTAG_SAMPLEFORMAT, std::uint16_t(SAMPLEFORMAT_IEEEFP));
        TIFFSetField(tiff.get(), TIFFTAG_PHOTOMETRIC, std::uint16_t(PHOTOMETRIC_MINISBLACK));
        TIFFSetField(tiff.get(), TIFFTAG_PLANARCONFIG, std::uint16_t(PLANARCONFIG_CONTIG));
        TIFFSetField(tiff.get(), TIFFTAG_ROWSPERSTRIP, std::uint32_t(1));
        std::vector<float> row(static_cast<std::size_t>(width));
        for (int y = 0; y < height; ++y) {
            std::memcpy(row.data(), depth + std::size_t(y) * std::size_t(width), row.size() * sizeof(float));
            if (TIFFWriteScanline(tiff.get(), row.data(), std::uint32_t(y), 0) != 1) {
                fail(ErrorCode::io, path, "writing row " + std::to_string(y) + " failed");
            }
        }
        // TIFFClose reports nothing: the directory and the buffered rows are written here, where a failure shows.
        if (TIFFFlush(tiff.get()) != 1) fail(ErrorCode::io, path, "writing the image failed");
    });
}

DepthView depth_view(const DepthImage& image, const Intrinsics& k, double metres_per_unit) {
    DepthView v;
    v.depth = image.depth.data();
    v.format = DepthFormat::f32;
    v.width = image.width;
    v.height = image.height;
    v.metres_per_unit = metres_per_unit;
    v.fx = k.fx;
    v.fy = k.fy;
    v.cx = k.cx;
    v.cy = k.cy;
    return v;
}

PointCloud depth_to_cloud(const DepthImage& image, const Intrinsics& k, double metres_per_unit) {
    if (image.width < 1 || image.height < 1 ||
        image.depth.size() != std::size_t(image.width) * std::size_t(image.height)) {
        throw Error(ErrorCode::invalid_argument, "depth_to_cloud: the depth image is " + std::to_string(image.width) +
                                                     " x " + std::to_string(image.height) + " with " +
                                                     std::to_string(image.depth.size()) + " samples");
    }
    const DepthView camera = depth_view(image, k, metres_per_unit);
    (void)check_depth_camera(camera);
    const double mm_per_unit = metres_per_unit * 1000.0;
    PointCloud cloud;
    cloud.width = image.width;
    cloud.height = image.height;
    cloud.points.assign(3 * image.depth.size(), std::numeric_limits<float>::quiet_NaN());
    for (int v = 0; v < image.height; ++v) {
        for (int u = 0; u < image.width; ++u) {
            const std::size_t i = std::size_t(v) * std::size_t(image.width) + std::size_t(u);
            const double d = image.depth[i];
            if (!(d > 0) || !std::isfinite(d)) continue;
            const double z = d * mm_per_unit;
            cloud.points[3 * i + 0] = float((u - k.cx) * z / k.fx);
            cloud.points[3 * i + 1] = float((v - k.cy) * z / k.fy);
            cloud.points[3 * i + 2] = float(z);
        }
    }
    return cloud;
}

}  // namespace pyrseg::io
