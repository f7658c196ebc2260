"""G2 fillets: every corner kind in both turning senses, errors, and the CAD paths (build123d, CadQuery, STEP)."""

import math

import numpy as np
import pytest

import spiral_cad as sc
from spiral_cad import Arc, BezierSpiral, Line
from spiral_cad.core.segments import measure_join
from spiral_cad.design.fillets import (
    continuous_polygon,
    continuous_rectangle,
    continuous_slot,
    corner_distance,
    fillet_path,
)


def assert_g2_everywhere(path, closed):
    chain = path.chain  # a Chain only exists when every joint is G2
    if closed:
        j = measure_join(chain[-1], chain[0])
        assert j.gap <= 1e-9 * chain.size and j.angle <= 1e-9 and j.curvature_jump * chain.size <= 1e-8


def corner_curvature_is_monotone_to_radius(path, radius):
    """Within each corner |κ| rises to 1/r and falls, never beyond (a fillet never tightens past r)."""
    for segment in path.segments:
        u = np.linspace(0, 1, 201)
        k = np.abs(np.broadcast_to(segment.curvature(u), u.shape))
        assert k.max() <= 1 / radius * (1 + 1e-9)
        if isinstance(segment, BezierSpiral):
            assert np.all(np.diff(k) >= -1e-12) or np.all(np.diff(k) <= 1e-12)  # monotone on each spiral


@pytest.mark.parametrize("sense", [1, -1])
@pytest.mark.parametrize("transition", [0.2, 0.5, 1.0])
def test_line_line_corners_in_both_senses(sense, transition):
    points = [(0, 0), (40, 0), (40, 25 * sense), (0, 25 * sense), (0, 0)]
    path = fillet_path(points, 4.0, transition=transition)
    assert path.closed and len(path.corners) == 4 and {c.kind for c in path.corners} == {"line-line"}
    assert all(math.copysign(1, c.turn) == sense for c in path.corners)
    assert_g2_everywhere(path, closed=True)
    corner_curvature_is_monotone_to_radius(path, 4.0)
    for c in path.corners:  # the arc makes (1 - transition) of the turn
        assert c.sweep == pytest.approx(abs(c.turn) * (1 - transition), abs=1e-9)
    kinds = [type(s) for s in path.segments]
    assert (Arc in kinds) == (transition < 1)


def test_corner_distance_matches_the_construction():
    path = fillet_path([(0, 0), (40, 0), (40, 30)], 5.0, transition=0.4)
    start = path.corners[0].transitions[0].start
    assert 40 - start[0] == pytest.approx(corner_distance(5.0, math.pi / 2, 0.4), rel=1e-12)


@pytest.mark.parametrize("sense", [1, -1])
@pytest.mark.parametrize("same_sense", ["nested", "C"])
def test_line_arc_corners_of_a_d_shape(sense, same_sense):
    # a D: a straight side closed by a half circle; both corners join a line and an arc turning the same way
    line = Line((0, -10 * sense), (0, 10 * sense))
    arc = Arc((0, 0), 10.0 * sense, math.pi / 2 * sense, math.pi)
    path = fillet_path([line, arc], 2.0, transition=0.5, same_sense=same_sense)
    assert {c.kind for c in path.corners} == {"line-arc", "arc-line"}
    assert_g2_everywhere(path, closed=True)
    arcs = [s for s in path.segments if isinstance(s, Arc)]
    assert any(a.radius == pytest.approx(10.0 * sense) for a in arcs)  # the original arc: a true circle, trimmed
    if same_sense == "nested":
        corner_curvature_is_monotone_to_radius(path, 2.0)
        spirals = [s for s in path.segments if isinstance(s, BezierSpiral)]
        assert len(spirals) == 4  # one spiral from the line, one nested spiral to the arc, per corner


@pytest.mark.parametrize("sense", [1, -1])
def test_line_arc_corner_turning_against_the_arc_uses_an_s(sense):
    # a line, then an arc bending the other way than the corner turns
    phi = 0.6 * sense  # the corner turns by φ; the arc then bends the other way
    center = (10 + 8 * math.sin(phi) * sense, -8 * math.cos(phi) * sense)
    arc = Arc(center, -8.0 * sense, math.atan2(-center[1], 10 - center[0]), 1.0)
    line = Line((0, 0), (10, 0))
    assert np.allclose(arc.start, (10, 0), atol=1e-12)
    assert measure_join(line, arc).angle == pytest.approx(0.6)
    path = fillet_path([line, arc], 1.0, transition=0.5)
    (corner,) = path.corners
    assert corner.kind == "line-arc"
    s_pair = corner.transitions[1]
    assert s_pair.kind == "S"
    assert_g2_everywhere(path, closed=False)


