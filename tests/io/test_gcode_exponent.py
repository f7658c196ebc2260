"""A number written with an exponent (``X1e3``) is refused by line and word, never read as ``X1`` and a word ``E3``.

LinuxCNC's ``rs274`` (a reader we did not write) refuses such a line too ("E word with no G70, G76, M66, M67 or
M68 to use it"); a printer reads it as X1 and an extrusion E3. Both G-code reading paths are checked: the in-place
rewriter (``spiral-cad g2``) and the built-in reader behind ``build --from-gcode``.
"""

from __future__ import annotations

import os
import tempfile

import pytest
from helpers import linuxcnc_rs274

from spiral_cad.app.cli import main
from spiral_cad.io import rs274
from spiral_cad.io.gcode import parse_gcode, parse_gcode_chain
from spiral_cad.io.gcode_inplace import gcode_g2


def _program(cut: str) -> str:
    """A plate contour whose fourth line is ``cut``."""
    return f"G21 G90 G17\nG0 X0 Y0 Z1\nG1 Z-1 F100\n{cut}\nG1 Y10\nG1 X0\nG1 Y0\nG0 Z5\nM2\n"


@pytest.mark.parametrize(
    ("cut", "word", "meant"),
    [("G1 X1e3 F500", "X1e3", "X1000"), ("G1 x2.5E-1 F500", "x2.5E-1", "X0.25"), ("G1 X.5e+1 Y0 F500", "X.5e+1", "X5")],
)
def test_both_readers_refuse_an_exponent_by_line_and_word(cut, word, meant):
    text = _program(cut)
    for read in (lambda: gcode_g2(text, 0.01, source="plate.nc"), lambda: parse_gcode(text, "plate.nc"),
                 lambda: parse_gcode_chain(text, "plate.nc")):  # fmt: skip
        with pytest.raises(
            ValueError, match=rf"plate\.nc line 4: {word.replace('.', '[.]').replace('+', '[+]')} is a number with an exponent"
        ) as info:
            read()
        assert f"write {meant}" in str(info.value)


def test_printer_dialect_refuses_an_exponent_but_reads_extrusion():
    """E is extrusion on a printer: ``X10 E3`` (a word E) is read as it is; ``X1e3`` is refused all the same."""
    printer = "G21 G90\nG92 E0\nG1 Z0.2 F600\nG1 X10 Y0 E0.5 F1500\nG1 X10 Y10 E1\nM2\n"
    assert gcode_g2(printer, 0.01, dialect="generic").text.splitlines()[-5:] == printer.splitlines()[-5:]
    with pytest.raises(ValueError, match=r"line 4: X10e3 is a number with an exponent"):
        gcode_g2(printer.replace("X10 Y0", "X10e3 Y0"), 0.01, dialect="generic")


def test_an_exponent_in_a_comment_is_no_word():
    text = _program("G1 X20 F500 (scale 1e3) ; 2E5 too")
    assert [r.status for r in gcode_g2(text, 0.01).runs] == ["G2"]
    assert parse_gcode(text).points.shape[0] > 4


@pytest.mark.skipif(rs274.rs274_executable() is None, reason="LinuxCNC's rs274 is not installed")
def test_rs274_refuses_the_same_line():
    with tempfile.TemporaryDirectory() as folder:
        path = os.path.join(folder, "p.ngc")
        with open(path, "w") as f:
            f.write(_program("G1 X1e3 F500"))
        done = linuxcnc_rs274(path, os.path.join(folder, "out"), cwd=folder)
    assert "E word" in done.stderr + done.stdout


@pytest.mark.parametrize("verb", ["g2", "build"])
def test_the_command_line_says_error_and_exits_2(tmp_path, capsys, verb):
    program = tmp_path / "plate.nc"
    program.write_text(_program("G1 X1e3 F500"))
    if verb == "g2":
        args = ["g2", str(program), "--max-deviation", "0.01", "-o", str(tmp_path / "out.nc")]
    else:
        args = ["build", "--from-gcode", str(program), "--max-deviation", "0.01", "--out", str(tmp_path / "out"), "--no-plots"]
    assert main(args) == 2
    err = capsys.readouterr().err
    assert "error:" in err and "line 4: X1e3 is a number with an exponent" in err and "Traceback" not in err
    assert not (tmp_path / "out.nc").exists()
