// What `pyrseg segment` reads: organized PCD and PLY clouds, and depth images back-projected with pinhole intrinsics.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>
#include <string_view>

#include "pyrseg/depth.hpp"
#include "pyrseg/error.hpp"
#include "tools/cloud_stats.hpp"
#include "tools/commands.hpp"

namespace pyrseg::cli {

const char* const kInputHelp =
    "Inputs:\n"
    "  .pcd                  organized PCD (ascii, binary or binary_compressed), fields x y z and optionally\n"
    "                        normal_x normal_y normal_z (otherwise normals are estimated)\n"
    "  .ply                  organized PLY (ascii or binary), vertex x y z and optionally nx ny nz; the grid from\n"
    "                        obj_info num_cols/num_rows (PCL), the camera viewport (PCL) or Photoneo's Width/Height\n"
    "  .npy                  a NumPy float32/float64 array, H x W x 3 (points) or H x W x 6 (points, normals);\n"
    "                        or H x W uint16/float32: a depth map, read like a depth image\n"
    "  .png, .tif, .tiff     a depth image: 16-bit PNG, or a TIFF of 16-bit or 32-bit float samples; 0 = no data.\n"
    "                        Back-projected on the backend's device (DepthView). Needs the camera's intrinsics:\n"
    "  --intrinsics FX,FY,CX,CY   focal lengths and principal point in pixels\n"
    "  --calib FILE[:NODE]   an OpenCV FileStorage file (XML/YAML/JSON, up to 1 MiB) with a 3x3 camera matrix or\n"
    "                        fx fy cx cy; NODE names the matrix when the file has several (e.g. IR_intrinsic_params)\n"
    "  --metres-per-unit M   the depth of one sample unit in metres, as depth SDKs state it (RealSense's depth\n"
    "                        scale, get_depth_scale()): 0.001 for millimetres (default for 16-bit images), 0.0002\n"
    "                        for TUM RGB-D (1/5000 m), 1 for metres (default for float images). A value that puts\n"
    "                        the frame's median depth outside 0.05 to 100 m is refused, with the value that fits.\n"
    "  --depth-scale S       deprecated: depth units per metre, the inverse of --metres-per-unit (1000 for\n"
    "                        millimetres); still read, with a warning saying what to pass instead\n"
    "  --color PATH          the colour camera's image registered to the frame (an 8-bit RGB or RGBA PNG of the\n"
    "                        frame's size; RealSense: aligned to depth), for the colour edge term\n"
    "                        (--color-edge-threshold). In a batch PATH is a folder: frame NAME_depth.EXT or NAME.EXT\n"
    "                        takes PATH/NAME_color.png, and a frame without one is segmented without colour\n"
    "\n";

const std::set<std::string> kInputValueOptions = {"intrinsics", "calib", "metres-per-unit", "depth-scale"};

namespace {

std::string lower_extension(const std::filesystem::path& path) {
    std::string ext = path.extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    return ext;
}

// The frame's samples as DepthView reads them: 16-bit images stay integers (their float copies are exact), float
// images stay floats.
DepthFrame depth_frame(const io::DepthImage& image, const io::Intrinsics& k, double metres_per_unit) {
    DepthFrame f;
    if (image.floating) {
        f.f32 = image.depth;
    } else {
        f.u16.resize(image.depth.size());
        for (std::size_t i = 0; i < image.depth.size(); ++i) f.u16[i] = static_cast<std::uint16_t>(image.depth[i]);
    }
    f.metres_per_unit = metres_per_unit;
    f.intrinsics = k;
    return f;
}

std::string number_text(double v) {
    char text[32];
    std::snprintf(text, sizeof text, "%.4g", v);
    return text;
}

// The samples' unit: --metres-per-unit, else the deprecated --depth-scale inverted, else the default of the
// sample type; checked with the intrinsics as the library checks every depth frame (pyrseg::check_depth_camera: a
// scale that puts the median depth out of every depth sensor's range, intrinsics in the wrong order), its message
// saying which option gave the scale, its warnings printed.
double depth_metres_per_unit(const Args& args, const io::DepthImage& image, const io::Intrinsics& k,
                             const std::filesystem::path& path) {
    double metres_per_unit = image.floating ? 1.0 : 0.001;
    std::string given = image.floating ? "float samples read as metres (the default)"
                                       : "16-bit samples read as millimetres (the default)";
    if (auto m = args.number("metres-per-unit")) {
        if (!(*m > 0) || !std::isfinite(*m)) {
            throw UsageError{"--metres-per-unit must be a number > 0 (0.001 for millimetres), got '" +
                             *args.value("metres-per-unit") + "'"};
        }
        metres_per_unit = *m;
        given = "--metres-per-unit " + *args.value("metres-per-unit");
    } else if (auto s = args.number("depth-scale")) {
        if (!(*s > 0) || !std::isfinite(*s)) {
            throw UsageError{
                "--depth-scale must be a number > 0; better, pass --metres-per-unit (0.001 for "
                "millimetres)"};
        }
        metres_per_unit = 1.0 / *s;
        given = "--depth-scale " + *args.value("depth-scale") +
                " (depth units per metre: " + number_text(metres_per_unit) + " m per unit)";
    }
    const DepthView camera = io::depth_view(image, k, metres_per_unit);
    try {
        for (const std::string& w : check_depth_camera(camera).warnings) {
            std::fprintf(stderr, "pyrseg: warning: %s: %s (the depth scale: %s)\n", path.string().c_str(), w.c_str(),
                         given.c_str());
        }
    } catch (const Error& e) {
        std::string message = e.what();
        constexpr std::string_view kPrefix = "pyrseg: ";  // Error's constructor adds it again
        if (message.starts_with(kPrefix)) message.erase(0, kPrefix.size());
        throw Error(e.code(), path.string() + ": with " + given + ", " + message);
    }
    return metres_per_unit;
}

// A NumPy depth map (H x W uint16 or float32) as a depth image.
io::DepthImage depth_map_of(const io::NpyArray& npy, const std::filesystem::path& path) {
    io::DepthImage image;
    image.height = int(npy.shape[0]);
    image.width = int(npy.shape[1]);
    const std::size_t n = npy.shape[0] * npy.shape[1];
    image.depth.resize(n);
    if (npy.dtype == "<u2") {
        for (std::size_t i = 0; i < n; ++i) {
            std::uint16_t v = 0;
            std::memcpy(&v, npy.bytes.data() + 2 * i, 2);
            image.depth[i] = float(v);
        }
    } else if (npy.dtype == "<f4") {
        std::memcpy(image.depth.data(), npy.bytes.data(), 4 * n);
        image.floating = true;
    } else {
        throw Error(ErrorCode::format,
                    path.string() + ": a NumPy depth map must be uint16 or float32 (H x W), got '" + npy.dtype + "'");
    }
    return image;
}

bool is_cloud_extension(const std::string& ext) {
    return ext == ".pcd" || ext == ".npy" || ext == ".ply";
}

bool is_depth_image_extension(const std::string& ext) {
    return ext == ".png" || ext == ".tif" || ext == ".tiff";
}

io::Intrinsics intrinsics_from(const Args& args, const std::filesystem::path& input) {
    const auto text = args.value("intrinsics");
    const auto calib = args.value("calib");
    if (text && calib) throw UsageError{"give --intrinsics or --calib, not both"};
    if (text) return io::parse_intrinsics(*text);
    if (!calib) {
        throw Error(ErrorCode::invalid_argument,
                    input.string() +
                        ": a depth image needs the camera's intrinsics: --intrinsics FX,FY,CX,CY or "
                        "--calib FILE[:NODE]");
    }
    // FILE:NODE, unless the whole text names an existing file.
    std::string file = *calib;
    std::string node;
    const std::size_t colon = calib->rfind(':');
    if (colon != std::string::npos && !std::filesystem::exists(*calib)) {
        file = calib->substr(0, colon);
        node = calib->substr(colon + 1);
    }
    return io::read_intrinsics(file, node);
}

}  // namespace

DepthView DepthFrame::view(int width, int height) const {
    DepthView v;
    v.depth = u16.empty() ? static_cast<const void*>(f32.data()) : static_cast<const void*>(u16.data());
    v.format = u16.empty() ? DepthFormat::f32 : DepthFormat::u16;
    v.width = width;
    v.height = height;
    v.metres_per_unit = metres_per_unit;
    v.fx = intrinsics.fx;
    v.fy = intrinsics.fy;
    v.cx = intrinsics.cx;
    v.cy = intrinsics.cy;
    return v;
}

void check_input_options(const Args& args) {
    if (args.value("metres-per-unit") && args.value("depth-scale")) {
        throw UsageError{"give --metres-per-unit, not --depth-scale as well (it is deprecated)"};
    }
    if (auto s = args.number("depth-scale"); s && *s > 0 && std::isfinite(*s)) {
        std::fprintf(stderr,
                     "pyrseg: warning: --depth-scale is deprecated (it is depth units per metre, the inverse of the "
                     "depth scale SDKs state): --depth-scale %s is --metres-per-unit %s; pass that instead\n",
                     args.value("depth-scale")->c_str(), number_text(1.0 / *s).c_str());
    }
}

bool is_supported_input(const std::filesystem::path& path) {
    const std::string ext = lower_extension(path);
    return is_cloud_extension(ext) || is_depth_image_extension(ext);
}

namespace {

// --color's image for the frame at `input`: the file itself, or in a folder the frame's NAME_color.png (nothing when
// the folder has none).
std::vector<std::uint8_t> color_for(const std::filesystem::path& input, const Args& args, int width, int height) {
    const std::optional<std::string> option = args.value("color");
    if (!option) return {};
    std::filesystem::path path = *option;
    if (std::filesystem::is_directory(path)) {
        std::string name = input.stem().string();
        if (name.size() > 6 && name.ends_with("_depth")) name.resize(name.size() - 6);
        path /= name + "_color.png";
        if (!std::filesystem::exists(path)) return {};
    }
    const io::Image png = io::read_png(path);
    if (png.bit_depth != 8 || png.channels < 3) {
        throw Error(ErrorCode::format, path.string() + ": --color needs an 8-bit RGB or RGBA PNG, this one has " +
                                           std::to_string(png.channels) + " channel(s) of " +
                                           std::to_string(png.bit_depth) + " bits");
    }
    if (png.width != width || png.height != height) {
        throw Error(ErrorCode::size_mismatch, path.string() + ": the colour image is " + std::to_string(png.width) +
                                                  " x " + std::to_string(png.height) + " but the frame is " +
                                                  std::to_string(width) + " x " + std::to_string(height) +
                                                  " (register the colour to the depth: RealSense's align)");
    }
    const std::size_t pixels = std::size_t(width) * std::size_t(height);
    std::vector<std::uint8_t> rgb(3 * pixels);
    for (std::size_t i = 0; i < pixels; ++i) {
        for (std::size_t c = 0; c < 3; ++c) rgb[3 * i + c] = png.data[std::size_t(png.channels) * i + c];
    }
    return rgb;
}

LoadedInput load_frame(const std::filesystem::path& path, const Args& args) {
    const std::string ext = lower_extension(path);
    if (is_cloud_extension(ext)) {
        for (const std::string& option : kInputValueOptions) {
            if (args.value(option) && ext != ".npy") {
                std::string message = "--" + option;
                message += " applies to depth images, not to " + ext;
                throw UsageError{message};
            }
        }
        if (ext == ".npy") {
            const io::NpyArray npy = io::read_npy(path);
            if (npy.shape.size() != 2) return {io::read_npy_cloud(path), "NumPy cloud", false, std::nullopt};
            // H x W: a depth map, which needs intrinsics and takes --metres-per-unit like a depth image.
            if (args.value("unit-mm")) {
                throw UsageError{"--unit-mm applies to point clouds; a depth map's unit is set by --metres-per-unit"};
            }
            const io::DepthImage image = depth_map_of(npy, path);
            const io::Intrinsics k = intrinsics_from(args, path);
            const double metres_per_unit = depth_metres_per_unit(args, image, k, path);
            return {io::depth_to_cloud(image, k, metres_per_unit), "NumPy depth map", true,
                    depth_frame(image, k, metres_per_unit)};
        }
        if (ext == ".ply") return {io::read_ply(path), "PLY", false, std::nullopt};
        return {io::read_pcd(path), "PCD", false, std::nullopt};
    }
    if (is_depth_image_extension(ext)) {
        if (args.value("unit-mm")) {
            throw UsageError{"--unit-mm applies to point clouds; a depth image's unit is set by --metres-per-unit"};
        }
        const io::Intrinsics k = intrinsics_from(args, path);
        const io::DepthImage depth = io::read_depth_image(path);
        const double metres_per_unit = depth_metres_per_unit(args, depth, k, path);
        return {io::depth_to_cloud(depth, k, metres_per_unit), "depth image", true,
                depth_frame(depth, k, metres_per_unit)};
    }
    throw Error(ErrorCode::format, path.string() + ": unsupported input format '" + ext +
                                       "' (pyrseg reads .pcd, .ply and .npy clouds, and .png/.tif/.tiff depth images)");
}

}  // namespace

LoadedInput load_input(const std::filesystem::path& path, const Args& args) {
    LoadedInput loaded = load_frame(path, args);
    loaded.color = color_for(path, args, loaded.cloud.width, loaded.cloud.height);
    return loaded;
}

}  // namespace pyrseg::cli
