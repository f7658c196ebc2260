"""G2 checker on real OCCT geometry (raw OCP edges, build123d for STEP export)."""

from __future__ import annotations

import math
import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

pytest.importorskip("OCP")

import build123d as bd  # noqa: E402
from OCP.BRep import BRep_Builder  # noqa: E402
from OCP.BRepBuilderAPI import (  # noqa: E402
    BRepBuilderAPI_MakeEdge,
    BRepBuilderAPI_MakeWire,
    BRepBuilderAPI_Transform,
)
from OCP.BRepTools import BRepTools_WireExplorer  # noqa: E402
from OCP.GC import GC_MakeArcOfCircle  # noqa: E402
from OCP.Geom import Geom_BezierCurve  # noqa: E402
from OCP.gp import gp_Ax1, gp_Ax2, gp_Circ, gp_Dir, gp_Pnt, gp_Trsf, gp_Vec  # noqa: E402
from OCP.IGESControl import IGESControl_Writer  # noqa: E402
from OCP.TColgp import TColgp_Array1OfPnt  # noqa: E402
from OCP.TopAbs import TopAbs_REVERSED  # noqa: E402
from OCP.TopoDS import TopoDS, TopoDS_Wire  # noqa: E402

import spiral_cad as sc  # noqa: E402
import spiral_cad.cad.export  # noqa: E402,F401
import spiral_cad.design  # noqa: E402,F401
from spiral_cad.app.cli import main  # noqa: E402
from spiral_cad.cad.continuity import Continuity, check_continuity  # noqa: E402

G0, G1, G2, NONE = Continuity.G0, Continuity.G1, Continuity.G2, Continuity.NONE


# ------------------------------------------------------------ raw OCCT edges


def _pnt(p) -> gp_Pnt:
    return gp_Pnt(float(p[0]), float(p[1]), float(p[2]) if len(p) > 2 else 0.0)


def line(a, b):
    return BRepBuilderAPI_MakeEdge(_pnt(a), _pnt(b)).Edge()


def bezier(control_points):
    poles = TColgp_Array1OfPnt(1, len(control_points))
    for i, p in enumerate(control_points, 1):
        poles.SetValue(i, _pnt(p))
    return BRepBuilderAPI_MakeEdge(Geom_BezierCurve(poles)).Edge()


def ccw_arc(center, radius, a0, a1):
    """Counterclockwise arc in the XY plane from polar angle a0 to a1."""
    circle = gp_Circ(gp_Ax2(_pnt(center), gp_Dir(0, 0, 1)), radius)
    return BRepBuilderAPI_MakeEdge(GC_MakeArcOfCircle(circle, a0, a1, True).Value()).Edge()


def wire(*edges) -> TopoDS_Wire:
    maker = BRepBuilderAPI_MakeWire()
    for e in edges:
        maker.Add(e)
        assert maker.IsDone(), maker.Error()
    return maker.Wire()


def loose_wire(*edges) -> TopoDS_Wire:
    """A wire holding edges that need not connect (BRepBuilderAPI_MakeWire refuses those)."""
    builder, w = BRep_Builder(), TopoDS_Wire()
    builder.MakeWire(w)
    for e in edges:
        builder.Add(w, e)
    return w


def spiral_path(point=(0.0, 0.0), direction=(1.0, 0.0), center=(0.0, 1.05), radius=1.0, lead=2.0, sweep=1.0):
    """Edges of line → spiral (line_to_circle) → arc of the circle, in travel order."""
    t = sc.line_to_circle(point, direction, center, radius)
    cp = t.spirals[0].control_points
    ux, uy = t.spirals[0].start_tangent
    circle = t.end_circle
    a0 = math.atan2(cp[3][1] - circle.center[1], cp[3][0] - circle.center[0])
    start = (cp[0][0] - lead * ux, cp[0][1] - lead * uy)
    if circle.radius > 0:
        arc = ccw_arc(circle.center, radius, a0, a0 + sweep)
    else:  # clockwise travel: the counterclockwise arc run backwards
        arc = TopoDS.Edge_s(ccw_arc(circle.center, radius, a0 - sweep, a0).Reversed())
    return [line(start, cp[0]), bezier(cp.tolist()), arc]


def levels(report, wire_index=0):
    return [j.level for j in report.wires[wire_index].joints]


# ------------------------------------------------------------------ levels


def test_levels_are_ordered_and_parse():
    assert NONE < G0 < G1 < G2
    assert Continuity.parse("g2") is G2 and Continuity.parse("none") is NONE and Continuity.parse(1) is G0
    assert str(NONE) == "none" and str(G1) == "G1"
    with pytest.raises(ValueError, match="G3"):
        Continuity.parse("G3")


