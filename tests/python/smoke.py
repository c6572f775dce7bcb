"""A built pyrseg module, checked in one process without pytest: it imports, lists its backends, and segments one
synthetic frame on each backend asked for, with labels identical to the cpu backend's. scripts/package.sh runs it on
the module of the shared build, scripts/gpu-check.sh on the module it builds on a GPU machine.

    python3 tests/python/smoke.py [--backend NAME]... [--shared-from DIR]

--shared-from DIR: the module must have loaded pyrseg's shared libraries (libpyrseg, libpyrseg_io,
libpyrseg_synthetic) from DIR or a folder below it, not a static copy or another install. Exits 1 on any failure.
pytest does not collect this file: its name does not start with test_."""

import argparse
import os
import sys


def loaded_libraries():
    """The shared objects this process has mapped, by file name: {name: folder}."""
    found = {}
    with open("/proc/self/maps") as f:
        for line in f:
            path = line.split(maxsplit=5)[-1].strip()
            if path.startswith("/"):
                found.setdefault(os.path.basename(path), os.path.dirname(os.path.realpath(path)))
    return found


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--backend", action="append", default=[], help="a backend to segment on (default: cpu)")
    ap.add_argument("--shared-from", help="the folder pyrseg's shared libraries must come from (or from below it)")
    args = ap.parse_args()
    import numpy as np
    import pyrseg

    print(f"python {sys.version.split()[0]} ({sys.executable}), numpy {np.__version__}, pyrseg {pyrseg.__version__}")
    print(f"module: {pyrseg._pyrseg.__file__}")
    libs = {name: folder for name, folder in loaded_libraries().items() if name.startswith("libpyrseg")}
    for name, folder in sorted(libs.items()):
        print(f"loaded: {folder}/{name}")
    if args.shared_from:
        want = os.path.realpath(args.shared_from)
        for base in ("libpyrseg.so", "libpyrseg_io.so", "libpyrseg_synthetic.so"):
            where = [folder for name, folder in libs.items() if name.startswith(base)]
            if len(where) != 1 or os.path.commonpath([want, where[0]]) != want:
                sys.exit(f"smoke: {base}* should be loaded from {want}, is from {where or 'nowhere (linked static?)'}")
    for b in pyrseg.backends():
        print(f"backend {b.name}: {'available' if b.available else 'unavailable: ' + b.reason}")

    s = pyrseg.synthetic.generate(320, 240, seed=11)
    want = pyrseg.Segmenter(320, 240, "cpu").segment(s.points)
    if want.segment_count < 2:
        sys.exit(f"smoke: the cpu backend found {want.segment_count} segments in a synthetic scene")
    for backend in args.backend or ["cpu"]:
        r = pyrseg.Segmenter(320, 240, backend).segment(s.points)
        if r.labels.tobytes() != want.labels.tobytes():
            sys.exit(f"smoke: {backend}'s labels differ from the cpu backend's")
        print(f"segmented a 320x240 synthetic frame on {backend}: {r.segment_count} segments")
    print("smoke: passed")


if __name__ == "__main__":
    main()
