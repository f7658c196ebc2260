"""``check`` of IFC 4.3 alignments (spiral_cad.io.ifc_check): buildingSMART's own validation files for the
rules of position and gradient continuity (ALS016, ALS017), our own export, and edited copies."""

from __future__ import annotations

import math
import shutil
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
from helpers import curve_road

ifcopenshell = pytest.importorskip("ifcopenshell")

import spiral_cad as sc  # noqa: E402
from spiral_cad.app.cli import main  # noqa: E402
from spiral_cad.continuity import Continuity  # noqa: E402
from spiral_cad.io.ifc_check import _profile_frames, check_ifc  # noqa: E402

DATA = Path(__file__).parents[1] / "data" / "ifc"


def _levels(report, kind: str) -> list[str]:
    return [str(j.level) for w in report.wires if w.kind == kind for j in w.joints]


def test_buildingsmarts_break_in_position_is_found_where_the_rule_finds_it():
    """ALS016's failing file: the second horizontal segment starts 2.6 cm (0.0857 ft) from where the first ends."""
    report = check_ifc(DATA / "fail-als016-scenario01-imperial_break_in_position.ifc")
    assert report.units == "ft" and report.min_level == Continuity.NONE
    (plan,) = [w for w in report.wires if w.kind == "plan"]
    assert plan.joints[0].gap == pytest.approx(0.0857, abs=5e-4) and plan.joints[0].level == Continuity.NONE
    assert all(j.level >= Continuity.G1 for j in plan.joints[1:])  # lines meet arcs: G1, tangent
    passing = check_ifc(DATA / "pass-als017-scenario01-imperial_continuous.ifc")  # the same road, joined
    assert _levels(passing, "plan") == ["G1"] * 6 and passing.min_level == Continuity.G1


def test_buildingsmarts_break_in_vertical_gradient_is_a_kink_in_the_profile():
    """ALS017's failing file: every vertical segment starts with a gradient 0.01 off the one before ends with."""
    report = check_ifc(DATA / "fail-als017-scenario02-metric_break_in_vertical_gradient.ifc")
    (profile,) = [w for w in report.wires if w.kind == "profile"]
    assert [j.level for j in profile.joints] == [Continuity.G0] * 5
    assert all(j.gap < 1e-9 and j.angle == pytest.approx(math.atan(0.01), rel=1e-6) for j in profile.joints)
    clean = check_ifc(DATA / "pass-als016-scenario01-metric_continuous.ifc")  # a line, a clothoid and an arc
    assert _levels(clean, "plan") == ["G2", "G2"] and clean.units == "m"


def test_a_profile_is_judged_on_its_gradient_curve_not_only_its_numbers():
    """ALS017's imperial failing file: the vertical segments' numbers meet, the gradient curve's segments do not."""
    report = check_ifc(DATA / "fail-als017-scenario02-imperial_break_in_direction_angle.ifc")
    (profile,) = [w for w in report.wires if w.kind == "profile"]
    gaps = [j.gap * 0.3048 for j in profile.joints]  # ft to m
    assert [str(j.level) for j in profile.joints][1::2] == ["none"] * 4
    assert max(gaps) == pytest.approx(0.0408, abs=5e-4) and min(gaps[1::2]) > 0.018


def test_a_georeferenced_plan_keeps_its_tolerance_beside_a_profile_from_zero(tmp_path):
    """The plan at 5e6 m and the profile at 0 are two pieces, not one 7e6 m model: a 0.5 m gap is still found."""
    model = ifcopenshell.open(str(DATA / "pass-als016-scenario01-metric_continuous.ifc"))
    (curve,) = [c for c in model.by_type("IfcCompositeCurve") if c.is_a() == "IfcCompositeCurve"]
    for k, segment in enumerate(curve.Segments):
        location = segment.Placement.Location
        shift = 0.5 if k >= 2 else 0.0  # the arc and what follows 0.5 m east: a gap where the clothoid ends
        location.Coordinates = (location.Coordinates[0] + 5e6 + shift, location.Coordinates[1] + 5e6)
    model.write(str(tmp_path / "far.ifc"))
    report = check_ifc(tmp_path / "far.ifc")
    assert {w.kind for w in report.wires} == {"plan", "profile"}
    assert report.size < 1e3 and report.gap_tol < 1e-3 and _levels(report, "plan") == ["G2", "none"]


