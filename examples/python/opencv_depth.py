#!/usr/bin/env python3
"""Segment depth images read with OpenCV, as a depth camera's frames, and save the segments as a picture.

    python3 opencv_depth.py [depth.png --intrinsics fx,fy,cx,cy --metres-per-unit 0.001] [--out segments.png]

A 16-bit PNG holds the camera's units (0.001 m for most cameras: pass the SDK's depth scale, as pyrseg segment's
--metres-per-unit). Without a file it
writes a few synthetic depth frames as 16-bit PNGs with OpenCV and segments them back, as a camera loop would: one
Segmenter, one labels array, reused every frame.
"""

import argparse
import os
import tempfile
import time

import cv2
import numpy as np
import pyrseg


def synthetic_frames(folder, count=4, size=(640, 480)):
    """Depth frames of a depth camera (Kinect v1-like noise) as 16-bit millimetre PNGs, and their intrinsics."""
    paths = []
    for i in range(count):
        scene = pyrseg.synthetic.generate(*size, seed=i + 1, sensor="kinect-v1")
        z = np.nan_to_num(scene.points[..., 2])
        path = os.path.join(folder, f"depth_{i}.png")
        cv2.imwrite(path, np.round(z).astype(np.uint16))
        paths.append(path)
    return paths, (scene.fx, scene.fy, scene.cx, scene.cy)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("depth", nargs="*", help="16-bit depth PNGs (default: synthetic frames)")
    ap.add_argument("--intrinsics", help="fx,fy,cx,cy in pixels")
    ap.add_argument("--metres-per-unit", type=float, default=0.001,
                    help="the depth of one sample unit in metres, the SDK's depth scale (default 0.001)")
    ap.add_argument("--preset", default="kinect-v1", help=f"one of {', '.join(pyrseg.presets())}")
    ap.add_argument("--out", default="segments.png", help="the last frame's segments, coloured")
    ap.add_argument("--backend", default=None, help="cpu, cuda, vulkan, opencl or auto")
    args = ap.parse_args()

    with tempfile.TemporaryDirectory() as tmp:
        if args.depth:
            if not args.intrinsics:
                ap.error("--intrinsics fx,fy,cx,cy is required with depth files")
            paths = args.depth
            k = pyrseg.io.parse_intrinsics(args.intrinsics)
            fx, fy, cx, cy = k.fx, k.fy, k.cx, k.cy
        else:
            paths, (fx, fy, cx, cy) = synthetic_frames(tmp)

        seg = None
        for path in paths:
            depth = cv2.imread(path, cv2.IMREAD_ANYDEPTH)  # uint16, read by pyrseg in place
            if depth is None or depth.dtype != np.uint16:
                raise SystemExit(f"{path}: not a 16-bit depth image")
            if seg is None:
                h, w = depth.shape
                seg = pyrseg.Segmenter(w, h, args.backend, preset=args.preset)
                labels = np.empty((h, w), np.uint32)
            start = time.perf_counter()
            result = seg.segment_depth(depth, fx, fy, cx, cy, metres_per_unit=args.metres_per_unit, out=labels)
            ms = (time.perf_counter() - start) * 1000
            print(f"{os.path.basename(path)}: {result.segment_count} segments in {ms:.1f} ms on {seg.backend}")

    colours = pyrseg.io.colorize_labels(labels)
    cv2.imwrite(args.out, cv2.cvtColor(colours, cv2.COLOR_RGB2BGR))
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