def test_arc_arc_corners():
    a = Arc.between((0, -6), 10.0, (-8, 0), (8, 0))
    b = Arc.between((0, 6), 10.0, (8, 0), (-8, 0))
    path = fillet_path([a, b], 1.0, transition=0.5)
    assert [c.kind for c in path.corners] == ["arc-arc", "arc-arc"]
    assert_g2_everywhere(path, closed=True)


def test_open_paths_keep_their_ends_and_tangent_vertices_stay():
    points = [(0, 0), (30, 0), (60, 0), (60, 40)]  # vertex 1 is straight through
    path = fillet_path(points, 5.0)
    assert [c.vertex for c in path.corners] == [2]
    assert np.allclose(path.segments[0].start, (0, 0)) and np.allclose(path.segments[-1].end, (60, 40))
    only = fillet_path([(0, 0), (30, 0), (30, 30), (0, 30)], 3.0, vertices=[2])
    assert [c.vertex for c in only.corners] == [2]
    with pytest.raises(ValueError, match="not G2"):
        only.chain  # the corner left sharp is not G2


def test_continuous_shapes():
    rect = continuous_rectangle(60, 30, 6)
    assert_g2_everywhere(rect, closed=True)
    slot = continuous_slot(50, 12, transition=1.0)
    assert_g2_everywhere(slot, closed=True)
    assert not any(isinstance(s, Line) and s.length < 1e-9 for s in slot.segments)
    ends = [s for s in slot.segments if isinstance(s, Line)]
    assert len(ends) == 2 and all(
        s.length == pytest.approx(50 - 12 * 1.0 * 0 - 2 * corner_distance(slot.corners[0].radius, math.pi / 2, 1.0), rel=1e-12)
        for s in ends
    )
    hexagon = continuous_polygon(20, 6, 4)
    assert_g2_everywhere(hexagon, closed=True)
    assert max(abs(c.radius) for c in hexagon.corners) == 4


@pytest.mark.parametrize(
    "call, message",
    [
        (lambda: fillet_path([(0, 0), (10, 0), (10, 10)], 50.0), r"corner 1: the fillet needs 52\.8\d* more of edge 0 than it has \(10\)"),
        (
            lambda: fillet_path([(0, 0), (10, 0), (10, 3), (0, 3)], 1.5),
            r"corner 1 and corner 2 both claim the same stretch of edge 1: .*missing 0\.77",
        ),
        (lambda: fillet_path([(0, 0), (10, 0), (10, 10)], 0.0), "radius must be positive"),
        (lambda: fillet_path([(0, 0), (10, 0), (10, 10)], 1.0, transition=1.5), r"transition must lie in \(0, 1\]"),
        (lambda: fillet_path([(0, 0), (10, 0), (0, 0)], 1.0), "folds straight back"),
        (lambda: fillet_path([Line((0, 0), (1, 0)), Line((2, 0), (2, 1))], 0.1), "do not meet"),
        (lambda: fillet_path([Line((0, 0), (1, 0)), sc.BezierSpiral((1, 0), (1, 0), 0.3, 1.0)], 0.1), "segment 1 is a BezierSpiral"),
        (lambda: fillet_path([(0, 0), (10, 0), (10, 10)], 1.0, vertices=[7]), r"vertices \[7\] are not corners"),
        (lambda: fillet_path([(0, 0), (10, 0), (10, 10)], 1.0, same_sense="S"), "same_sense must be one of"),
    ],
)
def test_fillet_errors_name_the_corner_and_the_numbers(call, message):
    with pytest.raises(ValueError, match=message):
        call()


# ------------------------------------------------------------------ CAD


bd = pytest.importorskip("build123d")


