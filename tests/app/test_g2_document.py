"""``spiral-cad g2`` and ``make_document_g2``: a CNC program comes back as the same program, its cuts made G2.

The judge is LinuxCNC's own interpreter ``rs274`` (``tests/rs274_judge.py``, which shares no code with the
rewriter): same rapids in the same order, same machine calls, only the input's feeds, and the cutting
path within the bound both ways.
"""

from __future__ import annotations

import math
import os
import re
import sys
from pathlib import Path

import numpy as np
import pytest

from spiral_cad.app.cli import main
from spiral_cad.app.g2_document import make_document_g2, rewriter_for
from spiral_cad.io.gcode_inplace import gcode_g2

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
import rs274_judge  # noqa: E402

DATA = Path(__file__).resolve().parents[1] / "data" / "gcode"
needs_rs274 = pytest.mark.skipif(not rs274_judge.available(), reason="LinuxCNC's rs274 is not installed (make rs274)")

#: The issue's 14-line plate contour: approach, plunge at F200, four lines and four G3 corners at F600, retract.
CONTOUR = """G21 G90 G17
G0 Z5
G0 X5 Y0
G1 Z-1 F200
G1 X55 Y0 F600
G3 X60 Y5 I0 J5
G1 X60 Y35
G3 X55 Y40 I-5 J0
G1 X5 Y40
G3 X0 Y35 I0 J-5
G1 X0 Y5
G3 X5 Y0 I5 J0
G0 Z5
M30
"""
CUT = re.compile(r"^\s*G[123]\s+X", re.I)


def _kept_in_order(before: str, after: str) -> bool:
    """Every line of ``before`` that is not a cutting move stands in ``after``, verbatim and in order."""
    rest = iter(after.splitlines())
    return all(any(line == other for other in rest) for line in before.splitlines() if not CUT.match(line) or "Z" in line)


@pytest.mark.parametrize("dialect", ["linuxcnc", "generic"])
def test_contour_comes_back_as_one_safe_program(dialect):
    report = gcode_g2(CONTOUR, 0.01, source="contour.nc", dialect=dialect)
    assert [r.status for r in report.runs] == ["G2"] and report.runs[0].joints_changed >= 7
    assert 0.0 < report.deviation <= 0.01
    text = report.text
    assert _kept_in_order(CONTOUR, text)
    assert "0.01 mm" in text.splitlines()[0] and "measured" in text.splitlines()[0]
    # the G0 lines are the input's, and no feed the input does not use
    assert [l for l in text.splitlines() if l.startswith("G0")] == [l for l in CONTOUR.splitlines() if l.startswith("G0")]
    assert set(re.findall(r"F([\d.]+)", text)) <= {"200", "600"}
    assert ("G5 " in text) == (dialect == "linuxcnc")


@needs_rs274
@pytest.mark.parametrize("dialect", ["linuxcnc", "generic"])
def test_contour_judged_by_rs274(dialect):
    report = gcode_g2(CONTOUR, 0.01, dialect=dialect)
    verdict = rs274_judge.judge(CONTOUR, report.text, 0.01)
    assert verdict.passed, verdict.reasons
    assert verdict.distance > 0.005  # the path did change (the transitions use the bound)
    assert verdict.feed_moves[1] > verdict.feed_moves[0]


#: Programs whose rewriting takes more than a few seconds.
SLOW_PROGRAMS = {"linuxcnc_arcspiral.ngc"}


@needs_rs274
@pytest.mark.parametrize(
    "name", [pytest.param(p.name, marks=[pytest.mark.slow] if p.name in SLOW_PROGRAMS else []) for p in sorted(DATA.glob("*.ngc"))]
)
def test_linuxcnc_programs_judged_by_rs274(name):
    path = DATA / name
    text = path.read_text()
    report = gcode_g2(text, 0.01, source=name)
    verdict = rs274_judge.judge(text, report.text, 0.01, folder=str(DATA))
    assert verdict.passed, (verdict.reasons, report.lines())
    if name in ("linuxcnc_3dtest.ngc", "linuxcnc_comp.ngc"):  # plain programs: their cuts are rewritten
        assert any(r.status == "G2" for r in report.runs)
    if name == "linuxcnc_leto-xy.ngc":  # a weighted order-3 NURBS block, made G2
        assert [(r.status, r.nurbs) for r in report.runs] == [("G2", True)]


