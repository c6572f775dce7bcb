"""color=: the colour edge term (docs/algorithm.md section 2c) from Python, on clouds and depth images."""

import numpy as np
import pyrseg
import pytest

W, H = 80, 60
CAMERA = dict(fx=100.0, fy=100.0, cx=40.0, cy=30.0, metres_per_unit=0.001)


def flat_depth():
    return np.full((H, W), 1000, np.uint16)


def two_colours():
    """A dark left half and a light right half: one colour edge down the middle of a flat surface."""
    rgb = np.zeros((H, W, 3), np.uint8)
    rgb[:, W // 2 :] = 200
    return rgb


def cloud_of(depth):
    z = depth.astype(np.float32)
    v, u = np.mgrid[0:H, 0:W].astype(np.float32)
    return np.ascontiguousarray(np.stack([(u - 40.0) * z / 100.0, (v - 30.0) * z / 100.0, z], axis=-1))


def test_colour_edge_splits_a_flat_surface():
    seg = pyrseg.Segmenter(W, H, "cpu", color_edge_threshold=100)
    assert seg.segment_depth(flat_depth(), **CAMERA).segment_count == 1
    r = seg.segment_depth(flat_depth(), **CAMERA, color=two_colours())
    assert r.segment_count == 2
    left, right = r.labels[H // 2, 2], r.labels[H // 2, W - 3]
    assert left != 0 and right != 0 and left != right


def test_threshold_above_the_difference_changes_nothing():
    seg = pyrseg.Segmenter(W, H, "cpu", color_edge_threshold=600, outputs=["fillable_mask"])
    plain = seg.segment_depth(flat_depth(), **CAMERA)
    coloured = seg.segment_depth(flat_depth(), **CAMERA, color=two_colours())
    assert np.array_equal(plain.fillable_mask, coloured.fillable_mask)
    assert np.array_equal(plain.labels, coloured.labels)


def test_cloud_and_depth_agree_and_the_edge_is_two_pixels_wide():
    seg = pyrseg.Segmenter(W, H, "cpu", color_edge_threshold=100, outputs=["fillable_mask"])
    from_depth = seg.segment_depth(flat_depth(), **CAMERA, color=two_colours())
    from_cloud = seg.segment(cloud_of(flat_depth()), color=two_colours())
    assert np.array_equal(from_depth.fillable_mask, from_cloud.fillable_mask)
    # Pixels W/2 - 1 and W/2 see both halves one pixel either side of them.
    row = from_depth.fillable_mask[H // 2]
    assert row[W // 2 - 1] == 0 and row[W // 2] == 0 and row[W // 2 - 2] == 1 and row[W // 2 + 1] == 1


def test_strided_colour_reads_like_packed_and_is_not_modified():
    seg = pyrseg.Segmenter(W, H, "cpu", color_edge_threshold=100)
    packed = two_colours()
    padded = np.zeros((H, W + 7, 3), np.uint8)[:, :W]  # rows 3 * (W + 7) bytes apart, read in place
    padded[...] = packed
    bgr_view = np.ascontiguousarray(packed[:, :, ::-1])[:, :, ::-1]  # negative channel stride: copied
    before = padded.copy()
    expected = seg.segment_depth(flat_depth(), **CAMERA, color=packed).labels
    assert np.array_equal(seg.segment_depth(flat_depth(), **CAMERA, color=padded).labels, expected)
    assert np.array_equal(seg.segment_depth(flat_depth(), **CAMERA, color=bgr_view).labels, expected)
    assert np.array_equal(padded, before)


def test_bad_colour_is_refused():
    seg = pyrseg.Segmenter(W, H, "cpu", color_edge_threshold=100)
    with pytest.raises(ValueError, match="H x W x 3"):
        seg.segment_depth(flat_depth(), **CAMERA, color=np.zeros((H, W), np.uint8))
    with pytest.raises(TypeError, match="uint8"):
        seg.segment_depth(flat_depth(), **CAMERA, color=np.zeros((H, W, 3), np.float32))
    with pytest.raises(ValueError, match="register"):
        seg.segment_depth(flat_depth(), **CAMERA, color=np.zeros((H, W + 1, 3), np.uint8))
    with pytest.raises(pyrseg.Error) as e:
        pyrseg.Segmenter(W, H, "cpu", color_edge_threshold=766)
    assert "color_edge_threshold" in e.value.message
    with pytest.raises(pyrseg.Error) as e:
        pyrseg.Segmenter(W, H, "cpu", color_edge_stride=0)
    assert "color_edge_stride" in e.value.message


def test_params_report_the_colour_term():
    seg = pyrseg.Segmenter(W, H, "cpu", color_edge_threshold=90, color_edge_stride=2)
    assert seg.params["color_edge_threshold"] == 90 and seg.params["color_edge_stride"] == 2


def ridge_depth():
    """Two planes meeting along column W/2 at about 33 degrees, nearest at the ridge: a crease a large ct keeps."""
    u = np.arange(W, dtype=np.float64)
    return np.tile(1000 + 3 * np.abs(u - W // 2), (H, 1)).astype(np.uint16)


ROBUST = dict(metric="robust", ct=1.0, dt=10.0, color_edge_threshold=100)


def test_curvature_gate_leaves_a_flat_surface_whole():
    ungated = pyrseg.Segmenter(W, H, "cpu", **ROBUST)
    gated = pyrseg.Segmenter(W, H, "cpu", color_edge_curvature_share=0.3, **ROBUST)
    assert ungated.segment_depth(flat_depth(), **CAMERA, color=two_colours()).segment_count == 2
    assert gated.segment_depth(flat_depth(), **CAMERA, color=two_colours()).segment_count == 1


def test_curvature_gate_cuts_a_weak_crease_with_a_colour_change():
    gated = pyrseg.Segmenter(W, H, "cpu", color_edge_curvature_share=0.1, outputs=["fillable_mask"], **ROBUST)
    plain = gated.segment_depth(ridge_depth(), **CAMERA)
    assert plain.segment_count == 1  # the metric alone keeps the crease
    r = gated.segment_depth(ridge_depth(), **CAMERA, color=two_colours())
    assert r.segment_count == 2
    assert r.fillable_mask[H // 2, W // 2 - 1] == 0 and r.fillable_mask[H // 2, W // 2] == 0
    everything_passes = pyrseg.Segmenter(W, H, "cpu", color_edge_curvature_share=1.0, **ROBUST)
    assert everything_passes.segment_depth(ridge_depth(), **CAMERA, color=two_colours()).segment_count == 1


def test_curvature_gate_is_checked():
    for bad in (-0.1, 1.5, float("nan")):
        with pytest.raises(pyrseg.Error) as e:
            pyrseg.Segmenter(W, H, "cpu", metric="robust", color_edge_curvature_share=bad)
        assert "color_edge_curvature_share" in e.value.message
    with pytest.raises(pyrseg.Error) as e:
        pyrseg.Segmenter(W, H, "cpu", color_edge_curvature_share=0.3)  # the paper metric has no curvature pairs
    assert "robust" in e.value.message
    seg = pyrseg.Segmenter(W, H, "cpu", preset="realsense-d435")
    assert seg.params["color_edge_threshold"] == 100 and seg.params["color_edge_curvature_share"] == 0.3
