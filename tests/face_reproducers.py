"""Parts a face checker with fixed samples passed though they are not G2 (issue 29), shared by the
checker's tests and the CLI's."""

from __future__ import annotations

import build123d as bd


def _array(kind, values):
    out = kind(1, len(values))
    for k, value in enumerate(values):
        out.SetValue(k + 1, value)
    return out


def bump_join(lo: float = 0.91, hi: float = 0.96) -> bd.Shell:
    """The plane z = 0 (−1 ≤ x ≤ 0) joined at x = 0 to the face z = x²·b(y) (0 ≤ x ≤ 1), b a cubic B-spline
    bump, nonzero on (lo, hi) only: tangent all along the edge, the curvature across it jumps over 5 % of it."""
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeFace, BRepBuilderAPI_Sewing
    from OCP.Geom import Geom_BSplineSurface
    from OCP.gp import gp_Pnt
    from OCP.TColgp import TColgp_Array2OfPnt
    from OCP.TColStd import TColStd_Array1OfInteger, TColStd_Array1OfReal

    inner = [lo + (hi - lo) * i / 4 for i in range(5)]
    flat = [0.0] * 4 + inner + [1.0] * 4
    count = len(flat) - 4
    greville = [sum(flat[j + 1 : j + 4]) / 3 for j in range(count)]  # y of the poles: y itself is linear
    bump = [1.0 if j == 4 else 0.0 for j in range(count)]  # the basis function on the knots lo … hi
    poles = TColgp_Array2OfPnt(1, 3, 1, count)
    for i, (x, a) in enumerate(((0.0, 0.0), (0.5, 0.0), (1.0, 1.0))):  # x² over 0 ≤ x ≤ 1, quadratic
        for j in range(count):
            poles.SetValue(i + 1, j + 1, gp_Pnt(x, greville[j], a * bump[j]))
    surface = Geom_BSplineSurface(poles, _array(TColStd_Array1OfReal, [0.0, 1.0]), _array(TColStd_Array1OfReal, [0.0, *inner, 1.0]),
                                  _array(TColStd_Array1OfInteger, [3, 3]), _array(TColStd_Array1OfInteger, [4, 1, 1, 1, 1, 1, 4]),
                                  2, 3)  # fmt: skip
    sewing = BRepBuilderAPI_Sewing(1e-6)
    sewing.Add(bd.Face.make_rect(1, 1).moved(bd.Location((-0.5, 0.5, 0))).wrapped)
    sewing.Add(BRepBuilderAPI_MakeFace(surface, 1e-7).Face())
    sewing.Perform()
    return bd.Shell(sewing.SewedShape())


def circle_square_circle_loft() -> bd.Part:
    return bd.loft([bd.Sketch() + bd.Circle(10), bd.Pos(0, 0, 10) * bd.Rectangle(12, 8), bd.Pos(0, 0, 20) * bd.Circle(6)])


def quadratic_prism() -> bd.Part:
    """A prism on a quadratic B-spline with simple knots (C1: its curvature jumps at each knot) closed by a line."""
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeEdge
    from OCP.Geom import Geom_BSplineCurve
    from OCP.gp import gp_Pnt
    from OCP.TColgp import TColgp_Array1OfPnt
    from OCP.TColStd import TColStd_Array1OfInteger, TColStd_Array1OfReal

    points = [(0, 0), (10, 0), (15, 8), (5, 14), (-4, 9), (-6, 3)]
    poles = TColgp_Array1OfPnt(1, len(points))
    for i, (x, y) in enumerate(points):
        poles.SetValue(i + 1, gp_Pnt(x, y, 0))
    spans = len(points) - 2
    curve = Geom_BSplineCurve(poles, _array(TColStd_Array1OfReal, [i / spans for i in range(spans + 1)]),
                              _array(TColStd_Array1OfInteger, [3] + [1] * (spans - 1) + [3]), 2)  # fmt: skip
    edge = bd.Edge(BRepBuilderAPI_MakeEdge(curve).Edge())
    return bd.extrude(bd.make_face([edge, bd.Line(edge @ 1, edge @ 0)]), 5)
