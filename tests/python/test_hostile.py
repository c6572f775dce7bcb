"""A hostile caller (issue 32): objects half made, arguments of the wrong type or missing, arrays that overlap
themselves or the input, values a file cannot hold. Each gets a clear exception, never a crash, a hang or garbage.

What could crash runs in a child interpreter (run_snippet), so that a segfault fails one test, not the run."""

import os
import subprocess
import sys
import textwrap

import numpy as np
import pyrseg
import pytest

ALL_OUTPUTS = ("raw_labels", "fillable_mask", "normals", "segment_stats")


def run_snippet(code, timeout=120):
    """Runs `code` in a fresh interpreter with this one's environment; returns (returncode, stdout + stderr)."""
    try:
        r = subprocess.run(
            [sys.executable, "-c", textwrap.dedent(code)],
            capture_output=True,
            text=True,
            timeout=timeout,
            env=dict(os.environ),
        )
    except subprocess.TimeoutExpired:
        return "timeout", f"no exit within {timeout} s"
    return r.returncode, r.stdout + r.stderr


def assert_snippet_passes(code, timeout=120):
    rc, output = run_snippet(code, timeout)
    assert rc == 0, f"the snippet ended with {rc} (negative: a signal):\n{output}"


# --- 1: every output for every kind of frame ---------------------------------------------------------------------


def test_every_output_for_every_frame_kind(backend):
    """Cloud, depth and mask frames with every output asked for: normals are None for a mask frame (it has no
    points), fillable_mask is the mask itself, and every other output has its shape and agrees with the labels."""
    assert_snippet_passes(
        f"""
        import numpy as np, pyrseg
        s = pyrseg.synthetic.generate(96, 64, seed=3)
        h, w = 64, 96
        seg = pyrseg.Segmenter(w, h, {backend!r}, outputs={ALL_OUTPUTS!r})
        z = s.points[..., 2]
        depth = np.where(np.isfinite(z), np.round(z), 0).astype(np.uint16)
        mask = np.zeros((h, w), bool)
        mask[4:30, 4:40] = True
        mask[36:60, 50:90] = True
        frames = {{
            "cloud": lambda: seg.segment(s.points),
            "depth": lambda: seg.segment_depth(depth, s.fx, s.fy, s.cx, s.cy, 0.001),
            "mask": lambda: seg.segment_mask(mask),
        }}
        for kind, frame in frames.items():
            r = frame()
            assert r.labels.shape == (h, w) and r.labels.dtype == np.uint32, kind
            assert r.segment_count > 1, kind
            assert r.raw_labels.shape == (h, w) and r.raw_labels.dtype == np.uint32, kind
            assert ((r.raw_labels == 0) == (r.labels == 0)).all(), kind
            assert r.fillable_mask.shape == (h, w) and r.fillable_mask.dtype == np.uint8, kind
            assert set(np.unique(r.fillable_mask)) <= {{0, 1}}, kind
            assert len(r.segments) == r.segment_count, kind
            if kind == "mask":
                assert r.normals is None
                np.testing.assert_array_equal(r.fillable_mask, mask.astype(np.uint8))
            else:
                assert r.normals.shape == (h, w, 3) and r.normals.dtype == np.float32, kind
                n = np.linalg.norm(r.normals[r.fillable_mask == 1], axis=1)
                assert np.allclose(n, 1, atol=1e-3), kind
        # A cloud frame after a mask frame has its normals again.
        assert seg.segment(s.points).normals is not None
        """
    )


# --- 2: a Segmenter never initialised, or initialised twice ------------------------------------------------------

SEGMENTER_MEMBERS = {
    "width": None,
    "height": None,
    "backend": None,
    "params": None,
    "outputs": None,
    "timings": None,
    "last_input_copied": None,
    "segment": "(np.zeros((4, 4, 3), np.float32))",
    "segment_depth": "(np.zeros((4, 4), np.uint16), 1, 1, 1, 1, 0.001)",
    "segment_mask": "(np.zeros((4, 4), bool))",
}


