"""pyrseg.io: the readers and writers of pyrseg/io.hpp round-trip numpy arrays."""

import numpy as np
import pyrseg
import pytest


@pytest.fixture(scope="module")
def cloud():
    s = pyrseg.synthetic.generate(64, 48, seed=4)
    labels = pyrseg.Segmenter(64, 48, "cpu").segment(s.points).labels
    return s, labels


@pytest.mark.parametrize("encoding", ["ascii", "binary", "binary_compressed"])
def test_pcd_round_trip(tmp_path, cloud, encoding):
    s, labels = cloud
    path = tmp_path / "c.pcd"
    pyrseg.io.write_pcd(path, s.points, normals=s.normals, labels=labels, encoding=encoding)
    points, normals = pyrseg.io.read_pcd(path)
    assert points.shape == (48, 64, 3) and points.dtype == np.float32
    if encoding == "ascii":
        np.testing.assert_allclose(points, s.points, rtol=1e-5, equal_nan=True)
    else:
        np.testing.assert_array_equal(points, s.points)
        np.testing.assert_array_equal(normals, s.normals)
    pyrseg.io.write_pcd(str(path), s.points)
    assert pyrseg.io.read_pcd(str(path))[1] is None


def test_ply_round_trip(tmp_path, cloud):
    s, labels = cloud
    path = tmp_path / "c.ply"
    try:
        pyrseg.io.write_ply(path, s.points, normals=s.normals, labels=labels)
    except pyrseg.Error as e:
        if "without PLY support" in e.message:
            pytest.skip(e.message)
        raise
    points, normals = pyrseg.io.read_ply(path)
    np.testing.assert_array_equal(points, s.points)
    np.testing.assert_array_equal(normals, s.normals)


def test_depth_images(tmp_path, cloud):
    s, _ = cloud
    z = np.nan_to_num(s.points[..., 2])
    mm = np.round(z).astype(np.uint16)
    pyrseg.io.write_png_gray16(tmp_path / "d.png", mm)
    back = pyrseg.io.read_depth_image(tmp_path / "d.png")
    assert back.dtype == np.uint16
    np.testing.assert_array_equal(back, mm)
    metres = (z / 1000).astype(np.float32)
    pyrseg.io.write_tiff_float(tmp_path / "d.tiff", metres)
    back = pyrseg.io.read_depth_image(tmp_path / "d.tiff")
    assert back.dtype == np.float32
    np.testing.assert_array_equal(back, metres)
    k = pyrseg.io.Intrinsics(s.fx, s.fy, s.cx, s.cy)
    cloud_mm = pyrseg.io.depth_to_cloud(mm, *k, 0.001)
    valid = mm > 0
    np.testing.assert_allclose(cloud_mm[valid][:, 2], mm[valid])
    assert np.isnan(cloud_mm[~valid]).all()
    assert pyrseg.io.parse_intrinsics("500,501,320,240").fy == 501


def test_png_and_colours(tmp_path, cloud):
    _, labels = cloud
    rgb = pyrseg.io.colorize_labels(labels)
    assert rgb.shape == (48, 64, 3) and rgb.dtype == np.uint8
    assert tuple(rgb[labels == 0][0]) == (0, 0, 0) if (labels == 0).any() else True
    assert tuple(rgb[labels == 1][0]) == pyrseg.io.label_color(1)
    pyrseg.io.write_png_rgb(tmp_path / "l.png", rgb)
    np.testing.assert_array_equal(pyrseg.io.read_png(tmp_path / "l.png"), rgb)


def test_segment_stats_table(tmp_path, cloud):
    s, _ = cloud
    r = pyrseg.Segmenter(64, 48, "cpu", outputs=("segment_stats",)).segment(s.points)
    pyrseg.io.write_segment_stats(tmp_path / "s.csv", r.segments, 64, 48)
    lines = (tmp_path / "s.csv").read_text().splitlines()
    assert len(lines) == r.segment_count + 1
    with pytest.raises(ValueError, match="segment_stats_dtype"):
        pyrseg.io.write_segment_stats(tmp_path / "s.csv", np.zeros(3), 64, 48)


def test_errors_name_the_file(tmp_path):
    with pytest.raises(pyrseg.Error) as e:
        pyrseg.io.read_pcd(tmp_path / "missing.pcd")
    assert e.value.code == pyrseg.ErrorCode.io and "missing.pcd" in e.value.message


def test_write_pcd_takes_further_integer_fields(tmp_path):
    points = np.arange(4 * 3 * 3, dtype=np.float32).reshape(4, 3, 3) + 1
    labels = np.arange(12, dtype=np.uint32).reshape(4, 3)
    track = (4000000000 - np.arange(12)).astype(np.uint32).reshape(4, 3)
    path = tmp_path / "f.pcd"
    pyrseg.io.write_pcd(path, points, labels=labels, fields={"object": labels % 3, "track": track}, encoding="ascii")
    text = path.read_text()
    assert "FIELDS x y z label object track\n" in text and "TYPE F F F U U U\n" in text
    rows = text.split("DATA ascii\n")[1].split("\n")
    assert rows[5].split()[3:] == ["5", "2", str(4000000000 - 5)]
    back, _ = pyrseg.io.read_pcd(path)
    np.testing.assert_array_equal(back, points)
    with pytest.raises(pyrseg.Error):  # a name PCL's header cannot hold, nothing written
        pyrseg.io.write_pcd(tmp_path / "bad.pcd", points, fields={"two words": labels})
    assert not (tmp_path / "bad.pcd").exists()
    with pytest.raises(ValueError, match="field 'object'"):
        pyrseg.io.write_pcd(tmp_path / "bad.pcd", points, fields={"object": labels[:2]})
    with pytest.raises(TypeError, match="dict"):
        pyrseg.io.write_pcd(tmp_path / "bad.pcd", points, fields=[labels])
