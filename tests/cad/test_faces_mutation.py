"""Mutation test of the face checker: local defects planted into G2 parts must all be found.

Each part is converted to B-spline faces (``BRepBuilderAPI_NurbsConvert``, exact) and checked G2 first.
Then, one at a time, a defect is planted on a G2 edge that is an isoparametric border of one of its faces:
knots are inserted along the edge so that one basis function spans 1–10 % of the edge's length, at a
random place, and the pole of that function in the second row from the edge (G0: the tangent plane tilts
there, a crease) or the third row (G1: tangent, the curvature across the edge jumps there) is moved along
the surface normal. Inserting knots and raising degrees leaves the surface and its parameters as they
were, so the edge and its pcurves stay valid; only the defect changes the part. Each defect is measured
independently at its centre (OCCT's ``BRepLProp_SLProps``, not the checker's formulas) before the checker
is asked to find it.
"""

from __future__ import annotations

import random
from dataclasses import dataclass

import numpy as np
import pytest

pytest.importorskip("OCP")

import build123d as bd  # noqa: E402
from OCP.BRep import BRep_Builder, BRep_Tool  # noqa: E402
from OCP.BRepAdaptor import BRepAdaptor_Curve, BRepAdaptor_Curve2d, BRepAdaptor_Surface  # noqa: E402
from OCP.BRepBuilderAPI import BRepBuilderAPI_Copy, BRepBuilderAPI_NurbsConvert  # noqa: E402
from OCP.BRepLProp import BRepLProp_SLProps  # noqa: E402
from OCP.GCPnts import GCPnts_AbscissaPoint  # noqa: E402
from OCP.Geom import Geom_BSplineSurface  # noqa: E402
from OCP.gp import gp_Dir, gp_Pnt2d, gp_Vec  # noqa: E402
from OCP.TopAbs import TopAbs_EDGE, TopAbs_FACE, TopAbs_REVERSED  # noqa: E402
from OCP.TopExp import TopExp  # noqa: E402
from OCP.TopLoc import TopLoc_Location  # noqa: E402
from OCP.TopoDS import TopoDS  # noqa: E402
from OCP.TopTools import TopTools_IndexedMapOfShape  # noqa: E402

from spiral_cad.build123d import ContinuousRectangle, G2Polyline  # noqa: E402
from spiral_cad.cad.faces import check_faces  # noqa: E402

#: Defects planted per part and kind; the test asserts that this many were planted and all were found.
PER_PART_AND_KIND = 8
SEED = 29


def slab() -> bd.Part:
    """Straight G2 edges between extruded spirals, arcs and lines."""
    return bd.extrude(ContinuousRectangle(40, 20, 5), 8)


def vase() -> bd.Part:
    """Circular G2 edges between surfaces of revolution."""
    with bd.BuildPart() as part:
        with bd.BuildSketch(bd.Plane.XZ):
            with bd.BuildLine():
                G2Polyline((0, 0), (10, 0), (10, 10), (4, 20), (0, 20), radius=2)
                bd.Line((0, 20), (0, 0))
            bd.make_face()
        bd.revolve(axis=bd.Axis.Z)
    return part.part


def rolled_box() -> bd.Part:
    """A ContinuousBox: every edge and corner G2, many B-spline patches."""
    from spiral_cad.build123d import ContinuousBox

    return ContinuousBox(60, 40, 12, 8, 3)


PARTS = {"slab": slab, "vase": vase, "rolled_box": rolled_box}


@dataclass(frozen=True)
class Planted:
    """One planted defect: the edge, its kind (``"G0"`` or ``"G1"``), its extent (fraction of the edge's
    length), and what OCCT measures at its centre (angle between the faces' normals, rad; relative jump
    of the normal curvature across the edge)."""

    edge: int
    kind: str
    width: float
    angle: float
    jump: float


def _maps(shape):
    faces, edges = TopTools_IndexedMapOfShape(), TopTools_IndexedMapOfShape()
    TopExp.MapShapes_s(shape, TopAbs_FACE, faces)
    TopExp.MapShapes_s(shape, TopAbs_EDGE, edges)
    return faces, edges


