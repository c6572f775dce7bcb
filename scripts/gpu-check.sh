#!/usr/bin/env bash
# One command verifies every GPU backend on a GPU machine. GPU time is rare and short, so everything is built
# beforehand, on a machine without a GPU, into a self-contained folder that travels with the checkout (all but the
# Python module, which is compiled there for that machine's Python, against shared libraries built here):
#
#   scripts/gpu-check.sh prepare            here: builds build/gpu/ (binaries, the .so files they need, pyrseg's
#                                           shared libraries and headers for the Python module, test data)
#   scripts/gpu-check.sh run [REPORT_DIR]   there: versions, conformance, the CUDA interop (device pointers on an
#                                           application's stream, graph capture), the Python module (CuPy arrays),
#                                           compute-sanitizer, bench, CuPy's label, Vulkan and OpenCL on the NVIDIA
#                                           driver; summary.md and logs in REPORT_DIR ($PYRSEG_GPU_REPORT, default
#                                           build/gpu-report/)
#   scripts/gpu-check.sh run --rehearse [REPORT_DIR]
#                                           the same steps with the cpu backend standing in for the GPU ones, to
#                                           test this script where there is no GPU; it checks nothing about GPUs
#
# backends/cuda/README.md gives the whole procedure and how long each step takes.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
bundle="${PYRSEG_GPU_BUNDLE:-$root/build/gpu}"
bundle_limit_mib=48
# The sample scans the tests read (tests/conformance): copied into the bundle, since a GPU machine has no ../shared.
data_files=(table_scene_mug_stereo_textured.pcd milk_cartoon_all_small_clorox.pcd cape_depth_0.png
            cape_calib_params.xml README.md LICENSE-PCL.txt LICENSE-CAPE.txt)
binaries=(tests/pyrseg_test_conformance tests/pyrseg_test_unit bench/pyrseg_bench tools/pyrseg)
# Built beside the preset's own targets: the GPU APIs' interop tests (pyrseg/cuda.hpp's among them) and the CUDA
# application (examples/cuda_app.cpp).
extra_targets=(pyrseg_test_interop pyrseg_example_cuda_app)
binaries+=(tests/pyrseg_test_interop examples/pyrseg_example_cuda_app)
fallback_libs=(libstdc++.so.6 libgcc_s.so.1 libGLX.so.0 libGLdispatch.so.0 libX11.so.6 libxcb.so.1 libXau.so.6
               libXdmcp.so.6 libbsd.so.0 libmd.so.0)

say() { printf 'gpu-check: %s\n' "$*"; }
die() { printf 'gpu-check: %s\n' "$1" >&2; exit "${2:-1}"; }

usage() {
  sed -n '2,16p' "$0" | sed 's/^# \{0,1\}//'
}

# The newest glibc symbol version any of the given ELF files asks for (e.g. 2.34).
glibc_needed() {
  objdump -T "$@" 2>/dev/null | grep -o 'GLIBC_[0-9][0-9.]*' | sed 's/GLIBC_//' | sort -V | tail -n 1
}

# The backends a configure log says are built, on one line (e.g. "cpu cuda vulkan opencl").
built_backends() {
  grep -E '^-- pyrseg backend' <<<"$1" | grep -o 'backend [a-z]*: built' |
    awk '{printf "%s%s", sep, substr($2, 1, length($2) - 1); sep=" "}'
}