@pytest.mark.parametrize("member", sorted(SEGMENTER_MEMBERS))
def test_uninitialised_segmenter_raises(member):
    call = SEGMENTER_MEMBERS[member] or ""
    assert_snippet_passes(
        f"""
        import numpy as np, pyrseg
        seg = pyrseg.Segmenter.__new__(pyrseg.Segmenter)
        try:
            seg.{member}{call}
        except TypeError as e:
            assert "not initialised" in str(e) and "pyrseg.Segmenter(width, height" in str(e), str(e)
        else:
            raise AssertionError("no exception")
        assert "not initialised" in repr(seg)
        """,
        timeout=60,
    )


def test_second_init_raises():
    seg = pyrseg.Segmenter(8, 6, "cpu")
    with pytest.raises(TypeError, match="already initialised"):
        seg.__init__(16, 12, "cpu")
    assert (seg.width, seg.height) == (8, 6)
    assert seg.segment(np.zeros((6, 8, 3), np.float32)).labels.shape == (6, 8)


def test_second_init_of_intrinsics_raises():
    k = pyrseg.io.Intrinsics(1, 2, 3, 4)
    with pytest.raises(TypeError, match="already initialised"):
        k.__init__(5, 6, 7, 8)
    assert (k.fx, k.cy) == (1, 4)


def test_copy_of_a_segmenter_is_refused():
    import copy

    seg = pyrseg.Segmenter(8, 6, "cpu")
    with pytest.raises(TypeError):
        copy.copy(seg)


def test_uninitialised_intrinsics_raise():
    assert_snippet_passes(
        """
        import numpy as np, pyrseg
        k = pyrseg.io.Intrinsics.__new__(pyrseg.io.Intrinsics)
        assert "not initialised" in repr(k)
        for f in (lambda: k.fx, lambda: setattr(k, "cy", 1.0),
                  lambda: list(k)):
            try:
                f()
            except TypeError as e:
                assert "not initialised" in str(e), str(e)
            else:
                raise AssertionError("no exception")
        """,
        timeout=60,
    )


# --- 3: wrong-typed and missing arguments -------------------------------------------------------------------------

SEGMENTER_KEYWORDS = {
    "ct": ("x", "number"),
    "dt": ([1], "number"),
    "unit_mm": ("1", "number"),
    "bridge_levels": (1.5, "integer"),
    "unjoinable_gap": ("2", "integer"),
    "label_edges": ("yes", "True or False"),
    "edge_rounds": (2.5, "integer"),
    "edge_max_depth_step": ("x", "number"),
    "compact": ("no", "True or False"),
    "normal_radius": ("2", "integer"),
    "metric": (1, "str"),
    "normal_window": (None, "integer"),
    "curvature_stride": ("1", "integer"),
    "dt_per_m2": ("x", "number"),
    "ct_growth_per_m2": ({}, "number"),
    "merge": ("yes", "True or False"),
    "merge_reach": (2.5, "integer"),
    "merge_tolerance_mm": ("1", "number"),
    "merge_tolerance_per_m2": ([], "number"),
    "merge_min_crossings": ("8", "integer"),
    "merge_max_bad_share": ("x", "number"),
    "preset": (3, "str"),
    "outputs": ([1], "str"),
}


@pytest.mark.parametrize("keyword", sorted(SEGMENTER_KEYWORDS))
def test_segmenter_keyword_of_the_wrong_type(keyword):
    value, want = SEGMENTER_KEYWORDS[keyword]
    with pytest.raises(TypeError) as e:
        pyrseg.Segmenter(8, 6, "cpu", **{keyword: value})
    message = str(e.value)
    assert keyword in message and want in message and "Unable to cast" not in message, message


