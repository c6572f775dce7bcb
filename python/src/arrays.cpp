#include "arrays.hpp"

#include "args.hpp"

#include <algorithm>
#include <bit>
#include <cstdlib>
#include <cstring>
#include <string>
#include <utility>

namespace pyrseg::python {
namespace {

std::string shape_text(const py::array& a) {
    std::string s = "(";
    for (py::ssize_t i = 0; i < a.ndim(); ++i) s += (i > 0 ? ", " : "") + std::to_string(a.shape(i));
    return s + (a.ndim() == 1 ? ",)" : ")");
}

std::string dtype_text(const py::array& a) {
    return py::str(a.dtype()).cast<std::string>();
}

bool is_float(const py::array& a) {
    return is_native(a.dtype(), 'f', 4) || is_native(a.dtype(), 'f', 8);
}

// Element (y, x, c) of a float32 or float64 array of any strides, as float.
float float_at(const py::array& a, py::ssize_t y, py::ssize_t x, py::ssize_t c) {
    const auto* base = static_cast<const char*>(a.data());
    const char* p = base + y * a.strides(0) + x * a.strides(1) + c * a.strides(2);
    if (a.itemsize() == 4) {
        float v = 0;
        std::memcpy(&v, p, sizeof v);
        return v;
    }
    double v = 0;
    std::memcpy(&v, p, sizeof v);
    return static_cast<float>(v);
}

// Channels [first, first + 3) of an H x W x C array into a packed H x W x 3 float32 buffer.
void pack_xyz(const py::array& a, py::ssize_t first, std::vector<float>& dst) {
    const py::ssize_t h = a.shape(0), w = a.shape(1);
    dst.resize(std::size_t(h * w * 3));
    float* out = dst.data();
    for (py::ssize_t y = 0; y < h; ++y) {
        for (py::ssize_t x = 0; x < w; ++x) {
            for (py::ssize_t c = 0; c < 3; ++c) *out++ = float_at(a, y, x, first + c);
        }
    }
}

// Bytes of an H x W array of 1-byte elements into a packed buffer.
void pack_bytes(const py::array& a, std::vector<std::uint8_t>& dst) {
    const py::ssize_t h = a.shape(0), w = a.shape(1);
    dst.resize(std::size_t(h * w));
    const auto* base = static_cast<const char*>(a.data());
    for (py::ssize_t y = 0; y < h; ++y) {
        for (py::ssize_t x = 0; x < w; ++x) {
            dst[std::size_t(y * w + x)] = static_cast<std::uint8_t>(base[y * a.strides(0) + x * a.strides(1)]);
        }
    }
}

// The steps that describe an H x W x C float32 array in place, or false when pyrseg's views cannot: channels not
// adjacent, points overlapping or backwards, rows closer than a row, an unaligned start.
bool float_steps(const py::array& a, std::size_t& point_step, std::size_t& row_step) {
    if (!is_native(a.dtype(), 'f', 4) || a.strides(2) != 4) return false;
    if (reinterpret_cast<std::uintptr_t>(a.data()) % alignof(float) != 0) return false;
    const py::ssize_t h = a.shape(0), w = a.shape(1);
    // A dimension of length 1 has no meaningful stride (numpy may give it any): take the packed one.
    const py::ssize_t ps = w > 1 ? a.strides(1) : 12;
    if (ps < 12 || ps % 4 != 0) return false;
    const py::ssize_t row_bytes = (w - 1) * ps + 12;
    const py::ssize_t rs = h > 1 ? a.strides(0) : w * ps;
    if (rs < row_bytes || rs % 4 != 0) return false;
    point_step = std::size_t(ps);
    row_step = std::size_t(rs);
    return true;
}

// The bytes [first, last) an array's elements span.
std::pair<std::uintptr_t, std::uintptr_t> extent(const py::array& a) {
    auto first = reinterpret_cast<std::uintptr_t>(a.data());
    auto last = first;
    for (py::ssize_t i = 0; i < a.ndim(); ++i) {
        if (a.shape(i) == 0) return {first, first};
        const py::ssize_t span = (a.shape(i) - 1) * a.strides(i);
        if (span < 0) {
            first -= std::uintptr_t(-span);
        } else {
            last += std::uintptr_t(span);
        }
    }
    return {first, last + std::uintptr_t(a.itemsize())};
}

// The labels are written after the frame has read its input, so they would not be wrong: but the input would be
// overwritten by what was computed from it, which no caller means.
void refuse_shared(const py::array& out, const py::array& in, const char* what) {
    const auto [a0, a1] = extent(out);
    const auto [b0, b1] = extent(in);
    if (a1 <= b0 || b1 <= a0) return;
    // The spans meet, which interleaved fields do without sharing an element (labels into PCL's PointXYZL beside
    // the points read in place): numpy decides whether any byte is shared; a problem too hard for it counts as one.
    bool shared = true;
    try {
        shared = py::module_::import("numpy").attr("shares_memory")(out, in).cast<bool>();
    } catch (const py::error_already_set&) {
        shared = true;
    }
    if (shared) {
        throw py::value_error(std::string("out= shares memory with ") + what +
                              ": the labels would overwrite the frame they are computed from; give out= an array of "
                              "its own (numpy.empty((H, W), numpy.uint32))");
    }
}

}  // namespace

bool is_native(const py::dtype& dtype, char kind, int bytes) {
    const char order = dtype.byteorder();
    const char foreign = std::endian::native == std::endian::little ? '>' : '<';
    return dtype.kind() == kind && dtype.itemsize() == bytes && order != foreign;
}

CloudInput::CloudInput(const py::object& points, const py::object& normals, int width, int height)
    : points_(as_array(points, "points")) {
    if (points_.ndim() != 3 || (points_.shape(2) != 3 && points_.shape(2) != 4 && points_.shape(2) != 6)) {
        throw py::value_error(
            "points must be H x W x 3 (xyz), H x W x 4 (xyz and a pad, PCL's PointXYZ) or H x W x "
            "6 (xyz then normals), got shape " +
            shape_text(points_) + "; give other layouts as views: points=cloud[..., :3], normals=cloud[..., 4:7]");
    }
    if (!is_float(points_)) throw py::type_error("points must be float32 or float64, got " + dtype_text(points_));
    height_ = int(points_.shape(0));
    width_ = int(points_.shape(1));
    if (width >= 0 && (width != width_ || height != height_)) {
        raise(ErrorCode::size_mismatch, "the cloud is " + std::to_string(width_) + " x " + std::to_string(height_) +
                                            " (shape " + shape_text(points_) + ") but the Segmenter was created for " +
                                            std::to_string(width) + " x " + std::to_string(height));
    }
    normals_in_points_ = points_.shape(2) == 6;
    if (!normals.is_none()) {
        if (normals_in_points_) {
            throw py::value_error("normals given twice: points is H x W x 6 (xyz then normals) and normals= is set");
        }
        normals_ = as_array(normals, "normals");
        const py::array& n = *normals_;
        if (n.ndim() != 3 || n.shape(0) != height_ || n.shape(1) != width_ || n.shape(2) != 3) {
            throw py::value_error("normals must be H x W x 3 like the points " + shape_text(points_) + ", got " +
                                  shape_text(n));
        }
        if (!is_float(n)) throw py::type_error("normals must be float32 or float64, got " + dtype_text(n));
    }
    has_normals_ = normals_in_points_ || !normals.is_none();
    copy_ = !float_steps(points_, point_step_, row_step_);
    if (!copy_ && !normals.is_none()) {
        std::size_t ps = 0, rs = 0;
        // One CloudView describes both arrays: normals in place only in the points' very layout.
        copy_ = !float_steps(*normals_, ps, rs) || ps != point_step_ || rs != row_step_;
    }
}

void CloudInput::refuse_alias(const py::array& out) const {
    refuse_shared(out, points_, "the points");
    if (normals_) refuse_shared(out, *normals_, "the normals");
}

CloudView CloudInput::view(Scratch& scratch) const {
    CloudView v;
    v.width = width_;
    v.height = height_;
    if (copy_) {
        pack_xyz(points_, 0, scratch.points);
        v.points = scratch.points.data();
        if (normals_in_points_) {
            pack_xyz(points_, 3, scratch.normals);
            v.normals = scratch.normals.data();
        } else if (has_normals_) {
            pack_xyz(*normals_, 0, scratch.normals);
            v.normals = scratch.normals.data();
        }
        return v;
    }
    v.points = static_cast<const float*>(points_.data());
    if (normals_in_points_) {
        v.normals = v.points + 3;
    } else if (has_normals_) {
        v.normals = static_cast<const float*>(normals_->data());
    }
    v.point_step_bytes = point_step_;
    v.row_step_bytes = row_step_;
    return v;
}

DepthInput::DepthInput(const py::object& depth) : depth_(as_array(depth, "depth")) {
    if (depth_.ndim() == 3 && depth_.shape(2) == 1) {
        depth_ = py::array::ensure(depth_.attr("squeeze")(2));
    }
    if (depth_.ndim() != 2) throw py::value_error("depth must be H x W, got shape " + shape_text(depth_));
    const py::dtype dt = depth_.dtype();
    u16_ = is_native(dt, 'u', 2);
    // Other integers are converted: numpy.asarray(PIL.Image.open(png)) is int32 for a 16-bit PNG, OpenCV's and
    // the SDKs' are uint16 but in another byte order or widened by arithmetic.
    integer_ = !u16_ && (dt.kind() == 'i' || dt.kind() == 'u') && dt.itemsize() <= 8;
    if (!u16_ && !integer_ && !is_float(depth_)) {
        throw py::type_error(
            "depth must be an integer dtype (uint16 read in place, others converted) or float32 "
            "(float64 converted), got " +
            dtype_text(depth_));
    }
    height_ = int(depth_.shape(0));
    width_ = int(depth_.shape(1));
    if (integer_) {
        u16_ = true;
        copy_ = true;
        is_signed_ = dt.kind() == 'i';
        swapped_ = dt.itemsize() > 1 && !is_native(dt, dt.kind(), int(dt.itemsize()));
        return;
    }
    const py::ssize_t sample = u16_ ? 2 : 4;
    const bool packed_samples = width_ <= 1 || depth_.strides(1) == sample;
    const bool rows_ok = height_ <= 1 || depth_.strides(0) >= width_ * sample;
    copy_ = depth_.itemsize() != sample || !packed_samples || !rows_ok;
}

void DepthInput::refuse_alias(const py::array& out) const {
    refuse_shared(out, depth_, "the depth image");
}

namespace {

// Integer samples of any size and byte order into uint16; ValueError for one outside 0..65535. No Python calls.
void integer_depth(const py::array& a, bool is_signed, bool swapped, std::vector<std::uint16_t>& dst) {
    const py::ssize_t h = a.shape(0), w = a.shape(1);
    const auto size = std::size_t(a.itemsize());
    const bool little = (std::endian::native == std::endian::little) != swapped;
    const auto* base = static_cast<const unsigned char*>(a.data());
    dst.resize(std::size_t(h * w));
    for (py::ssize_t y = 0; y < h; ++y) {
        for (py::ssize_t x = 0; x < w; ++x) {
            const unsigned char* p = base + y * a.strides(0) + x * a.strides(1);
            std::uint64_t bits = 0;
            for (std::size_t i = 0; i < size; ++i) bits |= std::uint64_t(p[little ? i : size - 1 - i]) << (8 * i);
            const bool negative = is_signed && ((bits >> (8 * size - 1)) & 1U) != 0;
            if (negative || bits > 65535) {
                const std::string value =
                    negative ? std::to_string(size == 8 ? std::int64_t(bits)
                                                        : std::int64_t(bits) - (std::int64_t(1) << (8 * size)))
                             : std::to_string(bits);
                throw py::value_error("depth holds " + value + " at (" + std::to_string(y) + ", " + std::to_string(x) +
                                      "): integer depth samples must be 0..65535 (uint16, the sensor's units); "
                                      "read 16-bit depth images with pyrseg.io.read_depth_image, which gives uint16");
            }
            dst[std::size_t(y * w + x)] = std::uint16_t(bits);
        }
    }
}

}  // namespace

DepthView DepthInput::view(Scratch& scratch) const {
    DepthView v;
    v.width = width_;
    v.height = height_;
    v.format = u16_ ? DepthFormat::u16 : DepthFormat::f32;
    if (integer_) {
        integer_depth(depth_, is_signed_, swapped_, scratch.depth_u16);
        v.depth = scratch.depth_u16.data();
        return v;
    }
    if (!copy_) {
        v.depth = depth_.data();
        v.row_step_bytes = height_ > 1 ? std::size_t(depth_.strides(0)) : 0;
        return v;
    }
    const auto* base = static_cast<const char*>(depth_.data());
    const std::size_t n = std::size_t(width_) * std::size_t(height_);
    if (u16_) {
        scratch.depth_u16.resize(n);
        for (int y = 0; y < height_; ++y) {
            for (int x = 0; x < width_; ++x) {
                std::memcpy(&scratch.depth_u16[std::size_t(y) * std::size_t(width_) + std::size_t(x)],
                            base + y * depth_.strides(0) + x * depth_.strides(1), 2);
            }
        }
        v.depth = scratch.depth_u16.data();
        return v;
    }
    scratch.depth.resize(n);
    for (int y = 0; y < height_; ++y) {
        for (int x = 0; x < width_; ++x) {
            const char* p = base + y * depth_.strides(0) + x * depth_.strides(1);
            float f = 0;
            if (depth_.itemsize() == 4) {
                std::memcpy(&f, p, 4);
            } else {
                double d = 0;
                std::memcpy(&d, p, 8);
                f = static_cast<float>(d);
            }
            scratch.depth[std::size_t(y) * std::size_t(width_) + std::size_t(x)] = f;
        }
    }
    v.depth = scratch.depth.data();
    return v;
}

ColorInput::ColorInput(const py::object& color, int width, int height) {
    if (color.is_none()) return;
    color_ = as_array(color, "color");
    const py::array& a = *color_;
    if (a.ndim() != 3 || a.shape(2) != 3) {
        throw py::value_error("color must be H x W x 3 (R, G, B), got shape " + shape_text(a));
    }
    if (!is_native(a.dtype(), 'u', 1)) {
        throw py::type_error("color must be uint8 (8-bit R, G, B), got " + dtype_text(a));
    }
    if (a.shape(0) != height || a.shape(1) != width) {
        throw py::value_error("color is " + std::to_string(a.shape(1)) + " x " + std::to_string(a.shape(0)) +
                              " (W x H) but the frame is " + std::to_string(width) + " x " + std::to_string(height) +
                              ": register the colour to the depth (RealSense: align)");
    }
    const bool packed = (width <= 1 || a.strides(1) == 3) && a.strides(2) == 1;
    const bool rows_ok = height <= 1 || a.strides(0) >= 3 * py::ssize_t(width);
    copy_ = !packed || !rows_ok;
}

const std::uint8_t* ColorInput::data(Scratch& scratch, std::size_t& row_step_bytes) const {
    row_step_bytes = 0;
    if (!color_) return nullptr;
    const py::array& a = *color_;
    const auto* base = static_cast<const std::uint8_t*>(a.data());
    if (!copy_) {
        row_step_bytes = a.shape(0) > 1 ? std::size_t(a.strides(0)) : 0;
        return base;
    }
    const py::ssize_t h = a.shape(0), w = a.shape(1);
    scratch.color.resize(std::size_t(h * w * 3));
    for (py::ssize_t y = 0; y < h; ++y) {
        for (py::ssize_t x = 0; x < w; ++x) {
            for (py::ssize_t c = 0; c < 3; ++c) {
                scratch.color[std::size_t((y * w + x) * 3 + c)] =
                    base[y * a.strides(0) + x * a.strides(1) + c * a.strides(2)];
            }
        }
    }
    return scratch.color.data();
}

void ColorInput::refuse_alias(const py::array& out) const {
    if (color_) refuse_shared(out, *color_, "the colour image");
}

MaskInput::MaskInput(const py::object& mask, const py::object& valid) : mask_(as_array(mask, "mask")) {
    const auto check = [](const py::array& a, const char* what) {
        if (a.ndim() != 2) throw py::value_error(std::string(what) + " must be H x W, got shape " + shape_text(a));
        if (!is_native(a.dtype(), 'b', 1) && !is_native(a.dtype(), 'u', 1)) {
            throw py::type_error(std::string(what) + " must be bool or uint8, got " + dtype_text(a));
        }
    };
    check(mask_, "mask");
    height_ = int(mask_.shape(0));
    width_ = int(mask_.shape(1));
    const auto in_place = [this](const py::array& a) {
        return (width_ <= 1 || a.strides(1) == 1) && (height_ <= 1 || a.strides(0) >= width_);
    };
    copy_ = !in_place(mask_);
    if (!valid.is_none()) {
        valid_ = as_array(valid, "valid");
        const py::array& v = *valid_;
        check(v, "valid");
        if (v.shape(0) != height_ || v.shape(1) != width_) {
            throw py::value_error("valid must have the mask's shape " + shape_text(mask_) + ", got " + shape_text(v));
        }
        has_valid_ = true;
        // One MaskView row stride serves both.
        copy_ = copy_ || !in_place(v) || (height_ > 1 && v.strides(0) != mask_.strides(0));
    }
}

void MaskInput::refuse_alias(const py::array& out) const {
    refuse_shared(out, mask_, "the mask");
    if (valid_) refuse_shared(out, *valid_, "valid");
}

MaskView MaskInput::view(Scratch& scratch) const {
    MaskView v;
    v.width = width_;
    v.height = height_;
    if (copy_) {
        pack_bytes(mask_, scratch.fillable);
        v.fillable = scratch.fillable.data();
        if (has_valid_) {
            pack_bytes(*valid_, scratch.valid);
            v.valid = scratch.valid.data();
        }
        return v;
    }
    v.fillable = static_cast<const unsigned char*>(mask_.data());
    if (has_valid_) v.valid = static_cast<const unsigned char*>(valid_->data());
    v.row_stride = height_ > 1 ? std::size_t(mask_.strides(0)) : 0;
    return v;
}

py::array check_labels_out(const py::object& out, int width, int height) {
    if (!py::isinstance<py::array>(out))
        throw py::type_error("out must be a numpy array (numpy.empty((H, W), uint32))");
    auto a = py::reinterpret_borrow<py::array>(out);
    if (!is_native(a.dtype(), 'u', 4)) throw py::type_error("out must be uint32, got " + dtype_text(a));
    if (a.ndim() != 2 || a.shape(0) != height || a.shape(1) != width) {
        throw py::value_error("out must have shape (" + std::to_string(height) + ", " + std::to_string(width) +
                              "), got " + shape_text(a));
    }
    if (!a.writeable()) throw py::value_error("out is read-only");
    // Distinct elements: steps of at least an element along the dimension of the smaller step, and along the other
    // at least that dimension's whole span (a transposed array passes; rows that overlap do not).
    py::ssize_t inner = std::abs(a.strides(1)), outer = std::abs(a.strides(0));
    py::ssize_t inner_n = width, outer_n = height;
    if (outer_n > 1 && (inner_n <= 1 || outer < inner)) {
        std::swap(inner, outer);
        std::swap(inner_n, outer_n);
    }
    const bool distinct = (inner_n <= 1 || inner >= 4) && (outer_n <= 1 || outer >= inner_n * inner);
    if (!distinct) {
        throw py::value_error("out= has elements that overlap (strides (" + std::to_string(a.strides(0)) + ", " +
                              std::to_string(a.strides(1)) + ") for shape " + shape_text(a) +
                              "): one label would overwrite another; give an array whose elements are distinct "
                              "(numpy.empty((H, W), numpy.uint32))");
    }
    return a;
}

void copy_labels(const std::uint32_t* labels, py::array& out) {
    const py::ssize_t h = out.shape(0), w = out.shape(1);
    auto* base = static_cast<char*>(out.mutable_data());
    const std::size_t row_bytes = std::size_t(w) * sizeof(std::uint32_t);
    if (out.strides(1) == 4 && out.strides(0) == w * 4) {
        std::memcpy(base, labels, row_bytes * std::size_t(h));
        return;
    }
    for (py::ssize_t y = 0; y < h; ++y) {
        if (out.strides(1) == 4) {
            std::memcpy(base + y * out.strides(0), labels + y * w, row_bytes);
            continue;
        }
        for (py::ssize_t x = 0; x < w; ++x) {
            std::memcpy(base + y * out.strides(0) + x * out.strides(1), labels + y * w + x, 4);
        }
    }
}

}  // namespace pyrseg::python