prepare() {
  local build="$root/build/gpu-build"
  "$root/scripts/deps.sh"
  command -v nvcc >/dev/null || die "prepare needs the CUDA compiler (nvcc) on the PATH"
  local log
  if ! log=$(cd "$root" && cmake --preset gpu-check 2>&1); then
    echo "$log"
    die "configuring the gpu-check preset failed"
  fi
  grep -E "^-- pyrseg" <<<"$log" || true
  (cd "$root" && cmake --build --preset gpu-check)
  (cd "$root" && cmake --build --preset gpu-check --target "${extra_targets[@]}")
  # The same configuration as shared libraries (cpu and cuda backends only), for the Python module that `run` builds
  # there with that machine's Python and pybind11 (scripts/gpu_check/python/CMakeLists.txt).
  local shared="$root/build/gpu-shared" shared_log
  if ! shared_log=$(cd "$root" && cmake --preset gpu-check-shared 2>&1); then
    echo "$shared_log"
    die "configuring the gpu-check-shared preset failed"
  fi
  (cd "$root" && cmake --build --preset gpu-check-shared)
  rm -rf "$shared/stage"
  cmake --install "$shared" --prefix "$shared/stage" >/dev/null

  rm -rf "$bundle"
  mkdir -p "$bundle/bin" "$bundle/lib" "$bundle/data"
  for b in "${binaries[@]}"; do
    cp "$build/$b" "$bundle/bin/"
  done
  strip --strip-unneeded "$bundle"/bin/*
  # The shared libraries as installed (the real file and its soname and development links, relative), their CMake
  # package and headers (the generated export headers among them): the bundle is their install prefix, so the
  # module built there finds them with find_package(pyrseg) and loads them through its RPATH to lib/. Not the
  # pkg-config files or the documents.
  cp -P "$shared"/stage/lib/libpyrseg*.so* "$bundle/lib/"
  mkdir -p "$bundle/lib/cmake"
  cp -R "$shared/stage/lib/cmake/pyrseg" "$bundle/lib/cmake/"
  cp -R "$shared/stage/include" "$bundle/"
  # Every shared library the binaries load, except glibc's own (any Linux has them): the GPU machine has none of
  # Debian's libraries (libpng, libtiff, OpenCV core, liblzf, Google Benchmark, the Vulkan and OpenCL loaders).
  # libstdc++ travels too, so an older one there cannot stop the binaries. The binaries' RPATH is $ORIGIN/../lib
  # (the preset), as DT_RPATH so that it also serves the libraries' own dependencies.
  # The shared pyrseg libraries' own dependencies too (their RPATH is $ORIGIN: the bundle's lib/).
  local lib name pyrseg_libs
  mapfile -t pyrseg_libs < <(find "$bundle/lib" -maxdepth 1 -type f -name 'libpyrseg*')
  while read -r lib; do
    name="$(basename "$lib")"
    case "$name" in
      libc.so.* | libm.so.* | libdl.so.* | libpthread.so.* | librt.so.* | libresolv.so.* | ld-linux*) continue ;;
      libpyrseg*) continue ;;
    esac
    cp -L "$lib" "$bundle/lib/$name"
  done < <(ldd "$bundle"/bin/* "${pyrseg_libs[@]}" | awk '$2 == "=>" && $3 ~ /^\// {print $3}' | sort -u)
  find "$bundle/lib" -maxdepth 1 -type f -exec chmod u+w {} + -exec strip --strip-unneeded {} +
  # Libraries a GPU machine most likely has already, and whose own copy should win there: the C++ runtime (Debian's
  # needs glibc 2.36) and glvnd's GLX with X11 (OpenCV core links them; NVIDIA's Vulkan driver uses glvnd too).
  # `run` uses these copies only for those its machine lacks.
  mkdir -p "$bundle/lib/fallback"
  for name in "${fallback_libs[@]}"; do
    if [ -f "$bundle/lib/$name" ]; then mv "$bundle/lib/$name" "$bundle/lib/fallback/"; fi
  done
  # Output captured before grep: `ldd | grep -q` under pipefail fails when grep stops reading first.
  local resolved
  resolved="$(env -u LD_LIBRARY_PATH ldd "$bundle"/bin/* "${pyrseg_libs[@]}")"
  if grep -q "not found" <<<"$resolved"; then
    grep "not found" <<<"$resolved" >&2
    die "a library the binaries or the shared pyrseg libraries need was not found"
  fi

  local data="${PYRSEG_SHARED_DATA_DIR:-$root/../shared/data}" missing=()
  for f in "${data_files[@]}"; do
    if [ -f "$data/$f" ]; then cp "$data/$f" "$bundle/data/"; else missing+=("$f"); fi
  done
  if ((${#missing[@]})); then
    say "warning: not in $data: ${missing[*]} (the real-scan tests will be skipped on the GPU machine)"
  fi

  local glibc glibcxx
  glibc="$(glibc_needed "$bundle"/bin/* "$bundle"/lib/*.so*)"
  glibcxx="$(objdump -T "$bundle"/bin/* "$bundle"/lib/*.so* | grep -o 'GLIBCXX_[0-9][0-9.]*' | sort -V | tail -n 1)"
  {
    echo "commit: $(git -C "$root" rev-parse --short HEAD 2>/dev/null || echo unknown)$(
      git -C "$root" diff --quiet HEAD 2>/dev/null || echo ' (with uncommitted changes)')"
    echo "prepared: $(date -u '+%Y-%m-%d %H:%M UTC') on $(uname -n)"
    echo "nvcc: $(nvcc --version | sed -n 's/.*release \([0-9.]*\).*/\1/p')"
    echo "cuda architectures: $(sed -n 's/^CMAKE_CUDA_ARCHITECTURES:[A-Z]*=//p' "$build/CMakeCache.txt")"
    echo "glibc needed: $glibc"
    echo "libstdc++ needed: $glibcxx"
    echo "glibc needed by lib/fallback: $(glibc_needed "$bundle"/lib/fallback/*)"
    echo "backends built: $(built_backends "$log")"
    echo "shared libraries for the Python module: $(cd "$bundle/lib" &&
      find . -maxdepth 1 -type l -name 'libpyrseg*.so.*' -printf '%f ')(backends $(built_backends "$shared_log"))"
  } >"$bundle/MANIFEST.txt"

  local bytes mib
  bytes=$(du -sb "$bundle" | cut -f1)
  mib=$(awk -v b="$bytes" 'BEGIN {printf "%.1f", b / 1048576}')
  say "bundle $bundle: $mib MiB (limit $bundle_limit_mib MiB); glibc >= $glibc needed"
  du -sh "$bundle"/bin "$bundle"/lib "$bundle"/include "$bundle"/data | sed 's/^/  /'
  if ((bytes >= bundle_limit_mib * 1048576)); then
    die "the bundle is over $bundle_limit_mib MiB: it would slow every copy to the GPU machine"
  fi
  # The binaries must start on their own: what they say here (no GPU) is what a GPU machine shows otherwise.
  say "the prepared binaries, started here:"
  env -u LD_LIBRARY_PATH "$bundle/bin/pyrseg" backends | sed 's/^/  /'
  say "next: copy the checkout with build/gpu to the GPU machine and run 'scripts/gpu-check.sh run' there"
}

