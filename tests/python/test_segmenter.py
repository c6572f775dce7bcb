"""The Python API over pyrseg::Segmenter: inputs in place or converted, results, outputs, errors, threads."""

import os
import pathlib
import threading
import time

import numpy as np
import pyrseg
import pytest


# The workplace's real sample data (read-only, beside the repository); tests that use it skip without it.
SHARED = pathlib.Path(os.environ.get("PYRSEG_SHARED_DATA_DIR", pathlib.Path(__file__).resolve().parents[3] / "shared" / "data"))


def reference(scene, **kw):
    seg = pyrseg.Segmenter(scene.points.shape[1], scene.points.shape[0], "cpu", **kw)
    return seg.segment(np.ascontiguousarray(scene.points)).labels


def test_result(scene):
    h, w, _ = scene.points.shape
    seg = pyrseg.Segmenter(w, h, "cpu")
    r = seg.segment(scene.points)
    assert isinstance(r, pyrseg.Result)
    assert r.labels.shape == (h, w) and r.labels.dtype == np.uint32 and r.labels.flags.c_contiguous
    assert r.segment_count == len(np.unique(r.labels[r.labels > 0])) > 1
    assert r.segments is None and r.normals is None and r.fillable_mask is None and r.raw_labels is None
    assert not seg.last_input_copied
    assert seg.width == w and seg.height == h and seg.backend == "cpu"
    assert "labels" in seg.timings


@pytest.mark.parametrize(
    "layout",
    ["pcl_padded", "strided_rows", "pointnormal_slices", "six_channels"],
)
def test_layouts_read_in_place(scene, layout):
    """Layouts a CloudView describes are read where they are, and give the packed cloud's labels."""
    h, w, _ = scene.points.shape
    want_kw = {}
    normals = None
    if layout == "pcl_padded":
        buf = np.zeros((h, w, 4), np.float32)
        buf[..., :3] = scene.points
        points = buf
    elif layout == "strided_rows":
        # Every other row of a frame twice as tall: rows 2 * 12 * W bytes apart.
        tall = np.zeros((2 * h, w, 3), np.float32)
        tall[::2] = scene.points
        points = tall[::2]
    elif layout == "pointnormal_slices":
        # PCL's PointNormal: x y z pad nx ny nz curvature pad -> two views into one buffer.
        buf = np.zeros((h, w, 8), np.float32)
        buf[..., :3] = scene.points
        buf[..., 4:7] = scene.normals
        points, normals = buf[..., :3], buf[..., 4:7]
        want_kw = {"normals": scene.normals}
    else:
        points = np.concatenate([scene.points, scene.normals], axis=2)
        want_kw = {"normals": scene.normals}
    seg = pyrseg.Segmenter(w, h, "cpu")
    want = seg.segment(np.ascontiguousarray(scene.points), **want_kw).labels
    got = seg.segment(points, normals=normals).labels
    assert not seg.last_input_copied, layout
    np.testing.assert_array_equal(got, want)


@pytest.mark.parametrize("layout", ["float64", "fortran", "flipped", "list"])
def test_other_inputs_are_converted(scene, layout):
    h, w, _ = scene.points.shape
    small = scene.points[:8, :8]
    if layout == "float64":
        points = scene.points.astype(np.float64)
    elif layout == "fortran":
        points = np.asfortranarray(scene.points)
    elif layout == "flipped":
        points = np.flip(scene.points, 0)  # negative row strides: no CloudView describes them
    else:
        points = small.tolist()
        w = h = 8
    seg = pyrseg.Segmenter(w, h, "cpu")
    want = seg.segment(np.ascontiguousarray(np.asarray(points, np.float32))).labels
    got = seg.segment(points).labels
    if layout != "list":
        assert seg.last_input_copied
    np.testing.assert_array_equal(got, want)