def test_line_then_tangent_arc_is_g1_not_g2():
    report = check_continuity(wire(line((-2, 0), (0, 0)), ccw_arc((0, 1), 1.0, -math.pi / 2, 0.0)))
    (joint,) = report.wires[0].joints
    assert joint.level is G1
    assert joint.gap < 1e-12 and joint.angle < 1e-12
    assert joint.curvature_before == pytest.approx(0.0, abs=1e-12)
    assert joint.curvature_after == pytest.approx(1.0, rel=1e-12)
    assert joint.curvature_jump == pytest.approx(1.0, rel=1e-12)
    assert report.passes("G1") and not report.passes("G2")


def test_line_spiral_arc_is_g2_at_both_joints():
    report = check_continuity(wire(*spiral_path()))
    w = report.wires[0]
    assert (w.edge_count, w.closed) == (3, False)
    assert levels(report) == [G2, G2]
    # The spiral starts with zero curvature (where OCCT's own analysis fails) and ends at 1/r.
    assert w.joints[0].curvature_after == pytest.approx(0.0, abs=1e-12)
    assert w.joints[1].curvature_before == pytest.approx(1.0, rel=1e-12)
    assert report.min_level is G2 and report.passes(G2)


@settings(max_examples=25)
@given(
    px=st.floats(-50, 50),
    py=st.floats(-50, 50),
    heading=st.floats(-math.pi, math.pi),
    radius=st.floats(0.05, 20.0),
    clearance=st.floats(1.01, 3.0),
    side=st.sampled_from([1.0, -1.0]),
)
def test_any_line_to_circle_transition_is_g2(px, py, heading, radius, clearance, side):
    tx, ty = math.cos(heading), math.sin(heading)
    d = radius * clearance
    center = (px - side * d * ty, py + side * d * tx)
    edges = spiral_path((px, py), (tx, ty), center, radius, lead=radius, sweep=0.5)
    assert levels(check_continuity(wire(*edges))) == [G2, G2]


def test_corner_is_g0_with_its_angle():
    (joint,) = check_continuity(wire(line((0, 0), (1, 0)), line((1, 0), (1 + math.cos(0.3), math.sin(0.3))))).joints
    assert joint.level is G0
    assert joint.angle == pytest.approx(0.3, rel=1e-12)


def test_disconnected_pair_is_below_g0():
    report = check_continuity(loose_wire(line((0, 0), (1, 0)), line((1.001, 0), (2, 0))))
    (joint,) = report.joints
    assert joint.level is NONE
    assert joint.gap == pytest.approx(1e-3, rel=1e-9)
    assert not report.passes("G0")


def test_loose_edges_are_chained_in_order_and_orientation():
    # Shuffled, with the first line pointing backwards: chaining must restore line → spiral → arc.
    _, spiral, arc = spiral_path()
    b0 = sc.line_to_circle((0, 0), (1, 0), (0, 1.05), 1.0).spirals[0].control_points[0]
    report = check_continuity([arc, line(b0, (b0[0] - 2.0, 0.0)), spiral])
    (w,) = report.wires
    assert w.loose and w.edge_count == 3
    assert levels(report) == [G2, G2]


def test_separate_loose_curves_stay_separate_but_a_small_gap_is_reported():
    far = check_continuity([line((0, 0), (1, 0)), line((5, 0), (6, 0))])
    assert [w.edge_count for w in far.wires] == [1, 1] and far.joints == []
    near = check_continuity([line((0, 0), (1, 0)), line((1.0 + 1e-6, 0), (2, 0))])
    assert levels(near) == [NONE]
    assert near.joints[0].gap == pytest.approx(1e-6, rel=1e-6)
    # The gap tolerance is absolute: the same gap passes when allowed.
    assert levels(check_continuity([line((0, 0), (1, 0)), line((1.0 + 1e-6, 0), (2, 0))], gap_tol=1e-5)) == [G2]


def test_reversed_edge_runs_from_last_to_first_parameter():
    first, _, arc = spiral_path()
    t = sc.line_to_circle((0, 0), (1, 0), (0, 1.05), 1.0)
    backwards = bezier(t.spirals[0].control_points[::-1].tolist())  # parameter runs arc → line
    w = wire(first, TopoDS.Edge_s(backwards.Reversed()), arc)
    explorer = BRepTools_WireExplorer(w)
    explorer.Next()
    assert explorer.Current().Orientation() == TopAbs_REVERSED
    report = check_continuity(w)
    assert levels(report) == [G2, G2]
    assert max(j.gap for j in report.joints) < 1e-12