# --- run -------------------------------------------------------------------------------------------------------

# Seconds a step may take: its own limit, cut so that the whole run ends within $PYRSEG_GPU_CHECK_BUDGET (default
# 480 s: a GPU lease's command limit is 600 s, and the summary must be written before anything is killed).
step_limit() {
  local left=$((deadline - SECONDS - 30))
  ((left < 1)) && left=1
  ((left < $1)) && echo "$left" || echo "$1"
}

backend_available() {  # backend_available NAME: from `pyrseg backends`, under the current environment
  "$bundle/bin/pyrseg" backends | awk -v b="$1" '$1 == b && $2 == "available" {found = 1} END {exit !found}'
}

# The copies in lib/fallback that this machine needs: each one whose soname the machine lacks, and the C++ runtime
# when the machine's is older than the one the binaries were built with. Linked into $work/fallback-lib.
use_fallback_libs() {
  local so name system need_cxx
  need_cxx="$(sed -n 's/^libstdc++ needed: //p' "$bundle/MANIFEST.txt" 2>/dev/null || true)"
  mkdir -p "$work/fallback-lib"
  for so in "$bundle"/lib/fallback/*; do
    [ -f "$so" ] || continue
    name="$(basename "$so")"
    system="$( (ldconfig -p 2>/dev/null || true) | awk -v n="$name" '$1 == n && !found {print $NF; found = 1}')"
    local dir
    for dir in ${LD_LIBRARY_PATH:+${LD_LIBRARY_PATH//:/ }}; do  # the driver's folders that find_nvidia_drivers added
      [ -z "$system" ] && [ -f "$dir/$name" ] && system="$dir/$name"
    done
    if [ -z "$system" ] ||
       { [ "$name" = libstdc++.so.6 ] && [ -n "$need_cxx" ] && ! grep -qa "$need_cxx" "$system"; }; then
      ln -s "$so" "$work/fallback-lib/$name"
    fi
  done
  if [ -n "$(find "$work/fallback-lib" -mindepth 1)" ]; then
    say "using the bundle's own $(find "$work/fallback-lib" -mindepth 1 -printf '%f ') (not found on this machine)"
    export LD_LIBRARY_PATH="$work/fallback-lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
  fi
}

# Points the carried Vulkan and OpenCL loaders at the NVIDIA driver when it is installed where they do not look
# (a container with the driver mounted under /usr/local/nvidia, say).
find_nvidia_drivers() {
  local dir
  for dir in /usr/local/nvidia/lib64 /usr/local/nvidia/lib /usr/lib/x86_64-linux-gnu/nvidia; do
    [ -d "$dir" ] && export LD_LIBRARY_PATH="${LD_LIBRARY_PATH:+$LD_LIBRARY_PATH:}$dir"
  done
  if [ -z "${VK_DRIVER_FILES:-}${VK_ICD_FILENAMES:-}" ]; then
    local json
    for json in /usr/share/vulkan/icd.d/nvidia_icd.json /etc/vulkan/icd.d/nvidia_icd.json \
                /usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json /usr/local/nvidia/icd.d/nvidia_icd.json; do
      if [ -f "$json" ]; then
        export VK_DRIVER_FILES="$json" VK_ICD_FILENAMES="$json"
        break
      fi
    done
  fi
  if [ -z "${OCL_ICD_VENDORS:-}" ] && [ ! -f /etc/OpenCL/vendors/nvidia.icd ]; then
    local so
    so="$( (ldconfig -p 2>/dev/null || true) | awk '/libnvidia-opencl\.so\.1/ && !found {print $NF; found = 1}')"
    for dir in /usr/local/nvidia/lib64 /usr/local/nvidia/lib; do
      [ -z "$so" ] && [ -f "$dir/libnvidia-opencl.so.1" ] && so="$dir/libnvidia-opencl.so.1"
    done
    if [ -n "$so" ]; then
      mkdir -p "$work/opencl-vendors"
      echo "$so" >"$work/opencl-vendors/nvidia.icd"
      export OCL_ICD_VENDORS="$work/opencl-vendors"
    fi
  fi
}

# run_sharded NAME BACKEND [VAR=VALUE...]: the conformance suite for BACKEND (in that environment), split over the
# machine's cores; XML per shard in $work, the suite's name in $work/suites.
run_sharded() {
  local name="$1" backend="$2" shards i status=0
  shift 2
  echo "$name" >>"$work/suites"
  shards=$(nproc)
  ((shards > 16)) && shards=16
  local filter="*/${backend}_*:*/${backend}"
  local start=$SECONDS limit
  limit=$(step_limit 180)
  if ((limit < 20)); then
    say "conformance on $backend: not run, out of time"
    echo "not run: out of time" >"$work/time_$name"
    return
  fi
  for ((i = 0; i < shards; ++i)); do
    env "$@" GTEST_TOTAL_SHARDS="$shards" GTEST_SHARD_INDEX="$i" timeout "$limit" \
      "$bundle/bin/pyrseg_test_conformance" --gtest_filter="$filter" --gtest_brief=1 \
      --gtest_output="xml:$work/xml/${name}_$i.xml" >"$work/logs/${name}_$i.log" 2>&1 &
  done
  for ((i = 0; i < shards; ++i)); do
    wait -n || status=1
  done
  echo "$((SECONDS - start))" >"$work/time_$name"
  {
    echo "=== conformance, backend $backend $* ($shards shards, $((SECONDS - start)) s, exit ${status}) ==="
    for ((i = 0; i < shards; ++i)); do
      grep -v -e '^Running main()' -e '^Note: This is test shard' "$work/logs/${name}_$i.log" || true
    done
  } >>"$report/conformance.log"
  say "conformance on $backend: $((SECONDS - start)) s, $( ((status)) && echo 'FAILURES' || echo 'all shards exited 0')"
}

