"""Tracks from Python (docs/algorithm.md section 11, docs/python.md "Tracks"): the Segmenter's frames are one stream
whose segments keep their track ids from frame to frame, until reset_tracks(). The matching itself is the C++ tests'
(tests/unit/test_segment_tracks.cpp, the conformance TrackStreams); these check what the binding adds: the outputs,
the arrays, the parameters, the stream's state in the Segmenter object, and the errors."""

import math

import numpy as np
import pyrseg
import pytest

W, H = 320, 240
PAN = 10  # frames of the pan, one pixel a frame


@pytest.fixture(scope="module")
def wide():
    """A scene wider than the frame by the pan: frame f is its columns f .. f + W - 1."""
    return pyrseg.synthetic.generate(W + PAN, H, seed=5, object_count=10, hole_fraction=0.0)


def window(wide, f):
    return np.ascontiguousarray(wide.points[:, f : f + W])


def kept_share(before, after):
    """The share of the pixels labelled in both frames of a one-pixel pan whose values agree: pixel (x, y) of the
    later frame is pixel (x + 1, y) of the earlier one."""
    a, b = before[:, 1:], after[:, :-1]
    both = (a != 0) & (b != 0)
    return float(np.count_nonzero(both & (a == b))) / max(1, int(np.count_nonzero(both)))


def check_ids_agree(r):
    """track_ids is each labelled pixel's segment's id, and tracks lists the segments 1..K in order."""
    k = r.segment_count
    assert r.tracks.dtype == pyrseg.segment_track_dtype and r.tracks.shape == (k,)
    np.testing.assert_array_equal(r.tracks["label"], np.arange(1, k + 1))
    assert r.track_ids.shape == (H, W) and r.track_ids.dtype == np.uint32 and r.track_ids.flags.c_contiguous
    lookup = np.concatenate([[0], r.tracks["id"]]).astype(np.uint32)
    np.testing.assert_array_equal(r.track_ids, lookup[r.labels])
    assert len(np.unique(r.tracks["id"])) == k, "two segments of one frame never share an id"


def test_a_pan_keeps_the_ids(wide):
    seg = pyrseg.Segmenter(W, H, "cpu", outputs=("segment_tracks", "track_ids", "segment_stats"))
    assert seg.outputs == ("segment_stats", "segment_tracks", "track_ids")
    before = None
    least_ids, least_labels = 1.0, 1.0
    for f in range(PAN):
        r = seg.segment(window(wide, f))
        check_ids_agree(r)
        t = r.tracks
        assert np.all(t["first_frame"] <= f) and np.all(t["age"] >= 1)
        if f == 0:
            np.testing.assert_array_equal(t["id"], np.arange(1, r.segment_count + 1))
            assert np.all(t["how"] == pyrseg.TrackMatch.new_track) and np.all(t["age"] == 1)
        else:
            # Every surface is seen in every frame: its segment keeps the id it had in the first.
            big = r.segments["pixel_count"] >= 200
            assert np.count_nonzero(big) > 5
            assert np.all(t["how"][big] == pyrseg.TrackMatch.overlap)
            assert np.all(t["first_frame"][big] == 0) and np.all(t["age"][big] == f + 1)
            assert np.all(t["hidden_frames"][big] == 0)
            least_ids = min(least_ids, kept_share(before.track_ids, r.track_ids))
            least_labels = min(least_labels, kept_share(before.labels, r.labels))
        before = r
    assert least_ids >= 0.99
    assert least_labels < least_ids, "the scene must be one whose plain labels change in a pan"
    assert pyrseg.TrackMatch(int(t["how"][0])).name in ("new_track", "overlap", "position")


def test_tracks_without_the_id_image(wide):
    seg = pyrseg.Segmenter(W, H, "cpu", outputs=("segment_tracks",))
    r = seg.segment(window(wide, 0))
    assert r.track_ids is None and r.segments is None and r.tracks.shape == (r.segment_count,)
    # track_ids brings the tracks it is made of (pyrseg::Outputs: track_ids implies segment_tracks).
    seg = pyrseg.Segmenter(W, H, "cpu", outputs=("track_ids",))
    r = seg.segment(window(wide, 0))
    check_ids_agree(r)
    # Without them both are None.
    r = pyrseg.Segmenter(W, H, "cpu").segment(window(wide, 0))
    assert r.tracks is None and r.track_ids is None