def test_out_array_is_written_and_returned(scene):
    h, w, _ = scene.points.shape
    seg = pyrseg.Segmenter(w, h, "cpu")
    out = np.full((h, w), 7, np.uint32)
    r = seg.segment(scene.points, out=out)
    assert r.labels is out
    np.testing.assert_array_equal(out, reference(scene))
    # A strided out: the columns of a wider array.
    wide = np.zeros((h, 2 * w), np.uint32)
    seg.segment(scene.points, out=wide[:, ::2])
    np.testing.assert_array_equal(wide[:, ::2], out)
    assert not wide[:, 1::2].any()
    with pytest.raises(TypeError, match="uint32"):
        seg.segment(scene.points, out=np.zeros((h, w), np.int32))
    with pytest.raises(ValueError, match="shape"):
        seg.segment(scene.points, out=np.zeros((h, w + 1), np.uint32))
    ro = np.zeros((h, w), np.uint32)
    ro.flags.writeable = False
    with pytest.raises(ValueError, match="read-only"):
        seg.segment(scene.points, out=ro)


def test_outputs_and_statistics(scene):
    h, w, _ = scene.points.shape
    seg = pyrseg.Segmenter(w, h, "cpu", outputs=("segment_stats", "normals", "fillable_mask", "raw_labels"))
    r = seg.segment(scene.points)
    assert r.normals.shape == (h, w, 3) and r.normals.dtype == np.float32
    assert r.fillable_mask.shape == (h, w) and r.fillable_mask.dtype == np.uint8
    assert set(np.unique(r.fillable_mask)) <= {0, 1}
    assert r.raw_labels.shape == (h, w) and r.raw_labels.dtype == np.uint32
    s = r.segments
    assert s.dtype == pyrseg.segment_stats_dtype and len(s) == r.segment_count
    np.testing.assert_array_equal(s["label"], np.arange(1, r.segment_count + 1))
    np.testing.assert_array_equal(s["pixel_count"], np.bincount(r.labels.ravel(), minlength=r.segment_count + 1)[1:])
    for row in s[:3]:
        ys, xs = np.nonzero(r.labels == row["label"])
        assert (row["x_min"], row["y_min"], row["x_max"], row["y_max"]) == (xs.min(), ys.min(), xs.max(), ys.max())
        surface = r.fillable_mask[ys, xs] == 1  # the centroid is of the fillable pixels
        pts = scene.points[ys[surface], xs[surface]].astype(np.float64)
        np.testing.assert_allclose(row["centroid"], np.nanmean(pts, axis=0), atol=0.1)
        assert abs(np.linalg.norm(row["mean_normal"]) - 1) < 1e-6


def test_segment_geometry_matches_numpy(scene):
    # The covariance, plane and box (docs/algorithm.md section 10b) against numpy on the labelled points.
    h, w, _ = scene.points.shape
    r = pyrseg.Segmenter(w, h, "cpu", outputs=("segment_stats", "fillable_mask")).segment(scene.points)
    s = r.segments
    assert r.segment_count > 3
    for row in s[np.argsort(s["pixel_count"])[::-1][:4]]:
        ys, xs = np.nonzero((r.labels == row["label"]) & (r.fillable_mask == 1))  # the sums are of fillable pixels
        assert row["fillable_count"] == len(ys) < row["pixel_count"]
        pts = scene.points[ys, xs].astype(np.float64)
        cov = np.cov(pts.T, bias=True)
        got = row["covariance"]
        full = np.array([[got[0], got[1], got[2]], [got[1], got[3], got[4]], [got[2], got[4], got[5]]])
        np.testing.assert_allclose(full, cov, atol=np.sqrt(np.trace(cov)) / 16 + 1 / 128)
        assert row["z_min"] == pytest.approx(pts[:, 2].min(), abs=1 / 32)
        assert row["z_max"] == pytest.approx(pts[:, 2].max(), abs=1 / 32)
        values, vectors = np.linalg.eigh(cov)
        assert abs(np.dot(row["plane_normal"], vectors[:, 0])) == pytest.approx(1, abs=1e-4)
        assert np.dot(row["plane_normal"], row["centroid"]) < 0, "the normal faces the camera"
        assert row["plane_rms"] == pytest.approx(np.sqrt(max(values[0], 0)), abs=0.05)
        np.testing.assert_allclose(row["axes"] @ row["axes"].T, np.eye(3), atol=1e-9)
        np.testing.assert_allclose(row["extents"], 2 * np.sqrt(3 * np.maximum(values[::-1], 0)), rtol=1e-3, atol=0.05)
        assert bool(row["planar"]) == (row["plane_rms"] <= 2.0)
        wide = [int(v["high"]) * 2**64 + int(v["low"]) for v in row["point_product_sum"]]
        fixed = np.rint(pts * 2.0 ** row["point_shift"]).astype(np.int64)
        assert wide[5] == sum(int(z) * int(z) for z in fixed[:, 2]), "the exact sum of z * z"