# The small subset compute-sanitizer runs (each tool slows kernels 10-100x): tiny and odd sizes, a 160x120 frame,
# saturating statistics, subnormal depths, strided clouds, the hand cases.
sanitizer_subset() {
  local b="$1"
  echo "*/${b}_case3_*:*/${b}_case4_*:*/${b}_case5_*:*/${b}_case10_*:*/${b}_case13_*:*/${b}_case15_*:*FarPoints*/${b}:*TinyDepths*/${b}:*StridedClouds*/${b}:*HandCases*/${b}"
}

run_sanitizers() {
  local tool pids=()
  if ! command -v compute-sanitizer >/dev/null; then
    for tool in memcheck racecheck synccheck initcheck; do echo "not run: compute-sanitizer is not on the PATH" \
      >"$work/sanitizer_$tool.status"; done
    return
  fi
  local sanitizer_timeout
  sanitizer_timeout=$(step_limit 180)
  if ((sanitizer_timeout < 20)); then
    for tool in memcheck racecheck synccheck initcheck; do echo "not run: out of time" >"$work/sanitizer_$tool.status"; done
    return
  fi
  for tool in memcheck racecheck synccheck initcheck; do
    (
      set +e
      timeout "$sanitizer_timeout" compute-sanitizer --tool "$tool" --error-exitcode 99 --print-limit 20 \
        "$bundle/bin/pyrseg_test_conformance" --gtest_filter="$(sanitizer_subset cuda)" --gtest_brief=1 \
        >"$work/logs/sanitizer_$tool.log" 2>&1
      rc=$?
      if grep -qiE "device not supported|not supported on this|unsupported device" "$work/logs/sanitizer_$tool.log"; then
        echo "not supported on this machine" >"$work/sanitizer_$tool.status"
      elif ((rc == 0)); then
        echo "clean" >"$work/sanitizer_$tool.status"
      elif ((rc == 99)); then
        echo "errors" >"$work/sanitizer_$tool.status"
      elif ((rc == 124)); then
        echo "timed out after $sanitizer_timeout s" >"$work/sanitizer_$tool.status"
      else
        echo "failed (exit $rc)" >"$work/sanitizer_$tool.status"
      fi
    ) &
    pids+=($!)
  done
  wait "${pids[@]}"
  for tool in memcheck racecheck synccheck initcheck; do
    echo "=== compute-sanitizer --tool $tool: $(cat "$work/sanitizer_$tool.status") ==="
    cat "$work/logs/sanitizer_$tool.log"
  done >"$report/sanitizers.log"
  say "compute-sanitizer: $(for t in memcheck racecheck synccheck initcheck; do
    printf '%s %s; ' "$t" "$(cat "$work/sanitizer_$t.status")"; done)"
}

run_bench() {  # run_bench NAME BACKEND_REGEX SIZE_REGEX MIN_TIME LIMIT_S [VAR=VALUE...]
  local name="$1" backends="$2" sizes="$3" min_time="$4" start=$SECONDS rc=0 limit
  limit=$(step_limit "$5")
  shift 5
  if ((limit < 20)); then
    say "bench $name: not run, out of time"
    return
  fi
  env "$@" PYRSEG_BENCH_MASKS="$work/masks" timeout "$limit" "$bundle/bin/pyrseg_bench" \
    --benchmark_filter="^(pipeline|pipeline_robust|pipeline_robust_merge|pipeline_depth|pipeline_device|pipeline_depth_device|stage|fills/maze|fills/spiral)/($backends)/($sizes)" --benchmark_min_time="$min_time" \
    --benchmark_out="$report/$name.json" --benchmark_out_format=json || rc=$?
  say "bench $name: $((SECONDS - start)) s, exit $rc"
}

# One test case as Google Test XML, for the summary: run_case_xml FILE NAME STATUS MESSAGE, STATUS passed, failed or
# skipped.
run_case_xml() {
  local file="$1" name="$2" status="$3" message="${4//[<>&\"]/ }" inner=""
  if [ "$status" = failed ]; then inner="<failure message=\"$message\"/>"; fi
  if [ "$status" = skipped ]; then inner="<skipped message=\"$message\"/>"; fi
  printf '<?xml version="1.0" encoding="UTF-8"?>\n<testsuites><testsuite name="gpu-check">' >"$file"
  printf '<testcase classname="gpu-check" name="%s">%s</testcase></testsuite></testsuites>\n' "$name" "$inner" >>"$file"
}

