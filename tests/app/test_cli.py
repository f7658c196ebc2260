"""The command line: demo, build (design files) and its validation."""

import copy
import json
import re
import subprocess
import sys
from pathlib import Path

import pytest
from helpers import assert_plain_csv

from spiral_cad.app.cli import DEMO_DESIGN, main
from spiral_cad.cad.continuity import check_continuity
from spiral_cad.design import circle_chain

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def test_demo_writes_every_output(tmp_path, capsys):
    assert main(["demo", "--out", str(tmp_path)]) == 0
    text = capsys.readouterr().out
    names = {p.name for p in tmp_path.iterdir()}
    # "wrote N files" counts what is there and what the progress lines list
    (count,) = map(int, re.findall(r"wrote (\d+) files", text))
    progress = re.findall(r"^  \S.* → (.*?)(?: \(\d+\.\d s\))?$", text, re.MULTILINE)
    listed = sum(len(files.split(", ")) for files in progress)
    assert count == listed == len(names) == 35
    assert "robot.ngc" in names  # the robot path's program
    from spiral_cad.app.gallery import GALLERY
    from spiral_cad.cad.faces import check_faces

    for part in GALLERY:  # the gallery's G2 parts, as OCCT reads them back
        report = check_faces(tmp_path / f"gallery_{part}.step")
        assert report.passes("G2") and report.counts["sharp"] == 0, report.describe()
    for csv_file in ("highway_stations.csv", "highway_criteria.csv", "highway_profile.csv"):
        assert_plain_csv(tmp_path / csv_file)
    assert "np.float64" not in text
    for design in ("highway", "circles", "robot"):
        for suffix in (".step", ".igs", ".dxf", ".svg", "_plan.png", "_curvature.png", "_continuity.txt"):
            assert design + suffix in names
        assert check_continuity(tmp_path / f"{design}.step").passes("G2")
    assert {
        "highway_stations.csv",
        "highway_profile.csv",
        "highway_3d.step",
        "highway.xml",
        "highway.ifc",
        "fig6.png",
        "bezier_vs_clothoid.png",
    } <= names
    assert "circle in circle (5th case)" in text and "G2" in text
    circles = [(c["center"], c["radius"]) for c in DEMO_DESIGN["designs"][1]["circles"]]
    kinds = {t.kind for t in circle_chain(circles).transitions}
    assert kinds == {"circle-circle-nested", "C", "S"}


def test_build_example_design_and_check_it(tmp_path):
    assert main(["build", str(EXAMPLES / "design.json"), "--out", str(tmp_path)]) == 0
    for name in ("rail", "loop", "cnc", "ramp"):
        assert main(["check", str(tmp_path / f"{name}.step"), "--require", "G2"]) == 0
    header = (tmp_path / "rail_stations.csv").read_text().splitlines()[0]
    assert "TS [m]" in header and "ST [m]" in header


def bad(path, edit):
    design = copy.deepcopy(DEMO_DESIGN)
    edit(design)
    path.write_text(json.dumps(design))
    return path


