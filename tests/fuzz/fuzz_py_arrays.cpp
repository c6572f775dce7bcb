// The Python module's array entry points (python/src/arrays.hpp, args.hpp) as a hostile caller reaches them: numpy
// arrays of any dtype, shape and strides (negative, zero, overlapping, unaligned) over a buffer of the harness's own,
// given to CloudInput, DepthInput and MaskInput (and their views), to check_labels_out and copy_labels, to the
// argument helpers, and to a real small Segmenter's segment, segment_depth and segment_mask through the compiled
// bindings (python/src/segmenter.cpp, in an embedded module). An embedded interpreter (with numpy) is started once.
//
// The contract: every call succeeds or raises TypeError, ValueError or pyrseg.Error; a success means what the
// headers say (a view of the array's very values, in place only inside its buffer; labels in out='s elements and
// nowhere else; the inputs never written). Anything else (a crash, a sanitizer report, another exception, a broken
// promise) is a finding. Python allocates through malloc (PYTHONMALLOC=malloc) so that ASan sees its memory too, and
// each array's buffer is a heap block of exactly its size, so that a read or write outside it is an ASan report.
#include <fuzzer/FuzzedDataProvider.h>
#include <pybind11/embed.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "pyrseg/error.hpp"
#include "python/src/args.hpp"
#include "python/src/arrays.hpp"
#include "python/src/bindings.hpp"
#include "tests/fuzz/fuzz_input.hpp"

namespace py = pybind11;
namespace python = pyrseg::python;
using pyrseg::fuzz::expect;

// pyrseg.Error and the Segmenter, as the module binds them (only what the frames need: not io or synthetic).
PYBIND11_EMBEDDED_MODULE(pyrseg_fuzz, m) {
    python::bind_errors(m);
    python::bind_segmenter(m);
}

