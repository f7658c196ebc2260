"""make_g2 front doors: build123d ``make_g2`` (Wire, Face, Sketch, Curve) and CadQuery ``makeG2``.

Judged by OCCT, not by the numbers that built them: every joint's curvature from OCCT's own
``BRepLProp_CLProps`` on each side, the edge types OCCT reports (CIRCLE kept), and the distance
of dense points of each result to the input shape by ``BRepExtrema_DistShapeShape``.
"""

import math
import re

import numpy as np
import pytest

build123d = pytest.importorskip("build123d")
cq = pytest.importorskip("cadquery")

from build123d import BuildSketch, Circle, Compound, Curve, Face, GeomType, Mode, Rectangle, SlotOverall, Vertex, Wire, fillet
from OCP.BRepAdaptor import BRepAdaptor_Curve
from OCP.BRepExtrema import BRepExtrema_DistShapeShape
from OCP.BRepLProp import BRepLProp_CLProps
from OCP.BRepTools import BRepTools_WireExplorer
from OCP.gp import gp_Dir
from OCP.TopAbs import TopAbs_REVERSED
from OCP.TopoDS import TopoDS

import spiral_cad.cadquery  # noqa: F401  (registers makeG2)
from spiral_cad import NoSolutionError
from spiral_cad.build123d import make_g2


def _signed_curvature(edge, at_end: bool) -> float:
    """OCCT's curvature of an edge at its travel end (start), signed about +Z in travel sense."""
    curve = BRepAdaptor_Curve(edge)
    reverse = edge.Orientation() == TopAbs_REVERSED
    u = (
        (curve.FirstParameter() if reverse else curve.LastParameter())
        if at_end
        else (curve.LastParameter() if reverse else curve.FirstParameter())
    )
    props = BRepLProp_CLProps(curve, u, 2, 1e-9)
    k = props.Curvature()
    if k < 1e-12:
        return 0.0
    tangent, normal = gp_Dir(), gp_Dir()
    props.Tangent(tangent)
    props.Normal(normal)
    side = tangent.X() * normal.Y() - tangent.Y() * normal.X()
    return math.copysign(k, side)


def _wire_curvature_jumps(wire) -> list[float]:
    """Relative curvature jump at every joint of a closed wire (closing joint included), OCCT's numbers."""
    edges = []
    explorer = BRepTools_WireExplorer(wire.wrapped)
    while explorer.More():
        edges.append(TopoDS.Edge_s(explorer.Current()))
        explorer.Next()
    jumps = []
    for a, b in zip(edges, edges[1:] + edges[:1]):
        ka, kb = _signed_curvature(a, True), _signed_curvature(b, False)
        jumps.append(abs(ka - kb) / max(abs(ka), abs(kb), 1e-3))
    return jumps


def _max_distance(result, reference) -> float:
    """Largest OCCT distance from points along ``result``'s edges to the ``reference`` shape."""
    worst = 0.0
    for edge in result.edges():
        for t in np.linspace(0.0, 1.0, 25):
            probe = Vertex(*edge.position_at(t))
            measure = BRepExtrema_DistShapeShape(probe.wrapped, reference.wrapped)
            worst = max(worst, measure.Value())
    return worst


def _hausdorff(a, b) -> float:
    return max(_max_distance(a, b), _max_distance(b, a))


def test_filleted_rectangle_sketch_becomes_g2_within_the_bound():
    rounded = fillet(Rectangle(10, 6).vertices(), 1)
    jumps = _wire_curvature_jumps(rounded.faces()[0].outer_wire())
    assert max(jumps) > 0.5  # fillet(): curvature jumps from 0 to 1 at every tangent joint
    made = make_g2(rounded, 0.01)
    assert type(made) is type(rounded)
    wire = made.faces()[0].outer_wire()
    assert max(_wire_curvature_jumps(wire)) < 1e-6
    kinds = [e.geom_type for e in made.edges()]
    assert kinds.count(GeomType.CIRCLE) == 4 and kinds.count(GeomType.LINE) == 4 and kinds.count(GeomType.BEZIER) == 8
    assert _hausdorff(made, rounded) <= 0.01 * (1 + 1e-6)
    assert made.area == pytest.approx(rounded.area, abs=0.01 * 32)  # within the band the bound allows


def test_slot_wire_and_face_with_a_hole_keep_their_kind():
    slot = SlotOverall(10, 3)
    made = make_g2(slot, 0.005)
    assert max(_wire_curvature_jumps(made.faces()[0].outer_wire())) < 1e-6
    assert [e.geom_type for e in made.edges()].count(GeomType.CIRCLE) == 2
    assert _hausdorff(made, slot) <= 0.005 * (1 + 1e-6)
    with BuildSketch() as sketch:
        Rectangle(20, 20)
        fillet(sketch.vertices(), 2)
        Circle(3, mode=Mode.SUBTRACT)
    face = sketch.sketch.faces()[0]
    made_face = make_g2(face, 0.05)
    assert isinstance(made_face, Face) and len(made_face.inner_wires()) == 1
    assert made_face.is_valid
    wire = face.outer_wire()
    made_wire = make_g2(wire, 0.05)
    assert isinstance(made_wire, Wire) and made_wire.is_closed
    curve = make_g2(Curve(Compound([wire]).wrapped), 0.05)
    assert isinstance(curve, Curve) and len(curve.edges()) == len(made_wire.edges())