@pytest.mark.parametrize(
    "edit, message",
    [
        (lambda d: d.update(units="furlong"), "units: must be one of"),
        (lambda d: d["designs"][0].update(radii=[450, -400, 600]), r"designs\[0\] \(highway\).radii\[1\]: must be positive; got -400"),
        (lambda d: d["designs"][0].update(spiral_angles_deg=[8, 95, 6]), r"spiral_angles_deg\[1\]: spiral angles are in degrees .* got 95"),
        (lambda d: d["designs"][0].pop("pis"), r"designs\[0\] \(highway\): missing field\(s\) pis"),
        (lambda d: d["designs"][1]["circles"][2].update(radius="40"), r"circles\[2\].radius: must be a finite number; got '40'"),
        (lambda d: d["designs"][2].update(max_curvature=0.01), r"designs\[2\] \(robot\): .*corner"),
        (lambda d: d["designs"][2].update(colour="red"), r"unknown field\(s\) colour"),
        (lambda d: d["designs"][1].update(type="spline"), r"designs\[1\].type: must be one of"),
        (lambda d: d["designs"][0].update(pis=[[0, 0], [600, 120], [1150, -80], [1700, 260], [2300, "x"]]), r"pis\[4\]\[1\]"),
        (
            lambda d: d["designs"][0].update(pis=[[1000 * k, 250 * (k % 2)] for k in range(20_001)]),
            r"designs\[0\] \(highway\).pis: 20,001 points; at most 20,000 per design",
        ),
        (
            lambda d: d["designs"][0].update(profile={"pvis": [[k, 0] for k in range(2_001)], "curve_lengths": 0.1}),
            r"designs\[0\] \(highway\).profile.pvis: 2,001 points; at most 2,000 per design",
        ),
    ],
)
def test_bad_designs_name_the_field_and_write_nothing(tmp_path, capsys, edit, message):
    out = tmp_path / "out"
    assert main(["build", str(bad(tmp_path / "d.json", edit)), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert re.search(message, err), err
    assert not out.exists() or not any(out.iterdir())


def test_malformed_json_names_the_line(tmp_path, capsys):
    path = tmp_path / "d.json"
    path.write_text('{"units": "m",\n "designs": [}')
    assert main(["build", str(path), "--out", str(tmp_path / "o")]) == 2
    assert "malformed JSON at line 2" in capsys.readouterr().err


def test_help_lists_the_commands():
    run = subprocess.run([sys.executable, "-m", "spiral_cad.app.cli", "--help"], capture_output=True, text=True)
    assert run.returncode == 0
    for word in ("demo", "build", "check", "g2"):
        assert word in run.stdout


# ------------------------------------------------------------------ manners


LAUNCH = """
import os, signal, sys

class InterruptOnImport:  # Ctrl-C exactly while the package imports numpy and numba
    def find_spec(self, name, path=None, target=None):
        if name == os.environ.get("INTERRUPT_ON_IMPORT"):
            os.kill(os.getpid(), signal.SIGINT)

sys.meta_path.insert(0, InterruptOnImport())
from spiral_cad_launcher import main
sys.exit(main())
"""


def launch(args: list[str], interrupt_on_import: str = "") -> subprocess.Popen:
    """``spiral-cad`` as its console script starts it, with Ctrl-C delivered as in a terminal."""
    import os
    import signal

    env = {**os.environ, "INTERRUPT_ON_IMPORT": interrupt_on_import}
    return subprocess.Popen([sys.executable, "-c", LAUNCH, *args], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            env=env, preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))  # fmt: skip


@pytest.mark.parametrize("moment", ["importing spiral_cad", "building and writing"])
def test_ctrl_c_at_any_moment_is_one_line_and_130(tmp_path, moment):
    """Ctrl-C during the long imports once printed a traceback or 'internal error (ImportError …)'."""
    import signal

    out = tmp_path / "out"
    out.mkdir()
    (out / "rail.step").write_text("from before")
    args = ["build", str(EXAMPLES / "design.json"), "--out", str(out)]
    if moment == "importing spiral_cad":
        process = launch(args, interrupt_on_import="spiral_cad.core.chain")
    else:
        process = launch(args)
        for line in process.stdout:
            if line.startswith("built "):
                break
        process.send_signal(signal.SIGINT)
    _, err = process.communicate(timeout=120)
    assert process.returncode == 130, err
    assert len(err.splitlines()) == 1 and err.startswith("error: interrupted"), err
    assert [p.name for p in out.iterdir()] == ["rail.step"] and (out / "rail.step").read_text() == "from before"


def test_a_build_whose_output_pipe_closes_ends_with_141_and_changes_nothing(tmp_path):
    script = Path(sys.executable).parent / "spiral-cad"
    if not script.exists():
        pytest.skip("spiral-cad script not installed next to this interpreter")
    out = tmp_path / "out"
    process = subprocess.Popen([str(script), "build", str(EXAMPLES / "design.json"), "--out", str(out), "--no-plots"],
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE)  # fmt: skip
    process.stdout.close()  # `| head -0`: the build's first line finds no reader
    err = process.stderr.read()
    assert process.wait(timeout=300) == 141 and err == b""
    assert not out.exists()


def test_an_interrupt_a_library_turned_into_another_exception_is_still_an_interrupt(tmp_path, capsys, monkeypatch):
    """OCP's modules turn Ctrl-C during their import into ImportError('initialization failed')."""
    import os
    import signal
    import time

    from spiral_cad.app import designfile

    def import_interrupted(*args, **kwargs):
        try:
            os.kill(os.getpid(), signal.SIGINT)
            time.sleep(5)
        except KeyboardInterrupt:
            raise ImportError("initialization failed") from None

    monkeypatch.setattr(designfile, "_write_design", import_interrupted)
    assert main(["build", str(EXAMPLES / "design.json"), "--out", str(tmp_path / "out"), "--no-plots"]) == 130
    assert capsys.readouterr().err == "error: interrupted\n"
    assert not (tmp_path / "out").exists()


class _InterruptedWhileCollected:
    """An object whose ``__del__`` gets the Ctrl-C: the interpreter prints "Exception ignored" and goes on."""

    def __del__(self):
        import os
        import signal

        os.kill(os.getpid(), signal.SIGINT)  # its handler runs inside this call, its KeyboardInterrupt is swallowed


@pytest.mark.filterwarnings("ignore::pytest.PytestUnraisableExceptionWarning")
def test_an_interrupt_the_interpreter_swallowed_still_stops_the_build_with_130(tmp_path, capsys, monkeypatch):
    """dask's Future.__del__ got a Ctrl-C this way: the run went on to the end and exited 0."""
    import gc

    from spiral_cad.app import designfile

    real = designfile._write_design

    def collected_then_written(*args, **kwargs):
        _InterruptedWhileCollected()
        gc.collect()
        return real(*args, **kwargs)

    monkeypatch.setattr(designfile, "_write_design", collected_then_written)
    assert main(["build", str(EXAMPLES / "design.json"), "--out", str(tmp_path / "out"), "--no-plots"]) == 130
    assert capsys.readouterr().err == f"error: interrupted; nothing in {tmp_path / 'out'}/ was changed\n"
    assert not (tmp_path / "out").exists()


def test_warnings_never_reach_the_terminal(tmp_path, capsys, monkeypatch, recwarn):
    import warnings

    from spiral_cad.app import designfile

    summary = designfile.summary

    def noisy_summary(*args):
        warnings.warn("overflow encountered in multiply", RuntimeWarning, stacklevel=2)
        return summary(*args)

    monkeypatch.setattr(designfile, "summary", noisy_summary)
    assert main(["build", str(EXAMPLES / "design.json"), "--out", str(tmp_path), "--no-plots"]) == 0
    assert capsys.readouterr().err == "" and len(recwarn) == 0  # not shown, and not left for anyone to show
