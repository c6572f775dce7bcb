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

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

ROOT = Path(__file__).resolve().parent


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
