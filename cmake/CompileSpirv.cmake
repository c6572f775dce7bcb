# cmake -P CompileSpirv.cmake: GLSLANG, SPIRV_VAL, INPUT (a .comp), INCLUDE_DIR, ENTRY (PYR_ENTRY_<ENTRY> is
# defined), SPV (the module's path), OUTPUT (a .cpp), SYMBOL.
cmake_policy(VERSION 3.25)
# Compiles one entry point of INPUT to SPIR-V for Vulkan 1.1, validates it with spirv-val, and writes the words as
# `extern const std::uint32_t SYMBOL[]` plus SYMBOL_words in OUTPUT. Any failure stops the build with the tool's log.
execute_process(
  COMMAND ${GLSLANG} -V --target-env vulkan1.1 -DPYR_ENTRY_${ENTRY} -I${INCLUDE_DIR} -o ${SPV} ${INPUT}
  RESULT_VARIABLE rc OUTPUT_VARIABLE log ERROR_VARIABLE log)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "glslangValidator failed on ${INPUT} (PYR_ENTRY_${ENTRY}):\n${log}")
endif()
execute_process(COMMAND ${SPIRV_VAL} --target-env vulkan1.1 ${SPV}
                RESULT_VARIABLE rc OUTPUT_VARIABLE log ERROR_VARIABLE log)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "spirv-val rejected ${SPV} (PYR_ENTRY_${ENTRY}):\n${log}")
endif()

file(READ ${SPV} hex HEX)
string(LENGTH "${hex}" hex_length)
math(EXPR remainder "${hex_length} % 8")
if(hex_length EQUAL 0 OR NOT remainder EQUAL 0)
  message(FATAL_ERROR "${SPV} is not a whole number of 32-bit words")
endif()
# SPIR-V words are little-endian in the file (glslang writes the host's order; the magic number checks it).
string(SUBSTRING "${hex}" 0 8 magic)
if(NOT magic STREQUAL "03022307")
  message(FATAL_ERROR "${SPV} does not start with the little-endian SPIR-V magic number")
endif()
string(REGEX REPLACE "(..)(..)(..)(..)" "0x\\4\\3\\2\\1u," words "${hex}")
math(EXPR word_count "${hex_length} / 8")
file(WRITE "${OUTPUT}.tmp"
     "// Generated from ${INPUT} (PYR_ENTRY_${ENTRY}) by cmake/CompileSpirv.cmake. Do not edit.\n"
     "#include <cstddef>\n#include <cstdint>\n"
     "extern const std::uint32_t ${SYMBOL}[];\nextern const std::size_t ${SYMBOL}_words;\n"
     "const std::uint32_t ${SYMBOL}[] = {${words}};\n"
     "const std::size_t ${SYMBOL}_words = ${word_count};\n")
file(COPY_FILE "${OUTPUT}.tmp" "${OUTPUT}" ONLY_IF_DIFFERENT)
file(REMOVE "${OUTPUT}.tmp")