@needs_rs274
def test_judge_sees_a_broken_program():
    """The judge fails a program with a rapid at cutting depth and a path beyond the bound (what build wrote)."""
    broken = CONTOUR.replace("G1 X55 Y0 F600", "G0 X55 Y0\nG1 F600").replace("G1 X60 Y35", "G1 X60.1 Y35")
    verdict = rs274_judge.judge(CONTOUR, broken, 0.01)
    assert not verdict.passed and any("rapids" in r for r in verdict.reasons)


def test_what_is_kept_and_why():
    text = "\n".join([
        "G20 G90 G17", "G0 X0 Y0 Z1", "G1 Z0 F10",
        "G1 X1 Y0", "G1 X2 Y0 A5", "G1 X3 Y1", "G1 X4 Y1 F20", "G1 X4 Y2", "G91", "G1 X1", "G1 Y1", "M2",
    ])  # fmt: skip
    report = gcode_g2(text, 0.001, source="t.ngc")
    assert any("rotary axis" in n for n in report.notes)
    assert "2 feed move(s) in incremental mode (G91) kept as they are (line 10, 11)" in report.notes
    assert report.units == "in"
    out = report.text.splitlines()
    for line in ("G1 X2 Y0 A5", "G91", "G1 X1", "G1 Y1", "G1 Z0 F10"):
        assert line in out
    # a feed change starts a new run: the F20 moves keep F20, the F10 ones F10
    assert set(re.findall(r"F(\d+)", report.text)) <= {"10", "20"}


def test_a_feed_move_with_a_word_a_cut_does_not_have_is_kept_and_named():
    # FreeCAD's grbl post writes K0.000 on XY arcs (LinuxCNC refuses it; the line is kept as it is, and said)
    text = "\n".join(["G21 G17 G90", "G0 X0 Y0 Z5", "G1 Z-1 F100", "G1 X10 Y0", "G1 X10 Y10", "G3 X0 Y20 I-10 J0 K0.000",
                      "G1 X-10 Y20", "G1 X-10 Y30", "G0 Z5", "M2"])  # fmt: skip
    report = gcode_g2(text, 0.01, source="k.ngc")
    assert "G3 X0 Y20 I-10 J0 K0.000" in report.text.splitlines()
    assert any(n.startswith("1 feed move(s) with the word(s) K kept as they are (line 6)") and "LinuxCNC" in n for n in report.notes)
    assert [r.status for r in report.runs] == ["G2", "G2"]


def test_parameters_stop_the_rewrite_by_line():
    report = gcode_g2("G21\n#1=5\nG0 X0 Y0\nG1 X#1 F100\nM2\n", 0.01)
    assert report.runs == [] and "line 2" in report.notes[0]
    assert report.text.endswith("G21\n#1=5\nG0 X0 Y0\nG1 X#1 F100\nM2\n")


def test_cli_writes_the_program_and_reports(tmp_path, capsys):
    src = tmp_path / "contour.nc"
    src.write_text(CONTOUR)
    assert main(["g2", str(src), "--max-deviation", "0.01", "-o", str(tmp_path / "out.ngc")]) == 0
    said = capsys.readouterr().out
    assert "lines 5-12: 8 moves made G2" in said and "joints changed" in said
    assert (tmp_path / "out.ngc").read_text().count("\nG0 ") == 3


