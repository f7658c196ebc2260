"""What a user installs: the core alone, a read-only install, the package metadata, the OCP binding.

The package is built and installed with pip, as a user would, into a fresh
environment pinned to ``requirements.lock`` (pip's cache makes this fast
after ``make test`` installed the same wheels). That environment lives in a
temporary folder every user can reach, never under the clone: a clone in a
private folder (a home directory, ``mktemp -d``) must pass too.
"""

import base64
import hashlib
import importlib.metadata
import json
import os
import pwd
import re
import shutil
import stat
import subprocess
import sys
import tempfile
from dataclasses import dataclass
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]


def _open_to_everyone(folder: Path) -> bool:
    """Every folder from ``/`` down to this one lets other users in, and programs may run from it."""
    folder = folder.resolve()
    if os.statvfs(folder).f_flag & os.ST_NOEXEC:
        return False
    return all(os.stat(p).st_mode & stat.S_IXOTH for p in (folder, *folder.parents))


def _shared_temp_dir() -> Path | None:
    """A writable temporary folder the unprivileged user of the read-only test can reach, if any."""
    for candidate in (tempfile.gettempdir(), "/var/tmp", "/tmp"):
        path = Path(candidate)
        if path.is_dir() and os.access(path, os.W_OK | os.X_OK) and _open_to_everyone(path):
            return path
    return None


def _chmod_tree(root: Path, add: int) -> None:
    """Add permission bits to every folder and file below ``root`` (execute bits only where someone has one)."""
    for folder, _, files in os.walk(root):
        os.chmod(folder, os.stat(folder).st_mode | add)
        for name in files:
            path = Path(folder, name)
            if not path.is_symlink():
                mode = os.stat(path).st_mode
                os.chmod(path, mode | (add & 0o666) | (add & 0o111 if mode & 0o111 else 0))


@dataclass
class CoreEnv:
    venv: Path
    build_log: str  # everything pip and the build backend printed while building the wheel

    @property
    def python(self) -> Path:
        return self.venv / "bin" / "python"


@pytest.fixture(scope="module")
def core_env():
    """A venv holding spiral_cad and its core dependencies only (numpy, scipy, numba)."""
    shared = _shared_temp_dir()
    root = Path(tempfile.mkdtemp(prefix="spiral-cad-core-env-", dir=shared))
    try:
        subprocess.run([sys.executable, "-m", "venv", str(root / "venv")], check=True)
        env = CoreEnv(root / "venv", "")
        pip = [str(env.python), "-m", "pip", "--disable-pip-version-check"]
        built = subprocess.run(
            pip + ["wheel", "-v", "--no-deps", "-w", str(root / "dist"), str(REPO)], capture_output=True, text=True, timeout=900
        )
        assert built.returncode == 0, built.stdout[-2000:] + built.stderr[-2000:]
        env.build_log = built.stdout + built.stderr
        wheels = [str(w) for w in (root / "dist").glob("spiral_cad-*.whl")]
        done = subprocess.run(
            pip + ["install", "-q", "-c", str(REPO / "requirements.lock"), *wheels], capture_output=True, text=True, timeout=900
        )
        assert done.returncode == 0, done.stdout[-2000:] + done.stderr[-2000:]
        if shared is not None:
            _chmod_tree(root, 0o555)  # readable by the unprivileged user whatever the umask
        yield env
    finally:
        _chmod_tree(root, 0o700)  # the read-only test took the write bits away
        shutil.rmtree(root)


def test_the_package_builds_without_warnings(core_env):
    """A newcomer's `pip install .` prints no deprecation or other warning from the build backend."""
    assert "Building wheel for spiral_cad" in core_env.build_log or "Created wheel for spiral" in core_env.build_log
    warnings = re.findall(r"^.*\b[A-Z]\w*Warning\b.*$", core_env.build_log, re.MULTILINE)
    assert not warnings, "\n".join(warnings)


def test_the_metadata_declares_the_license_as_an_spdx_expression_with_its_text(core_env):
    code = (
        "import importlib.metadata as m, json; d = m.distribution('spiral_cad'); md = d.metadata; "
        "print(json.dumps({'expression': md['License-Expression'], 'legacy': md['License'], "
        "'files': md.get_all('License-File'), 'text': d.read_text('licenses/LICENSE')}))"
    )
    done = subprocess.run([str(core_env.python), "-c", code], capture_output=True, text=True, cwd="/")
    assert done.returncode == 0, done.stderr[-2000:]
    found = json.loads(done.stdout)
    assert found["expression"] == "MIT" and found["legacy"] is None
    assert found["files"] == ["LICENSE"]
    assert found["text"] == (REPO / "LICENSE").read_text() and found["text"].startswith("MIT License")


def test_the_wheel_carries_the_web_pages_viewer(core_env):
    """``check --html`` embeds ``viewer.js``, a file beside the modules: the installed package has it."""
    code = "import importlib.resources as r; print(r.files('spiral_cad.app').joinpath('viewer.js').read_text()[:400])"
    done = subprocess.run([str(core_env.python), "-c", code], capture_output=True, text=True, cwd="/")
    assert done.returncode == 0, done.stderr[-2000:]
    assert "spiral_cad" in done.stdout and "WebGL" in done.stdout


