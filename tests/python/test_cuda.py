"""Device arrays (__cuda_array_interface__) on the CUDA backend, in place: the labels stay on the device."""

import numpy as np
import pyrseg
import pytest


class FakeDeviceArray:
    """Only the interface: enough for the checks made before any device memory is touched."""

    def __init__(self, shape, typestr):
        self.__cuda_array_interface__ = {"shape": shape, "typestr": typestr, "data": (0, False), "version": 3,
                                         "strides": None}


def test_device_array_on_a_host_backend_is_refused():
    seg = pyrseg.Segmenter(8, 8, "cpu")
    with pytest.raises(pyrseg.Error) as e:
        seg.segment(FakeDeviceArray((8, 8, 3), "<f4"))
    assert e.value.code == pyrseg.ErrorCode.invalid_argument and "backend='cuda'" in e.value.message


def cuda_or_skip():
    info = next(b for b in pyrseg.backends() if b.name == "cuda")
    if not info.available:
        pytest.skip(f"cuda unavailable: {info.reason}")
    try:
        import cupy
    except ImportError:
        pytest.skip("cupy is not installed: the device-array test makes its arrays with cupy")
    return cupy


def test_device_frames_match_host_frames():
    cp = cuda_or_skip()
    s = pyrseg.synthetic.generate(320, 240, seed=7)
    host = pyrseg.Segmenter(320, 240, "cpu").segment(s.points)
    seg = pyrseg.Segmenter(320, 240, "cuda")
    points = cp.asarray(s.points)
    out = cp.empty((240, 320), cp.uint32)
    count = cp.zeros(1, cp.uint32)
    assert seg.segment(points, out=out, count=count) is out
    cp.cuda.get_current_stream().synchronize()
    np.testing.assert_array_equal(cp.asnumpy(out), host.labels)
    assert int(count[0]) == host.segment_count
    z = np.nan_to_num(s.points[..., 2])
    depth = np.round(z).astype(np.uint16)
    k = dict(fx=s.fx, fy=s.fy, cx=s.cx, cy=s.cy, metres_per_unit=0.001)
    want = pyrseg.Segmenter(320, 240, "cpu").segment_depth(depth, **k).labels
    seg.segment_depth(cp.asarray(depth), out=out, **k)
    cp.cuda.get_current_stream().synchronize()
    np.testing.assert_array_equal(cp.asnumpy(out), want)
