"""The closed forms of elementary surfaces and curves agree with OCCT's own evaluation (``D2``, ``D1``)."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("build123d")
import build123d as bd
from OCP.BRepAdaptor import BRepAdaptor_Curve, BRepAdaptor_Curve2d, BRepAdaptor_Surface
from OCP.BRepTools import BRepTools
from OCP.gp import gp_Pnt, gp_Pnt2d, gp_Vec, gp_Vec2d

from spiral_cad.cad.batch_geometry import curve_frame, curve_points, surface_derivatives, surface_frame

pytestmark = pytest.mark.cad

_PLACED = bd.Location((12.5, -3.0, 40.0), (17.0, -35.0, 123.0))


def _solids() -> dict[str, bd.Part]:
    cone = bd.Cone(8, 3, 12)
    return {
        "box": bd.Box(10, 20, 30),
        "cylinder": bd.Cylinder(4, 9),
        "cone": cone,
        "sphere": bd.Sphere(6),
        "torus": bd.Torus(10, 2.5),
        "ellipse prism": bd.extrude(bd.Ellipse(7, 3), 5),
        # a mirror makes left-handed frames: the formulas must use OCCT's X, Y and Z as they are
        "mirrored cone": bd.mirror(cone, bd.Plane.YZ),
    }


@pytest.mark.parametrize("name", list(_solids()))
@pytest.mark.parametrize("placed", [False, True])
def test_surfaces_and_curves_agree_with_occt(name: str, placed: bool) -> None:
    solid = _solids()[name]
    if placed:
        solid = _PLACED * solid
    rng = np.random.default_rng(7)
    faces = curves = 0
    for face in solid.faces():
        surface = BRepAdaptor_Surface(face.wrapped)
        frame = surface_frame(surface)
        if frame is None:  # the ellipse prism's side, an extrusion: only its ellipses are compared
            assert name == "ellipse prism", f"{name}: {surface.GetType()} has no closed form"
        else:
            u0, u1, v0, v1 = BRepTools.UVBounds_s(face.wrapped)
            uvs = np.column_stack([rng.uniform(u0, u1, 25), rng.uniform(v0, v1, 25)])
            mine = surface_derivatives(np.repeat(frame[None], len(uvs), axis=0), uvs)
            p, vs = gp_Pnt(), [gp_Vec() for _ in range(5)]
            for (u, v), row in zip(uvs.tolist(), mine):
                surface.D2(u, v, p, *vs)
                occt = np.array([*p.Coord(), *(c for w in vs for c in w.Coord())])
                np.testing.assert_allclose(row, occt, rtol=0, atol=1e-12 * max(1.0, np.abs(occt).max()))
            faces += 1
        for edge in face.edges():
            for adaptor, point, vector in ((BRepAdaptor_Curve(edge.wrapped), gp_Pnt, gp_Vec),
                                           (BRepAdaptor_Curve2d(edge.wrapped, face.wrapped), gp_Pnt2d, gp_Vec2d)):  # fmt: skip
                frame = curve_frame(adaptor)
                if frame is None:
                    continue
                ts = rng.uniform(adaptor.FirstParameter(), adaptor.LastParameter(), 7)
                points, d1 = curve_points(frame, ts)
                for t, at, tangent in zip(ts.tolist(), points, d1):
                    p2, v2 = point(), vector()
                    adaptor.D1(t, p2, v2)
                    np.testing.assert_allclose(np.r_[at, tangent], [*p2.Coord(), *v2.Coord()], rtol=0, atol=1e-12 * 100)
                curves += 1
    assert faces and curves


def test_other_kinds_have_no_closed_form() -> None:
    lofted = bd.Solid.make_loft([bd.Wire.make_circle(5), bd.Pos(0, 0, 10) * bd.Wire.make_circle(3).moved(bd.Pos(1, 0, 0))])
    spline = bd.Edge.make_spline([(0, 0, 0), (3, 1, 0), (6, -1, 2)])
    assert curve_frame(BRepAdaptor_Curve(spline.wrapped)) is None
    kinds = {surface_frame(BRepAdaptor_Surface(f.wrapped)) is None for f in lofted.faces()}
    assert True in kinds  # the lofted side is a B-spline surface
