#!/usr/bin/env bash
# The README's test command: build and run the whole suite (CPU, and every GPU backend built and available;
# the others are reported as skipped with the reason). With --asan: the CPU suite under ASan + UBSan.
set -euo pipefail
cd "$(dirname "$0")/.."
preset=release
if [ "${1:-}" = "--asan" ]; then
  preset=asan
fi
scripts/build.sh "$preset"
ctest --preset "$preset" -j2 --timeout 900
