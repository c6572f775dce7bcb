"""Builds pyrseg's Python module with the project's own CMake (python/CMakeLists.txt) for the interpreter running
pip, and puts it in the wheel beside python/pyrseg/__init__.py. Offline: nothing is downloaded (pip's
--no-build-isolation uses Debian's setuptools and wheel; pybind11 and numpy come from Debian too).

Environment: PYRSEG_CMAKE_ARGS (extra configure arguments, e.g. -DPYRSEG_WITH_CUDA=OFF), PYRSEG_BUILD_DIR (the
CMake build folder; default build/python-wheel, reused by later installs)."""

import os
import re
import shlex
import shutil
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent
DEBIAN_PYTHON = "/usr/bin/python3"


def missing_build_parts():
    """What this interpreter lacks to build and use the module, as (what, why) pairs. pip's --no-build-isolation
    uses the interpreter's own packages: a pyenv or conda python3 usually has neither wheel (pip then stops with
    "invalid command 'bdist_wheel'") nor numpy, and this machine may reach no package index to fetch them."""
    missing = []
    for module, why in (
        ("setuptools", "setup.py is setuptools'"),
        ("wheel", "pip builds the wheel with it"),
        ("numpy", "the module's arrays are numpy's"),
    ):
        try:
            __import__(module)
        except ImportError:
            missing.append((module, why))
    if shutil.which("cmake") is None:
        missing.append(("cmake", "setup.py builds the module with the project's CMake"))
    pybind11_cmake = [Path("/usr/lib/cmake/pybind11"), Path("/usr/share/cmake/pybind11")]
    try:
        import pybind11  # noqa: F401  (a pip-installed pybind11 brings its CMake files too)
    except ImportError:
        if not any(p.exists() for p in pybind11_cmake):
            missing.append(("pybind11", "the bindings are written with it (Debian: pybind11-dev)"))
    return missing


def preflight():
    """Stops with one message naming what is missing and which interpreter to use, before setuptools or CMake
    fail with messages that point elsewhere."""
    if os.environ.get("PYRSEG_SKIP_PREFLIGHT"):
        return
    missing = missing_build_parts()
    if not missing:
        return
    lines = [f"pyrseg: this Python ({sys.executable}, {sys.version.split()[0]}) cannot build pyrseg: it lacks"]
    lines += [f"  - {name}: {why}" for name, why in missing]
    debian = Path(DEBIAN_PYTHON)
    if debian.exists() and Path(sys.executable).resolve() != debian.resolve():
        lines += [
            f"Use Debian's Python, which has them once scripts/deps.sh has run (a pyenv or conda python3 usually "
            f"does not):",
            f"  {DEBIAN_PYTHON} -m venv --system-site-packages ~/venv",
            "  ~/venv/bin/pip install --no-build-isolation .",
            "or install what is missing into this interpreter (python3 -m pip install wheel numpy pybind11).",
        ]
    else:
        lines += ["scripts/deps.sh installs them (Debian: python3-wheel python3-numpy pybind11-dev cmake)."]
    sys.exit("\n".join(lines))


preflight()

from setuptools import Extension, setup  # noqa: E402  (after the preflight, which names a missing setuptools)
from setuptools.command.build_ext import build_ext  # noqa: E402


def project_version():
    text = (ROOT / "CMakeLists.txt").read_text()
    return re.search(r"project\(pyrseg VERSION ([0-9.]+)", text).group(1)


class CMakeBuild(build_ext):
    def build_extension(self, ext):
        build_dir = Path(os.environ.get("PYRSEG_BUILD_DIR", ROOT / "build" / "python-wheel"))
        # The module links the static libraries (one self-contained file); the tests, benchmarks, CLI and peers are
        # not needed for it.
        configure = [
            "cmake", "-S", str(ROOT), "-B", str(build_dir), "-DCMAKE_BUILD_TYPE=Release",
            f"-DPython3_EXECUTABLE={sys.executable}", "-DPYRSEG_WITH_PYTHON=ON", "-DBUILD_SHARED_LIBS=OFF",
            "-DPYRSEG_BUILD_TESTS=OFF", "-DPYRSEG_BUILD_BENCH=OFF", "-DPYRSEG_BUILD_TOOLS=OFF",
            "-DPYRSEG_WITH_PEERS=OFF",
        ]
        if shutil.which("ninja") and not (build_dir / "CMakeCache.txt").exists():
            configure += ["-G", "Ninja"]
        configure += shlex.split(os.environ.get("PYRSEG_CMAKE_ARGS", ""))
        subprocess.check_call(configure)
        jobs = str(os.cpu_count() or 2)
        subprocess.check_call(["cmake", "--build", str(build_dir), "--target", "pyrseg_python", "-j", jobs])
        suffix = Path(self.get_ext_fullpath(ext.name)).name.split(".", 1)[1]
        built = build_dir / "python" / "pyrseg" / f"_pyrseg.{suffix}"
        if not built.exists():
            raise RuntimeError(f"CMake did not build {built}: was it configured for {sys.executable}?")
        dest = Path(self.get_ext_fullpath(ext.name))
        dest.parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(built, dest)


setup(
    version=project_version(),
    ext_modules=[Extension("pyrseg._pyrseg", sources=[])],
    cmdclass={"build_ext": CMakeBuild},
)
