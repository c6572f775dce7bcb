#!/usr/bin/env bash
# Compiles tests/dialect/check.<lang> (every shared pass function, check_calls.h) as one dialect of shaders/.
# Usage: check.sh opencl|glsl|cuda SHADERS_DIR OUT_DIR. Exit 77 (skipped) when the compiler is missing.
set -euo pipefail
lang="$1"; shaders="$2"; out="$3"; here="$(cd "$(dirname "$0")" && pwd)"
need() { command -v "$1" >/dev/null || { echo "skipped: $1 not found ($2)"; exit 77; }; }
case "$lang" in
  opencl)
    need clang "Debian package clang"
    clang -x cl -cl-std=CL1.2 -Xclang -finclude-default-header -fsyntax-only -Wall -Werror -I"$shaders" "$here/check.cl" ;;
  glsl)
    need glslangValidator "Debian package glslang-tools"
    need spirv-val "Debian package spirv-tools"
    glslangValidator -V --target-env vulkan1.1 -I"$shaders" -I"$here" -o "$out/check.spv" "$here/check.comp"
    spirv-val --target-env vulkan1.1 "$out/check.spv" ;;
  cuda)
    need nvcc "the CUDA toolkit"
    nvcc -std=c++20 --fmad=false -Werror all-warnings -I"$shaders" -I"$here" -c "$here/check.cu" -o "$out/check_cuda.o" ;;
  *) echo "unknown dialect $lang"; exit 2 ;;
esac
echo "shaders/ compiles as $lang"
