"""G2 rolls on plates with through holes (issue 41): ``g2_slab`` of an outline with holes, ``g2_fillet`` of a
plate's edges (all of them, or only some rims), and the refusals of what does not fit or is not a plate.

Volumes are checked against Steiner's offset formula evaluated from the segments' and the roll's own
formulas by mpmath (``test_solids``' independent integrals), continuity by the face checker and by
OCCT's evaluators, and, where FreeCAD is installed, the STEP file by FreeCAD's reader.
"""

from __future__ import annotations

import math
import re
import subprocess
import textwrap

import pytest
from build123d import Axis, Box, BuildSketch, Circle, Cylinder, GeomType, Locations, Mode, Pos, fillet
from helpers import freecad_lib
from hypothesis import given, settings
from hypothesis import strategies as st
from OCP.BRepCheck import BRepCheck_Analyzer
from OCP.TopAbs import TopAbs_FORWARD, TopAbs_SOLID
from OCP.TopExp import TopExp_Explorer
from test_solids import _outline_integrals, _profile_integrals, _props

from spiral_cad import Arc
from spiral_cad.build123d import ContinuousRectangle, g2_fillet, g2_slab
from spiral_cad.cad.faces import check_faces
from spiral_cad.cad.prism_fillet import plan_radius
from spiral_cad.cad.solids import roll_profile
from spiral_cad.cad.solids import rolled_slab as occ_slab
from spiral_cad.core.errors import NoSolutionError
from spiral_cad.design.fillets import continuous_rectangle


def _one_forward_valid_solid(shape) -> None:
    explorer, solids = TopExp_Explorer(shape, TopAbs_SOLID), []
    while explorer.More():
        solids.append(explorer.Current())
        explorer.Next()
    assert len(solids) == 1
    assert solids[0].Orientation() == TopAbs_FORWARD
    assert BRepCheck_Analyzer(shape).IsValid()


def _all_g2(shape, sharp: bool = False) -> None:
    """The face checker finds every edge G2, or a sharp feature where ``sharp`` (rims left unrolled)."""
    report = check_faces(shape)
    assert (report.counts["sharp"] > 0) == sharp, report.describe()
    assert report.counts["G2"] == len(report.edges) - report.counts["sharp"] > 0, report.describe()
    assert report.passes("G2")


def _rolled_away(length: float, roll, hole: bool) -> float:
    """Material one roll takes from a rim of ``length`` (Steiner: an outer rim's offset at w loses L·w − πw²,
    a hole's L·w + πw²; the roll takes ∫ that over its height)."""
    w_dz, w2_dz, _, _ = _profile_integrals(roll)
    return length * w_dz + (1.0 if hole else -1.0) * math.pi * w2_dz


@pytest.mark.slow
def test_g2_slab_rolls_the_rims_of_every_hole_and_the_outline():
    plan = continuous_rectangle(60, 40, 8)
    circle = [Arc((15, 0), 4, 0, 2 * math.pi)]
    square = list(continuous_rectangle(10, 10, 3).segments)  # centred on the origin: a rounded-square hole
    slab = occ_slab(plan, 8, 1.2, holes=[circle, square], tolerance=1e-10)
    _one_forward_valid_solid(slab.shape)
    _all_g2(slab.shape)
    roll = roll_profile(1.2)
    (area, length), (a_circle, l_circle), (a_square, l_square) = (_outline_integrals(list(x)) for x in (plan.segments, circle, square))
    expected = 8 * (area - a_circle - a_square) - 2 * (
        _rolled_away(length, roll, False) + _rolled_away(l_circle, roll, True) + _rolled_away(l_square, roll, True)
    )
    assert _props(slab.shape)[0] == pytest.approx(expected, rel=1e-9)
    assert 0.0 < slab.approximation <= 1e-10  # the plan's spirals are approximated, within the tolerance


