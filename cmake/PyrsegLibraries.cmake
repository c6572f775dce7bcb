# How pyrseg's libraries are built, once every directory has defined its targets (included at the end of the
# top-level CMakeLists.txt): position-independent code, the shared libraries' version and exported symbols.
include(GenerateExportHeader)

# Every static library is position-independent, so that a shared object (the Python module, an application's plugin,
# libpyrseg.so itself) can link it; Debian's default -fPIE code fails there with a relocation error. Executables keep
# the compiler's default (PIE). Walks the directory tree so that a library added later needs nothing here.
function(_pyrseg_libraries_pic dir)
  get_property(targets DIRECTORY ${dir} PROPERTY BUILDSYSTEM_TARGETS)
  foreach(target IN LISTS targets)
    get_target_property(type ${target} TYPE)
    if(type MATCHES "^(STATIC|OBJECT)_LIBRARY$")
      set_target_properties(${target} PROPERTIES POSITION_INDEPENDENT_CODE ON)
    endif()
  endforeach()
  get_property(subdirs DIRECTORY ${dir} PROPERTY SUBDIRECTORIES)
  foreach(subdir IN LISTS subdirs)
    _pyrseg_libraries_pic(${subdir})
  endforeach()
endfunction()
_pyrseg_libraries_pic(${PROJECT_SOURCE_DIR})

# 0.x releases may break the ABI at every minor version (as pyrsegConfigVersion.cmake's SameMinorVersion says), so the
# soname carries major.minor until 1.0, the major version alone after.
if(PROJECT_VERSION_MAJOR EQUAL 0)
  set(PYRSEG_SOVERSION ${PROJECT_VERSION_MAJOR}.${PROJECT_VERSION_MINOR})
else()
  set(PYRSEG_SOVERSION ${PROJECT_VERSION_MAJOR})
endif()

# The installed libraries (pyrseg, pyrseg_io, pyrseg_synthetic) export only what their public headers mark
# PYRSEG_EXPORT, PYRSEG_IO_EXPORT or PYRSEG_SYNTHETIC_EXPORT: everything else (core/, backends/, the bundled static
# CUDA runtime) is hidden, so applications cannot come to depend on internals and the symbols cannot clash with
# another copy of them in the process. The static libraries are built the same way, so that a shared object linking
# one (the Python module) does not re-export pyrseg either; the macros are then empty (<BASE>_STATIC_DEFINE).
function(_pyrseg_public_library target base header)
  generate_export_header(${target} BASE_NAME ${base}
                         EXPORT_FILE_NAME ${PROJECT_BINARY_DIR}/generated/include/pyrseg/${header})
  set_target_properties(${target} PROPERTIES CXX_VISIBILITY_PRESET hidden CUDA_VISIBILITY_PRESET hidden
                                             VISIBILITY_INLINES_HIDDEN ON VERSION ${PROJECT_VERSION}
                                             SOVERSION ${PYRSEG_SOVERSION})
  target_include_directories(${target} PUBLIC $<BUILD_INTERFACE:${PROJECT_BINARY_DIR}/generated/include>)
  get_target_property(type ${target} TYPE)
  if(type STREQUAL "STATIC_LIBRARY")
    target_compile_definitions(${target} PUBLIC ${base}_STATIC_DEFINE)
  else()
    set(map ${PROJECT_SOURCE_DIR}/cmake/pyrseg.map)
    target_link_options(${target} PRIVATE LINKER:--version-script=${map})
    set_property(TARGET ${target} APPEND PROPERTY LINK_DEPENDS ${map})
  endif()
endfunction()
_pyrseg_public_library(pyrseg PYRSEG export.hpp)
_pyrseg_public_library(pyrseg_io PYRSEG_IO io_export.hpp)
_pyrseg_public_library(pyrseg_synthetic PYRSEG_SYNTHETIC synthetic_export.hpp)