def test_reset_restarts_the_stream_at_1(wide):
    seg = pyrseg.Segmenter(W, H, "cpu", outputs=("track_ids",))
    frames = [window(wide, f) for f in (0, 4, 8)]
    first = seg.segment(frames[0])
    for f in frames[1:]:
        r = seg.segment(f)
    assert r.tracks["age"].max() == 3 and r.tracks["how"].max() > pyrseg.TrackMatch.new_track
    seg.reset_tracks()
    again = seg.segment(frames[0])
    np.testing.assert_array_equal(again.tracks, first.tracks)
    np.testing.assert_array_equal(again.track_ids, first.track_ids)
    assert again.tracks["id"].min() == 1 and np.all(again.tracks["age"] == 1)
    # Resetting twice, or before any frame, is harmless.
    seg.reset_tracks()
    seg.reset_tracks()
    np.testing.assert_array_equal(seg.segment(frames[0]).tracks, first.tracks)
    fresh = pyrseg.Segmenter(W, H, "cpu", outputs=("track_ids",))
    fresh.reset_tracks()
    np.testing.assert_array_equal(fresh.segment(frames[0]).tracks, first.tracks)


def test_each_segmenter_keeps_its_own_stream(wide):
    """Two streams interleaved: each Segmenter's tracks are as if it ran alone."""
    alone = pyrseg.Segmenter(W, H, "cpu", outputs=("track_ids",))
    want = [alone.segment(window(wide, f)).tracks for f in range(4)]
    a = pyrseg.Segmenter(W, H, "cpu", outputs=("track_ids",))
    b = pyrseg.Segmenter(W, H, "cpu", outputs=("track_ids",))
    other = pyrseg.synthetic.generate(W, H, seed=9)
    for f in range(4):
        np.testing.assert_array_equal(a.segment(window(wide, f)).tracks, want[f])
        b.segment(other.points)
    assert b.segment(other.points).tracks["age"].min() == 5


def test_hold_frames_reach_the_library():
    """An object that no frame sees for three frames comes back with its id when tracks are held longer, with a new
    one when they are held for two."""
    scene = pyrseg.synthetic.generate(W, H, seed=5, object_count=10, hole_fraction=0.0)
    ids, counts = np.unique(scene.object_id[scene.object_id >= pyrseg.synthetic.FIRST_OBJECT_ID], return_counts=True)
    hidden_id = ids[np.argmax(counts)]
    without = scene.points.copy()
    without[scene.object_id == hidden_id] = np.nan
    # A pixel well inside the object: its 7 x 7 window is all the object's.
    inside = scene.object_id == hidden_id
    core = np.ones_like(inside)
    for dy in range(-3, 4):
        for dx in range(-3, 4):
            core &= np.roll(np.roll(inside, dy, axis=0), dx, axis=1)
    y, x = np.argwhere(core[3:-3, 3:-3])[0] + 3

    def stream(**params):
        seg = pyrseg.Segmenter(W, H, "cpu", outputs=("track_ids",), **params)
        got = []
        for f in range(6):
            r = seg.segment(without if 2 <= f <= 4 else scene.points)
            got.append(r)
        return got

    held = stream()
    assert held[5].track_ids[y, x] == held[0].track_ids[y, x] != 0
    back = held[5].tracks[held[5].labels[y, x] - 1]
    assert back["how"] == pyrseg.TrackMatch.position and back["hidden_frames"] == 3 and back["age"] == 3
    short = stream(track_hold_frames=2)
    assert short[5].track_ids[y, x] != short[0].track_ids[y, x]
    back = short[5].tracks[short[5].labels[y, x] - 1]
    assert back["how"] == pyrseg.TrackMatch.new_track and back["first_frame"] == 5


def test_parameters():
    d = pyrseg.default_params()
    assert d["track_max_distance_mm"] == 50.0 and d["track_hold_frames"] == 10
    seg = pyrseg.Segmenter(W, H, "cpu", outputs=("segment_tracks",), track_max_distance_mm=20, track_hold_frames=0)
    assert seg.params["track_max_distance_mm"] == 20.0 and seg.params["track_hold_frames"] == 0
    assert pyrseg.preset("kinect-v1")["track_hold_frames"] == 10
    over = pyrseg.Segmenter(W, H, "cpu", preset="kinect-v1", track_hold_frames=1000)
    assert over.params["track_hold_frames"] == 1000 and over.preset == "kinect-v1"


@pytest.mark.parametrize(
    "params, message",
    [
        ({"track_hold_frames": -1}, "track_hold_frames"),
        ({"track_hold_frames": 1001}, "track_hold_frames"),
        ({"track_max_distance_mm": -1.0}, "track_max_distance_mm"),
        ({"track_max_distance_mm": math.inf}, "track_max_distance_mm"),
        ({"track_max_distance_mm": math.nan}, "track_max_distance_mm"),
        ({"compact": False, "outputs": ("segment_tracks",)}, "compact"),
        ({"compact": False, "outputs": ("track_ids",)}, "compact"),
    ],
)
def test_bad_parameters_are_the_librarys_errors(params, message):
    params.setdefault("outputs", ("track_ids",))
    with pytest.raises(pyrseg.Error, match=message) as e:
        pyrseg.Segmenter(W, H, "cpu", **params)
    assert e.value.code == pyrseg.ErrorCode.invalid_parameter


