#pragma once
// numpy arrays as pyrseg's views: in place when the array's layout is one the view can describe (any row and point
// strides, PCL's padded points), else converted into buffers the caller keeps (sized once, reused every frame).
#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include "bindings.hpp"
#include "pyrseg/cloud.hpp"
#include "pyrseg/depth.hpp"

namespace pyrseg::python {

// Buffers for inputs that cannot be viewed in place. They keep their capacity, so a loop of frames that need
// converting (float64 clouds, say) allocates only on its first frame.
struct Scratch {
    std::vector<float> points, normals, depth;
    std::vector<std::uint16_t> depth_u16;
    std::vector<std::uint8_t> fillable, valid, color;
};

// A frame's conversion, prepared with the GIL held (the arrays inspected, references kept) and run without it: the
// copies it needs read only raw memory.
class CloudInput {
public:
    // points: H x W x 3 (xyz), 4 (xyz and a pad, PCL's PointXYZ) or 6 (xyz then normals); float32 or float64.
    // normals: None or H x W x 3, float32 or float64. width/height < 0: take the array's.
    CloudInput(const py::object& points, const py::object& normals, int width, int height);
    // The view, after copying what must be copied into `scratch`. No Python calls: run it without the GIL.
    CloudView view(Scratch& scratch) const;
    [[nodiscard]] bool copies() const { return copy_; }
    [[nodiscard]] int width() const { return width_; }
    [[nodiscard]] int height() const { return height_; }
    // ValueError when out= shares memory with the points or normals.
    void refuse_alias(const py::array& out) const;

private:
    py::array points_;
    // Optional, as std::optional: a default py::array would be a new numpy array (and two allocations) a frame.
    std::optional<py::array> normals_;
    bool has_normals_ = false;
    bool normals_in_points_ = false;  // H x W x 6
    bool copy_ = false;
    int width_ = 0, height_ = 0;
    std::size_t point_step_ = 0, row_step_ = 0;
};

class DepthInput {
public:
    // depth: H x W (or H x W x 1) uint16 or float32 in place, float64 converted to float32, any other integer
    // dtype converted to uint16 (its values must be 0..65535: view() raises ValueError for one that is not).
    explicit DepthInput(const py::object& depth);
    DepthView view(Scratch& scratch) const;  // format, size, samples and row step; the caller adds the camera
    [[nodiscard]] bool copies() const { return copy_; }
    void refuse_alias(const py::array& out) const;

private:
    py::array depth_;
    bool copy_ = false;
    bool u16_ = false;      // the samples are uint16 (DepthFormat::u16), in place or converted
    bool integer_ = false;  // another integer dtype, converted to uint16
    bool is_signed_ = false, swapped_ = false;
    int width_ = 0, height_ = 0;
};

// A frame's colour image (color=): None, or H x W x 3 uint8 R, G, B registered to the frame's pixels; read in place
// when each row's pixels are packed (3 bytes apart), else copied.
class ColorInput {
public:
    ColorInput(const py::object& color, int width, int height);
    // The first byte (null for None) and the row step, after copying into `scratch` when needed. No Python calls.
    const std::uint8_t* data(Scratch& scratch, std::size_t& row_step_bytes) const;
    void refuse_alias(const py::array& out) const;
    [[nodiscard]] bool given() const { return color_.has_value(); }

private:
    std::optional<py::array> color_;
    bool copy_ = false;
};

class MaskInput {
public:
    // mask, valid: H x W bool or uint8 (non-zero: set); valid None for every pixel valid.
    MaskInput(const py::object& mask, const py::object& valid);
    MaskView view(Scratch& scratch) const;
    [[nodiscard]] bool copies() const { return copy_; }
    void refuse_alias(const py::array& out) const;

private:
    py::array mask_;
    std::optional<py::array> valid_;
    bool has_valid_ = false;
    bool copy_ = false;
    int width_ = 0, height_ = 0;
};

// out=: a writable H x W uint32 array, any strides whose elements are distinct (as_strided views may repeat them:
// one label would overwrite another). Raises TypeError/ValueError naming the problem.
py::array check_labels_out(const py::object& out, int width, int height);
// Writes W x H labels (row-major, packed) into `out` (as check_labels_out accepted it). No Python calls: it runs
// without the GIL.
void copy_labels(const std::uint32_t* labels, py::array& out);

// An H x W x C (C = 0: H x W) C-ordered array of T holding a copy of `data`.
template <class T>
py::array_t<T> array_of(const T* data, int height, int width, int channels = 0) {
    std::vector<py::ssize_t> shape{height, width};
    if (channels > 0) shape.push_back(channels);
    return py::array_t<T>(shape, data);
}

// numpy's dtype of native-order T.
[[nodiscard]] bool is_native(const py::dtype& dtype, char kind, int bytes);

}  // namespace pyrseg::python
