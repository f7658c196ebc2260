"""NAME.ngc from design files and `build --from-gcode`: our own program read back is the same chain."""

import json

import numpy as np
import pytest

from spiral_cad.app.cli import main
from spiral_cad.app.designfile import DesignError, build, write
from spiral_cad.io.gcode import read_gcode_chain

ROBOT = {"name": "robot", "type": "rounded_polyline", "max_curvature": 0.3,
         "points": (np.array([[0, 0], [1.0, 0.1], [1.4, 0.9], [2.4, 1.0], [2.6, 0.2], [3.6, 0.4]]) * 20).tolist()}  # fmt: skip
CIRCLES = {"name": "circles", "type": "circle_chain", "circles": [{"center": [0, 0], "radius": 60}, {"center": [150, -10], "radius": 40}]}


def test_a_path_gets_its_program_and_any_chain_on_request(tmp_path):
    design = {"units": "mm", "designs": [ROBOT, {**CIRCLES, "gcode_out": {"dialect": "generic", "feed": 500, "arc_tolerance": 0.01}},
                                         {**CIRCLES, "name": "plain"}]}  # fmt: skip
    units, built = build(design)
    written = write(built, tmp_path, units, progress=lambda line: None, plots=False)
    names = {p.name for p in written.files}
    assert {"robot.ngc", "circles.ngc"} <= names and "plain.ngc" not in names
    robot = (tmp_path / "robot.ngc").read_text()
    assert "dialect linuxcnc" in robot and robot.count("\nG5 ") == 8
    circles = (tmp_path / "circles.ngc").read_text()
    assert "dialect generic" in circles and "\nG5 " not in circles and "\nF500\n" in circles
    assert "biarcs within arc tolerance 0.01 mm" in circles
    assert read_gcode_chain(tmp_path / "robot.ngc").length == pytest.approx(built[0].chain.length, abs=1e-9)


def test_gcode_out_options_are_validated_by_name():
    for options, message in (({"dialect": "grbl"}, r"gcode_out.dialect"), ({"feed": -1}, r"gcode_out.feed"),
                             ({"speed": 1}, r"gcode_out: unknown field\(s\) speed")):  # fmt: skip
        with pytest.raises(DesignError, match=message):
            build({"units": "mm", "designs": [{**CIRCLES, "gcode_out": options}]})


def test_build_from_gcode_reads_our_program_back_as_the_same_chain(tmp_path, capsys):
    design = tmp_path / "design.json"
    design.write_text(json.dumps({"units": "mm", "designs": [ROBOT]}))
    assert main(["build", str(design), "--out", str(tmp_path / "first"), "--no-plots"]) == 0
    program = tmp_path / "first" / "robot.ngc"
    assert main(["build", "--from-gcode", str(program), "--max-deviation", "0.1", "--out", str(tmp_path / "again"), "--no-plots"]) == 0
    text = capsys.readouterr().out
    assert "robot          rounded_polyline" in text and "G2 (1 wire of 13 edges)" in text
    # the rounded program, written again from the chain read back: the same program
    assert (tmp_path / "again" / "robot.ngc").read_text() == program.read_text()
    first, again = read_gcode_chain(program), read_gcode_chain(tmp_path / "again" / "robot.ngc")
    assert np.array_equal(first.rows.geometry, again.rows.geometry)
