#!/usr/bin/env bash
# Configures and builds one CMake preset (default: release), installing missing packages first.
set -euo pipefail
cd "$(dirname "$0")/.."
preset="${1:-release}"
scripts/deps.sh
# Show which backends this build has and why not the others; the rest of configure's output is noise.
cmake --preset "$preset" | grep -E "^-- pyrseg" || true
cmake --build --preset "$preset"