def test_demo_without_the_cad_extra_names_the_extra_and_writes_the_rest(core_env, tmp_path):
    out = tmp_path / "out"
    spiral_cad = str(core_env.venv / "bin" / "spiral-cad")
    # the kernels as plain Python: compiling them all in this fresh environment takes a minute, and
    # test_a_read_only_install_imports_and_solves already compiles in it
    plain = {**os.environ, "NUMBA_DISABLE_JIT": "1"}
    done = subprocess.run([spiral_cad, "demo", "--out", str(out)], capture_output=True, text=True, env=plain)
    assert done.returncode == 2
    assert "Traceback" not in done.stderr and "ModuleNotFoundError" not in done.stderr
    assert done.stderr.startswith("error: not written: IGES") and 'pip install "spiral_cad[cad]"' in done.stderr
    written = {p.name for p in out.iterdir()}
    assert {"highway.step", "highway.svg", "highway_stations.csv", "robot.step", "circles.svg"} <= written
    assert not any(name.endswith((".igs", ".dxf", ".png")) for name in written)
    check = subprocess.run([spiral_cad, "check", str(out / "highway.step")], capture_output=True, text=True, env=plain)
    assert check.returncode == 2 and "CAD extra" in check.stderr and "Traceback" not in check.stderr


def _as_nobody(command: list[str]) -> list[str]:
    """``command`` run as the unprivileged user ``nobody`` (the caller is root)."""
    if shutil.which("setpriv") is None:
        pytest.skip("needs setpriv to drop root")
    try:
        nobody = pwd.getpwnam("nobody")
    except KeyError:
        pytest.skip("needs a user named nobody to drop root")
    return ["setpriv", f"--reuid={nobody.pw_uid}", f"--regid={nobody.pw_gid}", "--clear-groups", *command]


def test_a_read_only_install_imports_and_solves(core_env):
    """Nobody may write to the package or to HOME: numba cannot cache, the kernels compile in memory."""
    code = "import spiral_cad as sc; t = sc.line_to_circle((0, 0), (1, 0), (0, 1.05), 1.0); print(round(t.theta, 12))"
    env = {"PATH": os.environ.get("PATH", ""), "HOME": "/nonexistent"}
    command = [str(core_env.python), "-c", code]
    if os.geteuid() == 0:  # root writes anywhere: run as an unprivileged user instead
        if not _open_to_everyone(core_env.venv):
            pytest.skip(f"no temporary folder every user can reach (tried {tempfile.gettempdir()}, /var/tmp, /tmp)")
        command = _as_nobody(command)
        base = os.path.realpath(core_env.python)  # the interpreter the venv runs, wherever it lives
        probe = subprocess.run(_as_nobody([base, "-I", "-c", "import json"]), capture_output=True, env=env, cwd="/")
        if probe.returncode != 0:
            pytest.skip(f"an unprivileged user cannot run this Python ({base}); install it where every user can read it")
    else:
        for folder, _, _ in os.walk(core_env.venv):
            os.chmod(folder, 0o555)
    done = subprocess.run(command, capture_output=True, text=True, env=env, cwd="/", timeout=600)
    assert done.returncode == 0, done.stderr[-3000:]
    assert done.stdout.strip() == "0.643501108793"  # atan(3/4): the check MATH.md gives


def _record_hash(path: Path) -> str:
    """A file's hash as RECORD writes it (urlsafe base64 of SHA-256, no padding)."""
    digest = hashlib.sha256(path.read_bytes()).digest()
    return base64.urlsafe_b64encode(digest).rstrip(b"=").decode()


def test_the_cad_extra_s_two_ocp_distributions_install_one_ocp_the_vtk_build():
    """build123d needs cadquery-ocp-novtk, cadquery needs cadquery-ocp: both write the folder ``OCP``.

    They must be the same release, ship the same Python files (the VTK build adds the IVtk modules) and
    differ only in the compiled extension; the one on disk must be the VTK build's, which cadquery
    imports IVtk from and build123d runs on as well.
    """
    try:
        vtk, novtk = (importlib.metadata.distribution(n) for n in ("cadquery-ocp", "cadquery-ocp-novtk"))
    except importlib.metadata.PackageNotFoundError:
        pytest.skip("the CAD extra is not installed")
    assert vtk.version == novtk.version == importlib.metadata.version("cadquery-ocp-proxy")

    def ocp_files(dist):
        return {f.as_posix(): f for f in dist.files if f.parts[0] == "OCP" and f.hash is not None}

    with_vtk, without = ocp_files(vtk), ocp_files(novtk)
    assert set(without) <= set(with_vtk)
    assert {Path(p).parts[1] for p in set(with_vtk) - set(without)} == {"IVtk", "IVtkOCC", "IVtkTools", "IVtkVTK"}
    differing = {p for p in without if with_vtk[p].hash.value != without[p].hash.value}
    assert len(differing) == 1 and re.fullmatch(r"OCP/OCP\.cpython-[^/]+\.so", differing.pop()) is not None
    for name, file in with_vtk.items():
        if name.endswith(".so"):
            assert _record_hash(Path(vtk.locate_file(file))) == file.hash.value, f"{name} is not the VTK build's"
    import_both = "import cadquery, build123d, OCP.IVtkVTK; print(OCP.IVtkVTK.IVtkVTK_ShapeData.__name__)"
    done = subprocess.run([sys.executable, "-c", import_both], capture_output=True, text=True, cwd="/")
    assert done.returncode == 0 and done.stdout.strip() == "IVtkVTK_ShapeData", done.stderr[-2000:]


def test_the_numeric_core_names_no_cad_kernel_not_even_inside_a_function():
    import ast
    from pathlib import Path

    core = Path(__file__).resolve().parents[2] / "spiral_cad" / "core"
    cad = ("OCP", "build123d", "cadquery", "spiral_cad.cad")
    found = []
    for path in sorted(core.glob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Import):
                names = [alias.name for alias in node.names]
            elif isinstance(node, ast.ImportFrom):
                names = ["." * node.level + (node.module or "")]
            else:
                continue
            found += [
                f"{path.name}: {name}" for name in names if name.split(".")[0] in cad[:3] or name.startswith(("spiral_cad.cad", "..cad"))
            ]
    assert found == []