def test_g2_fillet_on_sketches_faces_and_wires_with_exact_edges(tmp_path):
    from spiral_cad.build123d import g2_fillet
    from spiral_cad.cad.continuity import check_continuity
    from spiral_cad.cad.export import export_step

    face = g2_fillet(bd.Rectangle(60, 30), 5.0)
    assert [e.geom_type.name for e in face.edges()][:4] == ["LINE", "BEZIER", "CIRCLE", "BEZIER"]
    report = check_continuity(face)
    assert report.passes("G2") and report.wires[0].closed and len(report.joints) == 16  # closing joint included
    path = tmp_path / "face.step"
    export_step(face, path)
    assert check_continuity(path).passes("G2")  # survives the STEP round trip
    wire = g2_fillet(bd.Polyline((0, 0), (10, 0), (10, 10), (0, 10), close=True), 2.0, transition=0.8)
    assert isinstance(wire, bd.Wire) and check_continuity(wire).passes("G2")
    solid = bd.extrude(face, 8)
    assert solid.is_valid and solid.volume == pytest.approx(face.area * 8, rel=1e-9)
    rail = g2_fillet(bd.Polyline((0, 0), (40, 0), (40, 30), (80, 30)), 6.0)
    swept = bd.sweep(bd.Plane(origin=rail @ 0, z_dir=rail % 0) * bd.Circle(1.0), path=rail)
    assert swept.is_valid


@pytest.mark.parametrize("plane", ["XY", "XZ", "YZ"])
def test_g2_fillet_in_build_sketch_on_any_plane(plane):
    from spiral_cad.build123d import g2_fillet
    from spiral_cad.cad.continuity import check_continuity

    with bd.BuildSketch(getattr(bd.Plane, plane)) as sketch:
        bd.Rectangle(40, 20)
        bd.Circle(4, mode=bd.Mode.SUBTRACT)
        g2_fillet(sketch.vertices(), 3.0)
    report = check_continuity(sketch.sketch)
    assert report.pieces == 2 and report.min_level.name == "G2" and sketch.sketch.is_valid
    with bd.BuildLine() as line:
        bd.Polyline((0, 0), (20, 0), (20, 10), (40, 10))
        g2_fillet(line.vertices(), 2.0)
    assert check_continuity(line.line).passes("G2")


def test_continuous_sketch_objects_and_the_comb():
    from spiral_cad.build123d import ContinuousPolygon, ContinuousRectangle, ContinuousSlot, curvature_comb
    from spiral_cad.cad.continuity import check_continuity

    for shape in (ContinuousRectangle(60, 30, 6), ContinuousPolygon(20, 6, 4), ContinuousSlot(50, 12)):
        assert shape.is_valid and check_continuity(shape).passes("G2")
        assert bd.extrude(shape, 3).is_valid
    comb = curvature_comb(ContinuousRectangle(60, 30, 6), per_edge=10)
    assert isinstance(comb, bd.Compound) and len(comb.edges()) > 16 * 10


def test_non_planar_and_non_arc_edges_are_refused():
    from spiral_cad.build123d import g2_fillet

    bent = bd.Wire([bd.Edge.make_line((0, 0, 0), (10, 0, 0)), bd.Edge.make_three_point_arc((10, 0, 0), (12, 0, 2), (10, 0, 4)),
                    bd.Edge.make_line((10, 0, 4), (10, 5, 4))])  # fmt: skip
    with pytest.raises(ValueError, match="planar"):  # in space only wires of lines are rounded (each corner in its plane)
        g2_fillet(bent, 1.0)
    spline = bd.Wire([bd.Edge.make_line((0, 0), (10, 0)), bd.Edge.make_spline([(10, 0), (12, 5), (10, 10)])])
    with pytest.raises(ValueError, match="edge 1 is a BSPLINE curve"):
        g2_fillet(spline, 1.0)


def test_cadquery_sketch_and_workplane():
    cq = pytest.importorskip("cadquery")
    import spiral_cad.cadquery  # noqa: F401
    from spiral_cad.cad.continuity import check_continuity

    sketch = cq.Sketch().rect(40, 20).vertices().g2fillet(4.0)
    assert check_continuity(sketch._faces).passes("G2")
    part = cq.Workplane("XZ").rect(40, 20).g2Fillet(4.0).extrude(5)
    assert part.val().isValid() and check_continuity(part.faces(">Y").wires().val()).passes("G2")
    slots = cq.Workplane().pushPoints([(0, 0), (50, 0)]).continuousSlot2D(30, 10).extrude(2)
    assert len(slots.solids().vals()) == 2
    assert cq.Workplane().continuousRect(30, 20, 3).extrude(1).val().isValid()
    assert check_continuity(cq.Sketch().continuousRect(30, 20, 3)._faces).passes("G2")
    with pytest.raises(ValueError, match="no pending wires|there are none"):
        cq.Workplane().g2Fillet(1.0)