def test_params_presets_and_errors(scene):
    h, w, _ = scene.points.shape
    assert set(pyrseg.presets()) == {"structured-light", "kinect-v1", "realsense-d435", "azure-kinect"}
    p = pyrseg.preset("realsense-d435", unit_mm=1000)
    seg = pyrseg.Segmenter(w, h, "cpu", preset="realsense-d435", unit_mm=1000, edge_rounds=5)
    assert seg.params == dict(p, edge_rounds=5)
    assert pyrseg.Segmenter(w, h, "cpu").params == pyrseg.default_params()
    with pytest.raises(pyrseg.Error) as e:
        pyrseg.Segmenter(w, h, "cpu", ct=-1)
    assert e.value.code == pyrseg.ErrorCode.invalid_parameter and "ct" in e.value.message
    assert isinstance(e.value, RuntimeError)
    with pytest.raises(pyrseg.Error) as e:
        pyrseg.Segmenter(w, h, "cpu", preset="phoxi")
    assert e.value.code == pyrseg.ErrorCode.invalid_parameter and "kinect-v1" in str(e.value)
    with pytest.raises(TypeError, match="ctt"):
        pyrseg.Segmenter(w, h, "cpu", ctt=0.3)
    with pytest.raises(pyrseg.Error) as e:
        pyrseg.Segmenter(w, h, "no-such-backend")
    assert e.value.code == pyrseg.ErrorCode.backend_unavailable
    seg = pyrseg.Segmenter(w, h, "cpu")
    with pytest.raises(pyrseg.Error) as e:
        seg.segment(scene.points[:, :-1])
    assert e.value.code == pyrseg.ErrorCode.size_mismatch
    with pytest.raises(TypeError, match="float32 or float64"):
        seg.segment(np.nan_to_num(scene.points).astype(np.int32))
    with pytest.raises(ValueError, match="H x W x 3"):
        seg.segment(scene.points[..., :2])
    with pytest.raises(ValueError, match="twice"):
        seg.segment(np.concatenate([scene.points, scene.normals], 2), normals=scene.normals)


def test_threads_of_its_own_give_the_same_labels(scene):
    """threads= gives a cpu Segmenter an arena of its own; the labels do not depend on it."""
    h, w, _ = scene.points.shape
    expected = reference(scene)
    for n in (1, 2, 3):
        assert np.array_equal(pyrseg.Segmenter(w, h, "cpu", threads=n).segment(scene.points).labels, expected)
    assert np.array_equal(pyrseg.Segmenter(w, h, "cpu", threads=None).segment(scene.points).labels, expected)
    with pytest.raises(ValueError, match="threads must be in 1..1024, got 0"):
        pyrseg.Segmenter(w, h, "cpu", threads=0)
    with pytest.raises(TypeError, match="threads"):
        pyrseg.Segmenter(w, h, "cpu", threads=2.0)
    others = [b.name for b in pyrseg.backends() if b.available and b.name != "cpu"]
    for name in others:
        with pytest.raises(ValueError, match="threads= is for the cpu backend"):
            pyrseg.Segmenter(w, h, name, threads=2)


def test_backends_and_choice():
    infos = pyrseg.backends()
    assert infos[-1].name == "cpu" and infos[-1].available
    for b in infos:
        assert b.available or b.reason
    name, reason = pyrseg.choose_backend("cpu")
    assert name == "cpu"
    assert pyrseg.choose_backend()[0] in {b.name for b in infos if b.available}


