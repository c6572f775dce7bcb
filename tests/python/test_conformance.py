"""Labels from the Python API are byte-identical to the C++ API's on the conformance scenes
(tests/conformance/cases.cpp), for every available backend: the scene made through pyrseg.synthetic, the parameters
through Segmenter's keywords, the cloud through numpy; the C++ side runs the same case with the C++ API alone."""

import numpy as np
import pyrseg
import pyrseg_testing
import pytest

def cases(suite):
    return [(suite, i, c) for i, c in enumerate(pyrseg_testing.conformance_cases(suite))]


ALL = cases("contract") + cases("robust")


@pytest.mark.parametrize("suite,index,case", ALL, ids=[c["name"] for _, _, c in ALL])
def test_labels_match_cpp(backend, suite, index, case):
    sc = case["scene"]
    s = pyrseg.synthetic.generate(**sc)
    try:
        want = pyrseg_testing.cpp_labels(suite, index, backend)
    except pyrseg_testing.Error as e:
        # Parameters that do not fit the image (an explicit bridge_levels on a strip): Python refuses them alike.
        with pytest.raises(pyrseg.Error) as got_error:
            pyrseg.Segmenter(sc["width"], sc["height"], backend, **case["params"])
        assert got_error.value.code.name == e.code.name and got_error.value.message == e.message
        return
    seg = pyrseg.Segmenter(sc["width"], sc["height"], backend, **case["params"])
    if case["given_normals"]:
        # H x W x 6, read in place: points and normals interleaved, as a PCL PointNormal-like buffer.
        frame = np.concatenate([s.points, s.normals], axis=2)
        got = seg.segment(frame).labels
    else:
        got = seg.segment(s.points).labels
    assert got.dtype == np.uint32 and got.shape == (sc["height"], sc["width"])
    assert got.tobytes() == want.tobytes()
