"""Shared fixtures of the Python tests. ctest (python/CMakeLists.txt) runs them with PYTHONPATH at the build tree's
python/ folder, which holds the pyrseg package and the tests' own module pyrseg_testing."""

import pyrseg
import pytest


def available_backends():
    return [b.name for b in pyrseg.backends() if b.available]


@pytest.fixture(params=[b.name for b in pyrseg.backends()])
def backend(request):
    """Each backend this build knows; those that cannot run here are skipped with the library's reason."""
    info = next(b for b in pyrseg.backends() if b.name == request.param)
    if not info.available:
        pytest.skip(f"{info.name} unavailable: {info.reason}")
    return info.name


@pytest.fixture(scope="session")
def scene():
    return pyrseg.synthetic.generate(160, 120, seed=3)