def test_depth_frames(scene):
    h, w, _ = scene.points.shape
    z = scene.points[..., 2]
    depth = np.where(np.isfinite(z), np.round(z), 0).astype(np.uint16)
    seg = pyrseg.Segmenter(w, h, "cpu")
    k = dict(fx=scene.fx, fy=scene.fy, cx=scene.cx, cy=scene.cy)
    r = seg.segment_depth(depth, metres_per_unit=0.001, **k)
    assert not seg.last_input_copied and r.segment_count > 1
    # Strided rows in place; a column-strided view converted; float32 metres and float64 metres agree.
    tall = np.zeros((2 * h, w), np.uint16)
    tall[::2] = depth
    np.testing.assert_array_equal(seg.segment_depth(tall[::2], metres_per_unit=0.001, **k).labels, r.labels)
    assert not seg.last_input_copied
    wide = np.zeros((h, 2 * w), np.uint16)
    wide[:, ::2] = depth
    np.testing.assert_array_equal(seg.segment_depth(wide[:, ::2], metres_per_unit=0.001, **k).labels, r.labels)
    assert seg.last_input_copied
    metres = depth.astype(np.float32) / 1000
    a = seg.segment_depth(metres, metres_per_unit=1.0, **k).labels
    b = seg.segment_depth(metres.astype(np.float64), metres_per_unit=1.0, **k).labels
    np.testing.assert_array_equal(a, b)
    with pytest.raises(pyrseg.Error) as e:
        seg.segment_depth(depth, metres_per_unit=0, **k)
    assert e.value.code == pyrseg.ErrorCode.invalid_parameter
    with pytest.raises(TypeError, match="uint16"):
        seg.segment_depth(depth.astype(np.float16), metres_per_unit=0.001, **k)


def test_mask_frames():
    mask = np.zeros((64, 96), bool)
    mask[4:30, 4:40] = True
    mask[36:60, 50:90] = True
    seg = pyrseg.Segmenter(96, 64, "cpu", outputs=("segment_stats",))
    r = seg.segment_mask(mask)
    assert r.segment_count == 2
    assert len(np.unique(r.labels[mask])) == 2
    assert np.isnan(r.segments["centroid"]).all()  # a mask has no points
    # uint8 with a valid mask in another layout (converted): nothing outside `valid` joins a segment.
    valid = np.zeros((64, 96), np.uint8)
    r2 = seg.segment_mask(mask.astype(np.uint8), valid=np.asfortranarray(valid))
    assert seg.last_input_copied
    assert (r2.labels[~mask] == 0).all() and r2.segment_count == 2
    with pytest.raises(TypeError, match="bool or uint8"):
        seg.segment_mask(mask.astype(np.float32))


def test_merge_joins_segments_and_refuses_masks():
    # A noisy frame under the contract's defaults: many small surfaces, some of which meet along flat boundaries.
    s = pyrseg.synthetic.generate(320, 240, seed=3, sensor="kinect-v1")
    h, w, _ = s.points.shape
    out = ("raw_labels",)
    seg = pyrseg.Segmenter(w, h, "cpu", merge=True, merge_reach=3, merge_max_bad_share=0.1, outputs=out)
    assert seg.params["merge"] and seg.params["merge_reach"] == 3 and seg.params["merge_max_bad_share"] == 0.1
    merged = seg.segment(s.points)
    plain = pyrseg.Segmenter(w, h, "cpu", outputs=out).segment(s.points)
    # Every merged segment is a union of whole plain ones: the merge only joins.
    for label in np.unique(plain.raw_labels[plain.raw_labels > 0]):
        assert len(np.unique(merged.raw_labels[plain.raw_labels == label])) == 1
    assert merged.segment_count < plain.segment_count
    with pytest.raises(pyrseg.Error) as e:
        seg.segment_mask(np.ones((h, w), bool))
    assert e.value.code == pyrseg.ErrorCode.invalid_parameter and "merge" in e.value.message
    with pytest.raises(pyrseg.Error) as e:
        pyrseg.Segmenter(w, h, "cpu", merge=True, merge_reach=17)
    assert e.value.code == pyrseg.ErrorCode.invalid_parameter and "merge_reach" in e.value.message


