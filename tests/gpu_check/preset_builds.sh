#!/usr/bin/env bash
# Keeps scripts/gpu-check.sh's build from rotting where no GPU ever is: configures the gpu-check preset (sm_90, no
# PLY, no peers, RPATH for the bundle) into a scratch folder and builds the library with its CUDA backend; checks
# the scripts' syntax. Usage: preset_builds.sh SOURCE_DIR. Exit 77 (skipped) without nvcc.
set -euo pipefail
source="$1"
command -v nvcc >/dev/null || { echo "skipped: nvcc not found (the gpu-check preset builds CUDA)"; exit 77; }
bash -n "$source/scripts/gpu-check.sh"
python3 -c 'import ast, sys; [ast.parse(open(f).read(), f) for f in sys.argv[1:]]' \
  "$source/scripts/gpu_check/summarize.py" "$source/scripts/gpu_check/cupy_label.py"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
cd "$source"
cmake --preset gpu-check -B "$work/build" >"$work/configure.log" 2>&1 || { cat "$work/configure.log"; exit 1; }
grep -E "^-- pyrseg backend cuda: built" "$work/configure.log"
grep -q '^CMAKE_CUDA_ARCHITECTURES:[A-Z]*=90-real$' "$work/build/CMakeCache.txt" ||
  { echo "the gpu-check preset must build sm_90 machine code"; exit 1; }
cmake --build "$work/build" --target pyrseg -j 2 >"$work/build.log" 2>&1 || { tail -n 50 "$work/build.log"; exit 1; }
grep -q 'generate-code=arch=compute_90,code=\[sm_90\]' "$work/build/build.ninja" ||
  { echo "the CUDA backend is not compiled to sm_90 machine code"; exit 1; }
# Captured first: `objdump | grep -q` under pipefail fails whenever grep stops reading before objdump ends.
sections="$(objdump -h "$work/build/core/CMakeFiles/pyrseg.dir/__/backends/cuda/cuda_backend.cu.o")"
grep -q nv_fatbin <<<"$sections" ||
  { echo "the CUDA backend's object carries no fat binary"; exit 1; }
echo "gpu-check preset: configured and built the library with sm_90 code"
