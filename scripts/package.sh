#!/usr/bin/env bash
# pyrseg as a package: builds the `package` preset (shared libraries, CPU backend, the tool; no tests or benchmarks,
# to keep CI short), makes the .deb with cpack, and checks both as a consumer would (tests/package/check.sh): the
# installed shared libraries through CMake's find_package and through pkg-config, their exported symbols, and the
# .deb unpacked into a scratch root. Installs missing packages first (scripts/deps.sh).
# Usage: scripts/package.sh    the .deb: build/package/pyrseg_VERSION_ARCH.deb
set -euo pipefail
cd "$(dirname "$0")/.."
t_start=$SECONDS
scripts/build.sh package
rm -f build/package/*.deb
(cd build/package && cpack -G DEB >/dev/null)
debs=(build/package/*.deb)
[ -f "${debs[0]}" ] || { echo "pyrseg: cpack made no .deb" >&2; exit 1; }
echo "pyrseg: made ${debs[0]}"
tests/package/check.sh build/package . "${debs[0]}"
echo "pyrseg: package checks passed in $((SECONDS - t_start)) s"