def test_edge_max_depth_step_keeps_bands_on_their_surface():
    # A far surface (left, z 2000) and a near one (right, z 1000 and 1015) with a band of edge pixels between them.
    h, w = 16, 16
    ys, xs = np.mgrid[0:h, 0:w].astype(np.float32)
    z = np.where(xs <= 5, 2000.0, np.where((xs == 6) | (xs == 8), 1015.0, 1000.0)).astype(np.float32)
    points = np.dstack([xs, ys, z])
    normals = np.zeros_like(points)
    normals[..., 2] = -1
    out = ("raw_labels",)
    crossed = pyrseg.Segmenter(w, h, "cpu", edge_rounds=8, outputs=out).segment(points, normals)
    seg = pyrseg.Segmenter(w, h, "cpu", edge_rounds=8, edge_max_depth_step=0.02, outputs=out)
    assert seg.params["edge_max_depth_step"] == 0.02
    kept = seg.segment(points, normals)
    far, near = crossed.raw_labels[0, 0], crossed.raw_labels[0, 15]
    assert crossed.raw_labels[0, 7] == far  # without the test the far label crosses the step
    assert kept.raw_labels[0, 5] == far and (kept.raw_labels[0, 6:] == near).all()
    assert pyrseg.preset("realsense-d435")["edge_max_depth_step"] == 0.02
    assert pyrseg.preset("structured-light")["edge_max_depth_step"] == 0
    with pytest.raises(pyrseg.Error) as e:
        seg.segment_mask(np.ones((h, w), bool))
    assert e.value.code == pyrseg.ErrorCode.invalid_parameter and "edge_max_depth_step" in e.value.message
    for bad in (-0.1, 1.5, float("nan"), 1e-9):
        with pytest.raises(pyrseg.Error) as e:
            pyrseg.Segmenter(w, h, "cpu", edge_max_depth_step=bad)
        assert e.value.code == pyrseg.ErrorCode.invalid_parameter and "edge_max_depth_step" in e.value.message


def test_frame_noise_suggests_a_preset():
    s = pyrseg.synthetic.generate(160, 120, sensor="kinect-v1")
    n = pyrseg.measure_frame_noise(s.points)
    assert n["suggested"] in pyrseg.presets() and n["samples"] > 1000 and n["reason"]
    # The same frame as a depth image in millimetres: the same depths, the same measurement and suggestion.
    z = s.points[..., 2]
    depth = np.where(np.isfinite(z), np.round(z), 0).astype(np.uint16)
    d = pyrseg.measure_depth_noise(depth, metres_per_unit=0.001)
    c = pyrseg.measure_frame_noise(np.dstack([np.zeros_like(z), np.zeros_like(z), depth.astype(np.float32)]))
    assert d == c and d["suggested"] == "kinect-v1", d
    assert 0 <= d["whole_mm_share"] <= 1 and d["level_step_mm_per_m2"] > 2.2
    with pytest.raises(pyrseg.Error) as e:
        pyrseg.measure_depth_noise(depth, metres_per_unit=0)
    assert e.value.code == pyrseg.ErrorCode.invalid_parameter


def test_preset_auto_chooses_on_the_first_frame_and_keeps_it():
    s = pyrseg.synthetic.generate(160, 120, seed=4, sensor="kinect-v1")
    seg = pyrseg.Segmenter(160, 120, "cpu", preset="auto", edge_rounds=5)
    assert seg.params is None and seg.preset is None and seg.preset_reason is None
    assert seg.width == 160 and seg.backend == "cpu" and seg.timings == {}
    with pytest.raises(ValueError, match="auto"):
        seg.segment_mask(np.ones((120, 160), bool))
    r = seg.segment(s.points)
    assert seg.preset == "kinect-v1" and "disparity steps" in seg.preset_reason
    # The chosen preset with the parameters given beside "auto" over it, and the same labels as naming it.
    assert seg.params == dict(pyrseg.preset("kinect-v1"), edge_rounds=5)
    named = pyrseg.Segmenter(160, 120, "cpu", preset="kinect-v1", edge_rounds=5).segment(s.points)
    np.testing.assert_array_equal(r.labels, named.labels)
    # Kept for the stream: a frame of another kind of sensor does not change it.
    scanner = pyrseg.synthetic.generate(160, 120, seed=4, sensor="structured-light")
    seg.segment(scanner.points)
    assert seg.preset == "kinect-v1"
    # Depth images choose from their samples.
    z = s.points[..., 2]
    depth = np.where(np.isfinite(z), np.round(z), 0).astype(np.uint16)
    d = pyrseg.Segmenter(160, 120, "cpu", preset="auto")
    d.segment_depth(depth, fx=s.fx, fy=s.fy, cx=s.cx, cy=s.cy, metres_per_unit=0.001)
    assert d.preset == "kinect-v1"
    # Parameters given beside "auto" are checked at once.
    with pytest.raises(pyrseg.Error) as e:
        pyrseg.Segmenter(160, 120, "cpu", preset="auto", merge_reach=0)
    assert e.value.code == pyrseg.ErrorCode.invalid_parameter
    assert pyrseg.Segmenter(160, 120, "cpu", preset="realsense-d435").preset == "realsense-d435"