@pytest.mark.parametrize(
    "args, name, want",
    [(("x", 6), "width", "integer"), ((8, 6.5), "height", "integer"), ((8, 6, 3), "backend", "str")],
)
def test_segmenter_positional_of_the_wrong_type(args, name, want):
    with pytest.raises(TypeError) as e:
        pyrseg.Segmenter(*args)
    assert name in str(e.value) and want in str(e.value), str(e.value)


def _depth_call(seg, depth, **kw):
    k = dict(fx=500.0, fy=500.0, cx=4.0, cy=3.0, metres_per_unit=0.001)
    k.update(kw)
    return seg.segment_depth(depth, **k)


@pytest.mark.parametrize("name", ["fx", "fy", "cx", "cy", "metres_per_unit"])
def test_segment_depth_number_of_the_wrong_type(name):
    seg = pyrseg.Segmenter(8, 6, "cpu")
    with pytest.raises(TypeError) as e:
        _depth_call(seg, np.zeros((6, 8), np.uint16), **{name: "a"})
    message = str(e.value)
    assert name in message and "number" in message and "Unable to cast" not in message, message


BIG = np.zeros((480, 640), np.uint16)


def short_type_error(f):
    """The TypeError f raises: short, with no array in it."""
    with pytest.raises(TypeError) as e:
        f()
    message = str(e.value)
    assert len(message) < 400 and "array(" not in message and "Invoked with" not in message, message
    return message


def test_missing_arguments_are_named_without_the_arrays():
    seg = pyrseg.Segmenter(640, 480, "cpu")
    m = short_type_error(lambda: seg.segment_depth(BIG))
    assert all(name in m for name in ("'fx'", "'fy'", "'cx'", "'cy'", "'metres_per_unit'")), m
    m = short_type_error(lambda: seg.segment_depth(BIG, 1, 2, 3))
    assert "'cy'" in m and "'fx'" not in m, m
    m = short_type_error(lambda: seg.segment_depth(BIG, 1, 2, 3, 4, 0.001, fxx=1))
    assert "fxx" in m, m
    m = short_type_error(lambda: seg.segment_depth(BIG, 1, 2, 3, 4, 0.001, fx=1))
    assert "fx" in m and "multiple" in m, m
    m = short_type_error(lambda: seg.segment_depth(BIG, 1, 2, 3, 4, 0.001, None, None, None, 9))
    assert "at most" in m, m
    m = short_type_error(lambda: seg.segment())
    assert "'points'" in m, m
    m = short_type_error(lambda: seg.segment(np.zeros((480, 640, 3), np.float32), normalz=None))
    assert "normalz" in m, m
    m = short_type_error(lambda: pyrseg.io.depth_to_cloud(BIG))
    assert "'fx'" in m and "_per_unit'" in m, m
    m = short_type_error(lambda: pyrseg.io.write_pcd(points=np.zeros((480, 640, 3), np.float32)))
    assert "'path'" in m, m
    m = short_type_error(lambda: pyrseg.io.write_png_gray16(1, BIG))
    assert "path" in m, m
    m = short_type_error(lambda: pyrseg.measure_frame_noise(np.zeros((48, 64, 3), np.float32), unit_mm="x"))
    assert "unit_mm" in m and "number" in m, m


