"""An inch program made G2 in place within 0.0005 in, judged by LinuxCNC's rs274 (a reader we did not write).

pcb2gcode mills slots as obrounds of 0.004 in radius in inch programs. rs274 prints 4 decimals in the program's
unit (2.5 µm in inch, a tenth of this bound): the judge allows that printing (``rs274_judge.PRINTED``), and this
checks the rewrite is within the bound by its own measure and by the judge's.
"""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

from spiral_cad.io.gcode_inplace import gcode_g2

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
import rs274_judge  # noqa: E402

#: A pcb2gcode-style slot (its last pass): two half circles of radius 0.00396 in joined by 0.0787 in lines.
SLOT = """G94 G20 G91.1 G90
G0 X-3.81104 Y-2.66535 Z0.08
G1 Z-0.06299 F50
G2 X-3.81896 Y-2.66535 I-0.00396 J0 F100
G1 X-3.81896 Y-2.58665
G2 X-3.81104 Y-2.58665 I0.00396 J0
G1 X-3.81104 Y-2.66535
G1 Z0.08 F50
M2
"""


@pytest.mark.skipif(not rs274_judge.available(), reason="LinuxCNC's rs274 is not installed")
def test_an_inch_slot_comes_back_within_the_bound_by_rs274():
    report = gcode_g2(SLOT, 0.0005, source="slot.ngc")
    assert report.units == "in" and [r.status for r in report.runs] == ["G2"]
    assert 0.0 < report.deviation <= 0.0005
    verdict = rs274_judge.judge(SLOT, report.text, 0.0005)
    assert verdict.passed, verdict.reasons
    # the judge sees the paths through rs274's 4 printed decimals: never farther apart than the bound and that printing
    assert verdict.distance <= 0.0005 + 0.0005 / 20 + rs274_judge.PRINTED


def _arcs(tail: str) -> str:
    return f"G20 G90 G17 G94\nG0 X0 Y1 Z0.1\nG1 Z-0.1 F10\nG1 X1 Y1 F20\n{tail}G1 X2 Y1\nG0 Z0.1\nM2\n"


@pytest.mark.skipif(not rs274_judge.available(), reason="LinuxCNC's rs274 is not installed")
def test_the_judge_reads_an_arc_shorter_than_the_printing_as_short_and_a_full_circle_as_full():
    """rs274 prints 4 decimals: an arc of 0.00005 in prints with its end on its start, as a full circle does; the judge
    tells them apart by the line's own words (biarcs for grbl hold such arcs)."""
    tiny = _arcs("G3 X0.99995 Y0.9999999988 I0 J-1\nG1 X1 Y1\n")
    assert rs274_judge.judge(tiny, _arcs(""), 0.0005).passed
    full = _arcs("G3 X1 Y1 I0 J-1\n")
    assert not rs274_judge.judge(full, _arcs(""), 0.0005).passed  # a whole turn of radius 1 is no short arc