@pytest.mark.skipif(not (SHARED / "realsense" / "wood_table_3_depth.png").exists(), reason="RealSense frames absent")
def test_realsense_depth_frames_suggest_the_stereo_preset():
    for name in ("wood_table_1", "wood_table_3", "low_table_5", "office_table_7"):
        depth = np.asarray(pyrseg.io.read_depth_image(str(SHARED / "realsense" / (name + "_depth.png"))))
        n = pyrseg.measure_depth_noise(depth, metres_per_unit=0.001)
        assert n["suggested"] == "realsense-d435", (name, n["reason"])


def test_gil_is_released_while_segmenting():
    """Another Python thread runs while a frame is segmented: the frame takes the GIL only around its arrays."""
    s = pyrseg.synthetic.generate(1280, 960, seed=5)
    seg = pyrseg.Segmenter(1280, 960, "cpu")
    seg.segment(s.points)
    inside = []
    done = threading.Event()

    def work():
        t0 = time.perf_counter()
        seg.segment(s.points)
        inside.append((t0, time.perf_counter()))
        done.set()

    ticks = []
    t = threading.Thread(target=work)
    t.start()
    while not done.is_set():
        ticks.append(time.perf_counter())
    t.join()
    (t0, t1), = inside
    # The middle of the frame, well clear of the conversions at either end, which hold the GIL.
    lo, hi = t0 + 0.2 * (t1 - t0), t1 - 0.2 * (t1 - t0)
    during = sum(lo < x < hi for x in ticks)
    # Held through the frame, the GIL would let this thread run not once in that span (a busy machine aside, it
    # runs thousands of times).
    assert during > 10, f"{during} steps of the main thread during a {1000 * (t1 - t0):.0f} ms frame"


def test_threads_share_a_segmenter(scene):
    h, w, _ = scene.points.shape
    seg = pyrseg.Segmenter(w, h, "cpu")
    want = reference(scene)
    results = []

    def work():
        for _ in range(10):
            results.append(seg.segment(scene.points).labels)

    threads = [threading.Thread(target=work) for _ in range(3)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert len(results) == 30
    for r in results:
        np.testing.assert_array_equal(r, want)


def test_segment_graph_matches_the_labels(scene):
    # Every pair of 4-neighbours with two labels is one crossing of its pair's edge (docs/algorithm.md section 10d).
    h, w, _ = scene.points.shape
    seg = pyrseg.Segmenter(w, h, "cpu", edge_rounds=4, outputs=("segment_graph",))
    r = seg.segment(scene.points)
    g = r.graph
    assert g.dtype == pyrseg.segment_graph_dtype and r.segments is None
    labels = r.labels.astype(np.int64)
    pairs = {}
    for a, b in ((labels[:, :-1], labels[:, 1:]), (labels[:-1, :], labels[1:, :])):
        touch = (a != 0) & (b != 0) & (a != b)
        lo, hi = np.minimum(a[touch], b[touch]), np.maximum(a[touch], b[touch])
        for key, n in zip(*np.unique(np.stack([lo, hi], axis=1), axis=0, return_counts=True)):
            pairs[tuple(key)] = pairs.get(tuple(key), 0) + n
    assert len(g) == len(pairs) > 0
    assert [(e["a"], e["b"]) for e in g] == sorted(pairs)
    np.testing.assert_array_equal(g["length"], [pairs[(e["a"], e["b"])] for e in g])
    np.testing.assert_array_equal(g["flat"] + g["convex"] + g["concave"] + g["step"], g["length"])
    with pytest.raises(ValueError, match="segment_graph"):
        pyrseg.Segmenter(w, h, "cpu", outputs=("graph",))
