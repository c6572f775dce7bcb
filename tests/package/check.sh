#!/usr/bin/env bash
# Installs the build into a temporary prefix, then configures, builds and runs tests/package as a consumer would.
# Usage: check.sh BUILD_DIR SOURCE_DIR
set -euo pipefail
build="$1"; source="$2"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
cmake --install "$build" --prefix "$work/prefix" >/dev/null
cmake -S "$source/tests/package" -B "$work/consumer" -G Ninja -DCMAKE_PREFIX_PATH="$work/prefix" \
      -DCMAKE_BUILD_TYPE=Release -DEXAMPLE_SOURCE="$source/examples/segment_frames.cpp" >/dev/null
cmake --build "$work/consumer" >/dev/null
"$work/consumer/consumer"
