#!/usr/bin/env bash
# libFuzzer harnesses of the file readers (tests/fuzz; docs/fuzzing.md), built with the fuzz preset (clang, ASan +
# UBSan) into build/fuzz.
#
#   scripts/fuzz.sh regress                      CI: build, then every harness from the generated seeds for a fixed
#                                                number of runs (fixed seed, so a pass is repeatable), two at a time
#   scripts/fuzz.sh long [SECONDS] [TARGET...]   build, then each TARGET (default: all) for SECONDS (default 600) on
#                                                JOBS processes (default: every core), growing build/fuzz/corpus/
#   scripts/fuzz.sh repro TARGET FILE...         run TARGET once on each FILE (a finding, a regression input)
#   scripts/fuzz.sh ledger                       executions per target over every `long` run so far
#   scripts/fuzz.sh list                         the targets
#
# Findings (crash-*, leak-*, oom-*, timeout-*) go to $FUZZ_FINDINGS/TARGET/ (default build/fuzz/findings), logs to
# build/fuzz/logs/. Environment: JOBS; FUZZ_KEEP_GOING=1 makes `long` go on after a finding (libFuzzer's -fork mode
# instead of -jobs/-workers); FUZZ_FLAGS adds libFuzzer flags to every run.
set -euo pipefail
cd "$(dirname "$0")/.."

# target, dictionaries (tests/fuzz/dict), regress runs: about 5 s each on one core of an idle 2-core machine, 20 s
# on a loaded one, where -max_total_time caps them, so that `regress` (build included) stays within 4 minutes.
targets=(
  "fuzz_pcd pcd 24000"
  "fuzz_ply ply 5000"
  "fuzz_ply_body ply 3000"
  "fuzz_npy npy 30000"
  "fuzz_png png 40000"
  "fuzz_tiff tiff 40000"
  "fuzz_depth png,tiff 50000"
  "fuzz_calib calib 16000"
  "fuzz_intrinsics intrinsics 120000"
  "fuzz_args args 80000"
  "fuzz_batch_plan batch_plan 8000"
  "fuzz_py_arrays py_arrays 1200"
)
# Absolute paths: `long` runs each harness in its log folder (libFuzzer's -jobs writes fuzz-N.log there).
build=$PWD/build/fuzz
bin=$build/tests/fuzz
findings_root=$(realpath -m "${FUZZ_FINDINGS:-$build/findings}")
logs=$build/logs
# One line per `long` run: target, executions, seconds, workers, date, commit (`scripts/fuzz.sh ledger` sums them).
ledger=$logs/ledger.tsv
# A single allocation or a process above this is a finding (an input that makes a reader balloon), as is an input
# that takes longer than timeout seconds (a hang).
limits=(-rss_limit_mb=2048 -malloc_limit_mb=2048 -timeout=10)
export ASAN_OPTIONS="${ASAN_OPTIONS:-detect_leaks=1}"
export UBSAN_OPTIONS="${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}"

usage() {
  sed -n '5,/^set /{/^#/p}' "$0" | sed 's/^# \{0,1\}//'
  exit 2
}

entry() {
  local t
  for t in "${targets[@]}"; do
    if [ "${t%% *}" = "$1" ]; then
      echo "$t"
      return
    fi
  done
  echo "scripts/fuzz.sh: unknown target '$1' (scripts/fuzz.sh list)" >&2
  exit 2
}

# The newest clang with libFuzzer: scripts/deps.sh installs Debian's default clang; a newer one is used when present.
# Its llvm-symbolizer goes first on PATH, so that the sanitizers' stacks name functions and lines.
cc=clang
cxx=clang++
for v in 18 17 16 15; do
  if command -v "clang++-$v" >/dev/null && command -v "clang-$v" >/dev/null; then
    cc=clang-$v cxx=clang++-$v
    break
  fi
done
if command -v "$cxx" >/dev/null; then
  PATH="$(dirname "$(readlink -f "$(command -v "$cxx")")"):$PATH"
fi
# By path: fuzz_py_arrays's embedded interpreter leaves ASan unable to find it on PATH (unsymbolized stacks).
if command -v llvm-symbolizer >/dev/null; then
  export ASAN_SYMBOLIZER_PATH="${ASAN_SYMBOLIZER_PATH:-$(command -v llvm-symbolizer)}"
fi

build_harnesses() {
  scripts/deps.sh
  local log
  if ! log=$(cmake --preset fuzz -DCMAKE_C_COMPILER="$cc" -DCMAKE_CXX_COMPILER="$cxx" 2>&1); then
    echo "$log"
    exit 1
  fi
  grep -E "^-- pyrseg fuzz" <<<"$log" || true
  cmake --build --preset fuzz
}

