"""setup.py's preflight: an interpreter without what the build needs (a pyenv or conda python3: no wheel, no numpy)
gets one message naming what is missing and the interpreter to use, instead of setuptools' "invalid command
'bdist_wheel'" or a traceback."""
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def run_setup(*python_flags):
    # -S: no site-packages, so neither setuptools nor wheel nor numpy: what a bare pyenv interpreter has.
    return subprocess.run([sys.executable, *python_flags, "setup.py", "--version"], cwd=ROOT, capture_output=True,
                          text=True, timeout=120)


def test_an_interpreter_without_the_build_parts_is_told_what_is_missing():
    r = run_setup("-S")
    assert r.returncode != 0
    assert "Traceback" not in r.stderr, r.stderr
    assert f"this Python ({sys.executable}" in r.stderr, r.stderr
    assert "cannot build pyrseg: it lacks" in r.stderr
    for name in ("setuptools", "wheel", "numpy"):
        assert f"  - {name}: " in r.stderr, r.stderr
    assert "--system-site-packages" in r.stderr or "scripts/deps.sh" in r.stderr, r.stderr


def test_an_interpreter_with_them_passes_the_preflight():
    r = run_setup()
    assert r.returncode == 0, r.stderr
    assert r.stdout.strip().splitlines()[-1][0].isdigit(), r.stdout