# The CUDA interop (pyrseg/cuda.hpp): the tests of device pointers on the test's own stream (frames byte-identical
# to the host path, stream order, a frame captured into the test's CUDA graph and replayed, bad input), the
# application example (examples/cuda_app.cpp: a depth loop, then a captured frame replayed), and the graph-capture
# tests again under compute-sanitizer memcheck. One summary row, "conformance, interop"; in a rehearsal they run
# when the bundle has them (the CUDA tests then skip) but count for nothing.
run_interop() {
  local rehearse="$1" start=$SECONDS limit rc=0 xml="$work/xml" name=conformance_interop
  if [ ! -x "$bundle/bin/pyrseg_test_interop" ] || [ ! -x "$bundle/bin/pyrseg_example_cuda_app" ]; then
    say "CUDA interop: not run, the bundle has no pyrseg_test_interop or pyrseg_example_cuda_app"
    if [ "$rehearse" = 0 ]; then
      echo "$name" >>"$work/suites"
      echo "not run: not in the bundle" >"$work/time_$name"
    fi
    return 0
  fi
  if [ "$rehearse" = 1 ]; then
    xml="$work/rehearsal-xml"  # not read by the summary
    mkdir -p "$xml"
  else
    echo "$name" >>"$work/suites"
  fi
  limit=$(step_limit 60)
  if ((limit < 20)); then
    say "CUDA interop: not run, out of time"
    if [ "$rehearse" = 0 ]; then echo "not run: out of time" >"$work/time_$name"; fi
    return 0
  fi
  timeout "$limit" "$bundle/bin/pyrseg_test_interop" --gtest_filter='Cuda*' --gtest_brief=1 \
    --gtest_output="xml:$xml/${name}_tests.xml" >"$work/logs/interop.log" 2>&1 || rc=$?
  local tests_rc=$rc
  # A crash or a timeout leaves no results, and a run where every test skipped checked nothing: both fail.
  if [ ! -s "$xml/${name}_tests.xml" ]; then
    run_case_xml "$xml/${name}_tests.xml" pyrseg_test_interop failed "exit $tests_rc and no results (crashed or timed out?)"
  elif [ "$rehearse" = 0 ] && ! grep -q 'result="completed"' "$xml/${name}_tests.xml"; then
    run_case_xml "$xml/${name}_ran.xml" pyrseg_test_interop failed "no CUDA interop test ran: every one skipped"
  fi
  rc=0
  timeout "$(step_limit 60)" "$bundle/bin/pyrseg_example_cuda_app" >"$work/logs/example_cuda_app.log" 2>&1 || rc=$?
  case "$rc" in
    0) run_case_xml "$xml/${name}_example.xml" example_cuda_app passed "" ;;
    77) run_case_xml "$xml/${name}_example.xml" example_cuda_app skipped "$(tail -n 1 "$work/logs/example_cuda_app.log")" ;;
    *) run_case_xml "$xml/${name}_example.xml" example_cuda_app failed "exit $rc: $(tail -n 1 "$work/logs/example_cuda_app.log")" ;;
  esac
  local example_rc=$rc memcheck="not run: compute-sanitizer is not on the PATH"
  if [ "$rehearse" = 1 ]; then
    memcheck="not run: rehearsal"
  elif command -v compute-sanitizer >/dev/null; then
    limit=$(step_limit 90)
    if ((limit < 20)); then
      memcheck="not run: out of time"
    else
      rc=0
      timeout "$limit" compute-sanitizer --tool memcheck --error-exitcode 99 --print-limit 20 \
        "$bundle/bin/pyrseg_test_interop" --gtest_filter='Cuda*Captur*' --gtest_brief=1 \
        >"$work/logs/interop_memcheck.log" 2>&1 || rc=$?
      case "$rc" in
        0) memcheck="clean" ;;
        99) memcheck="errors" ;;
        124) memcheck="timed out after $limit s" ;;
        *) memcheck="failed (exit $rc)" ;;
      esac
    fi
  fi
  case "$memcheck" in
    clean) run_case_xml "$xml/${name}_memcheck.xml" graph_capture_memcheck passed "" ;;
    "not run"*) run_case_xml "$xml/${name}_memcheck.xml" graph_capture_memcheck skipped "$memcheck" ;;
    *) run_case_xml "$xml/${name}_memcheck.xml" graph_capture_memcheck failed "compute-sanitizer memcheck: $memcheck" ;;
  esac
  local counted=""
  if [ "$rehearse" = 0 ]; then
    echo "$((SECONDS - start))" >"$work/time_$name"
  else
    counted=" (rehearsal: not counted)"
  fi
  {
    echo "=== CUDA interop: pyrseg_test_interop --gtest_filter='Cuda*' (exit $tests_rc) ==="
    cat "$work/logs/interop.log"
    echo "=== examples/cuda_app.cpp (exit $example_rc) ==="
    cat "$work/logs/example_cuda_app.log"
    echo "=== the graph-capture tests under compute-sanitizer memcheck: $memcheck ==="
    if [ -f "$work/logs/interop_memcheck.log" ]; then cat "$work/logs/interop_memcheck.log"; fi
  } >>"$report/conformance.log"
  say "CUDA interop: $((SECONDS - start)) s; tests exit $tests_rc, example exit $example_rc, graph capture under" \
    "memcheck: $memcheck$counted"
}

