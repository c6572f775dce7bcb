#!/usr/bin/env bash
# The full benchmark run: builds the release preset (installing what it needs), runs every benchmark of
# pyrseg_bench (every available backend and peer, every frame size) on an otherwise idle machine, and writes the
# report: build/bench/bench.json, build/bench/performance.md and its plots. Extra arguments go to pyrseg_bench
# (e.g. --benchmark_filter=2064). Takes about 10 minutes on 2 cores.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/build.sh release
out=build/bench
mkdir -p "$out"
build/release/bench/pyrseg_bench --benchmark_out="$out/bench.json" --benchmark_out_format=json "$@"
build/release/tools/pyrseg bench-report "$out/bench.json" --out-dir "$out"
