// pyrseg.io: the file formats of pyrseg/io.hpp as numpy arrays. (.npy needs none: numpy.save and numpy.load.)
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include "arrays.hpp"
#include "bindings.hpp"
#include "pyrseg/io.hpp"

namespace pyrseg::python {
namespace {

namespace fs = std::filesystem;

// (points, normals) as H x W x 3 float32 arrays; normals None when the file has none.
py::tuple cloud_tuple(const io::PointCloud& c) {
    py::object normals = py::none();
    if (!c.normals.empty()) normals = array_of(c.normals.data(), c.height, c.width, 3);
    return py::make_tuple(array_of(c.points.data(), c.height, c.width, 3), normals);
}

// An H x W x 3 array as a packed float32 cloud (numpy converts when it must).
void fill_xyz(const py::object& a, const char* what, int& width, int& height, std::vector<float>& dst) {
    const auto arr = py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(a);
    if (!arr || arr.ndim() != 3 || arr.shape(2) != 3) {
        throw py::value_error(std::string(what) + " must be an H x W x 3 float array");
    }
    if (width >= 0 && (arr.shape(0) != height || arr.shape(1) != width)) {
        throw py::value_error(std::string(what) + " must have the points' shape");
    }
    height = int(arr.shape(0));
    width = int(arr.shape(1));
    dst.assign(arr.data(), arr.data() + arr.size());
}

io::PointCloud cloud_of(const py::object& points, const py::object& normals) {
    io::PointCloud c;
    c.width = -1;
    fill_xyz(points, "points", c.width, c.height, c.points);
    if (!normals.is_none()) fill_xyz(normals, "normals", c.width, c.height, c.normals);
    return c;
}

// Labels (H x W uint32, or None) checked against the cloud's size, kept alive by `keep`.
const std::uint32_t* labels_of(const py::object& labels, int width, int height,
                               py::array_t<std::uint32_t, py::array::c_style>& keep) {
    if (labels.is_none()) return nullptr;
    keep = py::array_t<std::uint32_t, py::array::c_style | py::array::forcecast>::ensure(labels);
    if (!keep || keep.ndim() != 2 || keep.shape(0) != height || keep.shape(1) != width) {
        throw py::value_error("labels must be an H x W uint32 array of the cloud's size");
    }
    return keep.data();
}

template <class T>
py::array_t<T, py::array::c_style> image_of(const py::object& a, const char* what, int channels) {
    auto arr = py::array_t<T, py::array::c_style | py::array::forcecast>::ensure(a);
    const bool ok = arr && (channels == 1 ? arr.ndim() == 2 : arr.ndim() == 3 && arr.shape(2) == channels);
    if (!ok) {
        throw py::value_error(std::string(what) + " must be " + (channels == 1 ? "H x W" : "H x W x 3"));
    }
    return arr;
}

io::PcdEncoding encoding_of(const std::string& name) {
    if (name == "ascii") return io::PcdEncoding::ascii;
    if (name == "binary") return io::PcdEncoding::binary;
    if (name == "binary_compressed") return io::PcdEncoding::binary_compressed;
    throw py::value_error("encoding must be 'ascii', 'binary' or 'binary_compressed', got '" + name + "'");
}

}  // namespace

void bind_io(py::module_& io) {
    io.doc() = "pyrseg's file formats (pyrseg/io.hpp): PCD, PLY, depth images (16-bit PNG, TIFF), PNG, statistics.";
    py::class_<io::Intrinsics>(io, "Intrinsics", kLocal)
        .def(py::init([](double fx, double fy, double cx, double cy) {
                 return io::Intrinsics{fx, fy, cx, cy};
             }),
             py::arg("fx"), py::arg("fy"), py::arg("cx"), py::arg("cy"))
        .def_readwrite("fx", &io::Intrinsics::fx)
        .def_readwrite("fy", &io::Intrinsics::fy)
        .def_readwrite("cx", &io::Intrinsics::cx)
        .def_readwrite("cy", &io::Intrinsics::cy)
        .def("__repr__", [](const io::Intrinsics& k) {
            return "pyrseg.io.Intrinsics(fx=" + std::to_string(k.fx) + ", fy=" + std::to_string(k.fy) +
                   ", cx=" + std::to_string(k.cx) + ", cy=" + std::to_string(k.cy) + ")";
        });

    io.def(
        "read_pcd", [](const fs::path& path) { return cloud_tuple(io::read_pcd(path)); }, py::arg("path"),
        "An organized PCD file as (points, normals): H x W x 3 float32 arrays, normals None when absent.");
    io.def(
        "read_ply", [](const fs::path& path) { return cloud_tuple(io::read_ply(path)); }, py::arg("path"),
        "An organized PLY file as (points, normals), as read_pcd.");
    io.def(
        "read_npy_cloud", [](const fs::path& path) { return cloud_tuple(io::read_npy_cloud(path)); }, py::arg("path"),
        "An H x W x 3 or H x W x 6 .npy cloud as (points, normals).");
    io.def(
        "write_pcd",
        [](const fs::path& path, const py::object& points, const py::object& normals, const py::object& labels,
           const std::string& encoding) {
            const io::PointCloud c = cloud_of(points, normals);
            py::array_t<std::uint32_t, py::array::c_style> keep;
            io::write_pcd(path, c, labels_of(labels, c.width, c.height, keep), encoding_of(encoding));
        },
        py::arg("path"), py::arg("points"), py::arg("normals") = py::none(), py::arg("labels") = py::none(),
        py::arg("encoding") = "binary",
        "Writes x y z (normal_x normal_y normal_z with normals; a label field, PCL's PointXYZL, with labels).");
    io.def(
        "write_ply",
        [](const fs::path& path, const py::object& points, const py::object& normals, const py::object& labels,
           bool binary) {
            const io::PointCloud c = cloud_of(points, normals);
            py::array_t<std::uint32_t, py::array::c_style> keep;
            io::write_ply(path, c, labels_of(labels, c.width, c.height, keep), binary);
        },
        py::arg("path"), py::arg("points"), py::arg("normals") = py::none(), py::arg("labels") = py::none(),
        py::arg("binary") = true, "Writes an organized PLY, coloured by segment when labels are given.");
    io.def(
        "read_depth_image",
        [](const fs::path& path) -> py::array {
            const io::DepthImage d = io::read_depth_image(path);
            if (d.floating) return array_of(d.depth.data(), d.height, d.width);
            // Integer samples come back as they were stored, uint16: segment_depth reads them in place.
            std::vector<std::uint16_t> samples(d.depth.size());
            for (std::size_t i = 0; i < samples.size(); ++i) {
                samples[i] = d.depth[i] > 0 ? static_cast<std::uint16_t>(d.depth[i]) : std::uint16_t{0};
            }
            return array_of(samples.data(), d.height, d.width);
        },
        py::arg("path"),
        "A depth image: a 16-bit PNG or TIFF as H x W uint16 (the file's units), a float TIFF as H x W float32.");
    io.def(
        "write_tiff_float",
        [](const fs::path& path, const py::object& depth) {
            const auto a = image_of<float>(depth, "depth", 1);
            io::write_tiff_float(path, a.data(), int(a.shape(1)), int(a.shape(0)));
        },
        py::arg("path"), py::arg("depth"), "Writes an H x W float32 depth image as a TIFF.");
    io.def(
        "write_png_gray16",
        [](const fs::path& path, const py::object& image) {
            const auto a = image_of<std::uint16_t>(image, "image", 1);
            io::write_png_gray16(path, a.data(), int(a.shape(1)), int(a.shape(0)));
        },
        py::arg("path"), py::arg("image"), "Writes an H x W uint16 image (a depth map) as a 16-bit PNG.");
    io.def(
        "write_png_gray8",
        [](const fs::path& path, const py::object& image) {
            const auto a = image_of<std::uint8_t>(image, "image", 1);
            io::write_png_gray8(path, a.data(), int(a.shape(1)), int(a.shape(0)));
        },
        py::arg("path"), py::arg("image"), "Writes an H x W uint8 image as an 8-bit PNG.");
    io.def(
        "write_png_rgb",
        [](const fs::path& path, const py::object& image) {
            const auto a = image_of<std::uint8_t>(image, "image", 3);
            io::write_png_rgb(path, a.data(), int(a.shape(1)), int(a.shape(0)));
        },
        py::arg("path"), py::arg("image"), "Writes an H x W x 3 uint8 RGB image as a PNG.");
    io.def(
        "read_png",
        [](const fs::path& path) -> py::array {
            const io::Image img = io::read_png(path);
            const int channels = img.channels == 1 ? 0 : img.channels;
            if (img.bit_depth == 16) {
                std::vector<std::uint16_t> samples(img.data.size() / 2);
                std::memcpy(samples.data(), img.data.data(), samples.size() * 2);
                return array_of(samples.data(), img.height, img.width, channels);
            }
            return array_of(img.data.data(), img.height, img.width, channels);
        },
        py::arg("path"), "A PNG as H x W (gray) or H x W x C, uint8 or uint16.");
    io.def(
        "colorize_labels",
        [](const py::object& labels) {
            const auto a = image_of<std::uint32_t>(labels, "labels", 1);
            const std::vector<std::uint8_t> rgb = io::colorize_labels(a.data(), int(a.shape(1)), int(a.shape(0)));
            return array_of(rgb.data(), int(a.shape(0)), int(a.shape(1)), 3);
        },
        py::arg("labels"), "H x W x 3 uint8 colours of H x W labels: 0 black, each label its own fixed colour.");
    io.def(
        "label_color",
        [](std::uint32_t label) {
            const auto c = io::label_color(label);
            return py::make_tuple(c[0], c[1], c[2]);
        },
        py::arg("label"), "The (r, g, b) colour of a label, as colorize_labels and write_ply use it.");
    io.def(
        "write_segment_stats",
        [](const fs::path& path, const py::object& segments, int width, int height, double unit_mm,
           const std::string& source) {
            const auto a = py::array::ensure(segments);
            if (!a || a.ndim() != 1 || !a.dtype().equal(segment_stats_dtype())) {
                throw py::value_error("segments must be a 1-D array of pyrseg.segment_stats_dtype (Result.segments)");
            }
            std::vector<SegmentStats> stats(std::size_t(a.shape(0)));
            for (std::size_t i = 0; i < stats.size(); ++i) {
                std::memcpy(&stats[i], static_cast<const char*>(a.data()) + py::ssize_t(i) * a.strides(0),
                            sizeof(SegmentStats));
            }
            io::write_segment_stats(path, stats, io::SegmentTable{width, height, unit_mm, source});
        },
        py::arg("path"), py::arg("segments"), py::arg("width"), py::arg("height"), py::arg("unit_mm") = 1.0,
        py::arg("source") = "", "Per-segment statistics as CSV (a .csv path) or JSON.");
    io.def("parse_intrinsics", &io::parse_intrinsics, py::arg("text"), "'fx,fy,cx,cy' as Intrinsics.");
    io.def("read_intrinsics", &io::read_intrinsics, py::arg("path"), py::arg("node") = "",
           "Intrinsics from an OpenCV FileStorage file (XML, YAML, JSON).");
    io.def(
        "depth_to_cloud",
        [](const py::object& depth, const io::Intrinsics& k, double mm_per_unit) {
            const auto a = image_of<float>(depth, "depth", 1);
            io::DepthImage d;
            d.width = int(a.shape(1));
            d.height = int(a.shape(0));
            d.depth.assign(a.data(), a.data() + a.size());
            const io::PointCloud c = io::depth_to_cloud(d, k, mm_per_unit);
            return array_of(c.points.data(), c.height, c.width, 3);
        },
        py::arg("depth"), py::arg("intrinsics"), py::arg("mm_per_unit"),
        "An H x W x 3 float32 cloud in millimetres from a depth image (NaN where no data).");
}

}  // namespace pyrseg::python
