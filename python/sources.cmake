# The Python module's C++ sources, listed once for the two builds of it: python/CMakeLists.txt (the project's own,
# against the static or shared libraries of the same build tree) and scripts/gpu_check/python/CMakeLists.txt (built
# on a GPU machine by `scripts/gpu-check.sh run`, against the shared libraries the bundle carries).
#   PYRSEG_PYTHON_BINDINGS_SOURCES: the bindings (every module links them)
#   PYRSEG_PYTHON_MODULE_SOURCES:   the module's entry point (PYBIND11_MODULE, named by PYRSEG_PYTHON_MODULE_NAME)
set(PYRSEG_PYTHON_BINDINGS_SOURCES
    ${CMAKE_CURRENT_LIST_DIR}/src/segmenter.cpp
    ${CMAKE_CURRENT_LIST_DIR}/src/arrays.cpp
    ${CMAKE_CURRENT_LIST_DIR}/src/args.cpp
    ${CMAKE_CURRENT_LIST_DIR}/src/io.cpp
    ${CMAKE_CURRENT_LIST_DIR}/src/scene.cpp
    ${CMAKE_CURRENT_LIST_DIR}/src/synthetic.cpp
    ${CMAKE_CURRENT_LIST_DIR}/src/device.cpp)
set(PYRSEG_PYTHON_MODULE_SOURCES ${CMAKE_CURRENT_LIST_DIR}/src/module.cpp)