def test_opposite_curvature_of_equal_size_is_only_g1():
    # Two quarter arcs, counterclockwise then clockwise (an S of arcs): |κ| matches, the
    # curvature vectors point opposite ways, so this is G1. The clockwise arc is a
    # REVERSED edge, which also checks that orientation does not flip curvature vectors.
    ccw = ccw_arc((0, 1), 1.0, -math.pi / 2, 0.0)  # (0, 0) → (1, 1), heading +y
    cw = TopoDS.Edge_s(ccw_arc((2, 1), 1.0, math.pi / 2, math.pi).Reversed())  # (1, 1) → (2, 2)
    (joint,) = check_continuity(wire(ccw, cw)).joints
    assert joint.angle < 1e-12
    assert joint.curvature_before == pytest.approx(joint.curvature_after, rel=1e-12)
    assert joint.level is G1
    assert joint.curvature_jump == pytest.approx(2.0, rel=1e-12)


def test_s_transition_inflection_is_g2():
    t = sc.circle_to_circle((0, 0), -2.0, (5, 1), 1.0)
    edges = [bezier(s.control_points.tolist()) for s in t.spirals]
    (joint,) = check_continuity(wire(*edges)).joints
    assert joint.level is G2
    assert joint.curvature_before == pytest.approx(0.0, abs=1e-12)


def test_closed_wire_checks_its_closing_joint():
    # line → tangent arc (3/4 turn) → line back down to the start: the closing joint is a corner.
    edges = [line((0, 0), (1, 0)), ccw_arc((1, 1), 1.0, -math.pi / 2, math.pi), line((0, 1), (0, 0))]
    (w,) = check_continuity(wire(*edges)).wires
    assert w.closed and w.edge_count == 3
    assert [j.index for j in w.joints] == [0, 1, 2]
    assert [j.level for j in w.joints] == [G1, G1, G0]
    assert w.joints[2].angle == pytest.approx(math.pi / 2, rel=1e-12)


def test_single_closed_edge_has_one_joint():
    (joint,) = check_continuity(bd.Circle(2.0)).joints  # build123d face: its circle wire
    assert joint.level is G2 and joint.curvature_after == pytest.approx(0.5)


def test_solid_faces_and_shape_wrappers():
    report = check_continuity(bd.Box(1, 2, 3))
    assert len(report.wires) == 6 and all(w.closed and w.edge_count == 4 for w in report.wires)
    assert all(j.level is G0 and j.angle == pytest.approx(math.pi / 2) for j in report.joints)


def test_rotated_3d_copy_keeps_its_levels():
    trsf = gp_Trsf()
    trsf.SetRotation(gp_Ax1(gp_Pnt(1, 2, 3), gp_Dir(0.3, -0.5, 0.8)), 1.1)
    trsf.SetTranslationPart(gp_Vec(10, -4, 7))
    rotated = BRepBuilderAPI_Transform(wire(*spiral_path()), trsf, True).Shape()
    assert levels(check_continuity(rotated)) == [G2, G2]
    tangent_arc = wire(line((-2, 0), (0, 0)), ccw_arc((0, 1), 1.0, -math.pi / 2, 0.0))
    assert levels(check_continuity(BRepBuilderAPI_Transform(tangent_arc, trsf, True).Shape())) == [G1]


def test_degenerate_end_derivative_still_gives_a_tangent():
    # First two poles coincide: r'(0) = 0, the tangent comes from P2 − P0.
    curve = bezier([(0, 0), (0, 0), (1, 0), (2, 1)])
    (joint,) = check_continuity(wire(line((-1, 0), (0, 0)), curve)).joints
    assert joint.gap == 0.0 and joint.angle < 1e-9
    assert joint.level is G1  # the curvature is unbounded at such an end


def test_bad_tolerance_is_rejected():
    with pytest.raises(ValueError, match="gap_tol"):
        check_continuity(wire(line((0, 0), (1, 0))), gap_tol=-1.0)


# ----------------------------------------------------------------- files


CASES = {
    "spiral": lambda: spiral_path(),
    "tangent-arc": lambda: [line((-2, 0), (0, 0)), ccw_arc((0, 1), 1.0, -math.pi / 2, 0.0)],
    "corner": lambda: [line((0, 0), (1, 0)), line((1, 0), (1, 1))],
}


