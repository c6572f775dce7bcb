# `cmake --install`: the library (pyrseg::pyrseg), the file formats (pyrseg::io), the synthetic scenes
# (pyrseg::synthetic), their headers, the pyrseg tool, a CMake package so that consumers write find_package(pyrseg)
# and link pyrseg::pyrseg, pkg-config files (pyrseg, pyrseg-io, pyrseg-synthetic), and `cpack` making a .deb of it all.
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set_target_properties(pyrseg PROPERTIES EXPORT_NAME pyrseg)
set_target_properties(pyrseg_io PROPERTIES EXPORT_NAME io)
set_target_properties(pyrseg_synthetic PROPERTIES EXPORT_NAME synthetic)
# Static libraries carry their private link dependencies, so the interface targets they link go into the export set
# too: the flags target only adds link options (sanitizers); PCL io is found without a CMake package
# (io/CMakeLists.txt) and exported as the paths found here.
set(_pyrseg_exported pyrseg pyrseg_io pyrseg_synthetic pyrseg_build_flags)
foreach(_t pyrseg_pcl_io)
  if(TARGET ${_t})
    list(APPEND _pyrseg_exported ${_t})
  endif()
endforeach()
install(TARGETS ${_pyrseg_exported} EXPORT pyrsegTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
        LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
        RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR}
        INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
# The interop headers of backends this build lacks would declare functions the library does not have.
set(_pyrseg_header_excludes "")
foreach(_b IN LISTS PYRSEG_GPU_BACKENDS)
  if(NOT PYRSEG_BUILD_${_b})
    list(APPEND _pyrseg_header_excludes PATTERN "${_b}.hpp" EXCLUDE)
  endif()
endforeach()
install(DIRECTORY include/pyrseg DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}
        FILES_MATCHING PATTERN "*.hpp" ${_pyrseg_header_excludes})
install(FILES ${PROJECT_BINARY_DIR}/generated/include/pyrseg/version.hpp
              ${PROJECT_BINARY_DIR}/generated/include/pyrseg/export.hpp
              ${PROJECT_BINARY_DIR}/generated/include/pyrseg/io_export.hpp
              ${PROJECT_BINARY_DIR}/generated/include/pyrseg/synthetic_export.hpp
        DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/pyrseg)
