#!/usr/bin/env bash
# The CPU backend on aarch64, as a Jetson runs it: cross-builds the `aarch64` preset (Debian's g++-aarch64-linux-gnu,
# cmake/toolchains/aarch64-linux-gnu.cmake: the CPU backend, the reference, the conformance and unit tests) and
# runs its tests under qemu-user on emulated Arm CPUs, each with the Highway target that the CPU backend's dispatch
# picks there (backends/cpu/simd/):
#   orin    cortex-a76: Armv8.2 without SVE, like Jetson Orin's Cortex-A78AE                 -> NEON
#   thor    SVE2 with 128-bit vectors, like Jetson Thor's Neoverse V3AE                      -> SVE2_128
#   sve512  SVE2 with 512-bit vectors (qemu's default), for vector-length-agnostic code      -> SVE2
#   sve256  SVE with 256-bit vectors (Neoverse V1, Graviton3)                                -> SVE_256
# On the first three: the CPU conformance suite against the reference (a subset sized to CI's time: every CPU case
# but the two 2064x1544 frames); on all four: the unit tests that force every target the CPU runs in turn (tests/
# unit/test_cpu_simd.cpp, where the build has it); on orin also the rest of the unit suite. --full: the whole CPU
# conformance suite, and on orin again with the sweep fills (PYRSEG_CPU_FILL=sweeps). Without Highway in the CPU
# backend (no PYRSEG_CPU_SIMD) every CPU runs the same code, and only orin's runs are made. Installs what is
# missing first (root or sudo), like scripts/deps.sh.
#
# Usage: scripts/test-aarch64.sh [--full]    logs: build/aarch64/qemu-logs/
set -euo pipefail
cd "$(dirname "$0")/.."

full=0
case "${1:-}" in
  "") ;;
  --full) full=1 ;;
  *) echo "usage: scripts/test-aarch64.sh [--full]" >&2; exit 2 ;;
esac

say() { printf 'pyrseg: %s\n' "$*"; }
t_start=$SECONDS

# ---- Packages: the cross compiler, qemu-user, and the target's libraries as arm64 multiarch packages. Installing
# a Multi-Arch: same library for arm64 makes apt bring the host's copy to the same version (an upgrade at most).
sudo=""
if [ "$(id -u)" -ne 0 ]; then
  sudo=sudo
fi
need_root() {
  if [ -n "$sudo" ] && ! command -v sudo >/dev/null; then
    echo "pyrseg: need root or sudo to $1" >&2
    exit 1
  fi
}
packages=(
  cmake ninja-build nlohmann-json3-dev                  # the build (nlohmann/json is header-only, for any arch)
  g++-aarch64-linux-gnu libc6-dev-arm64-cross            # the cross compiler and its C library
  libgtest-dev:arm64 libhwy-dev:arm64                    # GoogleTest; Google Highway (the CPU backend's vectors)
  libtbb-dev:arm64 libgomp1:arm64                        # oneTBB (the CPU backend's threads); OpenMP (a test's)
  liblzf-dev:arm64 libpng-dev:arm64 libtiff-dev:arm64    # pyrseg_io, which the conformance suite reads scans with
  libtinyxml2-dev:arm64 libyaml-dev:arm64                # pyrseg_io's calibration files (XML, YAML)
)
if ! command -v qemu-aarch64 >/dev/null && ! command -v qemu-aarch64-static >/dev/null; then
  packages+=(qemu-user)
fi
update=0
if ! dpkg --print-foreign-architectures | grep -qx arm64; then
  need_root "add the arm64 architecture"
  say "adding the arm64 architecture to dpkg (multiarch)"
  $sudo dpkg --add-architecture arm64
  update=1
fi
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]} > 0)); then
  need_root "install ${missing[*]}"
  say "installing missing Debian packages: ${missing[*]}"
  update=1
fi
if ((update)); then
  $sudo apt-get update -qq
