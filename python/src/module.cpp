// The module itself: _pyrseg, which the pyrseg package re-exports, or pyrseg_testing, the same bindings with the
// tests' helpers (testing.cpp), as PYRSEG_PYTHON_MODULE_NAME says.
#include "bindings.hpp"

#ifndef PYRSEG_PYTHON_MODULE_NAME
#error "PYRSEG_PYTHON_MODULE_NAME must name the module (python/CMakeLists.txt)"
#endif

namespace pyrseg::python {
#if PYRSEG_PYTHON_TESTING
void bind_testing(py::module_& m);
#endif
}  // namespace pyrseg::python

PYBIND11_MODULE(PYRSEG_PYTHON_MODULE_NAME, m) {
    namespace python = pyrseg::python;
    m.doc() = "pyrseg: fast bridgeless pyramid segmentation of organized point clouds and depth images.";
    python::bind_errors(m);
    python::bind_segmenter(m);
    python::bind_scene(m);
    auto io = m.def_submodule("io");
    python::bind_io(io);
    auto synthetic = m.def_submodule("synthetic");
    python::bind_synthetic(synthetic);
#if PYRSEG_PYTHON_TESTING
    python::bind_testing(m);
#endif
}