def _border(edge, face) -> tuple[bool, bool] | None:
    """(the edge runs along v — it lies on u = const —, it is the first (not the last) u or v of the
    surface) when the edge is an isoparametric border of the face's B-spline surface; None otherwise."""
    surface = BRep_Tool.Surface_s(face, TopLoc_Location())
    if not isinstance(surface, Geom_BSplineSurface):
        return None
    curve = BRepAdaptor_Curve2d(edge, face)
    uv = gp_Pnt2d()
    points = []
    for t in np.linspace(curve.FirstParameter(), curve.LastParameter(), 7).tolist():
        curve.D0(t, uv)
        points.append((uv.X(), uv.Y()))
    u, v = np.array(points).T
    u0, u1, v0, v1 = surface.Bounds()
    for along_v, values, (lo, hi), periodic in ((True, u, (u0, u1), surface.IsUPeriodic()),
                                                (False, v, (v0, v1), surface.IsVPeriodic())):  # fmt: skip
        if not periodic and np.ptp(values) < 1e-9 * (hi - lo):
            for first, end in ((True, lo), (False, hi)):
                if abs(values[0] - end) < 1e-9 * (hi - lo):
                    return along_v, first
    return None


def plant(shape, edge_index: int, kind: str, rng: random.Random) -> tuple[object, Planted] | None:
    """A copy of ``shape`` with a defect of ``kind`` on edge ``edge_index`` (1-based), or None when no face
    of the edge has it as an isoparametric border."""
    copy = BRepBuilderAPI_Copy(shape).Shape()
    faces, edges = _maps(copy)
    edge = TopoDS.Edge_s(edges.FindKey(edge_index))
    candidates = []
    for i in range(1, faces.Extent() + 1):
        face = TopoDS.Face_s(faces.FindKey(i))
        face_edges = TopTools_IndexedMapOfShape()
        TopExp.MapShapes_s(face, TopAbs_EDGE, face_edges)
        if face_edges.Contains(edge) and (border := _border(edge, face)) is not None:
            candidates.append((face, border))
    if not candidates:
        return None
    face, (along_v, first) = rng.choice(candidates)
    location = TopLoc_Location()
    surface = BRep_Tool.Surface_s(face, location).Copy()
    assert isinstance(surface, Geom_BSplineSurface)
    for periodic, unset in ((surface.IsUPeriodic(), surface.SetUNotPeriodic), (surface.IsVPeriodic(), surface.SetVNotPeriodic)):
        if periodic:
            unset()  # the same surface and parameters, its poles in one row each
    # the defect's extent, by arc length along the edge, mapped to the surface's parameter along it
    curve = BRepAdaptor_Curve(edge)
    length = GCPnts_AbscissaPoint.Length_s(curve)
    width = rng.uniform(0.01, 0.10)
    start = rng.uniform(0.0, 1.0 - width)
    pcurve = BRepAdaptor_Curve2d(edge, face)
    uv = gp_Pnt2d()
    ends = []
    for fraction in (start, start + width):
        t = GCPnts_AbscissaPoint(curve, fraction * length, curve.FirstParameter()).Parameter()
        pcurve.D0(t, uv)
        ends.append(uv.Y() if along_v else uv.X())
    a, b = sorted(ends)
    # room for the defect: degree ≥ 3 across the edge (a third row of poles), ≥ 2 along it
    cross_degree, along_degree = (surface.UDegree(), surface.VDegree()) if along_v else (surface.VDegree(), surface.UDegree())
    want = (max(cross_degree, 3), max(along_degree, 2))
    surface.IncreaseDegree(*((want[0], want[1]) if along_v else (want[1], want[0])))
    p = want[1]
    insert = surface.InsertVKnot if along_v else surface.InsertUKnot
    for k in range(p + 2):
        insert(a + (b - a) * k / (p + 1), 1, 1e-12, True)
    knots = (surface.VKnotSequence if along_v else surface.UKnotSequence)()
    flat = [knots.Value(i) for i in range(knots.Lower(), knots.Upper() + 1)]
    inside = [j for j in range(len(flat) - p - 1) if flat[j] >= a - 1e-12 and flat[j + p + 1] <= b + 1e-12]
    j = max(inside, key=lambda j: flat[j + p + 1] - flat[j])  # the widest basis function within [a, b]
    count = surface.NbUPoles() if along_v else surface.NbVPoles()
    row = (2 if kind == "G0" else 3) if first else (count - 1 if kind == "G0" else count - 2)
    i_u, i_v = (row, j + 1) if along_v else (j + 1, row)
    # along the surface normal at the defect's centre, by a random fraction of the edge's length
    middle = 0.5 * (flat[j] + flat[j + p + 1])
    across = (surface.Bounds()[0] if first else surface.Bounds()[1]) if along_v else (surface.Bounds()[2] if first else surface.Bounds()[3])
    adaptor = BRepAdaptor_Surface(face, False)  # kept alive: the properties refer to it
    props = BRepLProp_SLProps(adaptor, 1, 1e-9)
    props.SetParameters(*((across, middle) if along_v else (middle, across)))
    normal = props.Normal()
    size = length * rng.uniform(1e-4, 1e-2) * rng.choice((-1.0, 1.0))
    pole = surface.Pole(i_u, i_v)
    surface.SetPole(i_u, i_v, pole.Translated(gp_Vec(normal) * size))
    _replace_surface(face, surface, location)
    angle, jump = _measured_at(copy, edge, face, (across, middle) if along_v else (middle, across))
    return copy, Planted(edge_index - 1, kind, width, angle, jump)