def test_a_build123d_face_with_holes_makes_a_slab_rolled_top_and_bottom_on_every_rim():
    with BuildSketch() as sketch:
        ContinuousRectangle(50, 30, 6)
        with Locations((12, 0), (-12, 0)):
            Circle(4, mode=Mode.SUBTRACT)
    part = g2_slab(sketch.sketch, 6, 1)
    _one_forward_valid_solid(part.wrapped)
    _all_g2(part.wrapped)
    sharp = sketch.sketch.faces()[0].area * 6
    assert sharp - 6 * (50 + 30) * 2 * 1.26**2 < part.volume < sharp  # within the sharp slab, rolls ≤ reach² deep
    top_only = g2_slab(sketch.sketch, 6, 1, bottom=False)
    _all_g2(top_only.wrapped, sharp=True)  # the bottom rims stay sharp: the outline's and two holes'
    assert part.volume < top_only.volume < sharp


def test_holes_that_cross_the_outline_or_each_other_are_malformed():
    plan = continuous_rectangle(60, 40, 8)
    with pytest.raises(ValueError, match=r"holes must lie inside the outline .* hole 0's rim"):
        occ_slab(plan, 8, 1, holes=[[Arc((29, 0), 4, 0, 2 * math.pi)]])
    with pytest.raises(ValueError, match=r"hole 0's rim and hole 1's rim cross or nest"):
        occ_slab(plan, 8, 1, holes=[[Arc((0, 0), 4, 0, 2 * math.pi)], [Arc((3, 0), 4, 0, 2 * math.pi)]])
    for inner, outer in ((0, 1), (1, 0)):  # a hole inside another, either order
        nested = [[Arc((0, 0), 2, 0, 2 * math.pi)], [Arc((0, 0), 6, 0, 2 * math.pi)]]
        with pytest.raises(ValueError, match=r"cross or nest"):
            occ_slab(plan, 8, 1, holes=[nested[inner], nested[outer]])


def test_the_plate_with_a_hole_from_the_issue_is_rounded_g2_on_every_edge(tmp_path):
    plate = Box(100, 60, 10) - Pos(20, 0, 0) * Cylinder(5, 10)
    rounded = g2_fillet(plate.edges(), 1.5)
    _one_forward_valid_solid(rounded.wrapped)
    _all_g2(rounded.wrapped)
    reach = float(roll_profile(1.5)[-1].end[0])
    corners = plan_radius(1.5)
    rims = (2 * (100 + 60) + 2 * math.pi * (5 + reach)) * 2 * reach**2  # each roll takes less than reach² per length
    assert plate.volume - 10 * 4 * corners**2 - rims < rounded.volume < plate.volume
    from spiral_cad.cad.export import export_step

    export_step(rounded, tmp_path / "plate.step")  # the approximation of the sweeps over the plan's spirals, noted
    assert "sweeps over spirals approximated within" in (tmp_path / "plate.step").read_text()
    bb = rounded.bounding_box()
    assert (bb.min.X, bb.max.X, bb.min.Z, bb.max.Z) == pytest.approx((-50, 50, -5, 5), abs=1e-6)


def _four_holes():
    return Box(100, 60, 10) - [Pos(x, y, 0) * Cylinder(5, 10) for x in (-30, 30) for y in (-15, 15)]


def test_only_the_chosen_rims_are_rolled_and_the_rest_stays_sharp():
    plate = _four_holes()
    rounded = g2_fillet(plate.edges().filter_by(GeomType.CIRCLE), 1.5)
    _one_forward_valid_solid(rounded.wrapped)
    _all_g2(rounded.wrapped, sharp=True)  # the box's 12 edges, unchosen
    for edge in check_faces(rounded.wrapped).edges:  # and only those: every sharp edge lies on the box's sides
        x, y, _ = edge.angle_at
        assert edge.level != "sharp" or abs(abs(x) - 50) < 1e-6 or abs(abs(y) - 30) < 1e-6, edge
    roll = roll_profile(1.5)
    assert rounded.volume == pytest.approx(plate.volume - 8 * _rolled_away(2 * math.pi * 5, roll, True), rel=1e-9)
    top_rims = plate.edges().filter_by(GeomType.CIRCLE).group_by(Axis.Z)[-1]
    tops = g2_fillet(top_rims + plate.edges().filter_by(Axis.Z), 1.5)  # box corners and the holes' top rims
    _one_forward_valid_solid(tops.wrapped)
    _all_g2(tops.wrapped, sharp=True)  # the box's top and bottom rims, the holes' bottom rims


