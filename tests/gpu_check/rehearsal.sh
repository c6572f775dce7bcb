#!/usr/bin/env bash
# scripts/gpu-check.sh run, end to end where there is no GPU: over a bundle of this build's binaries, the rehearsal
# (cpu backend standing in) must pass and write its summary, and a real run must refuse, saying there is no GPU.
# Usage: rehearsal.sh BUILD_DIR SOURCE_DIR DATA_DIR
set -euo pipefail
build="$1"; source="$2"; data="$3"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
mkdir -p "$work/bundle/bin" "$work/bundle/data"
for b in tests/pyrseg_test_conformance tests/pyrseg_test_unit bench/pyrseg_bench tools/pyrseg; do
  ln -s "$build/$b" "$work/bundle/bin/"
done
[ -d "$data" ] && ln -s "$data"/* "$work/bundle/data/"
echo "glibc needed: 2.17" >"$work/bundle/MANIFEST.txt"
# A library this machine lacks: the run must take the bundle's copy (nothing loads this one).
mkdir -p "$work/bundle/lib/fallback"
echo "not an ELF file" >"$work/bundle/lib/fallback/libpyrseg_rehearsal_only.so.0"
export PYRSEG_GPU_BUNDLE="$work/bundle"

"$source/scripts/gpu-check.sh" run --rehearse "$work/report" >"$work/rehearsal.out" 2>&1 ||
  { cat "$work/rehearsal.out"; echo "the rehearsal failed"; exit 1; }
summary="$work/report/summary.md"
grep -q "using the bundle's own libpyrseg_rehearsal_only.so.0" "$work/rehearsal.out" ||
  { cat "$work/rehearsal.out"; echo "the bundle's fallback library was not used"; exit 1; }
grep -q '^\*\*REHEARSAL PASS' "$summary" || { cat "$summary"; echo "no REHEARSAL PASS verdict"; exit 1; }
grep -Eq '^\| conformance, cpu \| [1-9][0-9]* \| 0 \|' "$summary" || { cat "$summary"; echo "no cpu conformance"; exit 1; }
grep -q '^| stage/cpu/640x480 |' "$summary" || { cat "$summary"; echo "no bench table"; exit 1; }
# This bundle has no shared pyrseg libraries (only `prepare` makes them): the python step says it did not run.
grep -q '^| python module | .*not run: the bundle has no shared pyrseg libraries' "$summary" ||
  { cat "$summary"; echo "no python module row"; exit 1; }
for f in run.log conformance.log bench_rehearsal.json cupy_label.json; do
  [ -s "$work/report/$f" ] || { echo "the report lacks $f"; exit 1; }
done
[ "$(find "$work/report" -type f | wc -l)" -le 8 ] || { ls "$work/report"; echo "more than 8 files in the report"; exit 1; }
echo "rehearsal: passed, summary and logs written"

if command -v nvidia-smi >/dev/null && grep -q "^GPU " <<<"$(nvidia-smi -L 2>/dev/null || true)"; then
  echo "a GPU is present: the refusal without one is not checked here"
  exit 0
fi
status=0
"$source/scripts/gpu-check.sh" run "$work/report2" >"$work/run.out" 2>&1 || status=$?
tail -n 3 "$work/run.out"
[ "$status" = 2 ] || { echo "run without a GPU exited $status, not 2"; exit 1; }
grep -q "no usable NVIDIA GPU here" "$work/run.out" || { echo "run did not say that no GPU is present"; exit 1; }
grep -q "Nothing was checked" "$work/report2/summary.md" || { echo "the summary does not say nothing was checked"; exit 1; }
if grep -qi "pass" "$work/report2/summary.md"; then echo "the no-GPU summary must not mention passing"; exit 1; fi
echo "run without a GPU: refused (exit 2), nothing claimed"
