"""pyrseg.describe_scene: the scene summary (docs/algorithm.md section 10c) from Python, as numpy structured arrays."""

import numpy as np
import pyrseg
import pytest


def tabletop(seed=3):
    s = pyrseg.synthetic.generate(
        seed=seed, object_count=8, bin=False, touching=False, sensor="realsense-d435", camera_distance_mm=1000.0
    )
    seg = pyrseg.Segmenter(640, 480, "cpu", preset="realsense-d435", outputs=["segment_stats", "fillable_mask"])
    return s, seg.segment(s.points)


def test_the_floor_is_the_support_and_objects_stand_on_it():
    s, r = tabletop()
    scene = pyrseg.describe_scene(r.segments)
    assert isinstance(scene, pyrseg.Scene)
    assert scene.supports.dtype == pyrseg.scene_support_dtype
    assert scene.objects.dtype == pyrseg.scene_object_dtype
    floor = scene.supports[0]
    assert floor["level"]
    # Most of the largest support's pixels are the floor's.
    floor_pixels = np.count_nonzero((r.labels == floor["label"]) & (s.object_id == pyrseg.synthetic.FLOOR_ID))
    assert floor_pixels > 0.9 * floor["pixel_count"]
    standing = scene.objects[scene.objects["support"] == 0]
    assert len(standing) >= 4
    assert np.all(standing["height"] > 0)
    # Up is the floor's normal, the box's third axis.
    assert np.allclose(standing["axes"][:, 2, :], floor["normal"])
    assert np.all(np.diff(scene.objects["label"].astype(np.int64)) > 0)


def test_fitted_boxes_hold_their_points():
    s, r = tabletop()
    scene = pyrseg.describe_scene(r.segments, points=s.points, labels=r.labels, fillable=r.fillable_mask)
    for o in scene.objects:
        pts = s.points[(r.labels == o["label"]) & (r.fillable_mask != 0) & np.isfinite(s.points[..., 2])]
        pts = pts.astype(np.float64)
        along = (pts - o["box_centre"]) @ o["axes"].T
        assert np.all(np.abs(along) <= 0.5 * o["extents"] + 1e-6 * o["extents"].sum()), o["label"]
    # The same scene as the statistics alone gives, but boxes the points' own size.
    plain = pyrseg.describe_scene(r.segments)
    assert np.array_equal(plain.objects["label"], scene.objects["label"])
    assert np.array_equal(plain.objects["support"], scene.objects["support"])


def test_bad_arguments_name_the_problem():
    s, r = tabletop()
    with pytest.raises(TypeError, match="segment_stats_dtype"):
        pyrseg.describe_scene(np.zeros(3))
    with pytest.raises(ValueError, match="points and labels go together"):
        pyrseg.describe_scene(r.segments, points=s.points)
    with pytest.raises(ValueError, match="labels must be Result.labels"):
        pyrseg.describe_scene(r.segments, points=s.points, labels=r.labels[:10])
    with pytest.raises(ValueError, match="labels must be Result.labels"):
        pyrseg.describe_scene(r.segments, points=s.points, labels=r.labels.astype(np.int64))
    with pytest.raises(ValueError, match="fillable must be Result.fillable_mask"):
        pyrseg.describe_scene(r.segments, points=s.points, labels=r.labels, fillable=r.fillable_mask[:, :5])
    with pytest.raises(pyrseg.Error, match="support_min_share"):
        pyrseg.describe_scene(r.segments, support_min_share=2.0)
    with pytest.raises(pyrseg.Error, match="unit_mm"):
        pyrseg.describe_scene(r.segments, unit_mm=float("nan"))


def test_a_mask_has_no_scene():
    seg = pyrseg.Segmenter(32, 24, "cpu", outputs=["segment_stats"])
    r = seg.segment_mask(np.ones((24, 32), np.uint8))
    scene = pyrseg.describe_scene(r.segments)
    assert len(scene.supports) == 0 and len(scene.objects) == 0