@pytest.mark.parametrize("case", sorted(CASES))
def test_step_round_trip_keeps_the_classification(case, tmp_path):
    w = wire(*CASES[case]())
    path = tmp_path / f"{case}.step"
    bd.export_step(bd.Wire(w), str(path))
    assert levels(check_continuity(path)) == levels(check_continuity(w))


@pytest.mark.parametrize("case", sorted(CASES))
def test_iges_round_trip_keeps_the_classification(case, tmp_path):
    w = wire(*CASES[case]())
    path = tmp_path / f"{case}.igs"
    writer = IGESControl_Writer("MM", 0)
    writer.AddShape(w)
    writer.ComputeModel()
    assert writer.Write(str(path))
    assert levels(check_continuity(str(path))) == levels(check_continuity(w))


def test_unreadable_files_raise_value_error(tmp_path):
    bad = tmp_path / "bad.step"
    bad.write_text("not a step file\n")
    for path in (bad, tmp_path / "missing.step", tmp_path / "model.txt"):
        with pytest.raises(ValueError, match="cannot read"):
            check_continuity(path)


def test_format_table_states_what_was_found_and_lists_every_joint():
    text = check_continuity(wire(*spiral_path())).format_table()
    assert text.startswith("TopoDS_Wire: 1 wire of 3 edges; worst joint G2")
    assert "wire 0: 3 edges, open, 2 joint(s), worst G2" in text
    assert text.count(" G2\n") + text.endswith(" G2") >= 2
    two = check_continuity([line((0, 0), (1, 0)), line((50, 0), (51, 0)), line((51, 0), (52, 1))])
    assert two.describe() == "2 loose pieces (1, 2 edges)" and two.pieces == 2
    assert not two.passes("G0") and two.passes("G0", pieces=2)


def test_a_gap_within_the_snap_distance_fails_g0_instead_of_splitting_the_path():
    # two loose lines 0.5 apart in a 100-unit model: one piece with a broken joint
    report = check_continuity([line((0, 0), (49.75, 0)), line((50.25, 0), (100, 0))])
    assert report.pieces == 1 and levels(report) == [NONE]
    assert report.joints[0].gap == pytest.approx(0.5)
    assert not report.passes("G0")
    # beyond the snap distance they are two pieces, and --require still fails on the count
    assert check_continuity([line((0, 0), (49.75, 0)), line((50.25, 0), (100, 0))], snap=0.1).pieces == 2


def test_survey_coordinates_are_not_failed_on_their_last_bit():
    x = 5.4e9  # millimetres: a survey coordinate
    report = check_continuity([line((x, 0), (x + 1000, 0)), line((x + 1000 + 2 * math.ulp(x), 0), (x + 2000, 0))])
    assert levels(report) == [G2]


def survey_highway() -> sc.Chain:
    """A G2 highway at survey coordinates (~3e6 m): 20 PIs 100 km apart, R 300 m."""
    pis = [[3e6 - 1e6 + 1e5 * k, 3e6 + 2.5e4 * (k % 2)] for k in range(22)]
    return sc.design.Alignment.from_pis(pis, 300.0, spiral_angles=0.08, units="m").chain


def test_a_g2_highway_at_survey_coordinates_is_g2_and_a_real_kink_there_is_caught(tmp_path, monkeypatch):
    import spiral_cad.cad.continuity as checker

    path = tmp_path / "survey.step"
    sc.cad.export.export_step(survey_highway(), path)
    report = check_continuity(path)
    assert report.describe() == "1 wire of 81 edges" and report.passes("G2")
    # the spirals' zero start curvatures read ~1e-13 1/m there: beyond the tolerance without the rounding floor
    monkeypatch.setattr(checker, "_rounding_floor", lambda p, *rest, **kw: np.zeros(len(p)))
    assert check_continuity(path).min_level is G1
    monkeypatch.undo()
    # a real kink there: the first spiral's third control point moved 0.1 mm along its last leg (the tangents stay)
    text = path.read_text()
    p2, p3 = re.search(r"B_SPLINE_CURVE_WITH_KNOTS\('',3,\(#\d+,#\d+,(#\d+),(#\d+)\)", text).groups()
    found = {n: re.search(rf"{n}=CARTESIAN_POINT\('',\(([^,]*),([^,]*),", text) for n in (p2, p3)}
    (x2, y2), (x3, y3) = (np.array([float(v) for v in found[n].groups()]) for n in (p2, p3))
    step = 1e-4 / math.hypot(x3 - x2, y3 - y2)
    moved = f"{p2}=CARTESIAN_POINT('',({float(x2 + step * (x3 - x2))!r},{float(y2 + step * (y3 - y2))!r},"
    path.write_text(text.replace(found[p2].group(0), moved))
    kinked = check_continuity(path)
    assert levels(kinked)[:2] == [G1, G1] and set(levels(kinked)[2:]) == {G2}  # its start and end curvature moved