def test_a_rim_chosen_in_part_is_refused_naming_the_edge_left_out():
    plate = Box(60, 40, 8) - Box(10, 10, 8)  # a square through hole
    top = plate.edges().group_by(Axis.Z)[-1]
    hole_edges = [e for e in top if abs(e.center().X) < 6 and abs(e.center().Y) < 6]
    assert len(hole_edges) == 4
    with pytest.raises(NoSolutionError, match=r"top cap's rim of hole 0 the edge at .* is not chosen while other edges"):
        g2_fillet(hole_edges[:3] + plate.edges().filter_by(Axis.Z), 1)
    with pytest.raises(NoSolutionError, match=r"the side edge at .* is sharp and not chosen"):
        g2_fillet(hole_edges, 1)  # a roll cannot turn the hole's sharp corner
    rounded = g2_fillet(hole_edges + plate.edges().filter_by(Axis.Z), 1)  # with the corners: G2
    _one_forward_valid_solid(rounded.wrapped)
    _all_g2(rounded.wrapped, sharp=True)  # the outer top and bottom rims, the hole's bottom rim


def _suggested(error: pytest.ExceptionInfo) -> float:
    found = re.search(r"radius up to ([0-9.e+-]+) fits", str(error.value))
    assert found, str(error.value)
    return float(found.group(1))


@pytest.mark.slow
def test_a_wall_thinner_than_the_rolls_is_refused_naming_a_radius_that_builds():
    thin = Box(100, 60, 10) - Pos(45, 0, 0) * Cylinder(4, 10)  # a wall 1 thick between the hole and the side
    with pytest.raises(NoSolutionError, match=r"hole 0's rim meet near \((4\d\.\d+|50), .*the material between them is 1 wide") as error:
        g2_fillet(thin.edges(), 1.5)
    radius = _suggested(error)
    reach = float(roll_profile(1.0)[-1].end[0])
    assert 0.9 * 1.0 / (2 * reach) < radius < 1.0 / (2 * reach)  # two rolls across the 1 mm wall
    built = g2_fillet(thin.edges(), radius)
    _one_forward_valid_solid(built.wrapped)
    plan = continuous_rectangle(60, 40, 8)
    with pytest.raises(NoSolutionError, match=r"hole 0's rim and hole 1's rim meet") as error:
        occ_slab(plan, 8, 2, holes=[[Arc((-5, 0), 4, 0, 2 * math.pi)], [Arc((5, 0), 4, 0, 2 * math.pi)]])
    occ_slab(plan, 8, _suggested(error), holes=[[Arc((-5, 0), 4, 0, 2 * math.pi)], [Arc((5, 0), 4, 0, 2 * math.pi)]])


def test_a_step_the_same_all_along_one_axis_is_a_prism_across():  # pockets and bosses: test_stacks
    step = Box(100, 60, 10) + Pos(0, 0, 7) * Box(30, 60, 4)  # the same section all along y: a prism along y
    rounded = g2_fillet(step.edges().filter_by(Axis.Y), 1)
    _one_forward_valid_solid(rounded.wrapped)


FREECAD = freecad_lib()
READ = textwrap.dedent(
    """
    import sys
    sys.path.append(sys.argv[1])
    import FreeCAD, Part  # Part alone, without FreeCAD's application first, crashes on reading (SIGSEGV)
    shape = Part.read(sys.argv[2])
    print(len(shape.Solids), shape.isValid(), repr(shape.Volume))
    """
)


