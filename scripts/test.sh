#!/usr/bin/env bash
# The README's test command: build and run the whole suite (CPU, and every GPU backend built and available;
# the others are reported as skipped with the reason). With --asan: the CPU suite under ASan + UBSan. With --tsan: the
# CPU backend's concurrency tests under ThreadSanitizer (the tsan test preset's filter).
set -euo pipefail
cd "$(dirname "$0")/.."
preset=release
if [ "${1:-}" = "--asan" ]; then
  preset=asan
elif [ "${1:-}" = "--tsan" ]; then
  preset=tsan
fi
scripts/build.sh "$preset"
status=0
ctest --preset "$preset" -j2 --timeout 900 || status=$?
# ctest lists skipped tests without their reasons; the tests' own words are in its log.
log="build/$preset/Testing/Temporary/LastTest.log"
if [ -f "$log" ] && grep -q "unavailable:" "$log"; then
  echo "Skipped backends, with the reasons they gave:"
  grep -h "unavailable:" "$log" | sort -u | sed 's/^/  /'
fi
exit "$status"
