"""The command line: demo, build (design files) and its validation."""

import copy
import json
import re
import subprocess
import sys
from pathlib import Path

import pytest

from spiral_cad.cli import DEMO_DESIGN, main
from spiral_cad.continuity import check_continuity
from spiral_cad.design import circle_chain

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"


def test_demo_writes_every_output(tmp_path, capsys):
    assert main(["demo", "--out", str(tmp_path)]) == 0
    text = capsys.readouterr().out
    names = {p.name for p in tmp_path.iterdir()}
    for design in ("highway", "circles", "robot"):
        for suffix in (".step", ".igs", ".dxf", ".svg", "_plan.png", "_curvature.png", "_continuity.txt"):
            assert design + suffix in names
        assert check_continuity(tmp_path / f"{design}.step").passes("G2")
    assert {"highway_stations.csv", "fig6.png", "bezier_vs_clothoid.png"} <= names
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
    run = subprocess.run([sys.executable, "-m", "spiral_cad.cli", "--help"], capture_output=True, text=True)
    assert run.returncode == 0
    for word in ("demo", "build", "check"):
        assert word in run.stdout
