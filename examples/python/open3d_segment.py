#!/usr/bin/env python3
"""Segment an organized cloud with pyrseg and colour it by segment in Open3D.

    python3 open3d_segment.py [cloud.pcd] [--out segments.ply] [--show]

Without a file it segments a synthetic bin-picking scene. Open3D's own PCD reader drops the organization pyrseg
needs (it returns N points, not H x W), so the cloud is read with pyrseg.io and handed to Open3D for display and
output. Needs Open3D (Debian: apt-get install python3-open3d); exits 77 without it.
"""

import argparse
import sys

import numpy as np
import pyrseg

try:
    import open3d as o3d
except ImportError:
    print("open3d is not installed (Debian: apt-get install python3-open3d)", file=sys.stderr)
    sys.exit(77)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("cloud", nargs="?", help="an organized PCD or PLY file in millimetres (default: a synthetic scene)")
    ap.add_argument("--out", default="segments.ply", help="where to write the coloured cloud")
    ap.add_argument("--show", action="store_true", help="open Open3D's viewer")
    ap.add_argument("--backend", default=None, help="cpu, cuda, vulkan, opencl or auto")
    args = ap.parse_args()

    if args.cloud:
        read = pyrseg.io.read_ply if args.cloud.endswith(".ply") else pyrseg.io.read_pcd
        points, normals = read(args.cloud)
    else:
        scene = pyrseg.synthetic.generate(640, 480, seed=1)
        points, normals = scene.points, None
    h, w, _ = points.shape

    # A noisy consumer camera would take a preset here: pyrseg.measure_frame_noise(points)["suggested"].
    seg = pyrseg.Segmenter(w, h, args.backend)
    result = seg.segment(points, normals=normals)
    sizes = np.bincount(result.labels.ravel())[1:]
    print(f"{w}x{h} on {seg.backend}: {result.segment_count} segments, largest {sorted(sizes)[::-1][:5]} pixels")

    valid = np.isfinite(points).all(axis=2) & (points[..., 2] > 0)
    colours = pyrseg.io.colorize_labels(result.labels)
    cloud = o3d.geometry.PointCloud()
    cloud.points = o3d.utility.Vector3dVector(points[valid].astype(np.float64))
    cloud.colors = o3d.utility.Vector3dVector(colours[valid] / 255.0)
    o3d.io.write_point_cloud(args.out, cloud)
    print(f"wrote {args.out}: {len(cloud.points)} points coloured by segment")
    if args.show:
        o3d.visualization.draw_geometries([cloud])


if __name__ == "__main__":
    main()
