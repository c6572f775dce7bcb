# Compiler flags for pyrseg's own targets: warnings (errors by default), no float contraction, sanitizers.
add_library(pyrseg_build_flags INTERFACE)
target_compile_options(pyrseg_build_flags INTERFACE
  $<$<COMPILE_LANGUAGE:CXX>:-Wall -Wextra -Wpedantic -Wshadow -Wnon-virtual-dtor -Wold-style-cast
                            -Wcast-align -Woverloaded-virtual -Wimplicit-fallthrough -ffp-contract=off>)
# CUDA: no fused multiply-add (float results decide outcomes), host code warned like the C++.
target_compile_options(pyrseg_build_flags INTERFACE
  $<$<COMPILE_LANGUAGE:CUDA>:--fmad=false -Xcompiler=-Wall,-Wextra,-ffp-contract=off>)
if(PYRSEG_WERROR)
  target_compile_options(pyrseg_build_flags INTERFACE $<$<COMPILE_LANGUAGE:CXX>:-Werror>
                                                      $<$<COMPILE_LANGUAGE:CUDA>:-Werror=all-warnings>)
endif()
if(PYRSEG_SANITIZE)
  target_compile_options(pyrseg_build_flags INTERFACE
    -fsanitize=address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer)
  target_link_options(pyrseg_build_flags INTERFACE -fsanitize=address,undefined)
endif()
if(PYRSEG_SANITIZE_THREAD)
  if(PYRSEG_SANITIZE)
    message(FATAL_ERROR "PYRSEG_SANITIZE_THREAD and PYRSEG_SANITIZE cannot be combined (ThreadSanitizer excludes ASan)")
  endif()
  target_compile_options(pyrseg_build_flags INTERFACE -fsanitize=thread -fno-omit-frame-pointer)
  target_link_options(pyrseg_build_flags INTERFACE -fsanitize=thread)
endif()
