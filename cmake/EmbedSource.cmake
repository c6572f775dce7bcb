# cmake -P EmbedSource.cmake: INPUT (a kernel source), INCLUDE_DIR, OUTPUT (a .cpp), SYMBOL.
cmake_policy(VERSION 3.25)
# Inlines #include "..." lines from INCLUDE_DIR (each file once, as include guards would) so the runtime compiler
# needs no file system, and writes the result as `extern const char SYMBOL[]` in OUTPUT.
function(_inline_includes file out_var)
  file(READ "${file}" text)
  string(REGEX MATCHALL "#include \"[^\"]+\"" includes "${text}")
  foreach(directive IN LISTS includes)
    string(REGEX REPLACE "#include \"([^\"]+)\"" "\\1" name "${directive}")
    if(name IN_LIST _seen)
      string(REPLACE "${directive}" "/* ${name} already included */" text "${text}")
    else()
      list(APPEND _seen "${name}")
      set(_seen "${_seen}" PARENT_SCOPE)
      _inline_includes("${INCLUDE_DIR}/${name}" inner)
      set(_seen "${_seen}" PARENT_SCOPE)
      string(REPLACE "${directive}" "/* begin ${name} */\n${inner}\n/* end ${name} */" text "${text}")
    endif()
  endforeach()
  set(${out_var} "${text}" PARENT_SCOPE)
endfunction()

set(_seen "")
_inline_includes("${INPUT}" source)
# A raw string literal cannot contain its own delimiter; the sources never contain )PYRSRC".
file(WRITE "${OUTPUT}.tmp" "// Generated from ${INPUT} by cmake/EmbedSource.cmake. Do not edit.\n"
     "extern const char ${SYMBOL}[];\nconst char ${SYMBOL}[] = R\"PYRSRC(${source})PYRSRC\";\n")
file(COPY_FILE "${OUTPUT}.tmp" "${OUTPUT}" ONLY_IF_DIFFERENT)
file(REMOVE "${OUTPUT}.tmp")