fi
if ((${#missing[@]} > 0)); then
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi
qemu=$(command -v qemu-aarch64 || command -v qemu-aarch64-static)
t_apt=$SECONDS

# ---- Configure and build (only the CPU backend, the libraries the tests need and the two test programs).
if ! configure_log=$(cmake --preset aarch64 2>&1); then
  echo "$configure_log"
  exit 1
fi
grep -E "^-- pyrseg" <<<"$configure_log" || true
t_configure=$SECONDS
cmake --build --preset aarch64
t_build=$SECONDS

# ---- Tests under qemu-user. The binaries name the multiarch loader (/lib/ld-linux-aarch64.so.1, from libc6:arm64),
# so qemu runs them without -L (which hangs qemu 7.2 at a program's first thread: see the toolchain file).
bin=build/aarch64/tests
logs=build/aarch64/qemu-logs
rm -rf "$logs"
mkdir -p "$logs"
conformance_filter='*cpu*:-*Availability*'
if ((!full)); then
  # The two 2064x1544 frames take over half the suite's time under qemu; 1031x772 and 640x480 frames, the real scans
  # and depth image, and every other case (both metrics, estimated and given normals, the hand-made fill and
  # compaction cases, statistics, strided layouts) stay.
  conformance_filter+=':*2064x1544*'
fi

total_passed=0
total_failed=0
total_skipped=0
summary=()

# run_tests LABEL CPU ENV... -- PROGRAM ARGS...: one gtest program under qemu -cpu CPU, its counts added to the totals.
run_tests() {
  local label=$1 cpu=$2
  shift 2
  local vars=()
  while [ "$1" != "--" ]; do
    vars+=("$1")
    shift
  done
  shift
  local log="$logs/${label//\//-}.log" start=$SECONDS rc=0
  timeout -k 10 900 env "${vars[@]}" "$qemu" -cpu "$cpu" "$@" --gtest_brief=1 --gtest_color=no >"$log" 2>&1 || rc=$?
  local passed failed skipped
  passed=$(sed -n 's/^\[  PASSED  \] \([0-9]\{1,\}\) tests\{0,1\}\..*/\1/p' "$log" | tail -n 1)
  failed=$(grep -c '^\[  FAILED  \] .* ([0-9]* ms)$' "$log" || true)  # each failed test, once (brief or not)
  skipped=$(sed -n 's/^\[  SKIPPED \] \([0-9]\{1,\}\) tests\{0,1\}[,.].*/\1/p' "$log" | tail -n 1)
  passed=${passed:-0}
  failed=${failed:-0}
  skipped=${skipped:-0}
  if ((rc != 0 && failed == 0)); then
    failed=1  # crashed, timed out (exit 124) or failed before gtest's summary
  fi
  total_passed=$((total_passed + passed))
  total_failed=$((total_failed + failed))
  total_skipped=$((total_skipped + skipped))
  local line
  line=$(printf '%-28s %5d passed, %d failed, %d skipped  (%ds)' "$label" "$passed" "$failed" "$skipped" \
    $((SECONDS - start)))
  summary+=("$line")
  say "$line"
  if ((rc != 0)); then
    say "$label failed (exit $rc); its output (full log: $log):"
    tail -n 60 "$log"
  fi
}

# The targets of the CPU backend's dispatch on an emulated CPU, best first ("scalar" first, then Highway's), from
# the error that an unknown PYRSEG_CPU_SIMD value gives (backends/cpu/simd/cpu_simd.cpp). Empty without Highway.
simd_targets() {
  PYRSEG_CPU_SIMD=pyrseg-list-targets "$qemu" -cpu "$1" "$bin/pyrseg_test_conformance" \
    --gtest_filter='Backends/FarPoints.*/cpu' --gtest_color=no 2>&1 |
    sed -n 's/.*use one of: \([a-z0-9_, ]*\) (or leave it unset.*/\1/p' | head -n 1 || true
}

# label|qemu -cpu|what it stands for|what runs there (all: the conformance subset and the target unit tests;
# simd: only the unit tests that force each target)
cpus=(
  "orin|cortex-a76|Jetson Orin-like (Armv8.2, no SVE)|all"
  "thor|max,sve-default-vector-length=16|Jetson Thor-like (SVE2, 128-bit vectors)|all"
  "sve512|max,sve-default-vector-length=64|SVE2, 512-bit vectors|all"
  "sve256|max,sve-default-vector-length=32|SVE, 256-bit vectors (Neoverse V1-like)|simd"
)
has_simd_tests=0
simd_tests=$("$qemu" "$bin/pyrseg_test_unit" --gtest_list_tests --gtest_filter='*CpuSimd*' 2>/dev/null || true)
if grep -q CpuSimd <<<"$simd_tests"; then
  has_simd_tests=1
fi
targets_seen=()
for entry in "${cpus[@]}"; do
  IFS='|' read -r label cpu what runs <<<"$entry"
  targets=$(simd_targets "$cpu")
  if [ -n "$targets" ]; then
    best=$(tr -d ' ' <<<"$targets" | tr ',' '\n' | grep -vx scalar | head -n 1)
    say "$label: qemu -cpu $cpu, $what: targets ${targets}; the dispatch picks ${best:-scalar}"
    targets_seen+=("$label=${best:-scalar}")
  else
    say "$label: qemu -cpu $cpu, $what: this build's CPU backend names no Highway targets (no PYRSEG_CPU_SIMD)"
    targets_seen+=("$label=n/a")
  fi
  if [ "$runs" = simd ] && ((!has_simd_tests)); then
    continue
  fi
  if [ "$runs" = all ]; then
    run_tests "$label/conformance" "$cpu" -- "$bin/pyrseg_test_conformance" --gtest_filter="$conformance_filter"
  fi
  if ((has_simd_tests)); then
    run_tests "$label/unit-cpu-simd" "$cpu" -- "$bin/pyrseg_test_unit" --gtest_filter='*CpuSimd*'
  fi
  if [ "$label" = orin ]; then
    run_tests "$label/unit" "$cpu" -- "$bin/pyrseg_test_unit" --gtest_filter='-*CpuSimd*'
    if ((full)); then
      run_tests "$label/conformance-sweeps" "$cpu" PYRSEG_CPU_FILL=sweeps -- "$bin/pyrseg_test_conformance" \
        --gtest_filter="$conformance_filter"
    fi
  fi
  if [ -z "$targets" ]; then
    # Without Highway targets every CPU runs the same scalar code: one CPU is enough.
    break
  fi
done
t_tests=$SECONDS

echo
say "aarch64 under qemu-user ($("$qemu" --version | head -n 1)):"
for line in "${summary[@]}"; do
  echo "  $line"
done
say "Highway targets picked: ${targets_seen[*]}"
say "times: packages $((t_apt - t_start))s, configure $((t_configure - t_apt))s, build $((t_build - t_configure))s," \
  "tests $((t_tests - t_build))s, total $((t_tests - t_start))s"
echo "aarch64: $total_passed passed, $total_failed failed, $total_skipped skipped"
if ((total_failed > 0)); then
  exit 1
fi