def _edge_points(shape) -> np.ndarray:
    return np.array([tuple(e.position_at(t)) for e in shape.edges() for t in np.linspace(0.0, 1.0, 9)])


def test_make_g2_twice_changes_nothing():
    """make_g2 of its own output, and of a ContinuousRectangle (BEZIER spirals, CIRCLE arcs), keeps every edge."""
    from spiral_cad.build123d import ContinuousRectangle

    once = make_g2(fillet(Rectangle(10, 6).vertices(), 1), 0.01)
    twice = make_g2(once, 0.01)
    assert [e.geom_type for e in twice.edges()] == [e.geom_type for e in once.edges()]
    assert np.abs(_edge_points(twice) - _edge_points(once)).max() < 1e-9
    rectangle = ContinuousRectangle(40, 20, 5)
    made = make_g2(rectangle, 0.1)
    assert len(made.edges()) == len(rectangle.edges())
    assert max(_wire_curvature_jumps(made.faces()[0].outer_wire())) < 1e-6
    assert _hausdorff(made, rectangle) < 1e-9
    # A kinked joint (a line turned by 1e-4 rad into the arc), as CAD exports have: made G2 too.
    arc = build123d.CenterArc((10, 5), 5, -90 + math.degrees(1e-4), 90)
    wire = Wire([build123d.Line((0, 0), arc.edges()[0].position_at(0)), arc.edges()[0]])
    made_wire = make_g2(wire, 0.01)
    assert [e.geom_type for e in made_wire.edges()] == [GeomType.LINE, GeomType.BEZIER, GeomType.CIRCLE]
    assert _hausdorff(made_wire, wire) <= 0.01 * (1 + 1e-6)


def test_cadquery_workplane_and_sketch():
    wp = cq.Workplane("XY").slot2D(10, 3).makeG2(0.01)
    solid = wp.extrude(2).val()
    assert solid.isValid()
    assert [e.geomType() for e in wp.val().Edges()].count("CIRCLE") == 2
    sketch = cq.Sketch().rect(10, 6).vertices().fillet(1).reset().makeG2(0.01)
    edges = sketch._faces.Edges()
    assert [e.geomType() for e in edges].count("BEZIER") == 8
    assert cq.Workplane().placeSketch(sketch).extrude(1).val().isValid()


def test_refusal_passes_through():
    with pytest.raises(NoSolutionError, match="works"):
        make_g2(fillet(Rectangle(10, 6).vertices(), 1).moved(build123d.Location((1e7, 1e7))), 1e-13)
    with pytest.raises(ValueError, match="planar Wire"):
        make_g2(build123d.Box(1, 1, 1), 0.1)


def test_check_of_a_g1_file_says_the_smallest_bound_that_makes_it_g2(tmp_path, capsys):
    """``spiral-cad check`` of a STEP file of a filleted rectangle (written by build123d, read back by
    OCCT's STEP reader) names the smallest max_deviation that works; that bound then builds G2 and a
    bound a tenth of it is refused."""
    from build123d import export_step

    from spiral_cad.app.cli import main
    from spiral_cad.cad.fillet import planar_frame, wire_path
    from spiral_cad.cad.g2wire import _all_wires
    from spiral_cad.cad.readers import read_shape
    from spiral_cad.design import make_g2 as make_path_g2
    from spiral_cad.design import smallest_max_deviation

    path = tmp_path / "rounded.step"
    wire = fillet(Rectangle(10, 6).vertices(), 1).faces()[0].outer_wire()
    export_step(wire, str(path))
    assert main(["check", str(path)]) == 0
    out = capsys.readouterr().out
    assert "worst G1" in out
    line = next(x for x in out.splitlines() if x.startswith("make_g2:"))
    assert "8 tangent joints" in line
    found = re.search(r"max_deviation (\S+) (\S+) \(built and checked; any bound from (\S+) ", line)
    assert found, line
    bound, unit = float(found[3]), found[2]  # the smallest; the first figure, a usable one, is tested in test_front_doors
    read_back = _all_wires(read_shape(str(path), units=unit))[0]  # the curves as the file holds them, in the unit told
    segments, closed = wire_path(read_back, planar_frame(read_back))
    assert smallest_max_deviation(segments, closed=closed) == bound
    made = make_path_g2(segments, bound, closed=closed)
    assert all(j.kind == "line-arc" for j in made.joints)
    with pytest.raises(NoSolutionError, match="works"):
        make_path_g2(segments, bound / 10.0, closed=closed)


def test_check_advice_that_cannot_read_the_file_leaves_the_verdict_last(tmp_path, capsys, monkeypatch):
    """The advice reads the file again its own way; when that read refuses, the check still ends with its
    verdict (the last line) and its own status."""
    from build123d import export_step

    import spiral_cad.cad.readers as readers
    from spiral_cad.app.cli import main

    path = tmp_path / "rounded.step"
    export_step(fillet(Rectangle(10, 6).vertices(), 1).faces()[0].outer_wire(), str(path))

    def refuse(*args, **kwargs):
        raise ValueError("the reader refuses it")

    monkeypatch.setattr(readers, "read_shape", refuse)
    assert main(["check", str(path), "--require", "G2"]) == 1
    out = capsys.readouterr().out.splitlines()
    assert "make_g2: no advice: the reader refuses it" in out and out[-1].startswith("FAIL: ")
