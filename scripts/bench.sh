#!/usr/bin/env bash
# The full benchmark run: builds the release preset (installing what it needs), runs every benchmark of
# pyrseg_bench (every available backend and peer, every frame size) on an otherwise idle machine, and writes the
# report: build/bench/bench.json, build/bench/performance.md and its plots. The load average at the end goes into
# the JSON (Google Benchmark records it at the start), and the report says when the machine was not idle.
#
#   scripts/bench.sh [ARGS...]                # ARGS go to pyrseg_bench (e.g. --benchmark_filter=2064)
#   scripts/bench.sh --update-docs [ARGS...]  # also refresh docs/performance.md's tables from this run: the JSON is
#                                             # copied to docs/data/bench.json (the ctest docs_performance_tables
#                                             # checks the doc against it) and its plots to docs/images/
#
# Takes about 11 minutes on 2 cores (2026-12-07: 381 rows, the GPU-path backends on the CPU most of it).
set -euo pipefail
cd "$(dirname "$0")/.."
update_docs=0
if [[ "${1:-}" == "--update-docs" ]]; then
  update_docs=1
  shift
fi
scripts/build.sh release
out=build/bench
mkdir -p "$out"
build/release/bench/pyrseg_bench --benchmark_out="$out/bench.json" --benchmark_out_format=json "$@"
read -r l1 l5 l15 _ </proc/loadavg
if command -v jq >/dev/null; then
  jq --argjson l "[$l1, $l5, $l15]" '.context.load_avg_after = $l' "$out/bench.json" >"$out/bench.json.tmp"
  mv "$out/bench.json.tmp" "$out/bench.json"
else
  echo "scripts/bench.sh: no jq: the load at the end ($l1 $l5 $l15) is not in the JSON" >&2
fi
build/release/tools/pyrseg bench-report "$out/bench.json" --out-dir "$out"
if ((update_docs)); then
  cp "$out/bench.json" docs/data/bench.json
  build/release/tools/pyrseg bench-report docs/data/bench.json --update docs/performance.md
  echo "Now read docs/performance.md's text after the tables (\"Reading them\") and README.md's performance figures"
  echo "against the new tables: they quote this run by its date."
else
  echo "To put this run in docs/performance.md: scripts/bench.sh --update-docs (or cp $out/bench.json"
  echo "docs/data/bench.json && build/release/tools/pyrseg bench-report docs/data/bench.json --update docs/performance.md)"
fi