def test_bad_arguments():
    with pytest.raises(TypeError, match="track_hold_frames"):
        pyrseg.Segmenter(W, H, "cpu", track_hold_frames=1.5)
    with pytest.raises(TypeError, match="track_max_distance_mm"):
        pyrseg.Segmenter(W, H, "cpu", track_max_distance_mm="50")
    with pytest.raises(ValueError, match="segment_tracks, track_ids"):
        pyrseg.Segmenter(W, H, "cpu", outputs=("tracks",))
    with pytest.raises(TypeError, match="track_max_distance_mm, track_hold_frames"):
        pyrseg.Segmenter(W, H, "cpu", track_distance=5)
    with pytest.raises(TypeError, match="not initialised"):
        pyrseg.Segmenter.__new__(pyrseg.Segmenter).reset_tracks()


def test_preset_auto_streams_from_its_first_frame(wide):
    seg = pyrseg.Segmenter(W, H, "cpu", preset="auto", outputs=("track_ids",))
    seg.reset_tracks()  # before the Segmenter is made: nothing to reset
    rs = [seg.segment(window(wide, f)) for f in range(3)]
    assert seg.preset is not None
    assert rs[0].tracks["id"].min() == 1 and rs[2].tracks["age"].max() == 3
    check_ids_agree(rs[2])


def test_masks_and_depth_images_are_tracked_too(wide):
    """A mask has no centroids (tracks match by overlap alone); a depth image is one stream with its own ids."""
    mask = pyrseg.Segmenter(W, H, "cpu", outputs=("fillable_mask",)).segment(window(wide, 0)).fillable_mask
    seg = pyrseg.Segmenter(W, H, "cpu", outputs=("track_ids",))
    a = seg.segment_mask(mask)
    assert a.segment_count > 1
    b = seg.segment_mask(mask)
    np.testing.assert_array_equal(a.track_ids, b.track_ids)
    assert np.all(b.tracks["how"] == pyrseg.TrackMatch.overlap) and np.all(b.tracks["age"] == 2)
    scene = pyrseg.synthetic.generate(W, H, seed=3)
    depth = np.nan_to_num(scene.points[..., 2], nan=0.0).astype(np.uint16)
    seg = pyrseg.Segmenter(W, H, "cpu", outputs=("track_ids",))
    first = seg.segment_depth(depth, scene.fx, scene.fy, scene.cx, scene.cy, metres_per_unit=0.001)
    second = seg.segment_depth(depth, scene.fx, scene.fy, scene.cx, scene.cy, metres_per_unit=0.001)
    check_ids_agree(second)
    np.testing.assert_array_equal(first.track_ids, second.track_ids)
    assert np.all(second.tracks["age"] == 2)


@pytest.mark.parametrize("backend", [b.name for b in pyrseg.backends() if b.name != "cpu"])
def test_other_backends_refuse_tracks_or_give_the_cpus(backend, wide):
    """A backend without tracks says so when the Segmenter is made (pyrseg.Error, backend_unavailable); one with
    them gives the cpu backend's ids (they are bit-identical on every backend, docs/algorithm.md section 11)."""
    info = next(b for b in pyrseg.backends() if b.name == backend)
    if not info.available:
        pytest.skip(f"{backend} unavailable: {info.reason}")
    try:
        seg = pyrseg.Segmenter(W, H, backend, outputs=("track_ids",))
    except pyrseg.Error as e:
        assert e.code == pyrseg.ErrorCode.backend_unavailable
        assert "tracks" in str(e) and backend in str(e)
        return
    cpu = pyrseg.Segmenter(W, H, "cpu", outputs=("track_ids",))
    for f in range(4):
        want = cpu.segment(window(wide, f))
        got = seg.segment(window(wide, f))
        np.testing.assert_array_equal(got.tracks, want.tracks)
        np.testing.assert_array_equal(got.track_ids, want.track_ids)


def test_warm_tracked_frames_allocate_nothing_in_cpp(wide):
    """As tests/python/test_no_allocation.py counts it: a tracked frame allocates no more than pybind11's dispatch."""
    T = pytest.importorskip("pyrseg_testing")
    seg = T.Segmenter(W, H, "cpu", outputs=("track_ids", "segment_stats"))
    out = np.empty((H, W), np.uint32)
    frames = [window(wide, f) for f in range(PAN)]
    probe = T.CallProbe()
    probe.segment(None, out=out)
    before = T.allocations()
    for _ in range(20):
        probe.segment(None, out=out)
    dispatch = (T.allocations() - before) / 20
    # The pan there and back, twice, sizes the Result and the tracks' state; the same again may allocate nothing.
    loop = frames + frames[::-1]
    for f in loop * 2:
        seg.segment(f, out=out)
    before = T.allocations()
    for f in loop:
        r = seg.segment(f, out=out)
    assert (T.allocations() - before) / len(loop) == dispatch
    assert r.labels is out and r.tracks["age"].max() == 6 * PAN
