// pyrseg.io: the file formats of pyrseg/io.hpp as numpy arrays. (.npy needs none: numpy.save and numpy.load.)
#include <cfloat>
#include <climits>
#include <cstring>
#include <filesystem>
#include <limits>
#include <string>
#include <type_traits>
#include <vector>

#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include "args.hpp"
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

// A numeric array (bool, integers, floats) from anything numpy can make one of (as_array); TypeError for any other
// dtype.
py::array numeric(const char* function, const char* what, const py::object& obj) {
    py::array a = as_array(obj, std::string(function) + ": " + what);
    const char k = a.dtype().kind();
    if (k != 'b' && k != 'i' && k != 'u' && k != 'f') {
        throw py::type_error(std::string(function) + ": " + what + " must be a numeric array, got dtype " +
                             py::str(a.dtype()).cast<std::string>());
    }
    return a;
}

// `a` as a C-ordered array of T, refusing (ValueError naming the first such value, where it is, the writer and
// what it stores) any value T cannot hold exactly: numpy's cast would wrap 65536 to 0 in a 16-bit PNG, truncate
// 1.5 to 1, or round 1e300 to infinity. float64 values are rounded to float32 (what the formats store) as long as
// they stay finite.
template <class T>
py::array_t<T, py::array::c_style> exact(const py::array& a, const char* function, const char* what,
                                         const char* store) {
    using Out = py::array_t<T, py::array::c_style | py::array::forcecast>;
    if (a.dtype().equal(py::dtype::of<T>()) || a.size() == 0) return Out::ensure(a);
    const py::module_ np = py::module_::import("numpy");
    const char k = a.dtype().kind();
    const auto either = [&np](const py::object& x, const py::object& y) { return np.attr("logical_or")(x, y); };
    py::object bad = py::none();
    std::string range;
    if constexpr (std::is_integral_v<T>) {
        const py::int_ lo(std::numeric_limits<T>::min()), hi(std::numeric_limits<T>::max());
        range = "integers " + std::to_string(std::numeric_limits<T>::min()) + ".." +
                std::to_string(std::numeric_limits<T>::max());
        if (k != 'b') {
            bad = either(np.attr("less")(a, lo), np.attr("greater")(a, hi));
            if (k == 'f') {
                bad = either(bad, np.attr("logical_not")(np.attr("isfinite")(a)));
                bad = either(bad, np.attr("not_equal")(np.attr("floor")(a), a));
            }
        }
    } else {
        static_assert(std::is_same_v<T, float>);
        range = "float32: finite values within +-3.4e38 (NaN and infinities as they are), integers within +-2^24";
        if (k == 'f' && a.itemsize() > 4) {
            bad = np.attr("logical_and")(np.attr("isfinite")(a), np.attr("greater")(np.attr("abs")(a), FLT_MAX));
        } else if (k == 'i' || k == 'u') {
            const py::int_ limit(1L << 24);
            bad = either(np.attr("greater")(a, limit), np.attr("less")(a, -(1L << 24)));
        }
    }
    if (!bad.is_none() && np.attr("any")(bad).cast<bool>()) {
        const py::tuple where(np.attr("argwhere")(bad)[py::int_(0)].attr("tolist")());
        const py::object value = a[where].attr("item")();
        std::string at;
        for (const py::handle i : where) at += (at.empty() ? "" : ", ") + py::str(i).cast<std::string>();
        throw py::value_error(std::string(function) + ": " + what + " holds " + py::str(value).cast<std::string>() +
                              " at (" + at + "), which " + store + " cannot store exactly (it takes " + range + ")");
    }
    return Out::ensure(a);
}

// An H x W x 3 array as a packed float32 cloud.
void fill_xyz(const char* function, const py::object& obj, const char* what, const char* store, int& width, int& height,
              std::vector<float>& dst) {
    const py::array a = numeric(function, what, obj);
    if (a.ndim() != 3 || a.shape(2) != 3) {
        throw py::value_error(std::string(function) + ": " + what + " must be an H x W x 3 float array");
    }
    if (width >= 0 && (a.shape(0) != height || a.shape(1) != width)) {
        throw py::value_error(std::string(function) + ": " + what + " must have the points' shape");
    }
    const auto arr = exact<float>(a, function, what, store);
    height = int(arr.shape(0));
    width = int(arr.shape(1));
    dst.assign(arr.data(), arr.data() + arr.size());
}

io::PointCloud cloud_of(const char* function, const char* store, const py::object& points, const py::object& normals) {
    io::PointCloud c;
    c.width = -1;
    fill_xyz(function, points, "points", store, c.width, c.height, c.points);
    if (!normals.is_none()) fill_xyz(function, normals, "normals", store, c.width, c.height, c.normals);
    return c;
}

