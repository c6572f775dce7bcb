#pragma once
// The parts of pyrseg's Python module (docs/python.md), each binding one part of the C++ API. module.cpp puts them
// together under the module's name: _pyrseg for users, pyrseg_testing for the tests (testing.cpp).
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include "pyrseg/error.hpp"
#include "pyrseg/params.hpp"

namespace pyrseg::python {

namespace py = pybind11;

// pyrseg.Error and pyrseg.ErrorCode; C++ pyrseg::Error thrown through any binding becomes pyrseg.Error.
void bind_errors(py::module_& m);
// Raises pyrseg.Error with `code` (the C++ type, translated as every other one is).
[[noreturn]] void raise(ErrorCode code, const std::string& message);

void bind_segmenter(py::module_& m);
// Segmenter.params and pyrseg.preset(): every parameter by its keyword name.
py::dict params_to_dict(const Params& p);
// pyrseg.segment_stats_dtype: SegmentStats as numpy sees it (Result.segments).
py::dtype segment_stats_dtype();
// pyrseg.describe_scene, scene_support_dtype, scene_object_dtype, Scene (scene.cpp).
void bind_scene(py::module_& m);
void bind_io(py::module_& io);
void bind_synthetic(py::module_& synthetic);

// Every class and enum is local to its module, so that the tests' own module (the same bindings again) can be
// imported beside pyrseg without pybind11 refusing a second registration of the same C++ types.
inline constexpr auto kLocal = py::module_local();

}  // namespace pyrseg::python
