#!/usr/bin/env python3
"""Segment a RealSense's depth frames: a folder of recorded 16-bit depth PNGs, or a live camera (pyrealsense2).

    python3 realsense_frames.py FOLDER [--calib camera.yml] [--metres-per-unit 0.001] [--out-dir segments]
    python3 realsense_frames.py --live [--frames 100]          # needs pyrealsense2 and a camera

FOLDER holds the frames as the RealSense SDK or ROS record them: 16-bit PNGs in the camera's depth units (*_depth.png
when the folder also holds colour images, else every .png); a frame NAME_depth.png segments with NAME_color.png, its
colour image registered to the depth, when there is one. The intrinsics come from an OpenCV FileStorage file
(--calib; FOLDER/camera.yml when there is one: fx fy cx cy, or a 3x3 camera matrix) or --intrinsics fx,fy,cx,cy;
the depth scale from --metres-per-unit (the SDK's get_depth_scale(): 0.001 on the D400 series, 0.0001 on a D405).
One Segmenter and one labels array serve every frame. Each frame's segments are written as a colour picture,
NAME.segments.png, into --out-dir.
"""

import argparse
import sys
import time
from pathlib import Path

import numpy as np
import pyrseg


def depth_files(folder):
    """The depth PNGs of a recorded folder, by name: *_depth.png beside colour images, else every .png."""
    named = sorted(folder.glob("*_depth.png"))
    return named if named else sorted(p for p in folder.glob("*.png") if not p.name.endswith(".segments.png"))


def intrinsics_of(args, folder):
    if args.intrinsics:
        return pyrseg.io.parse_intrinsics(args.intrinsics)
    calib = Path(args.calib) if args.calib else folder / "camera.yml"
    if not calib.exists():
        raise SystemExit(f"no intrinsics: give --calib FILE or --intrinsics fx,fy,cx,cy ({calib} does not exist)")
    return pyrseg.io.read_intrinsics(calib)


class FrameLoop:
    """A Segmenter made on the first frame and reused; the first frame's time is reported apart (warm-up)."""

    def __init__(self, args):
        self.args = args
        self.seg = None
        self.labels = None
        self.times = []

    def segment(self, name, depth, k, metres_per_unit, color=None):
        if self.seg is None:
            h, w = depth.shape
            self.seg = pyrseg.Segmenter(w, h, self.args.backend, preset=self.args.preset)
            self.labels = np.empty((h, w), np.uint32)
        start = time.perf_counter()
        r = self.seg.segment_depth(depth, *k, metres_per_unit=metres_per_unit, color=color, out=self.labels)
        ms = (time.perf_counter() - start) * 1000
        self.times.append(ms)
        note = " (first frame: includes warm-up)" if len(self.times) == 1 else ""
        labelled = 100.0 * np.count_nonzero(self.labels) / self.labels.size
        print(f"{name}: {r.segment_count} segments, {labelled:.0f}% of the pixels labelled, {ms:.1f} ms on "
              f"{self.seg.backend}{note}")
        return r

    def summary(self):
        if len(self.times) > 1:
            rest = self.times[1:]
            print(f"{len(self.times)} frames: first {self.times[0]:.1f} ms (warm-up), then {np.median(rest):.1f} ms "
                  f"per frame (median)")


def recorded(args):
    folder = Path(args.folder)
    files = depth_files(folder)
    if not files:
        raise SystemExit(f"{folder}: no depth PNG")
    k = intrinsics_of(args, folder)
    out_dir = Path(args.out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    loop = FrameLoop(args)
    for path in files:
        depth = pyrseg.io.read_depth_image(path)  # H x W uint16, the camera's units: read in place
        color_path = path.with_name(path.name.replace("_depth.png", "_color.png"))
        # The registered colour image, where the folder has one: the preset's colour edges (docs/algorithm.md 2c).
        color = pyrseg.io.read_png(color_path) if path.name.endswith("_depth.png") and color_path.exists() else None
        loop.segment(path.name, depth, k, args.metres_per_unit, color)
        out = out_dir / (path.stem + ".segments.png")
        pyrseg.io.write_png_rgb(out, pyrseg.io.colorize_labels(loop.labels))
    loop.summary()
    print(f"wrote {len(files)} pictures into {out_dir}")


def live(args):  # pragma: no cover - needs a camera: not run in this project's tests
    try:
        import pyrealsense2 as rs
    except ImportError:
        raise SystemExit("--live needs pyrealsense2 (pip install pyrealsense2) and a RealSense camera")
    pipeline = rs.pipeline()
    config = rs.config()
    config.enable_stream(rs.stream.depth, 640, 480, rs.format.z16, 30)
    profile = pipeline.start(config)
    try:
        metres_per_unit = profile.get_device().first_depth_sensor().get_depth_scale()
        i = profile.get_stream(rs.stream.depth).as_video_stream_profile().get_intrinsics()
        k = pyrseg.io.Intrinsics(i.fx, i.fy, i.ppx, i.ppy)
        loop = FrameLoop(args)
        for n in range(args.frames):
            frame = pipeline.wait_for_frames().get_depth_frame()
            depth = np.asanyarray(frame.get_data())  # H x W uint16, viewed in place
            loop.segment(f"frame {n}", depth, k, metres_per_unit)
        loop.summary()
    finally:
        pipeline.stop()


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("folder", nargs="?", help="a folder of 16-bit depth PNGs")
    ap.add_argument("--live", action="store_true", help="segment a live camera's frames (pyrealsense2)")
    ap.add_argument("--frames", type=int, default=100, help="with --live: how many frames")
    ap.add_argument("--calib", help="an OpenCV FileStorage file with fx fy cx cy (default: FOLDER/camera.yml)")
    ap.add_argument("--intrinsics", help="fx,fy,cx,cy in pixels, instead of --calib")
    ap.add_argument("--metres-per-unit", type=float, default=0.001,
                    help="the depth of one sample unit in metres, the SDK's depth scale (default 0.001)")
    ap.add_argument("--preset", default="realsense-d435", help=f"one of {', '.join(pyrseg.presets())}")
    ap.add_argument("--out-dir", default="segments", help="where the pictures go (default: segments)")
    ap.add_argument("--backend", default=None, help="cpu, cuda, vulkan, opencl or auto")
    args = ap.parse_args()
    if args.live:
        live(args)
    elif args.folder:
        recorded(args)
    else:
        ap.error("give a FOLDER of depth PNGs, or --live")


if __name__ == "__main__":
    sys.exit(main())
