#!/usr/bin/env bash
# The README's first command: build, then segment a built-in 2064x1544 synthetic bin-picking scene (and the
# shared sample scans when ../shared/data is there) with every available backend; pictures go to pyrseg-demo/.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/build.sh release
exec build/release/tools/pyrseg demo --out pyrseg-demo "$@"
