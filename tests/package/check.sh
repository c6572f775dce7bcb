#!/usr/bin/env bash
# pyrseg as its users get it: installs BUILD_DIR into a temporary prefix, then builds and runs consumers of it two
# ways, a CMake project (find_package(pyrseg)) and plain compiler commands from pkg-config. A shared build must export
# nothing but pyrseg's public API, and its consumers must load the installed libraries. With a .deb, the same checks
# run again on the package unpacked into a scratch root (dpkg-deb -x; nothing is installed on the system).
# Usage: check.sh BUILD_DIR SOURCE_DIR [PACKAGE.deb]
set -euo pipefail
build="$(realpath "$1")"; source="$(realpath "$2")"; deb="${3:+$(realpath "$3")}"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT

# consume PREFIX NAME: the checks on one installed tree (a prefix, or /usr inside an unpacked .deb).
consume() {
  local prefix="$1" name="$2"
  local pc libdir
  pc="$(find "$prefix" -path '*/pkgconfig/pyrseg.pc' -print -quit)"
  [ -n "$pc" ] || { echo "$name: no pyrseg.pc under $prefix" >&2; return 1; }
  libdir="$(cd "$(dirname "$pc")/.." && pwd)"
  local shared=0
  if [ -e "$libdir/libpyrseg.so" ]; then
    shared=1
    local so count=0 foreign
    for so in "$libdir"/libpyrseg.so "$libdir"/libpyrseg_io.so "$libdir"/libpyrseg_synthetic.so; do
      # Only pyrseg's own symbols: functions and data in pyrseg::, and the type information of its classes.
      foreign="$(nm -D --defined-only "$so" | c++filt | awk '{$1 = ""; $2 = ""; sub(/^ +/, ""); print}' |
                 grep -Ev '^((typeinfo|typeinfo name|vtable) for )?pyrseg::' || true)"
      if [ -n "$foreign" ]; then
        echo "$name: $(basename "$so") exports symbols outside pyrseg's API:" >&2
        echo "$foreign" >&2
        return 1
      fi
      count=$((count + $(nm -D --defined-only "$so" | wc -l)))
    done
    echo "$name: shared libraries export $count symbols, all pyrseg's"
  fi

  # CMake: find_package(pyrseg), pyrseg::pyrseg, pyrseg::io, pyrseg::synthetic.
  local consumer="$work/$name-cmake"
  cmake -S "$source/tests/package" -B "$consumer" -G Ninja -DCMAKE_PREFIX_PATH="$prefix" \
        -DCMAKE_BUILD_TYPE=Release -DEXAMPLE_SOURCE="$source/examples/segment_frames.cpp" >/dev/null
  cmake --build "$consumer" >/dev/null
  mkdir -p "$work/scratch"
  # pkg-config: the same two programs from the compiler's command line, with the command the README gives (no
  # --static, also for the static install: its dependencies are in Libs and Requires).
  local binaries=("$consumer/consumer" "$consumer/io_consumer")
  export PKG_CONFIG_PATH="$libdir/pkgconfig"
  local flags
  flags="$(pkg-config --cflags --libs pyrseg-synthetic pyrseg)"
  # shellcheck disable=SC2086  # pkg-config's output is a list of words
  mkdir -p "$work/$name-pkg-config"
  c++ -std=c++20 -O2 "$source/examples/segment_frames.cpp" -o "$work/$name-pkg-config/consumer" $flags
  flags="$(pkg-config --cflags --libs pyrseg-io pyrseg-synthetic)"
  # shellcheck disable=SC2086
  c++ -std=c++20 -O2 "$source/tests/package/io_consumer.cpp" -o "$work/$name-pkg-config/io_consumer" $flags
  binaries+=("$work/$name-pkg-config/consumer" "$work/$name-pkg-config/io_consumer")
  local binary
  for binary in "${binaries[@]}"; do
    if ((shared)) && ! readelf -d "$binary" | grep -q 'NEEDED.*libpyrseg\.so'; then
      echo "$name: $binary does not link the shared libpyrseg" >&2
      return 1
    fi
    echo "$(basename "$(dirname "$binary")"): $(basename "$binary")"
    LD_LIBRARY_PATH="$libdir" "$binary" "$work/scratch"
  done
}

cmake --install "$build" --prefix "$work/prefix" >/dev/null
consume "$work/prefix" install

if [ -n "$deb" ]; then
  dpkg-deb -f "$deb" Package Version Architecture Maintainer Depends
  dpkg-deb -x "$deb" "$work/root"
  consume "$work/root/usr" deb
  # The tool finds the package's libraries through its RPATH ($ORIGIN), with no LD_LIBRARY_PATH.
  echo "deb: $("$work/root/usr/bin/pyrseg" --version)"
  [ -f "$work/root/usr/share/doc/pyrseg/LICENSE" ] || { echo "deb: no LICENSE in the package" >&2; exit 1; }
fi
echo "package checks passed"