if(TARGET pyrseg_cli)
  install(TARGETS pyrseg_cli RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
  if(BUILD_SHARED_LIBS)
    # The tool finds the shared libraries beside it wherever the prefix is (a temporary prefix, an unpacked .deb).
    file(RELATIVE_PATH _bin_to_lib ${CMAKE_INSTALL_FULL_BINDIR} ${CMAKE_INSTALL_FULL_LIBDIR})
    set_target_properties(pyrseg_cli PROPERTIES INSTALL_RPATH "$ORIGIN/${_bin_to_lib}")
  endif()
endif()
install(FILES LICENSE CHANGELOG.md README.md DESTINATION ${CMAKE_INSTALL_DOCDIR})

# What a consumer's find_package(pyrseg) must find first: a static library's private dependencies become the
# consumer's link dependencies (pyrsegConfig.cmake.in); a shared library resolves them itself.
set(PYRSEG_STATIC_DEPENDENCIES "")
if(NOT BUILD_SHARED_LIBS)
  set(PYRSEG_STATIC_DEPENDENCIES "find_dependency(hwy)\nfind_dependency(nlohmann_json)\nfind_dependency(PNG)\n")
  string(APPEND PYRSEG_STATIC_DEPENDENCIES "find_dependency(TIFF)\nfind_dependency(tinyxml2)\n")
  foreach(_b IN LISTS PYRSEG_GPU_BACKENDS)
    if(PYRSEG_BUILD_${_b})
      string(APPEND PYRSEG_STATIC_DEPENDENCIES "find_dependency(${PYRSEG_API_PACKAGE_${_b}})\n")
    endif()
  endforeach()
endif()
install(EXPORT pyrsegTargets NAMESPACE pyrseg:: DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/pyrseg)
configure_package_config_file(cmake/pyrsegConfig.cmake.in ${PROJECT_BINARY_DIR}/pyrsegConfig.cmake
                              INSTALL_DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/pyrseg)
write_basic_package_version_file(${PROJECT_BINARY_DIR}/pyrsegConfigVersion.cmake COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/pyrsegConfig.cmake ${PROJECT_BINARY_DIR}/pyrsegConfigVersion.cmake
        DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/pyrseg)

# pkg-config files, relocatable (${pcfiledir}): the same files serve a temporary prefix and an unpacked .deb.
# A static library's dependencies are in Requires and Libs themselves, not in the .private fields: the default
# install is static, and `pkg-config --libs pyrseg` without --static must then link (it once left about 550
# undefined references). A shared library records its own (DT_NEEDED) and lists none.
if(IS_ABSOLUTE "${CMAKE_INSTALL_LIBDIR}" OR IS_ABSOLUTE "${CMAKE_INSTALL_INCLUDEDIR}")
  message(FATAL_ERROR "pyrseg: the pkg-config files need CMAKE_INSTALL_LIBDIR and CMAKE_INSTALL_INCLUDEDIR relative")
endif()
file(RELATIVE_PATH _pc_to_prefix /prefix/${CMAKE_INSTALL_LIBDIR}/pkgconfig /prefix)
string(REGEX REPLACE "/$" "" _pc_to_prefix "${_pc_to_prefix}")
set(PYRSEG_PC_PREFIX "\${pcfiledir}/${_pc_to_prefix}")
# _pyrseg_pc(NAME DESCRIPTION LIBRARY REQUIRES STATIC_REQUIRES STATIC_LIBS): STATIC_* only for static libraries.
function(_pyrseg_pc name description library requires static_requires static_libs)
  set(PC_NAME ${name})
  set(PC_DESCRIPTION "${description}")
  set(PC_LIBRARY ${library})
  set(PC_REQUIRES "${requires}")
  set(PC_LIBS "")
  if(NOT BUILD_SHARED_LIBS)
    string(STRIP "${requires} ${static_requires}" PC_REQUIRES)
    set(PC_LIBS "${static_libs}")
    # Instrumented static libraries need the sanitizers' runtimes wherever they are linked (the CMake package has
    # them through pyrseg_build_flags' link options).
    if(PYRSEG_SANITIZE)
      string(APPEND PC_LIBS " -fsanitize=address,undefined")
    endif()
    string(STRIP "${PC_LIBS}" PC_LIBS)
    if(PC_LIBS)
      set(PC_LIBS " ${PC_LIBS}")
    endif()
  endif()
  # A static library's export macros are empty (cmake/PyrsegLibraries.cmake), as they are in its own build.
  get_target_property(type ${library} TYPE)
  set(PC_CFLAGS "")
  if(type STREQUAL "STATIC_LIBRARY")
    string(TOUPPER "${library}" base)
    set(PC_CFLAGS " -D${base}_STATIC_DEFINE")
  endif()
  configure_file(${PROJECT_SOURCE_DIR}/cmake/pyrseg.pc.in ${PROJECT_BINARY_DIR}/pkgconfig/${name}.pc @ONLY)
  install(FILES ${PROJECT_BINARY_DIR}/pkgconfig/${name}.pc DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig)
endfunction()
set(_core_requires "libhwy")
set(_core_libs "")
foreach(_b IN LISTS PYRSEG_GPU_BACKENDS)
  if(PYRSEG_BUILD_${_b})
    if(PYRSEG_API_PC_REQUIRES_${_b})
      string(APPEND _core_requires " ${PYRSEG_API_PC_REQUIRES_${_b}}")
    endif()
    if(PYRSEG_API_PC_LIBS_${_b})
      string(APPEND _core_libs " ${PYRSEG_API_PC_LIBS_${_b}}")
    endif()
  endif()
endforeach()
_pyrseg_pc(pyrseg "${PROJECT_DESCRIPTION}" pyrseg "tbb" "${_core_requires}" "${_core_libs}")
set(_io_libs "${LZF_LIBRARY}")  # libyaml comes through Requires.private (yaml-0.1)
if(TARGET pyrseg_pcl_io)
  string(APPEND _io_libs " ${PYRSEG_PCL_IO_LIBRARY} ${PYRSEG_PCL_COMMON_LIBRARY}")
endif()
_pyrseg_pc(pyrseg-io "pyrseg's file formats: PCD, PLY, NumPy, PNG and TIFF depth images, calibration files"
           pyrseg_io pyrseg "libpng libtiff-4 tinyxml2 yaml-0.1" "${_io_libs}")
_pyrseg_pc(pyrseg-synthetic "Seeded synthetic bin-picking scenes with ground truth, for tests and demos"
           pyrseg_synthetic "" "" "")

# cpack: one .deb with the libraries, headers, CMake and pkg-config files and the tool (build/package, made by
# scripts/package.sh, is a shared CPU-only build). Its Depends come from dpkg-shlibdeps on the binaries inside.
set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME pyrseg)
set(CPACK_PACKAGE_VENDOR "pyrseg maintainers")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "${PROJECT_DESCRIPTION}")
set(CPACK_PACKAGE_DESCRIPTION "pyrseg segments organized point clouds and depth images into surfaces (C++20 \
library, file formats, synthetic test scenes and the pyrseg command-line tool), with CMake and pkg-config files.")
set(CPACK_RESOURCE_FILE_LICENSE ${PROJECT_SOURCE_DIR}/LICENSE)
set(PYRSEG_PACKAGE_MAINTAINER "pyrseg maintainers <maintainers@users.noreply.h-seed-f5177c9b.example>"
    CACHE STRING "The Maintainer field of the .deb cpack makes")
set(CPACK_DEBIAN_PACKAGE_MAINTAINER "${PYRSEG_PACKAGE_MAINTAINER}")
set(CPACK_DEBIAN_PACKAGE_SECTION libdevel)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
# The tool links the package's own libraries: dpkg-shlibdeps looks for them in the staging tree, not the system.
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS_PRIVATE_DIRS ${CMAKE_INSTALL_FULL_LIBDIR})
# libpyrseg.so is a library others link: ship its shlibs file so that their packages depend on this one.
set(CPACK_DEBIAN_PACKAGE_GENERATE_SHLIBS ON)
set(CPACK_DEBIAN_PACKAGE_GENERATE_SHLIBS_POLICY ">=")
include(CPack)