def test_the_rounding_floor_is_capped_so_a_segment_too_small_for_its_coordinates_hides_no_kink(monkeypatch):
    import spiral_cad.continuity.joints as joints

    # a 1 mm spiral at 3e6 m whose start curvature (~1e-3 1/m) is below what rounding can hide there
    x = y = 3e6
    h = 1.5e-9  # κ0 = (2/3) h / a² with legs a = 1e-3
    edges = [line((x - 1000, y), (x, y)), bezier([(x, y), (x + 1e-3, y), (x + 2e-3, y + h), (x + 3e-3, y + 4 * h)])]
    (joint,) = check_continuity(edges).joints
    assert joint.level is G1 and joint.curvature_after > 1e-4
    monkeypatch.setattr(joints, "ROUNDING_CAP", math.inf)  # uncapped, the floor would hide it
    assert check_continuity(edges).min_level is G2


# ------------------------------------------------------------------- CLI


@pytest.fixture()
def step_files(tmp_path) -> dict[str, Path]:
    files = {}
    for case in ("spiral", "tangent-arc"):
        files[case] = tmp_path / f"{case}.step"
        bd.export_step(bd.Wire(wire(*CASES[case]())), str(files[case]))
    return files


def test_cli_check_reports_and_exits_by_requirement(step_files, capsys):
    assert main(["check", str(step_files["tangent-arc"])]) == 0
    assert "worst G1" in capsys.readouterr().out
    assert main(["check", str(step_files["tangent-arc"]), "--require", "G1"]) == 0
    assert main(["check", str(step_files["tangent-arc"]), "--require", "G2"]) == 1
    assert "FAIL" in capsys.readouterr().out
    assert main(["check", str(step_files["spiral"]), "--require", "G2"]) == 0
    # A huge curvature tolerance lets the tangent arc pass G2.
    assert main(["check", str(step_files["tangent-arc"]), "--require", "G2", "--curvature-tol", "2"]) == 0


def test_timing_says_which_part_limits_the_check(step_files, capsys):
    report = check_continuity(step_files["spiral"])
    timing = report.timing
    assert timing.reader == "the STEP reader (OCCT)" and min(timing.reading, timing.measuring, timing.classifying) >= 0.0
    line = report.timing_line()
    limit = "the STEP reader (OCCT) limits" if timing.reading >= timing.measuring + timing.classifying else "classifying limit"
    assert re.match(r"time [0-9.e-]+ s: the STEP reader \(OCCT\) [0-9.e-]+ s \(\d+%\), measuring .* joints/s\); ", line)
    assert limit in line
    assert main(["check", str(step_files["spiral"]), "--timing"]) == 0
    out = capsys.readouterr().out.splitlines()
    assert out[-1].startswith("time ") and "joints/s" in out[-1] and out[:-1] == report.format_table().splitlines()
    shape_report = check_continuity(wire(*spiral_path()))
    assert shape_report.timing.reader == "" and "reader" not in shape_report.timing_line()


def test_cli_check_unreadable_file_exits_2(tmp_path, capsys):
    bad = tmp_path / "bad.igs"
    bad.write_text("garbage\n")
    assert main(["check", str(bad)]) == 2
    assert main(["check", str(tmp_path / "missing.step")]) == 2
    assert "error: cannot read" in capsys.readouterr().err


