#!/usr/bin/env bash
# clang-tidy (the repository's .clang-tidy) over the library, backends, tools, I/O, scene, peer and bench code; any
# finding fails. Needs a configured build for compile_commands.json (default: build/release, made by scripts/build.sh).
set -euo pipefail
cd "$(dirname "$0")/.."
build="${1:-build/release}"
[ -f "$build/compile_commands.json" ] || scripts/build.sh release
mapfile -t files < <(git ls-files 'core/*.cpp' 'backends/*.cpp' 'tools/*.cpp' 'io/*.cpp' 'synthetic/*.cpp' 'peers/*.cpp' 'python/*.cpp' 'bench/*.cpp')
# "N warnings generated" counts the suppressed system-header warnings: noise, so it is filtered out.
clang-tidy -p "$build" --quiet --warnings-as-errors='*' "${files[@]}" 2> >(grep -v "warnings generated" >&2)
echo "clang-tidy: ${#files[@]} files clean"