# The Python module (issue 17): objects with __cuda_array_interface__ (CuPy's arrays) on the CUDA backend in place.
# Built here, with this machine's python3, Python headers and pybind11, from the checkout's python/ sources against
# the bundle's shared pyrseg libraries (scripts/gpu_check/python/CMakeLists.txt); then tests/python/smoke.py (it
# imports, loads the libraries from the bundle, and segments a frame on each backend) and the tests of tests/python
# that need neither pyrseg_testing (the test-only module: the test suite's internals) nor what the bundle lacks:
# test_cuda.py (CuPy device arrays, labels identical to the host path), test_segmenter.py and test_io.py. One summary
# row, "python module", which fails when test_cuda.py's device test skipped on a GPU. A rehearsal runs all of it
# with the cpu backend (test_cuda.py's device test then skips) and fails when the module does not build or import.
python_tests=(tests/python/test_cuda.py tests/python/test_segmenter.py tests/python/test_io.py)

# The interpreter for the module: $PYRSEG_GPU_PYTHON, else the first of python3 on the PATH and /usr/bin/python3 that
# imports numpy, pybind11 and pytest (a pyenv's python3 often has none of them).
find_python() {
  local py
  for py in ${PYRSEG_GPU_PYTHON:-python3 /usr/bin/python3}; do
    if command -v "$py" >/dev/null && "$py" -c 'import numpy, pybind11, pytest' >/dev/null 2>&1; then
      command -v "$py"
      return 0
    fi
  done
  return 1
}

python_not_run() {
  echo "not run: $1" >"$work/python.status"
  say "python module: not run, $1"
}

# The bundle has the shared libraries but this machine cannot build the module: on a GPU machine that is "not run";
# a rehearsal fails instead, since it would otherwise have rehearsed nothing of this step.
python_cannot_build() {
  local rehearse="$1" why="$2"
  if [ "$rehearse" = 1 ]; then
    echo "not built: $why" >"$work/python.status"
    run_case_xml "$work/xml/python_build.xml" module_build failed "$why"
    say "python module: FAILED, $why"
  else
    python_not_run "$why"
  fi
}

run_python() {
  local rehearse="$1" start=$SECONDS xml="$work/xml" py limit rc=0 log="$work/logs/python.log"
  if [ ! -f "$bundle/lib/cmake/pyrseg/pyrsegConfig.cmake" ]; then
    python_not_run "the bundle has no shared pyrseg libraries (prepare it again)"
    return 0
  fi
  if ! py="$(find_python)"; then
    python_cannot_build "$rehearse" "no python3 with numpy, pybind11 and pytest (PYRSEG_GPU_PYTHON names one)"
    return 0
  fi
  command -v cmake >/dev/null || { python_cannot_build "$rehearse" "cmake is not on the PATH"; return 0; }
  limit=$(step_limit 240)
  if ((limit < 30)); then
    python_not_run "out of time"
    return 0
  fi
  local generator=() build="$work/python-build" package="$work/python"
  command -v ninja >/dev/null && generator=(-G Ninja)
  {
    echo "=== python module: built with $py against $bundle/lib ==="
    timeout "$limit" cmake -S "$root/scripts/gpu_check/python" -B "$build" "${generator[@]}" \
      -DCMAKE_BUILD_TYPE=Release -Dpyrseg_DIR="$bundle/lib/cmake/pyrseg" \
      -Dpybind11_DIR="$("$py" -m pybind11 --cmakedir)" -DPython_EXECUTABLE="$py" \
      -DPYRSEG_PYTHON_PACKAGE_DIR="$package/pyrseg" &&
      timeout "$((limit - (SECONDS - start) > 1 ? limit - (SECONDS - start) : 1))" cmake --build "$build" -j "$(nproc)"
  } >"$log" 2>&1 || rc=$?
  local built
  built="$(sed -n 's/^-- pyrseg Python module (gpu-check): //p' "$log")"
  if ((rc)); then
    echo "not built (${built:-configure failed})" >"$work/python.status"
    run_case_xml "$xml/python_build.xml" module_build failed \
      "exit $rc: $( (grep -m 1 -A 2 -iE 'error|not found' "$log" || tail -n 1 "$log") | tr -s ' \n' ' ')"
  else
    echo "$built" >"$work/python.status"
    run_case_xml "$xml/python_build.xml" module_build passed ""
    local backends=(--backend cpu)
    [ "$rehearse" = 1 ] || backends+=(--backend cuda)
    echo "=== tests/python/smoke.py ${backends[*]} ===" >>"$log"
    rc=0
    PYTHONPATH="$package" PYTHONDONTWRITEBYTECODE=1 timeout "$(step_limit 60)" "$py" "$root/tests/python/smoke.py" \
      --shared-from "$bundle/lib" "${backends[@]}" >>"$log" 2>&1 || rc=$?
    if ((rc)); then
      run_case_xml "$xml/python_smoke.xml" smoke failed "exit $rc: $(tail -n 1 "$log")"
    else
      run_case_xml "$xml/python_smoke.xml" smoke passed ""
    fi
    echo "=== pytest ${python_tests[*]} ===" >>"$log"
    rc=0
    # From $work, with no cache and no bytecode: nothing is written into the checkout. No plugins (that machine's
    # pytest has many): the tests need none.
    (cd "$work" && PYTHONPATH="$package" PYTHONDONTWRITEBYTECODE=1 PYTEST_DISABLE_PLUGIN_AUTOLOAD=1 \
      timeout "$(step_limit 120)" "$py" -m pytest -q -rs -p no:cacheprovider --junitxml="$xml/python_pytest.xml" \
      "${python_tests[@]/#/$root/}") >>"$log" 2>&1 || rc=$?
    if [ ! -s "$xml/python_pytest.xml" ]; then
      run_case_xml "$xml/python_pytest.xml" pytest failed "exit $rc and no results (crashed or timed out?)"
    fi
  fi
  echo "$((SECONDS - start))" >"$work/time_python"
  cat "$log" >>"$report/conformance.log"
  say "python module: $((SECONDS - start)) s; $(cat "$work/python.status");" \
    "$(grep -E '(passed|failed|skipped|error).* in [0-9.]+s' "$log" | tail -n 1)"
}