def test_a_file_cut_short_is_refused_not_judged_on_what_is_left(tmp_path):
    text = (DATA / "pass-als017-scenario01-imperial_continuous.ifc").read_bytes()
    (tmp_path / "cut.ifc").write_bytes(text[: len(text) // 2])
    with pytest.raises(ValueError, match=r"cut.ifc: the file ends before END-ISO-10303-21; \(cut short\)"):
        check_ifc(tmp_path / "cut.ifc")


@pytest.mark.parametrize("units", ["m", "ft"])
def test_our_alignment_is_g2_at_every_joint_where_the_chain_joins(tmp_path, units):
    chain = curve_road(units)
    sc.export(chain, tmp_path / "road.ifc")
    report = sc.check(tmp_path / "road.ifc")
    (plan,) = report.wires
    assert report.units == units and plan.kind == "plan" and report.min_level == Continuity.G2
    joints = np.array([j.point for j in plan.joints])[:, :2]
    assert np.abs(joints - chain.point_at(chain.stations[1:-1])).max() < 1e-6 * chain.length


def test_an_edited_circle_is_a_curvature_jump_an_edited_layout_a_note_and_a_moved_segment_a_gap(tmp_path):
    chain = curve_road("m")
    sc.export(chain, tmp_path / "road.ifc")
    model = ifcopenshell.open(str(tmp_path / "road.ifc"))
    (circle,) = model.by_type("IfcCircle")
    circle.Radius = circle.Radius * 1.01  # the curve's arc is another than the spirals end on
    model.write(str(tmp_path / "circle.ifc"))
    report = check_ifc(tmp_path / "circle.ifc")
    assert _levels(report, "plan")[1] == "G1"
    assert report.wires[0].joints[1].curvature_jump == pytest.approx(1 / 40 - 1 / 40.4, rel=1e-6)
    model = ifcopenshell.open(str(tmp_path / "road.ifc"))
    arc = next(p for p in model.by_type("IfcAlignmentHorizontalSegment") if p.PredefinedType == "CIRCULARARC")
    arc.StartRadiusOfCurvature = arc.StartRadiusOfCurvature * 1.01  # the layout says another radius than its curve
    model.write(str(tmp_path / "radius.ifc"))
    report = check_ifc(tmp_path / "radius.ifc")
    assert _levels(report, "plan") == ["G2"] * 4  # the curve is judged: it is continuous
    assert any("plan segment 2 starts with curvature 0.025, not the 0.0247525 its layout states" in n for n in report.notes)
    model = ifcopenshell.open(str(tmp_path / "road.ifc"))
    segment = model.by_type("IfcCompositeCurve")[0].Segments[2]  # the arc's curve segment, moved 1 mm
    location = segment.Placement.Location
    location.Coordinates = (location.Coordinates[0] + 0.001, location.Coordinates[1])
    model.write(str(tmp_path / "moved.ifc"))
    report = check_ifc(tmp_path / "moved.ifc")
    assert _levels(report, "plan")[1:3] == ["none", "none"]
    assert report.wires[0].joints[1].gap == pytest.approx(0.001, rel=1e-3)


@pytest.mark.parametrize("units", ["m", "mm", "ft"])
def test_curvature_is_in_the_files_unit_and_a_jump_of_a_large_radius_is_found(tmp_path, units):
    """A line, an arc of radius 200 km and one of 100 km: κ jumps 0 → 1/R → 2/R, per the file's unit (in mm,
    5e-9 against 1/size: found, not lost in a unit's factor)."""
    import ifcopenshell.api.alignment as alignment_api
    import ifcopenshell.api.context
    import ifcopenshell.api.root
    import ifcopenshell.api.unit

    scale = {"m": 1.0, "mm": 1000.0, "ft": 1 / 0.3048}[units]
    model = ifcopenshell.file(schema="IFC4X3_ADD2")
    ifcopenshell.api.root.create_entity(model, ifc_class="IfcProject", name="P")
    unit = (ifcopenshell.api.unit.add_conversion_based_unit(model, name="foot") if units == "ft"
            else ifcopenshell.api.unit.add_si_unit(model, unit_type="LENGTHUNIT", prefix="MILLI" if units == "mm" else None))  # fmt: skip
    ifcopenshell.api.unit.assign_unit(model, units=[unit])
    ifcopenshell.api.context.add_context(model, context_type="Model")
    layout = alignment_api.get_horizontal_layout(alignment_api.create(model, "A"))
    radius, x, y, heading = 200_000 * scale, 0.0, 0.0, 0.0
    for kind, r in (("LINE", 0.0), ("CIRCULARARC", radius), ("CIRCULARARC", radius / 2)):
        design = model.createIfcAlignmentHorizontalSegment(StartPoint=model.createIfcCartesianPoint((x, y)), StartDirection=heading,
                                                           StartRadiusOfCurvature=r, EndRadiusOfCurvature=r, SegmentLength=50 * scale,
                                                           PredefinedType=kind)  # fmt: skip
        end = alignment_api.create_layout_segment(model, layout, design)
        x, y, heading = (
            end[0][3] / (1 if units == "m" else 0.001 if units == "mm" else 0.3048),
            end[1][3] / (1 if units == "m" else 0.001 if units == "mm" else 0.3048),
            math.atan2(end[1][0], end[0][0]),
        )
    model.write(str(tmp_path / "arcs.ifc"))
    report = check_ifc(tmp_path / "arcs.ifc")
    (plan,) = report.wires
    assert report.units == units and [str(j.level) for j in plan.joints] == ["G1", "G1"]
    measured = [k for j in plan.joints for k in (j.curvature_before, j.curvature_after)]
    assert measured == pytest.approx([0.0, 1 / radius, 1 / radius, 2 / radius], rel=1e-9)


def test_a_helmert_curve_drawn_as_two_curve_segments_is_judged_on_its_curve(tmp_path):
    """IFC 4.3 draws a HELMERTCURVE layout segment as two IfcSecondOrderPolynomialSpiral: the layout no longer
    matches the curve one for one, and the curve's own curvatures are judged (G2 into the arc, G1 between arcs)."""
    import ifcopenshell.api.alignment as alignment_api
    import ifcopenshell.api.context
    import ifcopenshell.api.root
    import ifcopenshell.api.unit

    model = ifcopenshell.file(schema="IFC4X3_ADD2")
    ifcopenshell.api.root.create_entity(model, ifc_class="IfcProject", name="P")
    ifcopenshell.api.unit.assign_unit(model, units=[ifcopenshell.api.unit.add_si_unit(model, unit_type="LENGTHUNIT")])
    ifcopenshell.api.context.add_context(model, context_type="Model")
    layout = alignment_api.get_horizontal_layout(alignment_api.create(model, "H"))
    x, y, heading = 0.0, 0.0, 0.0
    for kind, r0, r1, length in (
        ("LINE", 0, 0, 100),
        ("HELMERTCURVE", 0, 300, 60),
        ("CIRCULARARC", 300, 300, 80),
        ("CIRCULARARC", 500, 500, 80),
    ):
        design = model.createIfcAlignmentHorizontalSegment(StartPoint=model.createIfcCartesianPoint((x, y)), StartDirection=heading,
                                                           StartRadiusOfCurvature=float(r0), EndRadiusOfCurvature=float(r1),
                                                           SegmentLength=float(length), PredefinedType=kind)  # fmt: skip
        end = alignment_api.create_layout_segment(model, layout, design)
        x, y, heading = end[0][3], end[1][3], math.atan2(end[1][0], end[0][0])
    model.write(str(tmp_path / "helmert.ifc"))
    report = check_ifc(tmp_path / "helmert.ifc")
    assert [str(j.level) for j in report.wires[0].joints] == ["G2", "G2", "G2", "G1"]
    assert any("plan: 5 layout segments for 6 curve segments" in n for n in report.notes)


def test_a_vertical_circular_arc_ends_where_its_circle_takes_it():
    """A crest of radius 2000 from +2 % to −3 %: its end height and curvature are the circle's."""
    radius, g0, g1 = 2000.0, 0.02, -0.03
    t0, t1 = math.atan(g0), math.atan(g1)
    length = radius * (math.sin(t0) - math.sin(t1))
    arc = SimpleNamespace(HorizontalLength=length, StartDistAlong=100.0, StartHeight=50.0, StartGradient=g0, EndGradient=g1,
                          PredefinedType="CIRCULARARC", is_a=lambda kind: kind == "IfcAlignmentVerticalSegment")  # fmt: skip
    ((start, end),), lengths = _profile_frames([arc], "crest", [])
    assert lengths == [length]
    assert end[1] == pytest.approx(50.0 + radius * (math.cos(t1) - math.cos(t0)), rel=1e-12)
    assert math.hypot(end[6], end[7]) == pytest.approx(1.0 / radius, rel=1e-12) and end[7] < 0  # a crest bends down
    notes: list[str] = []
    frames, _ = _profile_frames([SimpleNamespace(**{**vars(arc), "PredefinedType": "CLOTHOID"})], "crest", notes)
    assert math.isnan(frames[0][1][7]) and "vertical CLOTHOID segments are not measured" in notes[0]


def test_the_command_judges_an_ifc_file_and_refuses_what_does_not_apply(tmp_path, capsys):
    passing = str(DATA / "pass-als016-scenario01-metric_continuous.ifc")
    assert main(["check", passing, "--require", "G2", "--quiet"]) == 0  # its plan and its profile: two pieces, as found
    assert "OK: 1 plan of 3 segments and 1 profile of 1 segment" in capsys.readouterr().out
    assert main(["check", str(DATA / "fail-als016-scenario01-imperial_break_in_position.ifc"), "--require", "G0"]) == 1
    assert "FAIL: worst joint is none" in capsys.readouterr().out
    for options, message in ((["--units", "m"], "an IFC file states its unit"), (["--comb", str(tmp_path / "c.step")], "an IFC file is judged on its numbers"),
                             (["--html", str(tmp_path / "page.html")], "is judged on its own numbers")):  # fmt: skip
        assert main(["check", passing, *options]) == 2
        assert message in capsys.readouterr().err
    (tmp_path / "text.ifc").write_text("not IFC")
    assert main(["check", str(tmp_path / "text.ifc")]) == 2
    assert "text.ifc: not a readable IFC file" in capsys.readouterr().err
    old = tmp_path / "old.ifc"
    shutil.copy(passing, old)
    old.write_text(old.read_text().replace("FILE_SCHEMA(('IFC4X3_ADD2'));", "FILE_SCHEMA(('IFC4'));"))
    with pytest.raises(ValueError, match="old.ifc: alignments are IFC 4.3; this file is IFC4"):
        check_ifc(old)
