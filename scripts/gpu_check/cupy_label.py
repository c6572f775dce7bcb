#!/usr/bin/env python3
"""The GPU peer of pyrseg's segmentation stage: cupyx.scipy.ndimage.label (4-connected) on the very fillable masks
pyrseg_bench wrote (PYRSEG_BENCH_MASKS=DIR: fillable_WxH.npy), timed with CUDA events.

    cupy_label.py MASK_DIR OUT.json

The mask is on the device before timing starts (pyrseg's stage benchmark, by contrast, uploads its mask each frame:
the summary shows both its wall time and the sum of its passes). Writes {"available": false, "reason": ...} when
CuPy or a GPU is missing, so the summary can say so instead of failing.
"""
import glob
import json
import os
import re
import sys

WARMUP = 3
RUNS = 20


def main() -> int:
    if len(sys.argv) != 3:
        print(__doc__, file=sys.stderr)
        return 2
    mask_dir, out_path = sys.argv[1], sys.argv[2]
    result = {"available": False, "reason": "", "masks": []}
    try:
        import numpy as np
        import cupy as cp
        from cupyx.scipy import ndimage

        result["cupy"] = cp.__version__
        cp.cuda.runtime.getDeviceCount()
    except Exception as e:  # any import or driver failure means: no peer on this machine
        result["reason"] = f"{type(e).__name__}: {e}"
        write(out_path, result)
        print(f"cupy label: not available ({result['reason']})")
        return 0
    result["available"] = True
    paths = sorted(glob.glob(os.path.join(mask_dir, "fillable_*.npy")),
                   key=lambda p: [int(v) for v in re.findall(r"\d+", os.path.basename(p))])
    if not paths:
        result["reason"] = f"no fillable_*.npy masks in {mask_dir} (the bench wrote none)"
    for path in paths:
        size = re.search(r"fillable_(\d+x\d+)\.npy$", path).group(1)
        mask = cp.asarray(np.load(path) != 0)
        structure = cp.array([[0, 1, 0], [1, 1, 1], [0, 1, 0]], dtype=cp.int32)  # 4-connected, like pyrseg
        for _ in range(WARMUP):
            _, count = ndimage.label(mask, structure=structure)
        cp.cuda.Device().synchronize()
        times = []
        for _ in range(RUNS):
            start, stop = cp.cuda.Event(), cp.cuda.Event()
            start.record()
            _, count = ndimage.label(mask, structure=structure)  # as users call it: labels allocated by CuPy
            stop.record()
            stop.synchronize()
            times.append(cp.cuda.get_elapsed_time(start, stop))
        times.sort()
        entry = {"size": size, "components": int(count), "fillable_pixels": int(mask.sum()),
                 "median_ms": times[len(times) // 2], "min_ms": times[0], "runs": RUNS}
        result["masks"].append(entry)
        print(f"cupy label {size}: {entry['median_ms']:.3f} ms median of {RUNS} "
              f"({entry['components']} components)")
    write(out_path, result)
    return 0


def write(path: str, result: dict) -> None:
    with open(path, "w") as f:
        json.dump(result, f, indent=2)


if __name__ == "__main__":
    sys.exit(main())