# A report must come back whole from a machine that returns files of at most 16 MiB: a log over 8 MiB (a backend
# failing every test, say) keeps its first 6 MiB and its last 1 MiB.
cap_logs() {
  local f size
  for f in "$report"/conformance.log "$report"/sanitizers.log; do
    [ -f "$f" ] || continue
    size=$(stat -c %s "$f")
    if ((size > 8 * 1048576)); then
      { head -c $((6 * 1048576)) "$f"; printf '\n[... %d bytes cut by gpu-check.sh ...]\n' "$((size - 7 * 1048576))"
        tail -c 1048576 "$f"; } >"$f.cut"
      mv "$f.cut" "$f"
    fi
  done
}

finish_run() {  # run.log complete before the script returns (whoever collects the report may not wait for tee)
  exec 1>&- 2>&-
  wait "$tee_pid" 2>/dev/null || true
  rm -rf "$work"
}

run() {
  local rehearse=0
  if [ "${1:-}" = "--rehearse" ]; then
    rehearse=1
    shift
  fi
  report="${1:-${PYRSEG_GPU_REPORT:-$root/build/gpu-report}}"
  deadline=$((SECONDS + ${PYRSEG_GPU_CHECK_BUDGET:-480}))
  [ -x "$bundle/bin/pyrseg" ] ||
    die "no prepared bundle in $bundle: run 'scripts/gpu-check.sh prepare' on a build machine and bring build/gpu"
  mkdir -p "$report"
  rm -f "$report"/{summary.md,run.log,conformance.log,sanitizers.log,bench_cuda.json,bench_cuda_graphs.json}
  rm -f "$report"/{bench_other_gpus.json,bench_rehearsal.json,cupy_label.json}
  work="$(mktemp -d)"
  mkdir -p "$work/xml" "$work/logs" "$work/masks"
  exec > >(tee "$report/run.log") 2>&1
  tee_pid=$!
  trap finish_run EXIT
  say "bundle $bundle; report $report"

  local host_glibc need_glibc
  host_glibc="$(getconf GNU_LIBC_VERSION 2>/dev/null | awk '{print $2}')"
  need_glibc="$(sed -n 's/^glibc needed: //p' "$bundle/MANIFEST.txt" 2>/dev/null || true)"
  if [ -n "$host_glibc" ] && [ -n "$need_glibc" ] &&
     [ "$(printf '%s\n%s\n' "$need_glibc" "$host_glibc" | sort -V | sed -n 1p)" != "$need_glibc" ]; then
    die "this machine's glibc is $host_glibc; the bundle needs $need_glibc (prepare it on an older distribution)" 3
  fi
  export PYRSEG_DATA_DIR="$bundle/data"
  [ "$rehearse" = 1 ] || find_nvidia_drivers
  use_fallback_libs
  if [ -e "$work/fallback-lib/libstdc++.so.6" ]; then
    need_glibc="$(sed -n 's/^glibc needed by lib\/fallback: //p' "$bundle/MANIFEST.txt")"
    if [ "$(printf '%s\n%s\n' "$need_glibc" "$host_glibc" | sort -V | sed -n 1p)" != "$need_glibc" ]; then
      die "this machine's C++ runtime is older than the bundle's, and its glibc ($host_glibc) too old for the bundle's own (glibc $need_glibc)" 3
    fi
  fi

  {
    echo "date: $(date -u '+%Y-%m-%d %H:%M:%S UTC')"
    echo "host: $(uname -n), $(uname -srm), $(nproc) cores, glibc ${host_glibc:-unknown}"
    echo "--- bundle"
    cat "$bundle/MANIFEST.txt" 2>/dev/null || echo "(no MANIFEST.txt)"
    echo "--- nvidia-smi"
    if command -v nvidia-smi >/dev/null; then
      nvidia-smi --query-gpu=name,driver_version,memory.total,clocks.max.sm,clocks.max.mem,pcie.link.gen.max,pcie.link.width.max,compute_cap \
        --format=csv 2>&1 || true
      nvidia-smi 2>&1 || true
    else
      echo "nvidia-smi: not found"
    fi
    echo "--- nvcc"
    command -v nvcc >/dev/null && nvcc --version | tail -n 2 || echo "nvcc: not found"
    echo "--- loaders"
    echo "VK_DRIVER_FILES=${VK_DRIVER_FILES:-} OCL_ICD_VENDORS=${OCL_ICD_VENDORS:-}"
    echo "--- pyrseg backends"
    "$bundle/bin/pyrseg" backends 2>&1 || echo "pyrseg backends failed (exit $?)"
  } >"$work/environment.txt" 2>&1
  cat "$work/environment.txt"  # into run.log: the report keeps to 8 files

  local gpu_backends=()
  if [ "$rehearse" = 1 ]; then
    say "REHEARSAL: the cpu backend stands in for the GPU backends; nothing about a GPU is checked"
    gpu_backends=(cpu)
  else
    local why=""
    if ! command -v nvidia-smi >/dev/null; then
      why="nvidia-smi is not installed"
    elif ! grep -q "^GPU " <<<"$(nvidia-smi -L 2>/dev/null || true)"; then
      why="nvidia-smi lists no GPU"
    fi
    if backend_available cuda; then
      gpu_backends+=(cuda)
    else
      why="${why:+$why; }pyrseg: $( ("$bundle/bin/pyrseg" backends || true) | awk '$1 == "cuda" {getline; sub(/^ +/, ""); print}')"
    fi
    if [ "${#gpu_backends[@]}" = 0 ]; then
      printf '# pyrseg GPU check: no GPU\n\nNo usable NVIDIA GPU here (%s). Nothing was checked.\n' "$why" \
        >"$report/summary.md"
      die "no usable NVIDIA GPU here ($why): nothing was checked" 2
    fi
    local cap archs
    cap="$( (nvidia-smi --query-gpu=compute_cap --format=csv,noheader 2>/dev/null || true) | sed -n 1p | tr -d '. ')"
    archs="$(sed -n 's/^cuda architectures: //p' "$bundle/MANIFEST.txt" 2>/dev/null || true)"
    if [ -n "$cap" ] && [ -n "$archs" ] && ! grep -qE "(^|[ ;])$cap(-real)?([ ;]|$)" <<<"$archs" &&
       ! grep -q "virtual" <<<"$archs"; then
      say "WARNING: this GPU is sm_$cap but the bundle has machine code for $archs only: expect 'no kernel image'"
      say "         failures; prepare again with CMAKE_CUDA_ARCHITECTURES=$cap-real in the gpu-check preset"
    fi
    for b in vulkan opencl; do
      if backend_available "$b"; then gpu_backends+=("$b"); fi
    done
  fi
  say "backends to check: ${gpu_backends[*]}"
  echo "${gpu_backends[*]}" >"$work/backends"

  # CUDA first, then what needs its results (CuPy times the bench's masks), then the slower and the secondary
  # checks: if the time runs out, what is cut is the least important.
  run_sharded "conformance_${gpu_backends[0]}" "${gpu_backends[0]}"
  local start=$SECONDS
  timeout "$(step_limit 120)" "$bundle/bin/pyrseg_test_unit" --gtest_brief=1 --gtest_output="xml:$work/xml/unit_all.xml" \
    >"$work/logs/unit.log" 2>&1 || true
  { echo "=== unit tests, every available backend ($((SECONDS - start)) s) ==="; cat "$work/logs/unit.log"; } \
    >>"$report/conformance.log"
  run_interop "$rehearse"
  run_python "$rehearse"
  if [ "$rehearse" = 1 ]; then
    run_bench bench_rehearsal cpu 640x480 0.01 60
  else
    run_bench bench_cuda cuda "640x480|2064x1544|4128x3088" 0.5 150
    # The same frames as CUDA graphs (PYRSEG_CUDA_GRAPHS=1: the frame's launches captured once, then replayed).
    run_bench bench_cuda_graphs cuda "640x480|2064x1544|4128x3088" 0.5 90 PYRSEG_CUDA_GRAPHS=1
  fi
  command -v python3 >/dev/null || die "python3 is missing: no CuPy peer and no summary; the logs are in $report"
  start=$SECONDS
  timeout "$(step_limit 90)" python3 "$root/scripts/gpu_check/cupy_label.py" "$work/masks" "$report/cupy_label.json" ||
    true
  say "cupy label: $((SECONDS - start)) s"
  if [ "$rehearse" = 0 ]; then
    run_sharded conformance_cuda_graphs cuda PYRSEG_CUDA_GRAPHS=1
    run_sanitizers
    local b others=()
    for b in "${gpu_backends[@]:1}"; do
      run_sharded "conformance_$b" "$b"
      others+=("$b")
    done
    if ((${#others[@]})); then
      run_bench bench_other_gpus "$(IFS='|'; echo "${others[*]}")" "640x480|2064x1544|4128x3088" 0.2 120
    fi
  fi

  cap_logs
  local summarize_args=(--work "$work" --report "$report")
  [ "$rehearse" = 1 ] && summarize_args+=(--rehearsal)
  python3 "$root/scripts/gpu_check/summarize.py" "${summarize_args[@]}"
}

case "${1:-}" in
  prepare) prepare ;;
  run) shift; run "$@" ;;
  -h | --help | help) usage ;;
  *) usage >&2; exit 2 ;;
esac