def _replace_surface(face, surface, location) -> None:
    """Give ``face`` the surface ``surface`` (same parameters as its own) and move its edges' pcurves onto it."""
    from OCP.TopAbs import TopAbs_FORWARD
    from OCP.TopExp import TopExp_Explorer

    builder, kept = BRep_Builder(), []
    explorer = TopExp_Explorer(face, TopAbs_EDGE)
    while explorer.More():
        edge = TopoDS.Edge_s(explorer.Current())
        if not any(edge.IsSame(e) for e, *_ in kept):
            tolerance = BRep_Tool.Tolerance_s(edge)
            if BRep_Tool.IsClosed_s(edge, face):  # a seam: its two pcurves, in the order the builder takes them
                forward, backward = (TopoDS.Edge_s(edge.Oriented(o)) for o in (TopAbs_FORWARD, TopAbs_REVERSED))
                curves = [BRep_Tool.CurveOnSurface_s(e, face, 0.0, 0.0) for e in (forward, backward)]
            else:
                curves = [BRep_Tool.CurveOnSurface_s(edge, face, 0.0, 0.0)]
            kept.append((edge, curves, tolerance))
        explorer.Next()
    builder.UpdateFace(face, surface, location, BRep_Tool.Tolerance_s(face))
    for edge, curves, tolerance in kept:
        builder.UpdateEdge(edge, *curves, surface, location, tolerance)


def _measured_at(shape, edge, face, uv) -> tuple[float, float]:
    """Angle between the two faces' oriented normals and the relative jump of their normal curvatures
    across the edge at the edge point nearest ``uv`` of ``face``, by OCCT's local properties
    (``BRepLProp_SLProps``: normal, principal curvatures and directions; Euler's formula)."""
    from OCP.GeomAPI import GeomAPI_ProjectPointOnCurve
    from OCP.TopTools import TopTools_IndexedDataMapOfShapeListOfShape

    adaptor = BRepAdaptor_Surface(face)  # kept alive: the properties refer to it
    props = BRepLProp_SLProps(adaptor, 2, 1e-9)
    props.SetParameters(*uv)
    curve = BRepAdaptor_Curve(edge)
    t = GeomAPI_ProjectPointOnCurve(props.Value(), BRep_Tool.Curve_s(edge, 0.0, 1.0)).LowerDistanceParameter()
    ancestors = TopTools_IndexedDataMapOfShapeListOfShape()
    TopExp.MapShapesAndAncestors_s(shape, TopAbs_EDGE, TopAbs_FACE, ancestors)
    (other,) = [TopoDS.Face_s(f) for f in ancestors.FindFromKey(edge) if not f.IsSame(face)]
    point, d1 = props.Value(), gp_Vec()
    curve.D1(t, point, d1)
    tangent = gp_Dir(d1)
    found = []
    for f in (face, other):
        on = BRepAdaptor_Curve2d(edge, f).Value(t)
        surface = BRepAdaptor_Surface(f)
        pr = BRepLProp_SLProps(surface, 2, 1e-9)
        pr.SetParameters(on.X(), on.Y())
        sign = -1.0 if f.Orientation() == TopAbs_REVERSED else 1.0
        n = pr.Normal().Reversed() if sign < 0 else pr.Normal()
        d1_, d2_ = gp_Dir(), gp_Dir()
        pr.CurvatureDirections(d1_, d2_)
        c = n.Crossed(tangent).Dot(d1_)
        kappa = pr.MaxCurvature() * c * c + pr.MinCurvature() * (1 - c * c)  # Euler's formula
        found.append((n, sign * kappa))
    (na, ka), (nb, kb) = found
    return na.Angle(nb), abs(ka - kb) / max(abs(ka), abs(kb), 1e-9)


