#!/usr/bin/env bash
# pyrseg as a package: builds the `package` preset (shared libraries, CPU backend, the tool; no tests or benchmarks,
# to keep CI short), makes the .deb with cpack, and checks both as a consumer would (tests/package/check.sh): the
# installed shared libraries through CMake's find_package and through pkg-config, their exported symbols, and the
# .deb unpacked into a scratch root. The same build makes the Python module against the shared libraries (not
# packaged), which must load them, segment a frame and pass the tests of tests/python that need no test-only module.
# Installs missing packages first (scripts/deps.sh).
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

# The Python module of the shared build (issue 17): python/CMakeLists.txt builds it in build/package/python for the
# interpreter the preset names; it must link libpyrseg.so and load it, libpyrseg_io and libpyrseg_synthetic from this
# build tree (tests/python/smoke.py), not a static copy.
t_python=$SECONDS
py="$(sed -n 's/^PYRSEG_PYTHON_CHOSEN:FILEPATH=//p' build/package/CMakeCache.txt)"
modules=(build/package/python/pyrseg/_pyrseg*.so)
if [ -z "$py" ] || [ ! -f "${modules[0]}" ]; then
  echo "pyrseg: the package build made no Python module" >&2
  exit 1
fi
dynamic="$(readelf -d "${modules[0]}")"  # captured first: `readelf | grep -q` fails under pipefail
grep -q 'NEEDED.*libpyrseg\.so' <<<"$dynamic" ||
  { echo "pyrseg: ${modules[0]} does not link the shared libpyrseg" >&2; exit 1; }
export PYTHONPATH="$PWD/build/package/python" PYTHONDONTWRITEBYTECODE=1
"$py" tests/python/smoke.py --shared-from build/package
"$py" -m pytest -q -rs -p no:cacheprovider tests/python/test_segmenter.py tests/python/test_io.py \
  tests/python/test_cuda.py
echo "pyrseg: the Python module on the shared libraries: checked in $((SECONDS - t_python)) s"
echo "pyrseg: package checks passed in $((SECONDS - t_start)) s"
