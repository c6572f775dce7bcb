#!/usr/bin/env bash
# The API reference: doxygen (Debian's) over the public headers (docs/api/Doxyfile), into OUT_DIR/html (default
# build/api-docs/html). Any doxygen warning fails it, so that the reference stays complete and correct.
# Usage: scripts/api-docs.sh [OUT_DIR]
set -euo pipefail
cd "$(dirname "$0")/.."
command -v doxygen >/dev/null || scripts/deps.sh
out="${1:-build/api-docs}"
mkdir -p "$out"
PYRSEG_VERSION="$(sed -n 's/^project(pyrseg VERSION \([0-9.]*\).*/\1/p' CMakeLists.txt)"
[ -n "$PYRSEG_VERSION" ] || { echo "pyrseg: no version in CMakeLists.txt's project()" >&2; exit 1; }
export PYRSEG_VERSION
PYRSEG_API_DOCS_OUT="$(cd "$out" && pwd)"
export PYRSEG_API_DOCS_OUT
doxygen docs/api/Doxyfile
echo "pyrseg: API reference $PYRSEG_VERSION in $out/html/index.html"