def planted_defects(name: str, count: int, seed: int = SEED):
    """``count`` defects of each kind planted, one at a time, on random G2 edges of the part ``name``,
    converted to B-spline faces: (shape, planted) each."""
    base = BRepBuilderAPI_NurbsConvert(PARTS[name]().wrapped, True).Shape()
    report = check_faces(base)
    assert report.passes("G2"), report.table()
    rng = random.Random(f"{seed}-{name}")
    edges = [e.index + 1 for e in report.edges if e.level == "G2" and e.index >= 0 and not e.seam]
    faces, indexed = _maps(base)
    borders = [i for i in edges if any(_border(TopoDS.Edge_s(indexed.FindKey(i)), TopoDS.Face_s(faces.FindKey(f))) is not None
                                      for f in _faces_of(base, i))]  # fmt: skip
    assert borders, f"{name}: no G2 edge is an isoparametric border of a B-spline face"
    for kind in ("G0", "G1"):
        for _ in range(count):
            got = plant(base, rng.choice(borders), kind, rng)
            assert got is not None
            yield got


def _faces_of(shape, edge_index: int) -> list[int]:
    """The indices (1-based) of the faces holding edge ``edge_index``."""
    faces, edges = _maps(shape)
    edge = edges.FindKey(edge_index)
    out = []
    for i in range(1, faces.Extent() + 1):
        own = TopTools_IndexedMapOfShape()
        TopExp.MapShapes_s(faces.FindKey(i), TopAbs_EDGE, own)
        if own.Contains(edge):
            out.append(i)
    return out


def judged(report, planted: Planted) -> str:
    """The class the checker gives the planted defect's edge."""
    (row,) = [e for e in report.edges if e.index == planted.edge]
    return row.level


@pytest.mark.parametrize("name", ["slab", "vase"])
def test_every_planted_local_defect_is_found(name):
    assert_every_planted_defect_found(name)


def test_every_planted_local_defect_in_a_continuous_box_is_found():
    assert_every_planted_defect_found("rolled_box")


def assert_every_planted_defect_found(name: str) -> None:
    found, planted = {"G0": 0, "G1": 0}, {"G0": 0, "G1": 0}
    for shape, defect in planted_defects(name, PER_PART_AND_KIND):
        planted[defect.kind] += 1
        # the defect is real, measured by OCCT at its centre: a tilt of the tangent plane (G0) or, with the
        # tangent plane kept, a jump of the normal curvature (G1)
        if defect.kind == "G0":
            assert defect.angle > 1e-6, defect
        else:
            assert defect.angle < 1e-9 and defect.jump > 1e-3, defect
        level = judged(check_faces(shape), defect)
        expected = {"G0": "crease", "G1": "G1"}[defect.kind]  # local: tangent elsewhere, so never sharp
        assert level == expected, f"{name}: {defect} judged {level}"
        found[defect.kind] += level == expected
    assert planted == {"G0": PER_PART_AND_KIND, "G1": PER_PART_AND_KIND}
    assert found == planted