@pytest.mark.parametrize(
    "call, name, want",
    [
        (lambda: pyrseg.preset("kinect-v1", unit_mm="x"), "unit_mm", "number"),
        (lambda: pyrseg.preset(1), "name", "str"),
        (lambda: pyrseg.choose_backend(1), "requested", "str"),
        (lambda: pyrseg.io.read_pcd(1), "path", "path"),
        (lambda: pyrseg.io.read_depth_image(None), "path", "path"),
        (lambda: pyrseg.io.write_pcd("x.pcd", np.zeros((2, 2, 3)), encoding=1), "encoding", "str"),
        (lambda: pyrseg.io.write_ply("x.ply", np.zeros((2, 2, 3)), binary="yes"), "binary", "True or False"),
        (lambda: pyrseg.io.label_color("1"), "label", "integer"),
        (lambda: pyrseg.io.parse_intrinsics(1), "text", "str"),
        (lambda: pyrseg.io.Intrinsics("a", 1, 1, 1), "fx", "number"),
        (lambda: pyrseg.io.depth_to_cloud(BIG, "k", 1, 1, 1, 1.0), "fx", "number"),
        (lambda: pyrseg.io.depth_to_cloud(BIG, pyrseg.io.Intrinsics(1, 1, 1, 1), 1.0), "*k", "unpack"),
        (lambda: pyrseg.io.depth_to_cloud(BIG, *pyrseg.io.Intrinsics(1, 1, 1, 1), "1"), "_per_unit", "number"),
        (lambda: pyrseg.io.write_segment_stats("s.csv", np.zeros(0), "64", 48), "width", "integer"),
        (lambda: pyrseg.synthetic.generate(width="x"), "width", "integer"),
        (lambda: pyrseg.synthetic.generate(touching="x"), "touching", "True or False"),
        (lambda: pyrseg.synthetic.generate(sensor=1), "sensor", "str"),
    ],
)
def test_module_function_arguments_of_the_wrong_type(call, name, want):
    m = short_type_error(call)
    assert name in m and want in m and "Unable to cast" not in m, m


def test_integers_out_of_range_are_value_errors():
    with pytest.raises(ValueError, match=r"label must be in 0\.\.4294967295, got -1"):
        pyrseg.io.label_color(-1)
    with pytest.raises(ValueError, match="seed"):
        pyrseg.synthetic.generate(seed=-1)
    with pytest.raises(ValueError, match="edge_rounds"):
        pyrseg.Segmenter(8, 6, "cpu", edge_rounds=2**40)


def test_none_where_an_array_is_needed():
    seg = pyrseg.Segmenter(8, 6, "cpu")
    for f in (
        lambda: seg.segment(None),
        lambda: seg.segment_depth(None, 1, 1, 1, 1, 0.001),
        lambda: seg.segment_mask(None),
        lambda: pyrseg.measure_frame_noise(None),
        lambda: pyrseg.io.write_png_gray16("x.png", None),
        lambda: pyrseg.io.colorize_labels(None),
        lambda: pyrseg.io.write_pcd("x.pcd", None),
    ):
        m = short_type_error(f)
        assert "None" in m, m


def test_ragged_lists_are_value_errors_naming_the_argument():
    # numpy cannot make an array of a ragged list; the bindings used the null array it left (a segfault, found by
    # fuzz_py_arrays), so each call runs in a child interpreter.
    assert_snippet_passes(
        """
        import numpy as np
        import pyrseg
        seg = pyrseg.Segmenter(8, 6, "cpu")
        ragged = [[1.0], [1.0, 2.0]]
        calls = {
            "points": lambda: seg.segment(ragged),
            "normals": lambda: seg.segment([[[0.0, 0.0, 1.0]] * 8] * 6, normals=ragged),
            "depth": lambda: seg.segment_depth(ragged, 1, 1, 1, 1, 0.001),
            "mask": lambda: seg.segment_mask(ragged),
            "valid": lambda: seg.segment_mask(np.ones((6, 8), bool), valid=ragged),
            "image": lambda: pyrseg.io.write_png_gray16("x.png", ragged),
        }
        for name, call in calls.items():
            try:
                call()
            except ValueError as e:
                assert name in str(e) and "cannot be made an array" in str(e), (name, str(e))
            else:
                raise AssertionError(name + ": no ValueError")
        """
    )


# --- 4: out= that overlaps itself or the input -------------------------------------------------------------------


