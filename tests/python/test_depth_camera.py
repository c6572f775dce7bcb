"""The depth camera checks of the library (pyrseg::check_depth_camera) from Python: a depth scale or intrinsics that
once segmented a frame into one segment or none without a word are pyrseg.Error naming the value and the fix; a
legal but unusual value is a UserWarning, once per camera."""
import warnings

import numpy as np
import pytest

import pyrseg

# A RealSense D435's 640 x 480 frame of a wall at 0.8 m, in millimetres (the shared RealSense frames' intrinsics).
K = dict(fx=612.937, fy=613.173, cx=322.549, cy=248.158)


def wall():
    return np.full((480, 640), 800, np.uint16)


@pytest.mark.parametrize("wrong", [1.0, 1000.0])
def test_a_wrong_depth_scale_is_an_error_saying_which_fits(wrong):
    seg = pyrseg.Segmenter(640, 480, "cpu")
    with pytest.raises(pyrseg.Error) as e:
        seg.segment_depth(wall(), **K, metres_per_unit=wrong)
    assert e.value.code == pyrseg.ErrorCode.invalid_parameter
    assert "metres_per_unit 0.001 makes it 0.8 m" in str(e.value)


def test_intrinsics_in_the_wrong_order_are_an_error():
    seg = pyrseg.Segmenter(640, 480, "cpu")
    with pytest.raises(pyrseg.Error, match="the order is fx, fy, cx, cy"):
        seg.segment_depth(wall(), K["cx"], K["cy"], K["fx"], K["fy"], metres_per_unit=0.001)
    with pytest.raises(pyrseg.Error, match="field of view"):
        seg.segment_depth(wall(), 1e-300, K["fy"], K["cx"], K["cy"], metres_per_unit=0.001)


def test_an_unusual_scale_is_a_warning_once_per_camera():
    seg = pyrseg.Segmenter(640, 480, "cpu")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        seg.segment_depth(wall(), **K, metres_per_unit=0.0001)  # a D405's scale on millimetres: 0.08 m
        seg.segment_depth(wall(), **K, metres_per_unit=0.0001)
        seg.segment_depth(wall(), **K, metres_per_unit=0.001)
    messages = [str(w.message) for w in caught if issubclass(w.category, UserWarning)]
    assert len(messages) == 1, messages
    assert "the median depth is 0.08 m with metres_per_unit 0.0001" in messages[0]


def test_depth_to_cloud_checks_the_same_way():
    k = pyrseg.io.Intrinsics(K["fx"], K["fy"], K["cx"], K["cy"])
    assert pyrseg.io.depth_to_cloud(wall(), *k, 0.001)[0, 0, 2] == 800
    with pytest.raises(pyrseg.Error, match="metres_per_unit 0.001 makes it"):
        pyrseg.io.depth_to_cloud(wall(), *k, 1.0)
    # The same words as segment_depth's: the camera's five numbers, in the same order, by keyword too.
    seg = pyrseg.Segmenter(wall().shape[1], wall().shape[0], "cpu")
    by_keyword = dict(fx=k.fx, fy=k.fy, cx=k.cx, cy=k.cy, metres_per_unit=0.001)
    assert pyrseg.io.depth_to_cloud(wall(), **by_keyword)[0, 0, 2] == 800
    assert seg.segment_depth(wall(), **by_keyword).segment_count >= 1
