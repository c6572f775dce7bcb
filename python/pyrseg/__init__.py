"""pyrseg: fast bridgeless pyramid segmentation of organized point clouds and depth images.

    import numpy as np, pyrseg
    seg = pyrseg.Segmenter(640, 480, preset="realsense-d435", unit_mm=1000)   # a cloud in metres
    result = seg.segment(points)            # H x W x 3 float32
    result.labels, result.segment_count

See docs/python.md for the whole API.
"""

from ._pyrseg import (  # noqa: F401
    BackendInfo,
    Error,
    ErrorCode,
    Result,
    Scene,
    Segmenter,
    TrackMatch,
    __version__,
    backends,
    choose_backend,
    default_params,
    describe_scene,
    io,
    measure_depth_noise,
    measure_frame_noise,
    preset,
    presets,
    scene_object_dtype,
    scene_support_dtype,
    segment_graph_dtype,
    segment_stats_dtype,
    segment_track_dtype,
    synthetic,
)

import sys as _sys

# `import pyrseg.io` and `from pyrseg.synthetic import generate` as with any package's submodules.
_sys.modules[__name__ + ".io"] = io
_sys.modules[__name__ + ".synthetic"] = synthetic

__all__ = [
    "BackendInfo",
    "Error",
    "ErrorCode",
    "Result",
    "Scene",
    "Segmenter",
    "TrackMatch",
    "backends",
    "choose_backend",
    "default_params",
    "describe_scene",
    "io",
    "measure_depth_noise",
    "measure_frame_noise",
    "preset",
    "presets",
    "scene_object_dtype",
    "scene_support_dtype",
    "segment_graph_dtype",
    "segment_stats_dtype",
    "segment_track_dtype",
    "synthetic",
]