@pytest.mark.skipif(FREECAD is None, reason="FreeCAD is not installed (Debian/Ubuntu: apt-get install freecad-python3)")
def test_freecad_reads_the_rounded_plate_as_one_valid_solid(tmp_path):
    freecad_reads_one_valid_solid(g2_fillet(_four_holes().edges(), 1.5), tmp_path / "plate.step")


def freecad_reads_one_valid_solid(part, path) -> None:
    """FreeCAD reads ``part``'s STEP file (written to ``path``) as one valid solid of the same volume."""
    from spiral_cad.cad.export import export_step

    export_step(part, path)
    run = subprocess.run(["/usr/bin/python3", "-c", READ, FREECAD, str(path)], capture_output=True, text=True, timeout=600)
    assert run.returncode == 0, run.stderr[-2000:]
    solids, valid, volume = run.stdout.split()[-3:]
    assert (solids, valid) == ("1", "True")
    assert float(volume) == pytest.approx(part.volume, rel=1e-9)


def test_build123d_circular_fillet_of_the_same_edges_is_only_g1():  # the baseline the G2 plate is measured beside
    plate = _four_holes()
    circular = fillet(plate.edges(), 1.5)
    report = check_faces(circular.wrapped)
    assert report.counts["G1"] > 0 and not report.passes("G2")


def test_cadquery_g2_fillet_of_a_plates_edges_is_the_build123d_part():
    import cadquery as cq

    import spiral_cad.cadquery  # noqa: F401  (registers the methods)

    plate = cq.Workplane("XY").box(100, 60, 10).faces(">Z").workplane().center(20, 0).hole(10)
    rounded = plate.edges().g2Fillet(1.5).val()
    assert rounded.isValid() and len(rounded.Solids()) == 1
    ours = g2_fillet((Box(100, 60, 10) - Pos(20, 0, 0) * Cylinder(5, 10)).edges(), 1.5)
    assert rounded.Volume() == pytest.approx(ours.volume, rel=1e-9)


@pytest.mark.slow
def test_a_square_hole_too_small_for_the_plan_corners_is_refused_on_its_rim_with_a_radius_that_builds():
    plate = Box(60, 40, 8) - Box(4, 4, 8)
    with pytest.raises(NoSolutionError, match=r"on the rim of hole 0 \(near \(-?2, -?2, -4\)\): radius 1.5 rounds") as error:
        g2_fillet(plate.edges(), 1.5)
    radius = _suggested(error)
    assert plan_radius(radius) < 2.0  # two plan corners fit along the 4 mm side
    built = g2_fillet(plate.edges(), radius)
    _one_forward_valid_solid(built.wrapped)
    _all_g2(built.wrapped)


@pytest.mark.slow
@settings(max_examples=5, deadline=None)
@given(
    st.lists(st.tuples(st.integers(0, 3), st.integers(0, 1), st.floats(0.5, 6.0)), max_size=4, unique_by=lambda h: h[:2]),
    st.floats(0.2, 2.5),
    st.floats(4.0, 12.0),
)
def test_property_random_plates_with_holes_round_g2_or_name_a_radius_that_builds(holes, radius, height):
    plate = Box(100, 44, height)
    for i, j, r in holes:  # on a 25 × 25 grid: apart and inside the plate, walls from 3.5 mm up
        plate = plate - Pos(-37.5 + 25 * i, -12.5 + 25 * j, 0) * Cylinder(r, height)
    try:
        rounded = g2_fillet(plate.edges(), radius)
    except NoSolutionError as error:
        found = re.search(r"radius up to ([0-9.e+-]+) fits", str(error))
        assert found or "no radius fits" in str(error), str(error)
        if found:
            rounded = g2_fillet(plate.edges(), float(found.group(1)))
        else:
            return
    _one_forward_valid_solid(rounded.wrapped)
    _all_g2(rounded.wrapped)
    assert 0.8 * plate.volume < rounded.volume < plate.volume
