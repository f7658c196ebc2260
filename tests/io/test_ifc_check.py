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


@pytest.mark.parametrize("units", ["m", "ft"])
def test_our_alignment_is_g2_at_every_joint_where_the_chain_joins(tmp_path, units):
    chain = curve_road(units)
    sc.export(chain, tmp_path / "road.ifc")
    report = sc.check(tmp_path / "road.ifc")
    (plan,) = report.wires
    assert report.units == units and plan.kind == "plan" and report.min_level == Continuity.G2
    joints = np.array([j.point for j in plan.joints])[:, :2]
    assert np.abs(joints - chain.point_at(chain.stations[1:-1])).max() < 1e-6 * chain.length


def test_an_edited_radius_is_a_curvature_jump_and_a_moved_segment_a_gap(tmp_path):
    chain = curve_road("m")
    sc.export(chain, tmp_path / "road.ifc")
    model = ifcopenshell.open(str(tmp_path / "road.ifc"))
    arc = next(p for p in model.by_type("IfcAlignmentHorizontalSegment") if p.PredefinedType == "CIRCULARARC")
    arc.StartRadiusOfCurvature = arc.StartRadiusOfCurvature * 1.01  # the design says another radius than the spiral's end
    model.write(str(tmp_path / "radius.ifc"))
    levels = _levels(check_ifc(tmp_path / "radius.ifc"), "plan")
    assert levels == ["G2", "G1", "G2", "G2"]
    model = ifcopenshell.open(str(tmp_path / "road.ifc"))
    segment = model.by_type("IfcCompositeCurve")[0].Segments[2]  # the arc's curve segment, moved 1 mm
    location = segment.Placement.Location
    location.Coordinates = (location.Coordinates[0] + 0.001, location.Coordinates[1])
    model.write(str(tmp_path / "moved.ifc"))
    report = check_ifc(tmp_path / "moved.ifc")
    assert _levels(report, "plan")[1:3] == ["none", "none"]
    assert report.wires[0].joints[1].gap == pytest.approx(0.001, rel=1e-3)


def test_a_vertical_circular_arc_ends_where_its_circle_takes_it():
    """A crest of radius 2000 from +2 % to −3 %: its end height and curvature are the circle's."""
    radius, g0, g1 = 2000.0, 0.02, -0.03
    t0, t1 = math.atan(g0), math.atan(g1)
    length = radius * (math.sin(t0) - math.sin(t1))
    arc = SimpleNamespace(HorizontalLength=length, StartDistAlong=100.0, StartHeight=50.0, StartGradient=g0, EndGradient=g1,
                          PredefinedType="CIRCULARARC")  # fmt: skip
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