// Labels (H x W, values 0..2^32-1, or None) checked against the cloud's size, kept alive by `keep`.
const std::uint32_t* labels_of(const char* function, const char* store, const py::object& labels, int width, int height,
                               py::array_t<std::uint32_t, py::array::c_style>& keep, const char* what = "labels") {
    if (labels.is_none()) return nullptr;
    const py::array a = numeric(function, what, labels);
    if (a.ndim() != 2 || a.shape(0) != height || a.shape(1) != width) {
        throw py::value_error(std::string(function) + ": " + what + " must be an H x W array of the cloud's size");
    }
    keep = exact<std::uint32_t>(a, function, what, store);
    return keep.data();
}

// write_pcd's fields=: a dict of name -> H x W array, each appended to `fields` as a uint32 field, its array kept
// alive in `keep`.
void append_named_fields(const char* function, const py::object& given, int width, int height,
                         std::vector<py::array_t<std::uint32_t, py::array::c_style>>& keep,
                         std::vector<io::PcdField>& fields) {
    if (given.is_none()) return;
    if (!py::isinstance<py::dict>(given)) {
        throw py::type_error(std::string(function) + ": fields must be a dict of name -> H x W array, got " +
                             std::string(py::str(given.get_type().attr("__name__"))));
    }
    const py::dict named = given.cast<py::dict>();
    keep.reserve(keep.size() + named.size());
    for (const auto& [name, values] : named) {
        if (!py::isinstance<py::str>(name))
            throw py::type_error(std::string(function) + ": a field's name must be a str");
        const std::string text = name.cast<std::string>();
        const std::string what = "field '" + text + "'";
        keep.emplace_back();
        fields.push_back({text, labels_of(function, "a PCD file", py::reinterpret_borrow<py::object>(values), width,
                                          height, keep.back(), what.c_str())});
    }
}

template <class T>
py::array_t<T, py::array::c_style> image_of(const char* function, const py::object& obj, const char* what, int channels,
                                            const char* store) {
    const py::array a = numeric(function, what, obj);
    const bool ok = channels == 1 ? a.ndim() == 2 : a.ndim() == 3 && a.shape(2) == channels;
    if (!ok) {
        throw py::value_error(std::string(function) + ": " + what + " must be " +
                              (channels == 1 ? "H x W" : "H x W x 3"));
    }
    return exact<T>(a, function, what, store);
}

io::PcdEncoding encoding_of(const std::string& name) {
    if (name == "ascii") return io::PcdEncoding::ascii;
    if (name == "binary") return io::PcdEncoding::binary;
    if (name == "binary_compressed") return io::PcdEncoding::binary_compressed;
    throw py::value_error("write_pcd(): encoding must be 'ascii', 'binary' or 'binary_compressed', got '" + name + "'");
}

constexpr const char* kIntrinsicsUninitialised =
    "the Intrinsics were not initialised: call pyrseg.io.Intrinsics(fx, fy, cx, cy)";

io::Intrinsics& intrinsics_of(py::handle self) {
    return live<io::Intrinsics>(self, "pyrseg.io.Intrinsics", kIntrinsicsUninitialised);
}

// The functions' parameters (Args binds them; their docstrings show them).
constexpr Param kPath[] = {{"path"}};
constexpr Param kWritePcd[] = {
    {"path"}, {"points"}, {"normals", "None"}, {"labels", "None"}, {"encoding", "'binary'"}, {"fields", "None"}};
constexpr Param kWritePly[] = {{"path"}, {"points"}, {"normals", "None"}, {"labels", "None"}, {"binary", "True"}};
constexpr Param kWriteDepth[] = {{"path"}, {"depth"}};
constexpr Param kWriteImage[] = {{"path"}, {"image"}};
constexpr Param kLabels[] = {{"labels"}};
constexpr Param kLabel[] = {{"label"}};
constexpr Param kStats[] = {{"path"}, {"segments"}, {"width"}, {"height"}, {"unit_mm", "1.0"}, {"source", "''"}};
constexpr Param kParseIntrinsics[] = {{"text"}};
constexpr Param kReadIntrinsics[] = {{"path"}, {"node", "''"}};
// As Segmenter.segment_depth's: one vocabulary for a depth camera (an Intrinsics unpacks into fx, fy, cx, cy).
constexpr Param kDepthToCloud[] = {{"depth"}, {"fx"}, {"fy"}, {"cx"}, {"cy"}, {"metres_per_unit"}};

