// Depth images in (16-bit PNG through the PNG reader, TIFF through libtiff) and their back-projection.
#include <tiffio.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <string>

#include "file_util.hpp"
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

DepthImage from_tiff(const std::filesystem::path& path) {
    (void)detail::read_file(path);  // a clear io error for a missing file, a directory or a FIFO
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
    if (width == 0 || height == 0 || width > 1u << 16 || height > 1u << 16) {
        fail(ErrorCode::format, path,
             "TIFF size " + std::to_string(width) + " x " + std::to_string(height) + " is not a depth image size");
    }
    const tmsize_t line = TIFFScanlineSize(tiff.get());
    if (line != tmsize_t(width) * (bits / 8)) fail(ErrorCode::format, path, "unsupported TIFF layout (tiled?)");
    DepthImage out{int(width), int(height), {}, is_float};
    out.depth.resize(std::size_t(width) * height);
    std::vector<unsigned char> row(static_cast<std::size_t>(line));
    for (std::uint32_t y = 0; y < height; ++y) {
        if (TIFFReadScanline(tiff.get(), row.data(), y, 0) != 1) {
            fail(ErrorCode::format, path, "TIFF data ends early (row " + std::to_string(y) + " unreadable)");
        }
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
    std::string ext = path.extension().string();
    for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
    if (ext == ".png") return from_png(path);
    if (ext == ".tif" || ext == ".tiff") return from_tiff(path);
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

PointCloud depth_to_cloud(const DepthImage& image, const Intrinsics& k, double mm_per_unit) {
    if (!(k.fx > 0) || !(k.fy > 0) || !std::isfinite(k.fx) || !std::isfinite(k.fy) || !std::isfinite(k.cx) ||
        !std::isfinite(k.cy)) {
        throw Error(ErrorCode::invalid_argument, "intrinsics need finite fx, fy > 0 and finite cx, cy");
    }
    if (!(mm_per_unit > 0) || !std::isfinite(mm_per_unit)) {
        throw Error(ErrorCode::invalid_argument, "the depth scale must be finite and > 0");
    }
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
