# `cmake --build BUILD --target docs`: the API reference from the public headers (scripts/api-docs.sh, doxygen),
# into BUILD/api-docs/html. Not part of `all`: CI runs the script itself.
find_program(PYRSEG_DOXYGEN doxygen DOC "doxygen, for the API reference (the docs target)")
if(PYRSEG_DOXYGEN)
  add_custom_target(docs COMMAND ${PROJECT_SOURCE_DIR}/scripts/api-docs.sh ${PROJECT_BINARY_DIR}/api-docs
                    COMMENT "API reference in ${PROJECT_BINARY_DIR}/api-docs/html" VERBATIM)
else()
  message(STATUS "pyrseg: no docs target (doxygen not found; scripts/deps.sh installs it)")
endif()