// A reader: path -> what read(path) gives.
template <class Read>
void def_reader(py::module_& io, const char* name, const char* function, const char* doc, Read read) {
    def_args(io, name, kPath, doc, [function, read](const py::args& args, const py::kwargs& kwargs) {
        const Args a(function, kPath, args, kwargs);
        return read(a.path(0));
    });
}

// A writer of one image: (path, image) -> write(path, image as T).
template <class T, class Write>
void def_image_writer(py::module_& io, const char* name, const char* function, std::span<const Param> params,
                      int channels, const char* store, const char* doc, Write write) {
    def_args(io, name, params, doc,
             [function, params, channels, store, write](const py::args& args, const py::kwargs& kwargs) {
                 const Args a(function, params, args, kwargs);
                 const fs::path path = a.path(0);
                 const auto image = image_of<T>(function, a.object(1), a.name(1), channels, store);
                 write(path, image.data(), int(image.shape(1)), int(image.shape(0)));
             });
}

}  // namespace

void bind_io(py::module_& io) {
    io.doc() = "pyrseg's file formats (pyrseg/io.hpp): PCD, PLY, depth images (16-bit PNG, TIFF), PNG, statistics.";
    py::class_<io::Intrinsics> intrinsics(io, "Intrinsics", kLocal);
    intrinsics
        .def(py::init([](const py::object& fx, const py::object& fy, const py::object& cx, const py::object& cy) {
                 const char* f = "Intrinsics()";
                 return io::Intrinsics{number(f, "fx", fx), number(f, "fy", fy), number(f, "cx", cx),
                                       number(f, "cy", cy)};
             }),
             py::arg("fx"), py::arg("fy"), py::arg("cx"), py::arg("cy"))
        .def("__repr__", [](const py::object& self) {
            if (py::isinstance<io::Intrinsics>(self) && !initialised(self)) {
                return std::string("<pyrseg.io.Intrinsics, not initialised>");
            }
            const io::Intrinsics& k = intrinsics_of(self);
            return "pyrseg.io.Intrinsics(fx=" + std::to_string(k.fx) + ", fy=" + std::to_string(k.fy) +
                   ", cx=" + std::to_string(k.cx) + ", cy=" + std::to_string(k.cy) + ")";
        });
    const auto field = [&intrinsics](const char* name, double io::Intrinsics::*member) {
        intrinsics.def_property(
            name, [member](const py::object& self) { return intrinsics_of(self).*member; },
            [member, name](const py::object& self, const py::object& v) {
                intrinsics_of(self).*member = number("Intrinsics", name, v);
            });
    };
    field("fx", &io::Intrinsics::fx);
    field("fy", &io::Intrinsics::fy);
    field("cx", &io::Intrinsics::cx);
    field("cy", &io::Intrinsics::cy);
    // fx, fy, cx, cy in the order Segmenter.segment_depth and depth_to_cloud take them: seg.segment_depth(depth, *k,
    // metres_per_unit=0.001).
    intrinsics.def("__iter__", [](const py::object& self) {
        const io::Intrinsics& k = intrinsics_of(self);
        return py::iter(py::make_tuple(k.fx, k.fy, k.cx, k.cy));
    });
    refuse_second_init(intrinsics, "pyrseg.io.Intrinsics");

    def_reader(io, "read_pcd", "read_pcd()",
               "An organized PCD file as (points, normals): H x W x 3 float32 arrays, normals None when absent.",
               [](const fs::path& path) { return cloud_tuple(io::read_pcd(path)); });
    def_reader(io, "read_ply", "read_ply()", "An organized PLY file as (points, normals), as read_pcd.",
               [](const fs::path& path) { return cloud_tuple(io::read_ply(path)); });
    def_reader(io, "read_npy_cloud", "read_npy_cloud()", "An H x W x 3 or H x W x 6 .npy cloud as (points, normals).",
               [](const fs::path& path) { return cloud_tuple(io::read_npy_cloud(path)); });
    def_args(
        io, "write_pcd", kWritePcd,
        "Writes x y z (normal_x normal_y normal_z with normals; a label field, PCL's PointXYZL, with labels; "
        "then one uint32 field per item of fields, a dict of name -> H x W array, in its order). Points and "
        "normals are stored as float32, labels and fields as uint32: a value they cannot hold is a ValueError.",
        [](const py::args& args, const py::kwargs& kwargs) {
            const char* f = "write_pcd()";
            const Args a(f, kWritePcd, args, kwargs);
            const fs::path path = a.path(0);
            const io::PcdEncoding encoding = encoding_of(a.text(4, "binary"));
            const io::PointCloud c = cloud_of(f, "a PCD file", a.object(1), a.object(2));
            std::vector<py::array_t<std::uint32_t, py::array::c_style>> keep(1);
            std::vector<io::PcdField> fields;
            if (const std::uint32_t* labels = labels_of(f, "a PCD file", a.object(3), c.width, c.height, keep[0])) {
                fields.push_back({"label", labels});
            }
            append_named_fields(f, a.object(5), c.width, c.height, keep, fields);
            io::write_pcd(path, c, fields, encoding);
        });
    def_args(io, "write_ply", kWritePly,
             "Writes an organized PLY, coloured by segment when labels are given (points and normals float32, labels "
             "uint32: a value they cannot hold is a ValueError).",
             [](const py::args& args, const py::kwargs& kwargs) {
                 const char* f = "write_ply()";
                 const Args a(f, kWritePly, args, kwargs);
                 const fs::path path = a.path(0);
                 const bool binary = a.boolean(4, true);
                 const io::PointCloud c = cloud_of(f, "a PLY file", a.object(1), a.object(2));
                 py::array_t<std::uint32_t, py::array::c_style> keep;
                 io::write_ply(path, c, labels_of(f, "a PLY file", a.object(3), c.width, c.height, keep), binary);
             });
    def_reader(io, "read_depth_image", "read_depth_image()",
               "A depth image: a 16-bit PNG or TIFF as H x W uint16 (the file's units), a float TIFF as H x W float32.",
               [](const fs::path& path) -> py::array {
                   const io::DepthImage d = io::read_depth_image(path);
                   if (d.floating) return array_of(d.depth.data(), d.height, d.width);
                   // Integer samples come back as they were stored, uint16: segment_depth reads them in place.
                   std::vector<std::uint16_t> samples(d.depth.size());
                   for (std::size_t i = 0; i < samples.size(); ++i) {
                       samples[i] = d.depth[i] > 0 ? static_cast<std::uint16_t>(d.depth[i]) : std::uint16_t{0};
                   }
                   return array_of(samples.data(), d.height, d.width);
               });
    def_image_writer<float>(io, "write_tiff_float", "write_tiff_float()", kWriteDepth, 1, "a float32 TIFF",
                            "Writes an H x W depth image as a float32 TIFF (float64 rounded to float32; a finite "
                            "value beyond float32's range is a ValueError).",
                            io::write_tiff_float);
    def_image_writer<std::uint16_t>(io, "write_png_gray16", "write_png_gray16()", kWriteImage, 1, "a 16-bit PNG",
                                    "Writes an H x W image of integers 0..65535 (a depth map; any numeric dtype whose "
                                    "values are such integers) as a 16-bit PNG; another value is a ValueError.",
                                    io::write_png_gray16);
    def_image_writer<std::uint8_t>(io, "write_png_gray8", "write_png_gray8()", kWriteImage, 1, "an 8-bit PNG",
                                   "Writes an H x W image of integers 0..255 as an 8-bit PNG; another value is a "
                                   "ValueError.",
                                   io::write_png_gray8);
    def_image_writer<std::uint8_t>(io, "write_png_rgb", "write_png_rgb()", kWriteImage, 3, "an 8-bit RGB PNG",
                                   "Writes an H x W x 3 RGB image of integers 0..255 as a PNG; another value is a "
                                   "ValueError.",
                                   io::write_png_rgb);
    def_reader(io, "read_png", "read_png()", "A PNG as H x W (gray) or H x W x C, uint8 or uint16.",
               [](const fs::path& path) -> py::array {
                   const io::Image img = io::read_png(path);
                   const int channels = img.channels == 1 ? 0 : img.channels;
                   if (img.bit_depth == 16) {
                       std::vector<std::uint16_t> samples(img.data.size() / 2);
                       std::memcpy(samples.data(), img.data.data(), samples.size() * 2);
                       return array_of(samples.data(), img.height, img.width, channels);
                   }
                   return array_of(img.data.data(), img.height, img.width, channels);
               });
    def_args(io, "colorize_labels", kLabels,
             "H x W x 3 uint8 colours of H x W labels (integers 0..2^32-1): 0 black, each label its own fixed colour.",
             [](const py::args& args, const py::kwargs& kwargs) {
                 const char* f = "colorize_labels()";
                 const Args a(f, kLabels, args, kwargs);
                 const auto l = image_of<std::uint32_t>(f, a.object(0), "labels", 1, "uint32 labels");
                 const std::vector<std::uint8_t> rgb = io::colorize_labels(l.data(), int(l.shape(1)), int(l.shape(0)));
                 return array_of(rgb.data(), int(l.shape(0)), int(l.shape(1)), 3);
             });
    def_args(io, "label_color", kLabel, "The (r, g, b) colour of a label, as colorize_labels and write_ply use it.",
             [](const py::args& args, const py::kwargs& kwargs) {
                 const char* f = "label_color()";
                 const Args a(f, kLabel, args, kwargs);
                 const auto label = std::uint32_t(integer(f, "label", a.object(0), 0, UINT32_MAX));
                 const auto c = io::label_color(label);
                 return py::make_tuple(c[0], c[1], c[2]);
             });
    def_args(io, "write_segment_stats", kStats, "Per-segment statistics as CSV (a .csv path) or JSON.",
             [](const py::args& args, const py::kwargs& kwargs) {
                 const char* f = "write_segment_stats()";
                 const Args a(f, kStats, args, kwargs);
                 const fs::path path = a.path(0);
                 const int width = int(integer(f, "width", a.object(2), INT_MIN, INT_MAX));
                 const int height = int(integer(f, "height", a.object(3), INT_MIN, INT_MAX));
                 const double unit_mm = a.number(4, 1.0);
                 const std::string source = a.text(5, "");
                 const py::object segments = a.object(1);
                 const auto s = segments.is_none() ? py::array() : py::array::ensure(segments);
                 if (!s || s.ndim() != 1 || !s.dtype().equal(segment_stats_dtype())) {
                     PyErr_Clear();
                     throw py::value_error(
                         "write_segment_stats(): segments must be a 1-D array of pyrseg.segment_stats_dtype "
                         "(Result.segments)");
                 }
                 std::vector<SegmentStats> stats(std::size_t(s.shape(0)));
                 for (std::size_t i = 0; i < stats.size(); ++i) {
                     std::memcpy(&stats[i], static_cast<const char*>(s.data()) + py::ssize_t(i) * s.strides(0),
                                 sizeof(SegmentStats));
                 }
                 io::write_segment_stats(path, stats, io::SegmentTable{width, height, unit_mm, source});
             });
    def_args(io, "parse_intrinsics", kParseIntrinsics, "'fx,fy,cx,cy' as Intrinsics.",
             [](const py::args& args, const py::kwargs& kwargs) {
                 const Args a("parse_intrinsics()", kParseIntrinsics, args, kwargs);
                 return io::parse_intrinsics(a.text(0, ""));
             });
    def_args(io, "read_intrinsics", kReadIntrinsics, "Intrinsics from an OpenCV FileStorage file (XML, YAML, JSON).",
             [](const py::args& args, const py::kwargs& kwargs) {
                 const Args a("read_intrinsics()", kReadIntrinsics, args, kwargs);
                 return io::read_intrinsics(a.path(0), a.text(1, ""));
             });
    def_args(io, "depth_to_cloud", kDepthToCloud,
             "An H x W x 3 float32 cloud in millimetres from a depth image (NaN where no data). The camera as in "
             "Segmenter.segment_depth: the intrinsics in pixels (an Intrinsics k unpacks into them: "
             "depth_to_cloud(depth, *k, 0.001)) and metres_per_unit, the depth of one sample unit in metres (0.001 "
             "for millimetres).",
             [](const py::args& args, const py::kwargs& kwargs) {
                 const char* f = "depth_to_cloud()";
                 // Before the arguments are counted: depth_to_cloud(depth, k, 0.001) was this function's form.
                 if (args.size() >= 2 && py::isinstance<io::Intrinsics>(args[1])) {
                     throw py::type_error(
                         "depth_to_cloud(): fx must be a number: the camera is fx, fy, cx, cy, metres_per_unit as in "
                         "Segmenter.segment_depth; unpack an Intrinsics k with depth_to_cloud(depth, *k, "
                         "metres_per_unit)");
                 }
                 const Args a(f, kDepthToCloud, args, kwargs);
                 const io::Intrinsics k{a.number(1), a.number(2), a.number(3), a.number(4)};
                 const double metres_per_unit = a.number(5);
                 const auto depth = image_of<float>(f, a.object(0), "depth", 1, "float32 depth");
                 io::DepthImage d;
                 d.width = int(depth.shape(1));
                 d.height = int(depth.shape(0));
                 d.depth.assign(depth.data(), depth.data() + depth.size());
                 const io::PointCloud c = io::depth_to_cloud(d, k, metres_per_unit);
                 return array_of(c.points.data(), c.height, c.width, 3);
             });
}

}  // namespace pyrseg::python