def test_out_with_overlapping_rows_is_refused(scene):
    h, w, _ = scene.points.shape
    seg = pyrseg.Segmenter(w, h, "cpu")
    base = np.zeros(h + w, np.uint32)
    rows_overlap = np.lib.stride_tricks.as_strided(base, (h, w), (4, 4))
    with pytest.raises(ValueError, match="out="):
        seg.segment(scene.points, out=rows_overlap)
    one_element = np.lib.stride_tricks.as_strided(base, (h, w), (0, 0))
    with pytest.raises(ValueError, match="out="):
        seg.segment(scene.points, out=one_element)
    assert not base.any()
    # A transposed view does not overlap itself: it is written.
    t = np.zeros((w, h), np.uint32)
    r = seg.segment(scene.points, out=t.T)
    np.testing.assert_array_equal(t.T, seg.segment(scene.points).labels)
    assert r.labels.base is t


def test_out_aliasing_the_input_is_refused(scene):
    h, w, _ = scene.points.shape
    seg = pyrseg.Segmenter(w, h, "cpu")
    points = np.ascontiguousarray(scene.points)
    with pytest.raises(ValueError, match="out="):
        seg.segment(points, out=points.view(np.uint32)[..., 0])
    buf = np.zeros((h, w), np.uint32)
    with pytest.raises(ValueError, match="out="):
        seg.segment_depth(buf.view(np.uint16)[:, :w], w, w, w / 2, h / 2, 0.001, out=buf)
    mask = np.zeros((h, w, 4), np.uint8)
    with pytest.raises(ValueError, match="out="):
        seg.segment_mask(mask[..., 0], out=mask.view(np.uint32)[..., 0])
    # PCL's PointXYZL: the labels into the label field of the very buffer whose xyz are read in place.
    buf = np.zeros((h, w, 4), np.float32)
    buf[..., :3] = scene.points
    out = buf.view(np.uint32)[..., 3]
    r = seg.segment(buf[..., :3], out=out)
    assert r.labels is out
    np.testing.assert_array_equal(out, seg.segment(points).labels)


# --- 5: depth of any integer dtype ------------------------------------------------------------------------------


@pytest.mark.parametrize("dtype", [np.int32, np.int64, np.uint32, np.int16, np.uint8, ">u2"])
def test_integer_depth_of_any_dtype(scene, dtype):
    h, w, _ = scene.points.shape
    z = scene.points[..., 2]
    depth = np.where(np.isfinite(z), np.round(z), 0).astype(np.uint16)
    if np.dtype(dtype).itemsize == 1 or np.dtype(dtype) == np.int16:
        depth = np.minimum(depth, np.iinfo(dtype).max).astype(np.uint16)
    seg = pyrseg.Segmenter(w, h, "cpu")
    k = dict(fx=scene.fx, fy=scene.fy, cx=scene.cx, cy=scene.cy, metres_per_unit=0.001)
    want = seg.segment_depth(depth, **k).labels
    assert not seg.last_input_copied
    got = seg.segment_depth(depth.astype(dtype), **k).labels
    assert seg.last_input_copied
    np.testing.assert_array_equal(got, want)


def test_integer_depth_out_of_range_is_refused():
    seg = pyrseg.Segmenter(8, 6, "cpu")
    for bad in (-1, 65536):
        depth = np.zeros((6, 8), np.int32)
        depth[2, 3] = bad
        with pytest.raises(ValueError) as e:
            seg.segment_depth(depth, 1, 1, 1, 1, 0.001)
        assert "0..65535" in str(e.value) and "read_depth_image" in str(e.value) and str(bad) in str(e.value)


def test_pil_depth_png(tmp_path):
    Image = pytest.importorskip("PIL.Image")
    depth = (np.arange(48 * 64, dtype=np.uint32).reshape(48, 64) * 7 % 4000).astype(np.uint16)
    pyrseg.io.write_png_gray16(tmp_path / "d.png", depth)
    pil = np.asarray(Image.open(tmp_path / "d.png"))
    seg = pyrseg.Segmenter(64, 48, "cpu")
    np.testing.assert_array_equal(
        seg.segment_depth(pil, 50, 50, 32, 24, 0.001).labels, seg.segment_depth(depth, 50, 50, 32, 24, 0.001).labels
    )


