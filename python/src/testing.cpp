// The tests' own helpers in pyrseg_testing (never installed), which holds the whole Python API too:
// - operator new counted, as tests/unit/test_no_allocation.cpp counts it: this module's copy of the library and of
//   the bindings allocate through it, so a Python frame loop can be shown to allocate nothing in C++;
// - the C++ API run directly on the conformance scenes (tests/conformance/cases.cpp), whose labels the Python API
//   must reproduce byte for byte;
// - the same frame loop in C++, the baseline of the Python loop's time.
#include <atomic>
#include <chrono>
#include <cstdlib>
#include <new>
#include <string>

#include "arrays.hpp"
#include "bindings.hpp"
#include "conformance/cases.hpp"
#include "pyrseg/segmenter.hpp"
#include "pyrseg/synthetic.hpp"

namespace {
std::atomic<long> allocations{0};
}  // namespace

// A matched pair over malloc/free; GCC, seeing them inlined, would warn that free() gets a pointer from new.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
#endif

void* operator new(std::size_t size) {
    allocations.fetch_add(1, std::memory_order_relaxed);
    if (void* p = std::malloc(size == 0 ? 1 : size)) return p;
    throw std::bad_alloc();
}
void* operator new[](std::size_t size) {
    allocations.fetch_add(1, std::memory_order_relaxed);
    if (void* p = std::malloc(size == 0 ? 1 : size)) return p;
    throw std::bad_alloc();
}
void operator delete(void* p) noexcept {
    std::free(p);
}
void operator delete(void* p, std::size_t) noexcept {
    std::free(p);
}
void operator delete[](void* p) noexcept {
    std::free(p);
}
void operator delete[](void* p, std::size_t) noexcept {
    std::free(p);
}

namespace pyrseg::python {
namespace {

const test::ConformanceCase& conformance_case(const std::string& suite, std::size_t index) {
    const auto& cases = suite == "robust" ? test::robust_conformance_cases() : test::conformance_cases();
    if (index >= cases.size()) throw py::index_error("no conformance case " + std::to_string(index));
    return cases[index];
}

py::dict case_dict(const test::ConformanceCase& c) {
    const synthetic::SceneOptions& o = c.scene;
    py::dict scene;
    scene["width"] = o.width;
    scene["height"] = o.height;
    scene["seed"] = o.seed;
    scene["object_count"] = o.object_count;
    scene["noise_mm"] = o.noise_mm;
    scene["hole_fraction"] = o.hole_fraction;
    scene["touching"] = o.touching;
    scene["bin"] = o.bin;
    scene["sensor"] = synthetic::sensor_name(o.sensor);
    scene["camera_distance_mm"] = o.camera_distance_mm;
    scene["shadows"] = o.shadows;
    scene["threads"] = o.threads;
    py::dict d;
    d["name"] = c.name;
    d["scene"] = scene;
    d["params"] = params_to_dict(c.params);
    d["given_normals"] = c.given_normals;
    return d;
}

// pybind11's call machinery allocates its argument lists on every call, whatever the function does: a method taken
// as Segmenter.segment is (self, *args, **kwargs; args.hpp binds them) that does nothing measures that part.
struct CallProbe {};

}  // namespace

void bind_testing(py::module_& m) {
    m.def(
        "allocations", [] { return allocations.load(); }, "operator new calls in this module so far.");
    py::class_<CallProbe>(m, "CallProbe", kLocal)
        .def(py::init<>())
        .def("segment", [](const py::object&, const py::args&, const py::kwargs&) { return py::none(); });
    m.def(
        "throw_bad_alloc", [] { throw std::bad_alloc(); },
        "Throws std::bad_alloc, as a backend's allocation may: the module's translator makes it pyrseg.Error.");
    m.def(
        "conformance_cases",
        [](const std::string& suite) {
            py::list l;
            const auto& cases = suite == "robust" ? test::robust_conformance_cases() : test::conformance_cases();
            for (const auto& c : cases) l.append(case_dict(c));
            return l;
        },
        py::arg("suite") = "contract", "The conformance cases ('contract' or 'robust') as dictionaries.");
    m.def(
        "cpp_labels",
        [](const std::string& suite, std::size_t index, const std::string& backend) {
            const test::ConformanceCase& c = conformance_case(suite, index);
            Result r;
            {
                const py::gil_scoped_release nogil;
                const synthetic::Scene s = synthetic::generate(c.scene);
                Segmenter seg(s.width, s.height, c.params, backend);
                seg.segment(CloudView{s.points.data(), c.given_normals ? s.normals.data() : nullptr, s.width, s.height},
                            r);
            }
            return array_of(r.labels.data(), r.height, r.width);
        },
        py::arg("suite"), py::arg("index"), py::arg("backend"),
        "The labels the C++ API gives on a conformance case: its scene, its parameters, the backend named.");
    m.def(
        "cpp_loop_seconds",
        [](const py::array_t<float, py::array::c_style>& points, const std::string& backend, int frames) {
            if (points.ndim() != 3 || points.shape(2) != 3) throw py::value_error("points must be H x W x 3");
            const int w = int(points.shape(1)), h = int(points.shape(0));
            const CloudView view{points.data(), nullptr, w, h};
            const py::gil_scoped_release nogil;
            Segmenter seg(w, h, {}, backend);
            Result r;
            seg.segment(view, r);  // sizes the Result, as the Python loop's first frame does
            const auto start = std::chrono::steady_clock::now();
            for (int i = 0; i < frames; ++i) seg.segment(view, r);
            return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        },
        py::arg("points"), py::arg("backend"), py::arg("frames"),
        "Seconds the C++ API takes for `frames` warm frames of this cloud (packed float32, normals estimated).");
}

}  // namespace pyrseg::python
