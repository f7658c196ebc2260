"""A program that says neither G20 nor G21 (GrblGru writes none) is not rewritten blind: its feed moves are kept as they
are and the report names the first one and the way out (``units=``, ``--units``); with a unit given, it is made G2."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

from spiral_cad.io.gcode_inplace import gcode_g2

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
import rs274_judge  # noqa: E402

#: A GrblGru-style contour: lowercase words, feed before the axes, no unit code.
UNITLESS = """( Created by GrblGru )
G1 F200 Z25
G1 G90 F100
F2000 x0.000 y-53.000 z5.000
F2000 x0.000 y-53.000 z0.000
G90 F500
x0.000 y-53.000 z-1.700
x80.000 y-53.000 z-1.700
x80.000 y0.000 z-1.700
x0.000 y0.000 z-1.700
x0.000 y-53.000 z-1.700
F2000 z5.000
M5
M2
"""


def test_a_program_without_a_unit_is_kept_and_named():
    report = gcode_g2(UNITLESS, 0.01, source="cut.nc")
    assert report.runs == [] and report.text.endswith(UNITLESS)
    (note,) = [n for n in report.notes if "G20 or G21" in n]
    assert "first on line 2" in note and "units" in note


@pytest.mark.skipif(not rs274_judge.available(), reason="LinuxCNC's rs274 is not installed")
def test_with_its_unit_given_it_is_made_g2_and_judged_by_rs274():
    report = gcode_g2(UNITLESS, 0.01, source="cut.nc", units="mm")
    assert [r.status for r in report.runs] == ["G2"] and not [n for n in report.notes if "G20 or G21" in n]
    verdict = rs274_judge.judge(UNITLESS, report.text, 0.01)
    assert verdict.passed, verdict.reasons