def test_cli_exits_1_on_a_split_unless_allowed_and_unknown_kinds(tmp_path, capsys):
    src = tmp_path / "back.nc"  # a cut that goes straight back along itself: split there, left a corner
    src.write_text("G21\nG0 X0 Y0 Z0\nG1 X10 Y0 F100\nG3 X10 Y10 I0 J5\nG1 X0 Y10\nG1 X10 Y10\nM2\n")
    out = tmp_path / "back_g2.nc"
    assert main(["g2", str(src), "--max-deviation", "0.01", "-o", str(out)]) == 1  # written, but a split is told by the exit
    assert "FAIL: 1 left below G2" in capsys.readouterr().out and out.read_text().count("\nG0 ") == 1
    assert main(["g2", str(src), "--max-deviation", "0.01", "-o", str(out), "--allow-splits"]) == 0
    capsys.readouterr()
    assert main(["g2", str(tmp_path / "part.3mf"), "--max-deviation", "0.01", "-o", str(tmp_path / "p.3mf")]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: ") and ".3mf" in err and ".step" in err and ".xodr" in err  # the kinds made G2 in place are listed
    with pytest.raises(ValueError, match="no document kind"):
        rewriter_for("part.3mf")
    assert rewriter_for("PART.STP") is rewriter_for("part.step") and rewriter_for("p.igs") is rewriter_for("p.iges")
    with pytest.raises(ValueError, match="is the input"):
        make_document_g2(src, src, 0.01)
    assert main(["g2", str(src), "--max-deviation", "0.01", "-o", str(tmp_path / "no" / "such" / "out.nc")]) == 2
    assert capsys.readouterr().err.startswith("error: the output's folder ") and not (tmp_path / "no").exists()


def test_a_line_moving_by_the_modal_code_keeps_its_motion():
    """A rewritten run may end with another motion code than the input's: a later line that moves by the
    modal code gets the input's code in front (else it would run as the output's last code)."""
    text = "G21 G90 G17\nG0 X0 Y0 Z0\nG1 X10 Y0 F100\nG3 X10 Y10 I0 J5\nX10 Y20 I0 J5 M8\nM2\n"
    report = gcode_g2(text, 0.01)
    assert report.runs[0].status == "G2"
    assert "G3 X10 Y20 I0 J5 M8" in report.text.splitlines()
    if rs274_judge.available():
        verdict = rs274_judge.judge(text, report.text, 0.01)
        assert verdict.passed, verdict.reasons


def test_a_contour_entered_inside_a_side_is_made_g2_all_round():
    """Entered half-way along a side, the closed contour is made G2 at all 8 joints and still starts there."""
    text = CONTOUR.replace("G0 X5 Y0", "G0 X30 Y0").replace("G3 X5 Y0 I5 J0", "G3 X5 Y0 I5 J0\nG1 X30 Y0")
    report = gcode_g2(text, 0.01)
    assert report.runs[0].status == "G2" and report.runs[0].joints_changed == 8
    lines = report.text.splitlines()
    cut = [l for l in lines if re.match(r"G[1235] X", l)]
    assert cut[-1] == "G1 X30 Y0" and cut[0].startswith("G1 X") and cut[0].endswith(" Y0")
    if rs274_judge.available():
        verdict = rs274_judge.judge(text, report.text, 0.01)
        assert verdict.passed, verdict.reasons


NURBS = """G21 G90 G17 G94
G0 X10 Y0 Z1
G1 Z0 F100
G5.2 P1 L4
    X10 Y0 P1
    X20 Y20 P1
    X12 Y8 P1
    X10 Y20 P1
G5.3
G1 X30 Y20 F300
G2 X40 Y10 I0 J-10
G1 X40 Y0
G0 Z1
M2
"""


@pytest.mark.parametrize("dialect", ["linuxcnc", "generic"])
def test_a_nurbs_block_is_made_g2_and_the_cuts_after_it_too(dialect):
    """A G5.2 … G5.3 block (LinuxCNC's NURBS, adapted from its nc_files/nurbs/G5/trident-xy.ngc) is made G2 within
    the bound from its first point to its last, at its own feed; the cuts after it are made G2 too. The judge samples
    the input's NURBS from its words, as LinuxCNC defines it, and the output's G5 cubics from theirs."""
    report = gcode_g2(NURBS, 0.01, dialect=dialect)
    assert [(r.status, r.nurbs) for r in report.runs] == [("G2", True), ("G2", False)]
    assert report.runs[0].first == 4 and report.runs[0].last == 9 and 0.0 < report.runs[0].deviation <= 0.01
    text = report.text
    assert "G5.2" not in text and "G5.3" not in text and ("G5 " in text) == (dialect == "linuxcnc")
    assert set(re.findall(r"F([\d.]+)", text)) <= {"100", "300"}
    assert "NURBS block made G2" in "\n".join(report.lines())
    if rs274_judge.available():
        verdict = rs274_judge.judge(NURBS, text, 0.01)
        assert verdict.passed, verdict.reasons
        assert verdict.distance > 1e-4  # the path did change


def test_a_nurbs_block_the_reader_does_not_take_is_kept_and_the_cuts_after_it_are_rewritten():
    """A NURBS block with a comment inside is kept as it is (named); the tool ends on its last control point."""
    commented = NURBS.replace("X20 Y20 P1", "X20 Y20 P1 (a comment)")
    report = gcode_g2(commented, 0.01)
    assert "\n".join(commented.splitlines()[3:9]) in report.text
    assert [r.status for r in report.runs] == ["kept", "G2"] and "comment" in report.runs[0].reason
    if rs274_judge.available():
        verdict = rs274_judge.judge(commented, report.text, 0.01)
        assert verdict.passed, verdict.reasons


#: A run whose far corners float64 cannot round within 1e-8 mm at a million millimetres, its near ones it can.
FAR = """G21 G90 G17
G0 X0 Y0
G1 Z-1 F100
G1 X10 Y0 F600
G1 X10 Y10
G1 X20 Y10
G1 X20 Y20
G1 X1000000 Y20
G1 X1000000 Y30
G1 X1000010 Y30
G0 Z5
M2
"""


def test_a_refused_joint_splits_the_run_and_the_rest_is_made_g2():
    """Where make_g2 refuses a joint, the run is split there: that joint is left as it was (named with its line,
    point and reason), and the parts on either side are made G2 on their own."""
    report = gcode_g2(FAR, 1e-8)
    (run,) = report.runs
    assert run.status == "G2" and run.joints_changed >= 1 and len(run.refused) >= 2
    assert any(r.startswith("line 8 (X1000000 Y20): joint") for r in run.refused)
    assert any(r.startswith("line 9 (X1000000 Y30): joint") for r in run.refused)
    assert all("cannot be made G2" in r for r in run.refused)
    text = report.text.splitlines()
    assert "G1 X1000000 Y30" in text and "G1 X1000010 Y30" in text  # the refused corners' moves as they were
    assert text.index("G1 X1000000 Y30") < text.index("G1 X1000010 Y30")
    assert any(line.startswith("G5 ") for line in text)  # the near corners rounded
    assert "G1 X10 Y0 F600" not in text
    assert run in report.below_g2
    shown = "\n".join(report.lines())
    assert "refused joint(s) left as they were" in shown and "joint at line 9 (X1000000 Y30)" in shown
    assert f"1 of 1 runs made G2 within 1e-08 mm, {len(run.refused)} joint(s) in them refused and left as they were" in shown
    # the near part's ends are the input's: its last point is the refused joint's
    i = text.index("G1 X1000000 Y30")
    assert "X1000000 Y20" in text[i - 1]


@pytest.mark.skipif(
    len(os.sched_getaffinity(0)) < 2 if hasattr(os, "sched_getaffinity") else True, reason="one core: no processes to share"
)
def test_a_long_programs_runs_made_in_several_processes_come_back_as_made_in_one(monkeypatch):
    """Runs made G2 in forked processes (a long program) give the very program and report one process gives: NURBS
    blocks, feeds and kept lines in their places."""
    import spiral_cad.io.gcode_inplace as inplace

    program = "\n".join([CONTOUR, NURBS.replace("M2", ""), FAR.replace("G21 G90 G17", ""), CONTOUR.replace("G21 G90 G17", "")])
    apart = []
    made_apart = inplace._Rewriter.made_apart
    monkeypatch.setattr(inplace._Rewriter, "made_apart", lambda self: apart.append(dict(made_apart(self))) or dict(apart[-1]))
    monkeypatch.setattr(inplace, "PARALLEL_MOVES", 0)
    forked = gcode_g2(program, 0.01, source="long.ngc")
    monkeypatch.setattr(inplace, "PARALLEL_MOVES", 10**12)
    alone = gcode_g2(program, 0.01, source="long.ngc")
    assert len(apart[0]) == sum(not r.nurbs for r in forked.runs) >= 4 and apart[1] == {}
    assert forked.text == alone.text and forked.lines() == alone.lines()
    assert any(r.nurbs and r.status == "G2" for r in forked.runs) and sum(r.status == "G2" for r in forked.runs) >= 5


def test_another_kind_registers_by_suffix(tmp_path, monkeypatch):
    """The suffix table takes the rewriters of other kinds (DXF and LandXML come next) without touching the verb."""
    from spiral_cad.app import g2_document

    monkeypatch.setattr(g2_document, "REWRITERS", dict(g2_document.REWRITERS))
    seen = []

    class Report:
        below_g2: list = []

        def lines(self):
            return ["fake: 1 path made G2"]

    g2_document.register_rewriter((".FAKE",), lambda src, dst, d, **o: seen.append((Path(src).name, d, o)) or Report())
    (tmp_path / "a.fake").write_text("x")
    assert main(["g2", str(tmp_path / "a.fake"), "--max-deviation", "0.5", "-o", str(tmp_path / "b.fake")]) == 0
    assert seen == [("a.fake", 0.5, {})]
    with pytest.raises(ValueError, match="suffix starts with a dot"):
        g2_document.register_rewriter(("fake",), print)


def test_a_drawing_and_a_road_file_come_back_whole_through_the_one_verb(tmp_path, capsys):
    """``g2`` on a DXF and a LandXML file: one file in, one out, the report printed, options of other kinds refused by name."""
    import ezdxf

    doc = ezdxf.new("R2010")
    doc.header["$INSUNITS"] = 4
    msp = doc.modelspace()
    msp.add_lwpolyline([(0, 0), (40, 0), (40, 20), (0, 20)], close=True, dxfattribs={"layer": "OUTLINE"})
    msp.add_text("PLATE", dxfattribs={"layer": "NOTES"})
    doc.saveas(tmp_path / "plate.dxf")
    assert main(["g2", str(tmp_path / "plate.dxf"), "--max-deviation", "0.01", "-o", str(tmp_path / "out.dxf")]) == 0
    said = capsys.readouterr().out
    assert "4 of 4 joint(s) changed" in said and "0 left below G2" in said
    back = ezdxf.readfile(tmp_path / "out.dxf").modelspace()
    assert {e.dxftype() for e in back.query("*[layer=='OUTLINE']")} == {"LINE", "SPLINE"}
    assert len(back.query("TEXT")) == 1
    assert main(["g2", str(tmp_path / "plate.dxf"), "--max-deviation", "0.01", "-o", str(tmp_path / "o.dxf"), "--dialect", "generic"]) == 2
    assert "dialect" in capsys.readouterr().err
    road = next((DATA.parent / "landxml").glob("openroads_*.xml"))
    assert main(["g2", str(road), "--max-deviation", "0.01", "-o", str(tmp_path / "road.xml")]) == 0
    assert "made G2" in capsys.readouterr().out and (tmp_path / "road.xml").is_file()
    assert main(["g2", str(road), "--max-deviation", "0.01", "-o", str(tmp_path / "r.xml"), "--units", "m"]) == 2
    assert "units" in capsys.readouterr().err


def test_nurbs_points_follow_the_judges_reading_of_linuxcnc():
    """Our NURBS (scipy's B-spline in homogeneous coordinates) against the judge's own Cox–de Boor sampler of the same
    words (LinuxCNC's definition: weights, order 4, the first control point where the tool stands)."""
    import numpy as np
    from scipy.spatial import cKDTree

    from spiral_cad.io.gcode_nurbs import nurbs_points

    lines = ["G5.2 P1 L4", "X20 Y20 P3", "X12 Y8 P0.5", "X5 Y25 P1", "X10 Y20 P2", "G5.3"]
    theirs = rs274_judge.nurbs_samples(lines, 5, np.array([10.0, 0.0, 1.0]), (0, 1, 2), 0.005)[:, :2]
    ours = nurbs_points(np.array([[10, 0], [20, 20], [12, 8], [5, 25], [10, 20]]), np.array([1, 3, 0.5, 1, 2]), 4, 0.005)
    gap = max(cKDTree(ours).query(theirs)[0].max(), cKDTree(theirs).query(ours)[0].max())
    assert gap < 0.005
    assert np.allclose(ours[0], [10, 0]) and np.allclose(ours[-1], [10, 20])
    with pytest.raises(ValueError, match="order 4 needs at least 4"):
        nurbs_points(np.array([[0, 0], [1, 1], [2, 0]]), np.ones(3), 4, 0.01)


ARCSPIRAL = DATA / "linuxcnc_arcspiral.ngc"


def test_arcspirals_outer_turns_come_back_g2_through_the_cli(tmp_path, capsys):
    """LinuxCNC's arcspiral.ngc, its first 300 arcs (same-sense joints of radii 0.1 % apart, kinked by the
    program's rounding): the run is rewritten, every joint between arcs made G2 (C pairs between the crossing
    circles), the arcs kept as they are."""
    lines = ARCSPIRAL.read_text().splitlines()
    src = tmp_path / "arcspiral300.ngc"
    src.write_text("\n".join(lines[:307] + lines[-2:]) + "\n")  # the header, 300 arcs, the retract and M2
    out = tmp_path / "out.ngc"
    assert main(["g2", str(src), "--max-deviation", "0.01", "-o", str(out)]) == 0
    said = capsys.readouterr().out
    assert "lines 7-307: 301 moves made G2" in said and "299 joints changed" in said and "refused" not in said
    assert "1 of 1 runs made G2" in said
    # the arcs kept as they are: the C pairs lie between the circles where they cross
    assert float(re.search(r"deviation ([0-9.e+-]+) in", said).group(1)) < 1e-6
    if rs274_judge.available():
        verdict = rs274_judge.judge(src.read_text(), out.read_text(), 0.01)
        assert verdict.passed, verdict.reasons


@pytest.mark.slow
def test_arcspiral_comes_back_g2_but_for_its_innermost_joints():
    """The whole program: its run rewritten, all but a few of its 998 joints made G2 (the innermost arcs, radii
    of 0.002 … 0.026 in with kinks up to 0.6 rad, may be left as they were, named); judged by rs274."""
    text = ARCSPIRAL.read_text()
    report = gcode_g2(text, 0.01, source=ARCSPIRAL.name)
    [run] = report.runs
    assert run.status == "G2" and run.joints_changed >= 990 and len(run.refused) <= 5, report.lines()
    assert 0.0 < report.deviation <= 0.01
    if rs274_judge.available():
        verdict = rs274_judge.judge(text, report.text, 0.01)
        assert verdict.passed, verdict.reasons


@pytest.mark.skipif(
    len(os.sched_getaffinity(0)) < 2 if hasattr(os, "sched_getaffinity") else True, reason="one core: no processes to share"
)
def test_ctrl_c_while_processes_make_the_runs_g2_is_one_line_130_and_no_file(tmp_path):
    """Ctrl-C in a terminal reaches the command and its forked processes: the command says so in one line, the
    processes end with it, and no program is written."""
    import signal
    import subprocess
    import time

    from spiral_cad.io.gcode_inplace import PARALLEL_MOVES

    parts = []
    for k in range(PARALLEL_MOVES // 20 + 1):  # rounded rectangles of G1 chords, 24 moves each
        x, y = (k % 40) * 30.0, (k // 40) * 30.0
        chords = " ".join(f"X{x + 10 + 8 * math.cos(a):.4f} Y{y + 10 + 8 * math.sin(a):.4f}" for a in np.linspace(0, 6.2, 24))
        parts += [
            f"G0 X{x + 18:.4f} Y{y + 10:.4f}",
            "G1 Z-1 F200",
            "G1 F600",
            *[f"G1 {w}" for w in re.findall(r"X\S+ Y\S+", chords)],
            "G0 Z5",
        ]
    program = tmp_path / "long.ngc"
    program.write_text("G21 G90 G17\n" + "\n".join(parts) + "\nM2\n")
    out = tmp_path / "long_g2.ngc"
    process = subprocess.Popen([sys.executable, "-m", "spiral_cad.app.cli", "g2", str(program), "--max-deviation", "0.01", "-o", str(out)],
                               stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True, start_new_session=True)  # fmt: skip
    seen = []
    for line in process.stderr:
        seen.append(line)
        if "runs made G2:" in line:  # the processes are at work
            break
    os.killpg(process.pid, signal.SIGINT)  # as a terminal sends it: to the whole group
    err = "".join(seen) + process.stderr.read()
    assert process.wait(timeout=60) == 130, err
    said = [line for line in err.splitlines() if not re.match(r"g2 long\.ngc: (runs made G2|lines): ", line)]
    assert said == ["error: interrupted"], err
    assert not out.exists()
    time.sleep(0.5)
    with pytest.raises(ProcessLookupError):  # no process of the command is left
        os.killpg(process.pid, 0)


@needs_rs274
def test_a_bores_circle_comes_back_a_turn_short_of_full_and_the_judge_reads_it_so():
    """Fusion 360's bore bottom: two half circles, then an arc and a line. Made G2, the circle (shrunk for the transition
    after it) is written as one G3 whose end lies 1e-4 mm behind its start: a turn short of a full one, which rs274
    prints with both ends equal to its 4 decimals; the judge takes the sweep from the written ends."""
    text = ("G21 G90 G17\nG0 X14.636 Y-0.265 Z0\nG1 Z-12.8 F1000\nG3 X15.364 Y0.265 I0.364 J0.265\nX14.636 Y-0.265 I-0.364 J-0.265\n"
            "X14.95 Y-0.314 I0.182 J0.132\nG1 X15.059 Y-0.235\nG0 Z5\nM2\n")  # fmt: skip
    report = gcode_g2(text, 0.01)
    turns = [line for line in report.text.splitlines() if line.startswith("G3")]
    assert turns and report.runs[0].status == "G2"
    verdict = rs274_judge.judge(text, report.text, 0.01)
    assert verdict.passed, verdict.reasons
    assert verdict.distance > 1e-3  # the circle did shrink: the judge measured a full turn, not a short arc


def test_an_output_that_is_a_link_to_the_input_is_refused(tmp_path):
    source = tmp_path / "contour.nc"
    source.write_text(CONTOUR)
    os.link(source, tmp_path / "link.nc")
    with pytest.raises(ValueError, match="is the input"):
        make_document_g2(source, tmp_path / "link.nc", 0.01)
    assert source.read_text() == CONTOUR


def _in_a_pool_process(text: str) -> str:
    return gcode_g2(text, 0.01).text


def test_a_program_made_g2_inside_a_pools_process_is_made_in_that_process(monkeypatch):
    """A pool's own process may start none (daemonic): the runs are made in it, as in one process."""
    import multiprocessing

    import spiral_cad.io.gcode_inplace as inplace

    monkeypatch.setattr(inplace, "PARALLEL_MOVES", 0)  # every program "long" (forked into the pool's process too)
    with multiprocessing.get_context("fork").Pool(1) as pool:
        text = pool.apply(_in_a_pool_process, (CONTOUR,))
    monkeypatch.setattr(inplace, "PARALLEL_MOVES", 10**12)
    assert text == gcode_g2(CONTOUR, 0.01).text