namespace {

// The dtypes a caller might pass: the ones pyrseg takes (native float32/64, uint16, uint8, bool, uint32 for out=),
// the same in the other byte order, other integers (converted for depth), and ones it refuses.
const char* const kDtypes[] = {"<f4", ">f4", "<f8", ">f8", "<u2", ">u2", "<i4", ">i4", "<i8", ">i8", "|u1",
                               "|b1", "<f2", "<u4", ">u4", "|i1", "<i2", "<u8", "<c8", "O",   "V3",  "<U2"};
constexpr int kDtypeCount = int(sizeof kDtypes / sizeof kDtypes[0]);
constexpr std::size_t kMaxBuffer = 64 * 1024;
constexpr int kMaxDim = 9;

struct Interpreter {
    py::object numpy, ndarray, error, segmenter_type;
    std::map<std::pair<int, int>, py::object> segmenters;  // one per frame size, made when first needed
    std::vector<py::object> values;                        // scalars of every kind, for the argument helpers
};

Interpreter& interpreter() {
    static Interpreter* it = [] {
        // Before the interpreter starts: its allocations through malloc (ASan's), one CPU thread, the CPU backend.
        setenv("PYTHONMALLOC", "malloc", 1);
        setenv("PYRSEG_THREADS", "1", 1);
        setenv("PYRSEG_BACKEND", "cpu", 1);
        py::initialize_interpreter();  // never finalised: the process ends with the fuzzer
        auto* i = new Interpreter;
        i->numpy = py::module_::import("numpy");
        i->ndarray = i->numpy.attr("ndarray");
        // The camera checks' warnings are a normal outcome (and would fill the log).
        py::module_::import("warnings").attr("simplefilter")("ignore");
        const py::module_ m = py::module_::import("pyrseg_fuzz");
        i->error = m.attr("Error");
        i->segmenter_type = m.attr("Segmenter");
        const py::object np = i->numpy;
        const py::object builtins = py::module_::import("builtins");
        i->values = {
            py::int_(0),
            py::int_(1),
            py::int_(-1),
            py::int_(65535),
            py::reinterpret_steal<py::object>(PyLong_FromString("123456789012345678901234567890", nullptr, 10)),
            py::float_(0.0),
            py::float_(1.5),
            py::float_(-0.0),
            py::float_(std::nan("")),
            py::float_(INFINITY),
            py::float_(1e308),
            py::bool_(true),
            py::bool_(false),
            py::none(),
            py::str("1"),
            py::bytes("1"),
            np.attr("float32")(0.5),
            np.attr("float16")(2),
            np.attr("int64")(-7),
            np.attr("uint8")(200),
            np.attr("bool_")(true),
            np.attr("array")(3.0),
            np.attr("array")(py::make_tuple(1, 2)),
            py::module_::import("fractions").attr("Fraction")(1, 3),
            py::module_::import("decimal").attr("Decimal")("2.5"),
            builtins.attr("complex")(1, 1),
            py::list(),
            builtins.attr("object")()};
        return i;
    }();
    return *it;
}

// A Python exception is a normal answer when it is one of these.
bool allowed(const py::error_already_set& e) {
    return e.matches(PyExc_TypeError) || e.matches(PyExc_ValueError) || e.matches(interpreter().error);
}

[[noreturn]] void unexpected(const py::error_already_set& e) {
    std::fprintf(stderr, "fuzz_py_arrays: unexpected Python exception: %s\n", e.what());
    __builtin_trap();
}

// Runs f; its refusals (the C++ exceptions the conversions throw, and Python's) are normal, anything else escapes.
template <class F>
bool tolerate(F&& f) {
    try {
        f();
        return true;
    } catch (const py::type_error&) {
    } catch (const py::value_error&) {
    } catch (const pyrseg::Error&) {
    } catch (const py::error_already_set& e) {
        if (!allowed(e)) unexpected(e);
    }
    return false;
}

// One heap block of exactly the array's size: ASan's redzones are right before and after it.
struct Buffer {
    std::unique_ptr<unsigned char[]> bytes;
    std::size_t size = 0;
    [[nodiscard]] bool holds(const void* p, std::size_t n) const {
        const auto a = reinterpret_cast<std::uintptr_t>(p);
        const auto b = reinterpret_cast<std::uintptr_t>(bytes.get());
        return a >= b && a - b <= size && n <= size - (a - b);
    }
};

struct Array {
    py::object object;              // what the entry point is given (an array, a list, None, ...)
    std::optional<py::array> view;  // the numpy array over `buffer`, when it is one
    std::shared_ptr<Buffer> buffer;
};

// A value of the dtype that a real frame would have: a plane 1 m away, depth in millimetres, a set mask.
void plausible(unsigned char* p, char kind, int itemsize, std::size_t i) {
    if (kind == 'f' && itemsize == 4) {
        const float v = i % 3 == 2 ? 1.0f : 0.01f * float(i % 17);
        std::memcpy(p, &v, 4);
    } else if (kind == 'f' && itemsize == 8) {
        const double v = i % 3 == 2 ? 1.0 : 0.01 * double(i % 17);
        std::memcpy(p, &v, 8);
    } else if ((kind == 'u' || kind == 'i') && itemsize >= 2) {
        const std::uint16_t v = std::uint16_t(1000 + i % 50);
        std::memcpy(p, &v, 2);
    } else if (kind != 'O') {
        p[0] = 1;
    }
}

// Decodes an array spec and builds it. `like` (may be null) gives a shape to follow when the input asks for it, so
// that normals=, valid= and out= often fit the frame. Returns nullopt when the spec is too large.
std::optional<Array> make_array(FuzzedDataProvider& in, const std::vector<py::ssize_t>* like) {
    Interpreter& it = interpreter();
    const int kind = in.ConsumeIntegralInRange<int>(0, 15);
    Array a;
    // numpy cannot make an array of this (the bindings once read the null array py::array::ensure gives for it: a
    // segfault, docs/fuzzing-ledger.md "Findings so far"); every entry point must raise ValueError naming the argument.
    if (kind == 13) {
        py::list ragged;
        ragged.append(py::make_tuple(1.0, 2.0));
        ragged.append(py::make_tuple(3.0));
        a.object = ragged;
        return a;
    }
    if (kind == 14) {
        a.object = py::none();
        return a;
    }
    if (kind == 15) {
        a.object = it.values[in.ConsumeIntegralInRange<std::size_t>(0, it.values.size() - 1)];
        return a;
    }
    const py::dtype dtype{std::string(kDtypes[in.ConsumeIntegralInRange<int>(0, kDtypeCount - 1)])};
    const auto itemsize = py::ssize_t(dtype.itemsize());
    const char dkind = dtype.kind();
    std::vector<py::ssize_t> shape;
    if (like != nullptr && in.ConsumeBool()) {
        shape = *like;
        // The frame's H x W, with a channel dimension or not.
        shape.resize(2);
        const int channels = in.ConsumeIntegralInRange<int>(0, 7);
        if (channels > 0) shape.push_back(channels);
    } else {
        const int ndim = in.ConsumeIntegralInRange<int>(0, 4);
        for (int d = 0; d < ndim; ++d) shape.push_back(in.ConsumeIntegralInRange<int>(0, kMaxDim));
    }
    const auto ndim = std::size_t(shape.size());
    std::vector<py::ssize_t> natural(ndim), strides(ndim);
    for (std::size_t d = ndim; d-- > 0;) natural[d] = d + 1 == ndim ? itemsize : natural[d + 1] * shape[d + 1];
    py::ssize_t fortran = itemsize;
    for (std::size_t d = 0; d < ndim; ++d) {
        switch (in.ConsumeIntegralInRange<int>(0, 7)) {
            case 0:
            case 1:
                strides[d] = natural[d];
                break;
            case 2:
                strides[d] = fortran;
                break;
            case 3:
                strides[d] = -natural[d];
                break;
            case 4:
                strides[d] = 0;
                break;
            case 5:
                strides[d] = 2 * natural[d] + in.ConsumeIntegralInRange<int>(0, 3) * itemsize;
                break;
            case 6:
                strides[d] = in.ConsumeIntegral<std::int8_t>();
                break;  // unaligned, overlapping
            default:
                strides[d] = in.ConsumeIntegralInRange<int>(-4096, 4096);
                break;
        }
        fortran *= std::max<py::ssize_t>(shape[d], 1);
    }
    // The bytes the elements span, from the first element: numpy checks that they lie in the buffer.
    py::ssize_t low = 0, high = 0;
    bool empty = false;
    for (std::size_t d = 0; d < ndim; ++d) {
        if (shape[d] == 0) empty = true;
        const py::ssize_t span = (shape[d] - 1) * strides[d];
        (span < 0 ? low : high) += span;
    }
    const py::ssize_t lead = in.ConsumeIntegralInRange<int>(0, 7), tail = in.ConsumeIntegralInRange<int>(0, 7);
    const py::ssize_t offset = empty ? lead : lead - low;
    const py::ssize_t size = (empty ? 0 : high - low + itemsize) + lead + tail;
    if (size > py::ssize_t(kMaxBuffer)) return std::nullopt;
    const bool writeable = in.ConsumeIntegralInRange<int>(0, 3) != 0;
    a.buffer = std::make_shared<Buffer>();
    a.buffer->size = std::size_t(size);
    a.buffer->bytes.reset(new unsigned char[std::size_t(std::max<py::ssize_t>(size, 1))]);
    unsigned char* bytes = a.buffer->bytes.get();
    std::memset(bytes, 0, std::size_t(size));
    for (py::ssize_t i = 0; i + itemsize <= size; i += itemsize) plausible(bytes + i, dkind, int(itemsize), i);
    // Some of the input's bytes over the plausible values: NaNs, negative depths, huge coordinates.
    const std::vector<std::uint8_t> noise = in.ConsumeBytes<std::uint8_t>(in.ConsumeIntegralInRange<int>(0, 64));
    const py::ssize_t at = noise.empty() ? 0 : in.ConsumeIntegralInRange<py::ssize_t>(0, size);
    for (std::size_t i = 0; i < noise.size() && at + py::ssize_t(i) < size; ++i) bytes[std::size_t(at) + i] ^= noise[i];
    if (dkind == 'O') {
        // numpy makes no object array over a buffer: one of its own, of Python floats.
        a.object = it.numpy.attr("full")(py::cast(shape), py::float_(1.0), dtype);
        return a;
    }
    const py::object memory = py::reinterpret_steal<py::object>(
        PyMemoryView_FromMemory(reinterpret_cast<char*>(bytes), size, writeable ? PyBUF_WRITE : PyBUF_READ));
    if (!memory) throw py::error_already_set();
    try {
        a.object = it.ndarray(py::cast(shape), dtype, memory, offset, py::cast(strides));
    } catch (const py::error_already_set& e) {
        // A spec numpy refuses (a zero-size dtype with strides, say) is not pyrseg's to answer.
        if (!e.matches(PyExc_ValueError) && !e.matches(PyExc_TypeError)) throw;
        return std::nullopt;
    }
    if (writeable && in.ConsumeIntegralInRange<int>(0, 7) == 0) a.object.attr("flags").attr("writeable") = false;
    a.view = py::reinterpret_borrow<py::array>(a.object);
    if (kind == 12) {
        // The same values as nested lists (not for code points numpy cannot make a str of).
        try {
            a.object = a.object.attr("tolist")();
        } catch (const py::error_already_set&) {
            return std::nullopt;
        }
    }
    return a;
}

std::vector<py::ssize_t> shape_of(const Array& a) {
    if (!a.view) return {};
    return {a.view->shape(), a.view->shape() + a.view->ndim()};
}

// Element (y, x, c) of an array (the caller checked its dimensions) by its strides, from the raw memory.
const unsigned char* element(const py::array& a, py::ssize_t y, py::ssize_t x, py::ssize_t c = 0) {
    const py::ssize_t offset = y * a.strides(0) + x * a.strides(1) + (a.ndim() > 2 ? c * a.strides(2) : 0);
    return static_cast<const unsigned char*>(a.data()) + offset;
}

bool native(const py::array& a) {
    const char order = a.dtype().byteorder();
    return order != '>';
}

float as_float(const py::array& a, const unsigned char* p) {
    if (a.itemsize() == 4) {
        float f = 0;
        std::memcpy(&f, p, 4);
        return f;
    }
    double d = 0;
    std::memcpy(&d, p, 8);
    return static_cast<float>(d);
}

bool same_float(float a, float b) {
    return std::memcmp(&a, &b, sizeof a) == 0;
}

// An in-place view's bytes lie inside the array's own buffer (when it is one of the harness's).
void expect_inside(const Array& a, const void* p, std::size_t n) {
    if (a.buffer && a.view) expect(a.buffer->holds(p, n));
}

// --- the conversions ------------------------------------------------------------------------------------------

// points[y, x, first + c] as the view gives it.
float view_point(const pyrseg::CloudView& v, const float* base, int x, int y, int c) {
    const auto* p = reinterpret_cast<const unsigned char*>(base);
    if (v.point_step_bytes != 0) {
        p += std::size_t(y) * v.row_step_bytes + std::size_t(x) * v.point_step_bytes;
    } else {
        p += (std::size_t(y) * std::size_t(v.width) + std::size_t(x)) * 12;
    }
    float f = 0;
    std::memcpy(&f, p + 4 * c, 4);
    return f;
}

void cloud(FuzzedDataProvider& in) {
    const std::optional<Array> points = make_array(in, nullptr);
    if (!points) return;
    std::optional<Array> normals;
    const int normals_kind = in.ConsumeIntegralInRange<int>(0, 3);
    if (normals_kind == 1) normals = points;
    if (normals_kind >= 2) {
        const auto like = shape_of(*points);
        normals = make_array(in, like.size() >= 2 ? &like : nullptr);
        if (!normals) return;
    }
    const int size_kind = in.ConsumeIntegralInRange<int>(0, 3);
    const py::object normals_object = normals ? normals->object : py::none();
    tolerate([&] {
        const auto shape = shape_of(*points);
        int w = -1, h = -1;
        if (size_kind == 1 && shape.size() >= 2) {
            w = int(shape[1]);
            h = int(shape[0]);
        } else if (size_kind >= 2) {
            w = in.ConsumeIntegralInRange<int>(0, kMaxDim);
            h = in.ConsumeIntegralInRange<int>(0, kMaxDim);
        }
        const python::CloudInput input(points->object, normals_object, w, h);
        python::Scratch scratch;
        const pyrseg::CloudView v = input.view(scratch);
        if (!points->view || points->object.ptr() != points->view->ptr()) return;  // a list: numpy's own copy
        const py::array& a = *points->view;
        // What was accepted: H x W x {3, 4, 6} float32 or float64 in native order, of the Segmenter's size.
        expect(a.ndim() == 3 && (a.shape(2) == 3 || a.shape(2) == 4 || a.shape(2) == 6));
        expect(a.dtype().kind() == 'f' && (a.itemsize() == 4 || a.itemsize() == 8) && native(a));
        expect(v.width == a.shape(1) && v.height == a.shape(0));
        expect(w < 0 || (w == v.width && h == v.height));
        const std::size_t n = std::size_t(v.width) * std::size_t(v.height);
        if (input.copies()) {
            expect(v.points == scratch.points.data() && scratch.points.size() == 3 * n);
        } else if (n > 0) {
            expect(v.point_step_bytes >= 12 && v.row_step_bytes >= std::size_t(v.width - 1) * v.point_step_bytes + 12);
            for (int y = 0; y < v.height; ++y) {
                const auto* row = reinterpret_cast<const unsigned char*>(v.points) + std::size_t(y) * v.row_step_bytes;
                expect_inside(*points, row, std::size_t(v.width - 1) * v.point_step_bytes + 12);
                if (v.normals != nullptr) {
                    const auto* nrow =
                        reinterpret_cast<const unsigned char*>(v.normals) + std::size_t(y) * v.row_step_bytes;
                    const Array& holder = a.shape(2) == 6 ? *points : *normals;
                    expect_inside(holder, nrow, std::size_t(v.width - 1) * v.point_step_bytes + 12);
                }
            }
        }
        const bool has_normals = a.shape(2) == 6 || !normals_object.is_none();
        expect(n == 0 || (v.normals != nullptr) == has_normals);  // an empty vector's data() may be null
        // The very values, in place or converted.
        for (int y = 0; y < v.height; ++y) {
            for (int x = 0; x < v.width; ++x) {
                for (int c = 0; c < 3; ++c) {
                    expect(same_float(view_point(v, v.points, x, y, c), as_float(a, element(a, y, x, c))));
                    if (a.shape(2) == 6) {
                        expect(same_float(view_point(v, v.normals, x, y, c), as_float(a, element(a, y, x, c + 3))));
                    }
                }
            }
        }
        if (normals && normals->view && normals->object.ptr() == normals->view->ptr()) {
            const py::array& na = *normals->view;
            expect(na.ndim() == 3 && na.shape(0) == a.shape(0) && na.shape(1) == a.shape(1) && na.shape(2) == 3);
            expect(na.dtype().kind() == 'f' && native(na));
            for (int y = 0; y < v.height; ++y) {
                for (int x = 0; x < v.width; ++x) {
                    for (int c = 0; c < 3; ++c) {
                        expect(same_float(view_point(v, v.normals, x, y, c), as_float(na, element(na, y, x, c))));
                    }
                }
            }
        }
    });
}

void depth(FuzzedDataProvider& in) {
    const std::optional<Array> depth = make_array(in, nullptr);
    if (!depth) return;
    tolerate([&] {
        const python::DepthInput input(depth->object);
        python::Scratch scratch;
        const pyrseg::DepthView v = input.view(scratch);
        if (!depth->view || depth->object.ptr() != depth->view->ptr()) return;
        const py::array& a = *depth->view;
        expect(a.ndim() == 2 || (a.ndim() == 3 && a.shape(2) == 1));
        const char kind = a.dtype().kind();
        const bool integer = kind == 'u' || kind == 'i';
        expect(integer || (kind == 'f' && (a.itemsize() == 4 || a.itemsize() == 8) && native(a)));
        expect(v.width == a.shape(1) && v.height == a.shape(0));
        expect(v.format == (integer ? pyrseg::DepthFormat::u16 : pyrseg::DepthFormat::f32));
        const std::size_t sample = integer ? 2 : 4;
        const std::size_t row = v.row_step_bytes != 0 ? v.row_step_bytes : std::size_t(v.width) * sample;
        for (int y = 0; y < v.height; ++y) {
            const auto* r = static_cast<const unsigned char*>(v.depth) + std::size_t(y) * row;
            if (!input.copies() && v.width > 0) expect_inside(*depth, r, std::size_t(v.width) * sample);
            for (int x = 0; x < v.width; ++x) {
                const unsigned char* e = element(a, y, x);
                if (integer) {
                    std::uint16_t got = 0;
                    std::memcpy(&got, r + std::size_t(x) * 2, 2);
                    // The element's value, in its byte order: within 0..65535 (view() refuses others).
                    std::uint64_t bits = 0;
                    const auto n = std::size_t(a.itemsize());
                    const bool little = native(a);
                    for (std::size_t i = 0; i < n; ++i) bits |= std::uint64_t(e[little ? i : n - 1 - i]) << (8 * i);
                    expect(bits == got);
                } else {
                    float got = 0;
                    std::memcpy(&got, r + std::size_t(x) * 4, 4);
                    expect(same_float(got, as_float(a, e)));
                }
            }
        }
    });
}

void mask(FuzzedDataProvider& in) {
    const std::optional<Array> mask = make_array(in, nullptr);
    if (!mask) return;
    std::optional<Array> valid;
    const int valid_kind = in.ConsumeIntegralInRange<int>(0, 3);
    if (valid_kind == 1) valid = mask;
    if (valid_kind >= 2) {
        const auto like = shape_of(*mask);
        valid = make_array(in, like.size() >= 2 ? &like : nullptr);
        if (!valid) return;
    }
    const py::object valid_object = valid ? valid->object : py::none();
    tolerate([&] {
        const python::MaskInput input(mask->object, valid_object);
        python::Scratch scratch;
        const pyrseg::MaskView v = input.view(scratch);
        const auto check = [&](const Array& from, const unsigned char* data) {
            if (!from.view || from.object.ptr() != from.view->ptr()) return;
            const py::array& a = *from.view;
            expect(a.ndim() == 2 && a.itemsize() == 1 && (a.dtype().kind() == 'b' || a.dtype().kind() == 'u'));
            expect(v.width == a.shape(1) && v.height == a.shape(0));
            const std::size_t stride = v.row_stride != 0 ? v.row_stride : std::size_t(v.width);
            for (int y = 0; y < v.height; ++y) {
                const unsigned char* r = data + std::size_t(y) * stride;
                if (!input.copies() && v.width > 0) expect_inside(from, r, std::size_t(v.width));
                for (int x = 0; x < v.width; ++x) expect(r[x] == *element(a, y, x));
            }
        };
        check(*mask, v.fillable);
        expect(v.width * v.height == 0 || (v.valid != nullptr) == !valid_object.is_none());
        if (valid) check(*valid, v.valid);
    });
}

// The bytes of `a`'s buffer that are none of its elements' (out= must leave them as they were).
std::vector<bool> element_bytes(const py::array& a, const Buffer& b, int width, int height) {
    std::vector<bool> mine(b.size, false);
    const auto* base = b.bytes.get();
    for (int y = 0; y < height; ++y) {
        for (int x = 0; x < width; ++x) {
            const std::size_t at = std::size_t(element(a, y, x) - base);
            for (std::size_t i = 0; i < 4 && at + i < b.size; ++i) mine[at + i] = true;
        }
    }
    return mine;
}

// After labels 1..W*H were written into out: each element holds its own (so no two share memory), and no other
// byte of the buffer changed.
void expect_labels(const Array& out, const std::vector<unsigned char>& before, int width, int height,
                   const std::uint32_t* labels) {
    const py::array& a = *out.view;
    const std::vector<bool> mine = element_bytes(a, *out.buffer, width, height);
    for (std::size_t i = 0; i < before.size(); ++i) expect(mine[i] || out.buffer->bytes[i] == before[i]);
    for (int y = 0; y < height; ++y) {
        for (int x = 0; x < width; ++x) {
            std::uint32_t got = 0;
            std::memcpy(&got, element(a, y, x), 4);
            expect(got == labels[std::size_t(y) * std::size_t(width) + std::size_t(x)]);
        }
    }
}

std::vector<unsigned char> snapshot(const Array& a) {
    if (!a.buffer) return {};
    return {a.buffer->bytes.get(), a.buffer->bytes.get() + a.buffer->size};
}

void labels_out(FuzzedDataProvider& in) {
    const int w = in.ConsumeIntegralInRange<int>(0, kMaxDim), h = in.ConsumeIntegralInRange<int>(0, kMaxDim);
    const std::vector<py::ssize_t> like = {h, w};
    const std::optional<Array> out = make_array(in, &like);
    if (!out) return;
    tolerate([&] {
        py::array a = python::check_labels_out(out->object, w, h);
        expect(out->view && out->object.ptr() == out->view->ptr() && a.ptr() == out->object.ptr());
        expect(a.ndim() == 2 && a.shape(0) == h && a.shape(1) == w && a.writeable());
        expect(a.dtype().kind() == 'u' && a.itemsize() == 4 && native(a));
        std::vector<std::uint32_t> labels(std::size_t(w) * std::size_t(h));
        for (std::size_t i = 0; i < labels.size(); ++i) labels[i] = std::uint32_t(i + 1);
        // The bindings copy a frame's labels, never none (a Segmenter is at least 1 x 1): labels.data() of an empty
        // vector is null, which memcpy may not be given even for 0 bytes.
        if (labels.empty()) return;
        const std::vector<unsigned char> before = snapshot(*out);
        python::copy_labels(labels.data(), a);
        expect_labels(*out, before, w, h, labels.data());
    });
}

// --- the argument helpers -------------------------------------------------------------------------------------

void arguments(FuzzedDataProvider& in) {
    Interpreter& it = interpreter();
    const auto pick = [&] { return it.values[in.ConsumeIntegralInRange<std::size_t>(0, it.values.size() - 1)]; };
    const py::object v = pick();
    tolerate([&] { (void)python::number("f()", "x", v); });
    tolerate([&] {
        const long long lo = in.ConsumeIntegralInRange<int>(-70000, 70000);
        const long long hi = lo + in.ConsumeIntegralInRange<int>(0, 70000);
        const long long got = python::integer("f()", "x", v, lo, hi);
        expect(got >= lo && got <= hi);
    });
    tolerate([&] { (void)python::unsigned_integer("f()", "x", v); });
    tolerate([&] { (void)python::boolean("f()", "x", v); });
    tolerate([&] { (void)python::text("f()", "x", v); });
    tolerate([&] { (void)python::path("f()", "x", v); });
    // Binding a call's arguments to segment_depth's parameters, positional then by keyword (names from the list
    // and ones it lacks).
    static constexpr python::Param kParams[] = {{"depth"},           {"fx"},          {"fy"},           {"cx"}, {"cy"},
                                                {"metres_per_unit"}, {"out", "None"}, {"count", "None"}};
    static const char* const kNames[] = {"depth", "fx", "fy", "cx", "cy", "metres_per_unit", "out", "count", "x", ""};
    tolerate([&] {
        py::list positional;
        const int n = in.ConsumeIntegralInRange<int>(0, 10);
        for (int i = 0; i < n; ++i) positional.append(pick());
        py::kwargs kwargs;
        const int k = in.ConsumeIntegralInRange<int>(0, 4);
        for (int i = 0; i < k; ++i) kwargs[py::str(kNames[in.ConsumeIntegralInRange<int>(0, 9)])] = pick();
        const python::Args a("segment_depth()", kParams, py::args(py::tuple(positional)), kwargs);
        // Bound: every required parameter given, each value the one passed.
        for (std::size_t i = 0; i < 6; ++i) expect(a.given(i));
        for (std::size_t i = 0; i < 8; ++i) {
            if (i < std::size_t(n)) expect(a.object(i).ptr() == positional[i].ptr());
        }
        for (std::size_t i = 0; i < 8; ++i) (void)a.number(i, 0.0);
    });
}

// --- a real Segmenter through the bindings --------------------------------------------------------------------

py::object segmenter(int w, int h) {
    Interpreter& it = interpreter();
    auto& s = it.segmenters[{w, h}];
    if (!s) s = it.segmenter_type(w, h, "cpu");
    return s;
}

void frame(FuzzedDataProvider& in, int which) {
    const std::optional<Array> input = make_array(in, nullptr);
    if (!input) return;
    auto shape = shape_of(*input);
    int w = 0, h = 0;
    if (shape.size() >= 2 && in.ConsumeIntegralInRange<int>(0, 7) != 0) {
        w = int(shape[1]);
        h = int(shape[0]);
    } else {
        w = in.ConsumeIntegralInRange<int>(0, kMaxDim);
        h = in.ConsumeIntegralInRange<int>(0, kMaxDim);
    }
    if (w < 1 || h < 1) return;   // no Segmenter of that size (Segmenter() refuses it: not this harness's subject)
    std::optional<Array> second;  // normals= or valid=
    if (which != 1 && in.ConsumeIntegralInRange<int>(0, 3) == 0) {
        const std::vector<py::ssize_t> like = {h, w};
        second = make_array(in, &like);
        if (!second) return;
    }
    std::optional<Array> out;
    const int out_kind = in.ConsumeIntegralInRange<int>(0, 3);
    if (out_kind == 1) out = input;  // out= aliasing the frame
    if (out_kind >= 2) {
        const std::vector<py::ssize_t> like = {h, w};
        out = make_array(in, &like);
        if (!out) return;
    }
    const py::object seg = segmenter(w, h);
    const std::vector<unsigned char> input_before = snapshot(*input);
    const std::vector<unsigned char> second_before = second ? snapshot(*second) : std::vector<unsigned char>{};
    const std::vector<unsigned char> out_before = out ? snapshot(*out) : std::vector<unsigned char>{};
    py::kwargs kwargs;
    if (second) kwargs[which == 0 ? "normals" : "valid"] = second->object;
    if (out) kwargs["out"] = out->object;
    if (which != 2 && in.ConsumeIntegralInRange<int>(0, 15) == 0) kwargs["count"] = py::int_(1);
    const char* method = which == 0 ? "segment" : which == 1 ? "segment_depth" : "segment_mask";
    py::list call;
    call.append(input->object);
    if (which == 1) {
        Interpreter& it = interpreter();
        const auto camera = [&](double plausible_value) -> py::object {
            if (in.ConsumeIntegralInRange<int>(0, 7) != 0) return py::float_(plausible_value);
            return it.values[in.ConsumeIntegralInRange<std::size_t>(0, it.values.size() - 1)];
        };
        // fx, fy, cx, cy, metres_per_unit
        for (const double v : {double(w), double(w), 0.5 * (w - 1), 0.5 * (h - 1), 0.001}) call.append(camera(v));
    }
    const py::tuple call_args(call);
    py::object result;
    try {
        result = seg.attr(method)(*call_args, **kwargs);
    } catch (const py::error_already_set& e) {
        if (!allowed(e)) unexpected(e);
    }
    // The frame never writes into its inputs, whatever happened; out= only into its elements.
    const bool out_is_input = out_kind == 1;
    if (!out_is_input) {
        expect(input_before == snapshot(*input));
        if (second) expect(second_before == snapshot(*second));
    }
    if (!result) {
        if (out && !out_is_input) expect(out_before == snapshot(*out));
        return;
    }
    const py::object labels = result.attr("labels");
    const py::array la = py::reinterpret_borrow<py::array>(labels);
    expect(la.ndim() == 2 && la.shape(0) == h && la.shape(1) == w);
    if (out && !out->object.is_none()) {
        expect(labels.ptr() == out->object.ptr());
        if (out->view && out->view->ptr() == out->object.ptr()) {
            // The same frame again into a new array: out= held those very labels, each in its own element, and
            // nothing else of its buffer changed.
            kwargs.attr("pop")("out");
            const py::object again = seg.attr(method)(*call_args, **kwargs);
            {
                const auto fresh = py::reinterpret_borrow<py::array>(again.attr("labels"));
                std::vector<std::uint32_t> expected(std::size_t(w) * std::size_t(h));
                for (int y = 0; y < h; ++y) {
                    for (int x = 0; x < w; ++x) {
                        std::memcpy(&expected[std::size_t(y) * std::size_t(w) + std::size_t(x)], element(fresh, y, x),
                                    4);
                    }
                }
                expect_labels(*out, out_before, w, h, expected.data());
            }
        }
    }
}

}  // namespace

// Blocks the interpreter allocates and loses track of to LeakSanitizer (objects it keeps through pointers into their
// middle, its caches): CPython is not leak-clean, and a harness that reported it would stop at the first input.
// Leaks of pyrseg's own (operator new, malloc in the bindings or the library) have no libpython frame and are found.
extern "C" const char* __lsan_default_suppressions() {  // NOLINT: the sanitizer runtime's name
    return "leak:libpython3\n";
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    Interpreter& it = interpreter();
    (void)it;
    FuzzedDataProvider in(data, size);
    switch (in.ConsumeIntegralInRange<int>(0, 7)) {
        case 0:
            cloud(in);
            break;
        case 1:
            depth(in);
            break;
        case 2:
            mask(in);
            break;
        case 3:
            labels_out(in);
            break;
        case 4:
            arguments(in);
            break;
        case 5:
            frame(in, 0);
            break;
        case 6:
            frame(in, 1);
            break;
        default:
            frame(in, 2);
            break;
    }
    return 0;
}
