#!/usr/bin/env bash
# Configures and builds one CMake preset (default: release), installing missing packages first.
set -euo pipefail
cd "$(dirname "$0")/.."
preset="${1:-release}"
scripts/deps.sh
# Show which backends this build has and why not the others; the rest of configure's output is noise.
if ! configure_log=$(cmake --preset "$preset" 2>&1); then
  echo "$configure_log"
  exit 1
fi
grep -E "^-- pyrseg" <<<"$configure_log" || true
cmake --build --preset "$preset"