@pytest.mark.parametrize("suffix", ["step", "igs"])
def test_a_truncated_file_exits_2_with_the_readers_reason_and_no_chatter(tmp_path, capfd, suffix):
    chain = sc.design.Alignment.from_pis([(0, 0), (600, 120), (1150, -80), (1700, 260)], [450, 400], spiral_angles=0.12).chain
    whole = tmp_path / f"road.{suffix}"
    (sc.cad.export.export_step if suffix == "step" else sc.cad.export.export_iges)(chain, whole)
    assert main(["check", str(whole), "--require", "G2"]) == 0
    assert "1 wire of 9 edges" in capfd.readouterr().out
    lines = whole.read_text().splitlines(keepends=True)
    cut = tmp_path / f"cut.{suffix}"
    reason = {"step": "the STEP reader reports: .*unexpected end of file", "igs": "no IGES terminate section"}[suffix]
    for kept, why in ((lines[: len(lines) // 2], reason), (lines[: len(lines) // 2] + lines[-1:], "declares|reader reports")):
        cut.write_text("".join(kept))
        assert main(["check", str(cut), "--require", "G2"]) == 2
        out, err = capfd.readouterr()
        assert re.match(f"error: cannot read 'cut.{suffix}': .*({why})", err), err
        assert "\x1b[" not in out + err and "Traceback" not in err


def test_cli_counts_pieces(tmp_path, capsys):
    first = sc.design.round_corners([(0, 0), (10, 0), (10, 10)]).chain
    second = sc.design.round_corners([(30, 0), (40, 0), (40, 10)]).chain
    path = tmp_path / "two.step"
    sc.cad.export.export_step([first, second], path)
    assert main(["check", str(path), "--require", "G2"]) == 1
    assert "2 separate pieces, expected 1" in capsys.readouterr().out
    assert main(["check", str(path), "--require", "G2", "--pieces", "2"]) == 0
    assert "OK: 2 wires (2, 2 edges)" in capsys.readouterr().out  # Cor. 4.5: spirals use the whole legs


def test_cli_script_runs(step_files):
    script = Path(sys.executable).parent / "spiral-cad"
    if not script.exists():
        pytest.skip("spiral-cad script not installed next to this interpreter")
    done = subprocess.run([str(script), "check", str(step_files["tangent-arc"]), "--require", "G2"], capture_output=True, text=True)
    assert done.returncode == 1
    assert "worst G1" in done.stdout


# ------------------------------------------------------- NaN and scale


def frame(point=(0.0, 0.0), tangent=(1.0, 0.0), curvature=(0.0, 0.0)):
    return (point[0], point[1], 0.0, tangent[0], tangent[1], 0.0, curvature[0], curvature[1], 0.0)


def test_nan_never_passes_and_is_its_own_level():
    from spiral_cad.continuity.joints import ContinuityReport, JointReport, WireReport, classify_joint

    nan, inf = math.nan, math.inf
    grade = lambda a, b: classify_joint(0, a, b, 1e-7, 1e-7, 1e-6, 0.1).level  # noqa: E731
    assert grade(frame(), frame()) is G2
    assert grade(frame(), frame(tangent=(nan, nan))) is Continuity.UNMEASURABLE  # a 0/0 tangent
    assert grade(frame(), frame(point=(nan, 0.0))) is Continuity.UNMEASURABLE
    assert grade(frame(), frame(curvature=(nan, 0.0))) is Continuity.UNMEASURABLE
    assert grade(frame(curvature=(nan, 0.0)), frame()) is Continuity.UNMEASURABLE  # max() would drop a NaN here
    assert grade(frame(), frame(curvature=(inf, 0.0))) is Continuity.UNMEASURABLE
    # a measure that is decided before the NaN one keeps its verdict: a kink is G0 whatever its curvature
    assert grade(frame(), frame(tangent=(0.0, 1.0), curvature=(nan, 0.0))) is G0
    assert Continuity.UNMEASURABLE < NONE and str(Continuity.UNMEASURABLE) == "unmeasurable"
    joint = JointReport(0, nan, nan, nan, Continuity.UNMEASURABLE)
    broken = ContinuityReport((WireReport(0, 2, False, (joint,)),), 1e-7, 1e-7, 1e-6, 1.0)
    assert all(not broken.passes(required) for required in ("none", "G0", "G1", "G2", 0, 3))
    for bad in ("unmeasurable", -1, 4, True, 2.0):
        with pytest.raises(ValueError, match="continuity level must be one of none, G0, G1, G2"):
            Continuity.parse(bad)


def test_model_size_names_the_coordinate_it_cannot_measure():
    from spiral_cad.continuity.joints import model_size

    assert model_size([(0.0, 0.0, 0.0), (3e300, 4e300, 0.0)]) == pytest.approx(5e300)  # no overflow short of the range
    with pytest.raises(ValueError, match=r"f.step: a point of the model is not finite: \(0.0, nan, 0.0\)"):
        model_size([(0.0, 0.0, 0.0), (0.0, math.nan, 0.0)], "f.step")
    with pytest.raises(ValueError, match=r"spans x = -1.7e\+308 to 1.7e\+308, wider than a float can measure"):
        model_size([(-1.7e308, 0.0, 0.0), (1.7e308, 0.0, 0.0)])


def test_curvature_is_measured_at_any_scale():
    # |r'|⁴ overflows beyond 1e77: measured without it, a tangent arc at 1e80 is still only G1
    s = 1e80
    report = check_continuity([line((-2 * s, 0), (0, 0)), ccw_arc((0, s), s, -math.pi / 2, 0.0)], gap_tol=1e-12 * s)
    (joint,) = report.joints
    assert joint.level is G1 and joint.curvature_after * s == pytest.approx(1.0, rel=1e-12)


def scaled_step(text: str, factor: float) -> str:
    """A STEP text of lines and Bézier spirals with every length multiplied by ``factor``."""

    def scale(match: re.Match) -> str:
        return "%.17E" % (float(match.group(0)) * factor)

    text = re.sub(r"(?<=CARTESIAN_POINT\('',\()[^)]*", lambda m: re.sub(r"[-0-9.E+]+", scale, m.group(0)), text)
    return re.sub(r"(?<=PARAMETER_VALUE\()[-0-9.E+]+", scale, text)


def test_a_file_at_1e300_is_measured_not_refused_for_its_snap(tmp_path, capsys):
    chain = sc.design.round_corners([(0, 0), (10, 0), (10, 10), (20, 10)], units="m").chain
    path = tmp_path / "huge.step"
    sc.cad.export.export_step(chain, path)
    path.write_text(scaled_step(path.read_text(), 1e300))
    status = main(["check", str(path), "--require", "G2"])
    out, err = capsys.readouterr()
    # OCCT cannot place vertices this far out (beyond its 2e100 "infinite"): never a false pass, never a word of snap
    assert "snap" not in err and "OK" not in out
    assert status == 2 and "root entities could be transferred" in err


def test_reports_state_their_unit():
    chain = sc.design.round_corners([(0, 0), (10, 0), (10, 10)], units="ft").chain
    assert check_continuity(chain).units == "ft"
    assert "gap 1e-07 ft" in check_continuity(chain).format_table()
    assert "model size" in check_continuity(wire(line((0, 0), (1, 0)))).format_table()
    assert "(model units)" in check_continuity(wire(line((0, 0), (1, 0)))).format_table()
    assert check_continuity(wire(line((0, 0), (1, 0))), units="in").units == "in"
    with pytest.raises(ValueError, match="units must be one of"):
        check_continuity(wire(line((0, 0), (1, 0))), units="parsec")


def test_the_demo_report_and_the_cli_print_the_same_numbers(tmp_path, capsys):
    import json

    design = tmp_path / "d.json"
    design.write_text(json.dumps({"units": "m", "designs": [
        {"name": "road", "type": "alignment", "pis": [[0, 0], [600, 120], [1150, -80]], "radii": [450], "spiral_angles_deg": 8},
        {"name": "loop", "type": "circle_chain", "circles": [{"center": c, "radius": r} for c, r in
                                                              [([0, 0], 60), ([29.85, 0], 30), ([150, -10], 40), ([150, 120], -35)]]},
    ]}))  # fmt: skip
    assert main(["build", str(design), "--out", str(tmp_path / "out"), "--no-plots"]) == 0
    capsys.readouterr()
    for name in ("road", "loop"):
        assert main(["check", str(tmp_path / "out" / f"{name}.step")]) == 0
        printed = capsys.readouterr().out
        written = (tmp_path / "out" / f"{name}_continuity.txt").read_text()
        assert printed == written and re.search(r"; model size \d+\.\d+ m\n", printed)  # metres, as declared


# ------------------------------------------------------------------ comb


def test_comb_refuses_to_overwrite_the_checked_file_by_any_name(step_files, tmp_path, capsys):
    source = step_files["spiral"]
    original = source.read_bytes()
    (tmp_path / "link.step").symlink_to(source)
    os.link(source, tmp_path / "hard.step")
    (tmp_path / "folder.step").mkdir()
    for comb, reason in ((str(source), "is the file being checked"), (str(tmp_path / "link.step"), "is the file being checked"),
                         (str(tmp_path / "hard.step"), "is the file being checked"),
                         (str(tmp_path / "." / source.name), "is the file being checked"),
                         (str(tmp_path / "c.igs"), "give a .step or .stp file"), (str(tmp_path / "c"), "give a .step or .stp file"),
                         (str(tmp_path / "folder.step"), "is a folder")):  # fmt: skip
        assert main(["check", str(source), "--comb", comb]) == 2
        err = capsys.readouterr().err
        assert err.startswith("error: --comb") and reason in err, err
    assert source.read_bytes() == original and not (tmp_path / "c.igs").exists()


def test_comb_is_written_in_the_unit_of_the_checked_file(tmp_path, capsys):
    chain = sc.design.round_corners([(0, 0), (10, 0), (10, 10)], units="m").chain
    path, comb = tmp_path / "r.step", tmp_path / "comb.STP"
    sc.cad.export.export_step(chain, path)
    assert main(["check", str(path), "--comb", str(comb), "--require", "G2"]) == 0
    assert check_continuity(comb).units == "m"
    assert check_continuity(comb).size == pytest.approx(check_continuity(path).size, rel=0.5)  # teeth stick out a little


# -------------------------------------------------------- CLI manners


def test_a_closed_pipe_ends_check_quietly_with_141(step_files):
    script = Path(sys.executable).parent / "spiral-cad"
    if not script.exists():
        pytest.skip("spiral-cad script not installed next to this interpreter")
    process = subprocess.Popen([str(script), "check", str(step_files["spiral"])], stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    process.stdout.close()  # the reader of our output is gone before we print (`| head -0`)
    err = process.stderr.read()
    assert process.wait(timeout=120) == 141
    assert err == b""


def test_no_numpy_warning_reaches_the_terminal(tmp_path, capfd):
    import warnings

    kink = tmp_path / "kink.xodr"
    kink.write_text(
        '<?xml version="1.0"?><OpenDRIVE><header revMajor="1" revMinor="8"/><road id="1" junction="-1" length="20"><planView>'
        '<geometry s="0" x="0" y="0" hdg="0" length="10"><line/></geometry>'
        '<geometry s="10" x="10" y="0" hdg="0" length="10"><paramPoly3 aU="0" bU="0" cU="1" dU="0" aV="0" bV="0" cV="1" dV="0"/>'
        "</geometry></planView></road></OpenDRIVE>"
    )
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # any warning would be an exception here
        assert main(["check", str(kink), "--require", "G0"]) == 1
    out, err = capfd.readouterr()
    assert err == "" and "worst joint unmeasurable" in out


def test_a_wire_that_returns_along_its_start_is_an_open_path_but_a_corner_loop_stays_closed():
    # out along y = 0, up, and back down to the start along y = 0 the other way: the last edge
    # reverses the first at the shared point, so there is no closing joint to judge
    edges = [line((0, 0), (4, 0)), line((4, 0), (4, 3)), line((4, 3), (2, 0)), line((2, 0), (0, 0))]
    (w,) = check_continuity(wire(*edges)).wires
    assert not w.closed and w.reverses and len(w.joints) == 3
    assert "open (its ends meet, reversing: no closing joint)" in check_continuity(wire(*edges)).format_table()
    # a square meets its start at a right angle: a closed loop whose closing joint is a corner
    square = [line((0, 0), (1, 0)), line((1, 0), (1, 1)), line((1, 1), (0, 1)), line((0, 1), (0, 0))]
    (w,) = check_continuity(wire(*square)).wires
    assert w.closed and not w.reverses and len(w.joints) == 4


def test_a_program_that_ends_where_it_started_builds_and_checks_g2(tmp_path, capsys):
    program = tmp_path / "back.nc"
    program.write_text("G21 G90\nG1 X0 Y0\nG1 X40 Y0\nG1 X40 Y30\nG1 X20 Y0\nG1 X0 Y0\n")  # back along its first move
    out = tmp_path / "out"
    assert main(["build", "--from-gcode", str(program), "--max-deviation", "2", "--out", str(out), "--no-plots"]) == 0
    assert "G2 (1 wire of 10 edges)" in capsys.readouterr().out  # the build's own report of its STEP
    assert main(["check", str(out / "back.step"), "--require", "G2"]) == 0
    assert "open (its ends meet, reversing: no closing joint), 9 joint(s), worst G2" in capsys.readouterr().out
    (w,) = check_continuity(out / "back.step").wires
    assert w.reverses and not w.closed and w.min_level is Continuity.G2


def test_a_smooth_loop_whose_ends_are_two_vertices_is_still_a_loop():
    # two half circles whose end points coincide but are separate vertices: the seam is judged (G2), as
    # in a wire that shares them; the same with a corner at the seam stays an open path
    halves = [ccw_arc((0, 0), 1.0, 0.0, math.pi), ccw_arc((0, 0), 1.0, math.pi, 2 * math.pi)]
    (w,) = check_continuity(loose_wire(*halves)).wires
    assert w.closed and len(w.joints) == 2 and w.min_level is G2
    corner = [line((0, 0), (1, 0)), line((1, 0), (1, 1)), line((1, 1), (0, 0))]
    (w,) = check_continuity(loose_wire(*corner)).wires
    assert not w.closed and len(w.joints) == 2
