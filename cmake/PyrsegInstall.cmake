# `cmake --install`: the library (pyrseg::pyrseg), the synthetic scenes (pyrseg::synthetic), their headers, the
# pyrseg tool, and a CMake package so that consumers write find_package(pyrseg) and link pyrseg::pyrseg.
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set_target_properties(pyrseg PROPERTIES EXPORT_NAME pyrseg)
set_target_properties(pyrseg_synthetic PROPERTIES EXPORT_NAME synthetic)
# Static libraries carry their private link dependencies; the flags target only adds link options (sanitizers).
install(TARGETS pyrseg pyrseg_synthetic pyrseg_build_flags EXPORT pyrsegTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR} LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR})
install(DIRECTORY include/pyrseg DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}
        FILES_MATCHING PATTERN "*.hpp" PATTERN "io.hpp" EXCLUDE)
install(FILES ${PROJECT_BINARY_DIR}/generated/include/pyrseg/version.hpp
        DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/pyrseg)
if(TARGET pyrseg_cli)
  install(TARGETS pyrseg_cli RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
endif()
install(EXPORT pyrsegTargets NAMESPACE pyrseg:: DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/pyrseg)
configure_package_config_file(cmake/pyrsegConfig.cmake.in ${PROJECT_BINARY_DIR}/pyrsegConfig.cmake
                              INSTALL_DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/pyrseg)
write_basic_package_version_file(${PROJECT_BINARY_DIR}/pyrsegConfigVersion.cmake COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/pyrsegConfig.cmake ${PROJECT_BINARY_DIR}/pyrsegConfigVersion.cmake
        DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/pyrseg)
