#!/usr/bin/env python3
"""Draws docs/images/real_sensors.png: the shared real scans segmented by pyrseg with the default parameters, with
the camera's preset, and by PCL (tuned for that camera, `pyrseg segment --pcl-png`), one row per scan.

Usage: scripts/figures/real_scans.py [PYRSEG_CLI] [DATA_DIR] [OUT_PNG]
Needs python3 with numpy and OpenCV (Debian: python3-numpy python3-opencv) and a pyrseg built with PCL.
"""
import subprocess
import sys
import tempfile
from pathlib import Path

import cv2
import numpy as np

ROOT = Path(__file__).resolve().parents[2]
CLI = Path(sys.argv[1]) if len(sys.argv) > 1 else ROOT / "build/release/tools/pyrseg"
DATA = Path(sys.argv[2]) if len(sys.argv) > 2 else ROOT.parent / "shared/data"
OUT = Path(sys.argv[3]) if len(sys.argv) > 3 else ROOT / "docs/images/real_sensors.png"

SCANS = [  # name, input options, preset, title
    ("milk", [str(DATA / "milk_cartoon_all_small_clorox.pcd"), "--unit-mm", "1000"], "kinect-v1",
     "milk scan (Kinect-style, PCL test data)"),
    ("mug", [str(DATA / "table_scene_mug_stereo_textured.pcd"), "--unit-mm", "1000"], "realsense-d435",
     "mug scan (stereo, PCL test data)"),
    ("cape", [str(DATA / "cape_depth_0.png"), "--calib", str(DATA / "cape_calib_params.xml") + ":IR_intrinsic_params"],
     "kinect-v1", "CAPE depth image (Kinect v1)"),
]
PANEL_W, PANEL_H, BAR = 320, 240, 22


def caption(text, width, shade):
    bar = np.full((BAR, width, 3), shade, np.uint8)
    cv2.putText(bar, text, (4, 16), cv2.FONT_HERSHEY_SIMPLEX, 0.45, (235, 235, 235), 1, cv2.LINE_AA)
    return bar


def main():
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for name, inputs, preset, title in SCANS:
            default_png, preset_png, pcl_png = (Path(tmp) / f"{name}_{k}.png" for k in ("default", "preset", "pcl"))
            cli = [str(CLI), "segment", *inputs, "--backend", "cpu"]
            subprocess.run([*cli, "--png", str(default_png)], check=True, stderr=subprocess.DEVNULL)
            subprocess.run([*cli, "--sensor", preset, "--png", str(preset_png), "--pcl-png", str(pcl_png)],
                           check=True)
            panels = []
            for path, text in ((default_png, "pyrseg, default parameters"), (preset_png, f"pyrseg, --sensor {preset}"),
                               (pcl_png, f"PCL, tuned for {preset}")):
                image = cv2.resize(cv2.imread(str(path)), (PANEL_W, PANEL_H), interpolation=cv2.INTER_NEAREST)
                panels += [np.concatenate([caption(text, PANEL_W, 24), image]), np.full((BAR + PANEL_H, 4, 3), 24,
                                                                                       np.uint8)]
            row = np.concatenate(panels[:-1], axis=1)
            rows.append(np.concatenate([caption(title, row.shape[1], 48), row]))
    cv2.imwrite(str(OUT), np.concatenate(rows))
    print(f"wrote {OUT}")


if __name__ == "__main__":
    main()
