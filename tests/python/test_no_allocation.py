"""A frame loop from Python allocates nothing in the library per frame (what it costs next to the same loop in C++ is
measured by bench/python_loop.py: speed is a benchmark, not a test).

pyrseg_testing is the whole module again with operator new counted (python/src/testing.cpp), as the C++
tests/unit/test_no_allocation.cpp counts it: the library, the bindings and pybind11 all allocate through it.
pybind11's call dispatch allocates its argument lists on every call of any function (a few small blocks); a method
with segment's arguments that does nothing (CallProbe) measures them, and the frame may allocate no more than that.
numpy's own allocations are Python's, and tracemalloc traces them."""

import os
import tracemalloc

import numpy as np
import pyrseg
import pyrseg_testing as T
import pytest

W, H = 320, 240
FRAMES = 100


def call_allocations(**kwargs):
    """operator new calls per call of pybind11's dispatch for a method taking segment's arguments."""
    probe = T.CallProbe()
    probe.segment(None, **kwargs)
    before = T.allocations()
    for _ in range(FRAMES):
        probe.segment(None, **kwargs)
    return (T.allocations() - before) / FRAMES


@pytest.fixture(scope="module")
def frames():
    a = T.synthetic.generate(W, H, seed=1)
    b = T.synthetic.generate(W, H, seed=2)
    return a, b


def test_loop_allocates_nothing_in_cpp(backend, frames):
    if backend == "vulkan" and os.environ.get("PYRSEG_VULKAN_VALIDATION") == "1":
        pytest.skip("the Vulkan validation layer allocates on every call it checks (ctest sets it to 0 here)")
    a, b = frames
    outputs = ("segment_stats", "normals", "fillable_mask", "raw_labels")
    for inputs in ({}, {"normals": True}):
        seg = T.Segmenter(W, H, backend, outputs=outputs)
        out = np.empty((H, W), np.uint32)

        def frame(i):
            s = a if i % 2 else b
            return seg.segment(s.points, normals=s.normals if inputs else None, out=out)

        frame(0)  # sizes the Result
        frame(1)  # the statistics grow to the larger segment count
        dispatch = call_allocations(normals=None, out=out)
        before = T.allocations()
        for i in range(FRAMES):
            r = frame(i)
        per_frame = (T.allocations() - before) / FRAMES
        assert per_frame == dispatch, f"{per_frame} allocations a frame, pybind11's dispatch makes {dispatch}"
        assert r.segment_count > 1 and r.labels is out
    # The counter does count: a new Segmenter allocates.
    before = T.allocations()
    T.Segmenter(W, H, backend)
    assert T.allocations() > before


def test_loop_with_conversion_allocates_nothing_after_the_first_frame(frames):
    """float64 clouds are converted into buffers the Segmenter keeps: only the first frame sizes them."""
    a, _ = frames
    points = a.points.astype(np.float64)
    seg = T.Segmenter(W, H, "cpu")
    out = np.empty((H, W), np.uint32)
    seg.segment(points, out=out)
    assert seg.last_input_copied
    dispatch = call_allocations(out=out)
    before = T.allocations()
    for _ in range(FRAMES):
        seg.segment(points, out=out)
    assert (T.allocations() - before) / FRAMES == dispatch


def test_loop_with_out_makes_no_frame_sized_python_allocation(frames):
    """With out=, a frame's Python allocations are its small result tuple: nothing the size of an image, no leak."""
    a, _ = frames
    seg = pyrseg.Segmenter(W, H, "cpu")
    out = np.empty((H, W), np.uint32)
    seg.segment(a.points, out=out)
    tracemalloc.start()
    try:
        for _ in range(3):
            seg.segment(a.points, out=out)
        tracemalloc.reset_peak()
        start, _ = tracemalloc.get_traced_memory()
        for _ in range(20 * FRAMES):
            seg.segment(a.points, out=out)
        end, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    # Python's free lists and caches move by about 10 KB; one object leaked a frame (32 bytes or more) would keep
    # 64 KB or more.
    assert peak - start < W * H * 4 // 8, f"peak {peak - start} bytes above the start during the loop"
    assert end - start < 32768, f"{end - start} bytes kept after {20 * FRAMES} frames"
    # Without out=, each frame's labels are a new array, which tracemalloc sees: the check above can fail.
    tracemalloc.start()
    try:
        start, _ = tracemalloc.get_traced_memory()
        seg.segment(a.points)
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert peak - start >= W * H * 4

