#!/usr/bin/env python3
"""The same warm frame loop from Python (pyrseg, out=) and from C++ (the C++ API on the same array, run by the
build's test-only module pyrseg_testing), alternating, the fastest round of each compared: what the binding costs
per frame. Exits 1 when Python takes more than 5% longer (issue 17's target).

    PYTHONPATH=build/release/python /usr/bin/python3 bench/python_loop.py [--frames 100] [--size 320x240]
"""

import argparse
import sys
import time

import numpy as np
import pyrseg
import pyrseg_testing as T


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--frames", type=int, default=100)
    parser.add_argument("--size", default="320x240", help="WxH")
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--backend", default="cpu")
    args = parser.parse_args()
    w, h = (int(v) for v in args.size.split("x"))
    points = np.ascontiguousarray(T.synthetic.generate(w, h, seed=1).points)
    seg = pyrseg.Segmenter(w, h, args.backend)
    out = np.empty((h, w), np.uint32)
    seg.segment(points, out=out)
    py_times, cpp_times = [], []
    for _ in range(args.rounds):
        cpp_times.append(T.cpp_loop_seconds(points, args.backend, args.frames))
        start = time.perf_counter()
        for _ in range(args.frames):
            seg.segment(points, out=out)
        py_times.append(time.perf_counter() - start)
    py, cpp = min(py_times), min(cpp_times)
    ratio = py / cpp
    print(f"{args.frames} frames {w}x{h} {args.backend}, fastest of {args.rounds} rounds: "
          f"Python {py * 1000:.1f} ms, C++ {cpp * 1000:.1f} ms, Python / C++ {ratio:.3f}")
    return 0 if ratio <= 1.05 else 1


if __name__ == "__main__":
    sys.exit(main())
