"""Points and derivatives of elementary curves and surfaces, many parameters at once, in closed form.

Most faces of a machined part are planes, cylinders, cones, spheres and tori, bounded by lines and circles.
OCCT evaluates them one point per call; here a whole batch is one numpy expression, in OCCT's own
parametrisation (``ElSLib``/``ElCLib``), so the results are interchangeable with ``D2``/``D1``/``D0``.

Every surface of revolution among them is one formula. With the frame (O, X, Y, Z), the radial direction
r(u) = cos u X + sin u Y and its turn t(u) = −sin u X + cos u Y,

    S(u, v) = O + ρ(v) r(u) + h(v) Z,   ρ = a + v sin α + b cos v,   h = v cos α + b sin v,

a cylinder (a = R, α = 0, b = 0), a cone (a = R, α its semi-angle, b = 0), a sphere (a = 0, α = 0, b = R)
and a torus (a = R, α = 0, b = r). A plane is S = O + u X + v Y. A line, circle or ellipse (in 2-D or 3-D)
is C(t) = O + (l t + a cos t) X + b sin t Y: a line (l = 1, a = b = 0), a circle (a = b = R), an ellipse
(a, b its semi-axes).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray
from OCP.BRepAdaptor import BRepAdaptor_Curve, BRepAdaptor_Curve2d, BRepAdaptor_Surface
from OCP.GeomAbs import GeomAbs_CurveType, GeomAbs_SurfaceType

__all__ = ["curve_frame", "curve_points", "surface_derivatives", "surface_frame"]

_S = GeomAbs_SurfaceType


def _xyz(v: object) -> list[float]:
    return list(v.Coord())  # type: ignore[attr-defined]


def surface_frame(surface: BRepAdaptor_Surface) -> NDArray | None:
    """The 17 numbers of an elementary surface (a plane flag, O, X, Y, Z, a, sin α, cos α, b; located as
    the adaptor's face), or None for any other surface."""
    kind = surface.GetType()
    if kind == _S.GeomAbs_Plane:
        position, shape = surface.Plane().Position(), [0.0, 0.0, 0.0, 0.0]
    elif kind == _S.GeomAbs_Cylinder:
        c = surface.Cylinder()
        position, shape = c.Position(), [c.Radius(), 0.0, 1.0, 0.0]
    elif kind == _S.GeomAbs_Cone:
        c = surface.Cone()
        position, shape = c.Position(), [c.RefRadius(), np.sin(c.SemiAngle()), np.cos(c.SemiAngle()), 0.0]
    elif kind == _S.GeomAbs_Sphere:
        c = surface.Sphere()
        position, shape = c.Position(), [0.0, 0.0, 0.0, c.Radius()]
    elif kind == _S.GeomAbs_Torus:
        c = surface.Torus()
        position, shape = c.Position(), [c.MajorRadius(), 0.0, 0.0, c.MinorRadius()]
    else:
        return None
    axes = [_xyz(position.Location()), _xyz(position.XDirection()), _xyz(position.YDirection()), _xyz(position.Direction())]
    return np.array([1.0 if kind == _S.GeomAbs_Plane else 0.0, *sum(axes, []), *shape])


def surface_derivatives(frames: NDArray, uvs: NDArray) -> NDArray:
    """Rows (n × 18) of P, Su, Sv, Suu, Svv, Suv at ``uvs`` (n × 2), each on the surface of its row of
    ``frames`` (n × 17, from ``surface_frame``)."""
    plane = frames[:, 0] > 0.5
    o, x, y, z = (frames[:, i : i + 3] for i in (1, 4, 7, 10))
    a, sa, ca, b = (frames[:, i : i + 1] for i in (13, 14, 15, 16))
    u, v = uvs[:, :1], uvs[:, 1:]
    cu, su, cv, sv = np.cos(u), np.sin(u), np.cos(v), np.sin(v)
    radial, turn = cu * x + su * y, cu * y - su * x
    rho, rho1, rho2 = a + v * sa + b * cv, sa - b * sv, -b * cv
    h, h1, h2 = v * ca + b * sv, ca + b * cv, -b * sv
    out = np.concatenate([o + rho * radial + h * z, rho * turn, rho1 * radial + h1 * z, -rho * radial,
                          rho2 * radial + h2 * z, rho1 * turn], axis=1)  # fmt: skip
    if plane.any():
        zero = np.zeros((int(plane.sum()), 9))
        out[plane] = np.concatenate([o[plane] + u[plane] * x[plane] + v[plane] * y[plane], x[plane], y[plane], zero], axis=1)
    return out


def curve_frame(curve: BRepAdaptor_Curve | BRepAdaptor_Curve2d) -> list[float] | None:
    """The numbers of a line, circle or ellipse (O, X, Y, l, a, b; 2 or 3 coordinates each, located as the
    adaptor's edge), or None for any other curve. A list: many frames become one array at once."""
    kind = curve.GetType()
    if kind == GeomAbs_CurveType.GeomAbs_Line:
        line = curve.Line()
        o = line.Location().Coord()
        return [*o, *line.Direction().Coord(), *(0.0,) * len(o), 1.0, 0.0, 0.0]
    if kind == GeomAbs_CurveType.GeomAbs_Circle:
        conic = curve.Circle()
        a = b = conic.Radius()
    elif kind == GeomAbs_CurveType.GeomAbs_Ellipse:
        conic = curve.Ellipse()
        a, b = conic.MajorRadius(), conic.MinorRadius()
    else:
        return None
    return [*conic.Location().Coord(), *conic.XAxis().Direction().Coord(), *conic.YAxis().Direction().Coord(), 0.0, a, b]


def curve_points(frames: NDArray | list[float], ts: NDArray) -> tuple[NDArray, NDArray]:
    """Points and first derivatives (n × d each) at ``ts`` (n) of the curve ``frames`` (from ``curve_frame``;
    one for all, or one row per parameter)."""
    frames = np.atleast_2d(np.asarray(frames, dtype=float))
    d = (frames.shape[1] - 3) // 3
    o, x, y = frames[:, :d], frames[:, d : 2 * d], frames[:, 2 * d : 3 * d]
    l, a, b = (frames[:, i : i + 1] for i in range(3 * d, 3 * d + 3))
    t = np.asarray(ts, dtype=float)[:, None]
    c, s = np.cos(t), np.sin(t)
    return o + (l * t + a * c) * x + (b * s) * y, (l - a * s) * x + (b * c) * y