# --- 6: writers refuse what they cannot store -------------------------------------------------------------------


@pytest.mark.parametrize(
    "write, value",
    [
        (lambda p, v: pyrseg.io.write_png_gray16(p / "a.png", np.full((2, 2), v)), -1),
        (lambda p, v: pyrseg.io.write_png_gray16(p / "a.png", np.full((2, 2), v)), 65536),
        (lambda p, v: pyrseg.io.write_png_gray16(p / "a.png", np.full((2, 2), v)), 1.5),
        (lambda p, v: pyrseg.io.write_png_gray8(p / "a.png", np.full((2, 2), v)), 256),
        (lambda p, v: pyrseg.io.write_png_rgb(p / "a.png", np.full((2, 2, 3), v)), -3),
        (lambda p, v: pyrseg.io.write_tiff_float(p / "a.tiff", np.full((2, 2), v)), 1e300),
        (lambda p, v: pyrseg.io.write_pcd(p / "a.pcd", np.zeros((2, 2, 3)), labels=np.full((2, 2), v)), 0.5),
        (lambda p, v: pyrseg.io.write_pcd(p / "a.pcd", np.zeros((2, 2, 3)), labels=np.full((2, 2), v)), -1),
        (lambda p, v: pyrseg.io.write_pcd(p / "a.pcd", np.full((2, 2, 3), v)), 1e40),
        (lambda p, v: pyrseg.io.write_ply(p / "a.ply", np.zeros((2, 2, 3)), labels=np.full((2, 2), v)), 2**32),
        (lambda p, v: pyrseg.io.colorize_labels(np.full((2, 2), v)), 1.25),
    ],
)
def test_writers_refuse_values_they_cannot_store(tmp_path, write, value):
    with pytest.raises((ValueError, pyrseg.Error)) as e:
        write(tmp_path, value)
    assert str(value) in str(e.value) or repr(value) in str(e.value), str(e.value)
    assert not any(tmp_path.iterdir())


def test_writers_take_exact_values_of_other_dtypes(tmp_path):
    d = np.array([[0, 1], [65535, 7]], np.int64)
    pyrseg.io.write_png_gray16(tmp_path / "a.png", d)
    np.testing.assert_array_equal(pyrseg.io.read_depth_image(tmp_path / "a.png"), d)
    pyrseg.io.write_png_gray16(tmp_path / "b.png", d.astype(np.float64))
    np.testing.assert_array_equal(pyrseg.io.read_depth_image(tmp_path / "b.png"), d)
    pyrseg.io.write_pcd(tmp_path / "a.pcd", np.zeros((2, 2, 3)), labels=d)


# --- 7: out of memory is pyrseg.Error(out_of_memory) on every backend ---------------------------------------------


def test_bad_alloc_is_out_of_memory():
    T = pytest.importorskip("pyrseg_testing")
    with pytest.raises(T.Error) as e:
        T.throw_bad_alloc()
    assert e.value.code == T.ErrorCode.out_of_memory


def test_too_large_segmenter_is_out_of_memory(backend):
    # 50000 x 50000 fits 32-bit labels but no machine's memory (60000 x 60000 does not fit the labels:
    # image_too_large).
    with pytest.raises(pyrseg.Error) as e:
        pyrseg.Segmenter(50000, 50000, backend)
    assert e.value.code in (pyrseg.ErrorCode.out_of_memory, pyrseg.ErrorCode.image_too_large), e.value
    with pytest.raises(pyrseg.Error) as e:
        pyrseg.Segmenter(60000, 60000, backend)
    assert e.value.code == pyrseg.ErrorCode.image_too_large
