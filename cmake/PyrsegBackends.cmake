# Every backend pyrseg knows, in the order 'auto' prefers them: the GPU backends, then the CPU (always built). The
# registry (backends/CMakeLists.txt), install rules, examples, bench and tests follow this list; list_backends() gives
# it at run time. Adding a backend: its name here, its option, toolchain test, _pyrseg_backend line and
# _pyrseg_gpu_api line below, its block in backends/CMakeLists.txt (docs/architecture.md has the whole checklist).
set(PYRSEG_GPU_BACKENDS cuda vulkan opencl)
set(PYRSEG_BACKENDS ${PYRSEG_GPU_BACKENDS} cpu)

# Backend options: ON (required), OFF, or AUTO (built when the toolchain is found). One line per backend at
# configure time says what is built and why the others are not.
set(PYRSEG_WITH_CUDA AUTO CACHE STRING "Build the CUDA backend (ON/OFF/AUTO)")
set(PYRSEG_WITH_VULKAN AUTO CACHE STRING "Build the Vulkan backend (ON/OFF/AUTO)")
set(PYRSEG_WITH_OPENCL AUTO CACHE STRING "Build the OpenCL backend (ON/OFF/AUTO)")
foreach(_b IN LISTS PYRSEG_GPU_BACKENDS)
  string(TOUPPER "${_b}" _opt)
  set_property(CACHE PYRSEG_WITH_${_opt} PROPERTY STRINGS ON OFF AUTO)
endforeach()
# The sanitizer, cross, fuzz and package builds: the CPU backend alone, whatever the options above say.
option(PYRSEG_CPU_ONLY "Build the CPU backend only (every PYRSEG_WITH_<GPU backend> taken as OFF)" OFF)

# _pyrseg_backend(NAME OPTION FOUND TOOLCHAIN_TEXT IMPLEMENTED NOT_IMPLEMENTED_TEXT)
function(_pyrseg_backend name opt found toolchain implemented pending)
  set(value "${${opt}}")
  string(TOUPPER "${value}" value)
  set(build OFF)
  if(PYRSEG_CPU_ONLY)
    set(why "disabled (PYRSEG_CPU_ONLY=ON)")
  elseif(value STREQUAL "OFF")
    set(why "disabled (${opt}=OFF)")
  elseif(NOT found)
    set(why "not built: ${toolchain} not found")
    if(value STREQUAL "ON")
      message(FATAL_ERROR "pyrseg: ${opt}=ON but ${toolchain} was not found")
    endif()
  elseif(NOT implemented)
    set(why "not built: ${pending}")
    if(value STREQUAL "ON")
      message(FATAL_ERROR "pyrseg: ${opt}=ON but ${pending}")
    endif()
  else()
    set(build ON)
    set(why "built (${toolchain} found)")
  endif()
  message(STATUS "pyrseg backend ${name}: ${why}")
  set(PYRSEG_BUILD_${name} ${build} PARENT_SCOPE)
  set(PYRSEG_WHY_${name} "${why}" PARENT_SCOPE)
endfunction()

# _pyrseg_gpu_api(NAME LIBRARY PACKAGE PC_REQUIRES PC_LIBS DIALECT): what the rest of the build needs of a GPU
# backend's API, for those who follow the list: the import target an application links (the interop tests, the
# examples, the bench), the package a consumer's find_package(pyrseg) finds first and the pkg-config Requires and
# Libs of a static install (cmake/PyrsegInstall.cmake), and the dialect tests/dialect/check.sh compiles its shaders
# as ("" where the API adds none of them).
function(_pyrseg_gpu_api name library package pc_requires pc_libs dialect)
  set(PYRSEG_API_LIBRARY_${name} "${library}" PARENT_SCOPE)
  set(PYRSEG_API_PACKAGE_${name} "${package}" PARENT_SCOPE)
  set(PYRSEG_API_PC_REQUIRES_${name} "${pc_requires}" PARENT_SCOPE)
  set(PYRSEG_API_PC_LIBS_${name} "${pc_libs}" PARENT_SCOPE)
  set(PYRSEG_DIALECT_${name} "${dialect}" PARENT_SCOPE)
endfunction()

message(STATUS "pyrseg backend cpu: built (always)")
set(PYRSEG_BUILD_cpu ON)
set(PYRSEG_WHY_cpu "built (always)")

include(CheckLanguage)
check_language(CUDA)
set(_cuda_found OFF)
if(CMAKE_CUDA_COMPILER)
  set(_cuda_found ON)
endif()
_pyrseg_backend(cuda PYRSEG_WITH_CUDA ${_cuda_found} "a CUDA compiler (nvcc)" ON "")
if(PYRSEG_BUILD_cuda)
  # Jetson Orin (sm_87), H100 (sm_90), Jetson Thor (sm_110) as machine code, plus PTX for sm_75 that the driver
  # compiles for any other GPU CUDA 13 supports. Override with -DCMAKE_CUDA_ARCHITECTURES=...
  if(NOT DEFINED CMAKE_CUDA_ARCHITECTURES)
    set(CMAKE_CUDA_ARCHITECTURES 87-real 90-real 110-real 75-virtual)
  endif()
  enable_language(CUDA)
  # CMake 3.25 does not know nvcc's C++20 flag; CUDA 12+ has it.
  set(CMAKE_CUDA20_STANDARD_COMPILE_OPTION "-std=c++20")
  set(CMAKE_CUDA20_EXTENSION_COMPILE_OPTION "-std=c++20")
  set(CMAKE_CUDA_STANDARD 20)
  set(CMAKE_CUDA_STANDARD_REQUIRED ON)
  find_package(CUDAToolkit REQUIRED)
endif()
_pyrseg_gpu_api(cuda CUDA::cudart_static CUDAToolkit "" "-L${CUDAToolkit_LIBRARY_DIR} -lcudart_static -ldl -lrt" cuda)

find_package(Vulkan 1.1 QUIET COMPONENTS glslangValidator)
find_program(PYRSEG_SPIRV_VAL spirv-val DOC "spirv-val (SPIRV-Tools), which checks the embedded SPIR-V")
set(_vk_found OFF)
if(Vulkan_FOUND AND Vulkan_glslangValidator_FOUND AND PYRSEG_SPIRV_VAL)
  set(_vk_found ON)
endif()
_pyrseg_backend(vulkan PYRSEG_WITH_VULKAN ${_vk_found} "the Vulkan loader and headers, glslangValidator and spirv-val"
                ON "")
_pyrseg_gpu_api(vulkan Vulkan::Vulkan Vulkan vulkan "" glsl)

find_package(OpenCL QUIET)
_pyrseg_backend(opencl PYRSEG_WITH_OPENCL ${OpenCL_FOUND} "the OpenCL ICD loader and headers" ON "")
_pyrseg_gpu_api(opencl OpenCL::OpenCL OpenCL OpenCL "" opencl)