# Seeds are written afresh by pyrseg's own writers (tests/fuzz/seeds), plus the shared sample calibration when there.
make_seeds() {
  rm -rf "$build/seeds"
  "$bin/pyrseg_fuzz_seeds" "$build/seeds"
  if [ -f ../shared/data/cape_calib_params.xml ]; then
    cp ../shared/data/cape_calib_params.xml "$build/seeds/fuzz_calib/"
  fi
}

# One dictionary file per target: libFuzzer takes a single -dict.
dict_for() {
  local name=$1 dicts=$2 out="$build/dict/$1.dict" d
  mkdir -p "$build/dict"
  # Replaced whole, never truncated in place: -fork children of a running `long` read it again at each job.
  for d in ${dicts//,/ }; do cat "$PWD/tests/fuzz/dict/$d.dict"; done >"$out.$$"
  mv -f "$out.$$" "$out"
  echo "$out"
}

# Scratch folders a crashed harness could not remove (tests/fuzz/fuzz_input.hpp names them by process id).
clean_scratch() {
  local d
  for d in /dev/shm/pyrseg-fuzz-*; do
    [ -d "$d" ] || continue
    [ -d "/proc/${d##*-}" ] || rm -rf "$d"
  done
}

# The committed inputs of fixed findings (tests/fuzz/regressions/TARGET), replayed before any fuzzing.
regression_dir() {
  local dir="$PWD/tests/fuzz/regressions/$1"
  if [ -d "$dir" ]; then echo "$dir"; fi
}

# regress_one TARGET: prints one line; the log and any finding stay for the summary.
regress_one() {
  local name dicts runs
  read -r name dicts runs <<<"$(entry "$1")"
  # fuzz_py_arrays is not built without python3-dev, python3-numpy and pybind11-dev (tests/fuzz/CMakeLists.txt).
  if [ ! -x "$bin/$name" ]; then
    printf '%-16s skipped (not built: see the configure output)\n' "$name"
    return 0
  fi
  local corpus="$build/regress/$name" artifacts="$findings_root/$name/"
  rm -rf "$corpus"
  mkdir -p "$corpus" "$artifacts"
  local start=$SECONDS status=0
  # -max_total_time only caps a slow machine; the run count is what makes two passes the same.
  # shellcheck disable=SC2046,SC2086
  "$bin/$name" -seed=1 -runs="$runs" -max_total_time=20 "${limits[@]}" -dict="$(dict_for "$name" "$dicts")" \
    -artifact_prefix="$artifacts" -print_final_stats=1 ${FUZZ_FLAGS:-} "$corpus" "$build/seeds/$name" \
    $(regression_dir "$name") >"$logs/$name.log" 2>&1 || status=$?
  local execs speed
  execs=$(grep -m1 -oE "stat::number_of_executed_units:[[:space:]]*[0-9]+" "$logs/$name.log" | grep -oE "[0-9]+$" || echo "?")
  speed=$(grep -m1 -oE "stat::average_exec_per_sec:[[:space:]]*[0-9]+" "$logs/$name.log" | grep -oE "[0-9]+$" || echo "?")
  if [ "$status" -eq 0 ]; then
    printf '%-16s ok      %8s execs %6s/s %4ds\n' "$name" "$execs" "$speed" $((SECONDS - start))
  else
    printf '%-16s FINDING (exit %d, %ds): %s\n' "$name" "$status" $((SECONDS - start)) \
      "$(grep -m1 -oE "Test unit written to .*" "$logs/$name.log" || echo "see $logs/$name.log")"
  fi
  return "$status"
}

cmd_regress() {
  build_harnesses
  make_seeds
  mkdir -p "$logs"
  local t name failed=()
  # Two at a time: CI has two cores. Each run leaves its exit status beside its log.
  for t in "${targets[@]}"; do
    name=${t%% *}
    while (($(jobs -rp | wc -l) >= 2)); do wait -n || true; done
    (if regress_one "$name" >&3; then echo 0; else echo 1; fi) 3>&1 >"$logs/$name.status" &
  done
  wait
  for t in "${targets[@]}"; do
    name=${t%% *}
    [ "$(cat "$logs/$name.status")" = 0 ] || failed+=("$name")
  done
  clean_scratch
  if ((${#failed[@]})); then
    for t in "${failed[@]}"; do
      echo "---- $t: $logs/$t.log"
      grep -E -A12 "==ERROR|^SUMMARY|ERROR: libFuzzer|runtime error" "$logs/$t.log" | head -40 || tail -20 "$logs/$t.log"
    done
    echo "scripts/fuzz.sh: findings in ${failed[*]} (inputs under $findings_root; docs/fuzzing.md says what next)"
    exit 1
  fi
}

cmd_long() {
  local seconds=600
  if [[ "${1:-}" =~ ^[0-9]+$ ]]; then
    seconds=$1
    shift
  fi
  local names=("$@") t
  if ((${#names[@]} == 0)); then
    for t in "${targets[@]}"; do names+=("${t%% *}"); done
  fi
  for t in "${names[@]}"; do entry "$t" >/dev/null; done
  build_harnesses
  make_seeds
  local jobs="${JOBS:-$(nproc)}"
  for t in "${names[@]}"; do
    local name dicts runs
    read -r name dicts runs <<<"$(entry "$t")"
    local corpus="$build/corpus/$name" artifacts="$findings_root/$name/" workdir="$logs/$name"
    mkdir -p "$corpus" "$artifacts" "$workdir"
    local parallel=(-jobs="$jobs" -workers="$jobs")
    if [ "${FUZZ_KEEP_GOING:-0}" = 1 ]; then
      parallel=(-fork="$jobs" -ignore_crashes=1 -ignore_ooms=1 -ignore_timeouts=1)
    fi
    echo "== $name: ${seconds}s on $jobs processes; corpus $corpus, findings $artifacts, logs $workdir"
    # -jobs writes fuzz-N.log into the working directory; the previous run's are removed so that they are not
    # counted again. FUZZ_FLAGS and the regression folder (absent or one path) are split on purpose.
    rm -f "$workdir"/fuzz-*.log
    local dict start=$SECONDS
    dict=$(dict_for "$name" "$dicts")
    # shellcheck disable=SC2046,SC2086
    (cd "$workdir" && "$bin/$name" -max_total_time="$seconds" "${parallel[@]}" "${limits[@]}" -dict="$dict" \
      -artifact_prefix="$artifacts" -print_final_stats=1 ${FUZZ_FLAGS:-} "$corpus" "$build/seeds/$name" \
      $(regression_dir "$name")) 2>&1 | tee "$workdir/run.log" || true
    record_run "$name" "$workdir" $((SECONDS - start)) "$jobs"
    find "$artifacts" -type f -printf "  finding: %p\n"
  done
  clean_scratch
}

# Appends a `long` run's executions to the ledger: the workers' final stats (-jobs), or the last status line of
# the -fork parent, whose children's stats it does not print.
record_run() {
  local name=$1 workdir=$2 seconds=$3 jobs=$4 execs
  execs=$(cat "$workdir"/fuzz-*.log 2>/dev/null | grep -oE "number_of_executed_units:[[:space:]]*[0-9]+" |
    grep -oE "[0-9]+$" | awk '{ n += $1 } END { if (NR) print n }' || true)
  if [ -z "$execs" ]; then
    execs=$(grep -oE "^#[0-9]+" "$workdir/run.log" | tail -1 | tr -d '#' || true)
  fi
  mkdir -p "$logs"
  printf '%s\t%s\t%s\t%s\t%s\t%s\n' "$name" "${execs:-0}" "$seconds" "$jobs" "$(date -u +%FT%TZ)" \
    "$(git rev-parse --short HEAD 2>/dev/null || echo unknown)" >>"$ledger"
  echo "  $name: ${execs:-0} executions in ${seconds}s (ledger: $ledger)"
}

# The issue's bar: 10 million executions a target (or two hours for the slow ones).
cmd_ledger() {
  [ -f "$ledger" ] || { echo "no long runs recorded yet ($ledger)"; return; }
  local t name
  printf '%-16s %12s %8s %5s\n' target executions hours runs
  for t in "${targets[@]}"; do
    name=${t%% *}
    awk -F'\t' -v n="$name" -v bar_execs=10000000 -v bar_seconds=7200 '$1 == n { e += $2; s += $3 * $4; r++ }
      END { reached = e >= bar_execs ? "  (10M reached)" : s >= bar_seconds ? "  (2 h reached)" : ""
            printf "%-16s %12d %8.2f %5d%s\n", n, e, s / 3600, r, reached }' "$ledger"
  done
}

cmd_repro() {
  (($# >= 2)) || usage
  entry "$1" >/dev/null
  local name dicts runs
  read -r name dicts runs <<<"$(entry "$1")"
  shift
  [ -x "$bin/$name" ] || build_harnesses
  "$bin/$name" "${limits[@]}" "$@"
}

case "${1:-}" in
  regress) shift; cmd_regress "$@" ;;
  long) shift; cmd_long "$@" ;;
  repro) shift; cmd_repro "$@" ;;
  ledger) cmd_ledger ;;
  list) for t in "${targets[@]}"; do echo "${t%% *}"; done ;;
  *) usage ;;
esac
