"""A plain ``pip install`` (no CAD extra) works, and so does an install nobody may write to.

The package is installed with pip, as a user would, into a fresh
environment pinned to ``requirements.lock`` (pip's cache makes this fast
after ``make test`` installed the same wheels).
"""

import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parent.parent


@pytest.fixture(scope="module")
def core_env():
    """A venv holding spiral_cad and its core dependencies only (numpy, scipy, numba)."""
    (REPO / "build").mkdir(exist_ok=True)
    root = Path(tempfile.mkdtemp(prefix="core-env-", dir=REPO / "build"))
    os.chmod(root, 0o755)  # readable by the unprivileged user of the read-only test
    try:
        subprocess.run([sys.executable, "-m", "venv", str(root / "venv")], check=True)
        python = root / "venv" / "bin" / "python"
        install = [str(python), "-m", "pip", "install", "-q", "--disable-pip-version-check", "-c", str(REPO / "requirements.lock")]
        done = subprocess.run(install + [str(REPO)], capture_output=True, text=True, timeout=900)
        assert done.returncode == 0, done.stdout[-2000:] + done.stderr[-2000:]
        yield root / "venv"
    finally:
        shutil.rmtree(root, ignore_errors=True)


def test_demo_without_the_cad_extra_names_the_extra_and_writes_the_rest(core_env, tmp_path):
    out = tmp_path / "out"
    done = subprocess.run([str(core_env / "bin" / "spiral-cad"), "demo", "--out", str(out)], capture_output=True, text=True)
    assert done.returncode == 2
    assert "Traceback" not in done.stderr and "ModuleNotFoundError" not in done.stderr
    assert done.stderr.startswith("error: not written: IGES") and 'pip install "spiral_cad[cad]"' in done.stderr
    written = {p.name for p in out.iterdir()}
    assert {"highway.step", "highway.svg", "highway_stations.csv", "robot.step", "circles.svg"} <= written
    assert not any(name.endswith((".igs", ".dxf", ".png")) for name in written)
    check = subprocess.run([str(core_env / "bin" / "spiral-cad"), "check", str(out / "highway.step")], capture_output=True, text=True)
    assert check.returncode == 2 and "CAD extra" in check.stderr and "Traceback" not in check.stderr


def test_a_read_only_install_imports_and_solves(core_env):
    """Nobody may write to the package or to HOME: numba cannot cache, the kernels compile in memory."""
    code = "import spiral_cad as sc; t = sc.line_to_circle((0, 0), (1, 0), (0, 1.05), 1.0); print(round(t.theta, 12))"
    env = {"PATH": os.environ.get("PATH", ""), "HOME": "/nonexistent"}
    command = [str(core_env / "bin" / "python"), "-c", code]
    if os.geteuid() == 0:  # root writes anywhere: run as an unprivileged user instead
        if shutil.which("setpriv") is None:
            pytest.skip("needs setpriv to drop root")
        command = ["setpriv", "--reuid=nobody", "--regid=nogroup", "--clear-groups", *command]
    else:
        for folder, _, _ in os.walk(core_env):
            os.chmod(folder, 0o555)
    done = subprocess.run(command, capture_output=True, text=True, env=env, cwd="/", timeout=600)
    assert done.returncode == 0, done.stderr[-3000:]
    assert done.stdout.strip() == "0.643501108793"  # atan(3/4): the check MATH.md gives
