"""Where the face checker looks: sample points along an edge or a knot line, adapted to the geometry.

A fixed set of points per edge is fooled by a defect that lies between them (a
curvature jump over 5 % of an edge, a crease near a vertex). The points here
follow the geometry instead:

* a **floor**: ``samples`` midpoints of equal parameter steps, and the two ends
  of the edge moved in by ``END_INSET`` of its range (near a vertex, where a
  loft's faces turn tangent, without evaluating a pole, an apex or a corner
  patch's collapsed side);
* **every polynomial span**: the knots of the edge's curve, of each face's
  pcurve, and the parameters where each pcurve crosses a knot line of its
  face's surface (any surface kind: B-spline, extrusion or revolution of a
  B-spline curve, offset, trimmed) cut the edge into spans, and each span
  gets points at its quarters. A local defect in a B-spline is bounded by
  knots, so it holds a span, and inside a span every measure is one smooth
  (rational) function. The knots are read from the geometry itself
  (``curve_knots``, ``surface_knots``): OCCT's adaptors list only the knots
  below C3, and a defect inside a span of a degree-9 patch hides from them;
* **refinement**: an interval is bisected (up to ``REFINE_ROUNDS`` times) where
  the edge or a face's normal turns by more than ``TURN`` between its ends,
  where a measure below its tolerance at both ends changes by enough to cross
  it in between, and where the faces are sharp at both ends but their angle
  changes by enough to dip below the feature angle (a partly tangent edge).

A knot line inside a face (continuity below C2 there: a crease or a curvature
jump may hide in it) is a pseudo-edge: both sides of the line are evaluated —
exactly from the two spans' polynomials for a B-spline surface (``LocalD2``),
and for every other kind a hair either side (``KNOT_STEP`` of the face's range)
with a first-order correction back onto the line — and it is sampled the same
way along its length.

Everything is measured in rounds over all edges at once, so plain parts
(straight or gently curved edges, no knots) cost the floor and one pass.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray
from OCP.BRep import BRep_Tool
from OCP.BRepAdaptor import BRepAdaptor_Curve, BRepAdaptor_Curve2d, BRepAdaptor_Surface
from OCP.BRepTools import BRepTools
from OCP.Geom import (
    Geom_BSplineCurve,
    Geom_BSplineSurface,
    Geom_OffsetCurve,
    Geom_OffsetSurface,
    Geom_RectangularTrimmedSurface,
    Geom_SurfaceOfLinearExtrusion,
    Geom_SurfaceOfRevolution,
    Geom_TrimmedCurve,
)
from OCP.Geom2d import Geom2d_BSplineCurve, Geom2d_OffsetCurve, Geom2d_TrimmedCurve
from OCP.GeomAbs import GeomAbs_Shape
from OCP.gp import gp_Pnt, gp_Pnt2d, gp_Vec
from OCP.TColStd import TColStd_Array1OfReal
from OCP.TopoDS import TopoDS_Edge, TopoDS_Face

from ..check.joints import norms

__all__ = ["END_INSET", "FACE_FLOATS", "KNOT_STEP", "REFINE_ROUNDS", "TURN", "EdgeLine", "KnotLine", "Line", "Tolerances",
           "curve_knots", "knot_lines", "measures", "sample_lines", "surface_knots"]  # fmt: skip

#: Floats per sample and face: point (3), oriented unit normal (3), normal curvature across the edge.
FACE_FLOATS = 7

#: The ends of an edge are sampled this far inside its parameter range (relative): close enough to see
#: faces that turn tangent towards a vertex (a loft's), far enough from a pole, an apex or the collapsed
#: side of a corner patch, where the second fundamental form is ill-conditioned (on a ContinuousBox's
#: corner patch the normal curvature read 1e-6 from such a vertex is off by 0.1 relative; at 1e-3 it agrees
#: with its neighbour's within 3e-7).
END_INSET = 1e-3

#: An interval is bisected where the edge's tangent or a face's normal turns by more than this (radians).
TURN = 0.4

#: Rounds of bisection at most; each halves the intervals it touches.
REFINE_ROUNDS = 6

#: Where no one-sided evaluation exists, a knot line's two sides are evaluated this far from it (relative to
#: the face's parameter range) and moved back onto it to first order.
KNOT_STEP = 1e-9


@dataclass(frozen=True)
class Tolerances:
    """The thresholds the refinement watches: the checker's own."""

    gap: float  # absolute (gap_tol × size)
    angle: float
    curvature: float
    feature: float
    size: float


# ------------------------------------------------------------ what OCCT says about spans


def _values(count: int, fill: Callable[[TColStd_Array1OfReal], None]) -> list[float]:
    array = TColStd_Array1OfReal(1, count + 1)
    fill(array)
    return [array.Value(i) for i in range(1, count + 2)]


def curve_knots(curve: Any) -> list[float]:
    """Every knot of a Geom or Geom2d curve's B-spline (through trimmed and offset curves); none for
    other kinds (lines, conics, Bézier curves: one polynomial span)."""
    while isinstance(curve, (Geom_TrimmedCurve, Geom2d_TrimmedCurve, Geom_OffsetCurve, Geom2d_OffsetCurve)):
        curve = curve.BasisCurve()
    if isinstance(curve, (Geom_BSplineCurve, Geom2d_BSplineCurve)):
        return [curve.Knot(i) for i in range(1, curve.NbKnots() + 1)]
    return []


def surface_knots(surface: Any) -> tuple[list[float], list[float]]:
    """Every u and every v knot of a Geom surface's B-spline: of a B-spline surface, of the B-spline curve
    of an extrusion (u) or a revolution (v), through offset and trimmed surfaces. OCCT's adaptors list
    only the knots below C3, and a defect inside a span of a high-degree surface hides from them."""
    while isinstance(surface, (Geom_RectangularTrimmedSurface, Geom_OffsetSurface)):
        surface = surface.BasisSurface()
    if isinstance(surface, Geom_BSplineSurface):
        return ([surface.UKnot(i) for i in range(1, surface.NbUKnots() + 1)],
                [surface.VKnot(i) for i in range(1, surface.NbVKnots() + 1)])  # fmt: skip
    if isinstance(surface, Geom_SurfaceOfLinearExtrusion):
        return curve_knots(surface.BasisCurve()), []
    if isinstance(surface, Geom_SurfaceOfRevolution):
        return [], curve_knots(surface.BasisCurve())
    return [], []


def surface_breaks(surface: BRepAdaptor_Surface, shape: GeomAbs_Shape) -> tuple[list[float], list[float]]:
    """The interior u and v values inside the face's bounds where the surface is less smooth than ``shape``
    (``GeomAbs_C2``: where a crease or a curvature jump may be), as OCCT's adaptor finds them for any kind:
    knot lines of a B-spline surface, of the B-spline curve of an extrusion or a revolution, of an offset's
    or a trimmed surface's basis."""
    nu, nv = surface.NbUIntervals(shape), surface.NbVIntervals(shape)
    us = _values(nu, lambda a: surface.UIntervals(a, shape))[1:-1] if nu > 1 else []
    vs = _values(nv, lambda a: surface.VIntervals(a, shape))[1:-1] if nv > 1 else []
    return us, vs


def span_points(lo: float, hi: float, breaks: list[float]) -> list[float]:
    """The quarter points of every span that ``breaks`` cut [lo, hi] into (none without breaks)."""
    inside = sorted(b for b in breaks if lo < b < hi)
    if not inside:
        return []
    edges = [lo, *inside, hi]
    out = []
    for a, b in zip(edges[:-1], edges[1:]):
        if b - a > 1e-12 * (hi - lo):
            out += [a + 0.25 * (b - a), a + 0.75 * (b - a)]
    return out


def floor_points(lo: float, hi: float, samples: int) -> list[float]:
    """``samples`` midpoints of equal steps and the two ends moved in by ``END_INSET``."""
    width = hi - lo
    mids = (lo + width * (np.arange(samples) + 0.5) / samples).tolist()
    return [lo + END_INSET * width, *mids, hi - END_INSET * width]


def _crossings(pcurve: BRepAdaptor_Curve2d, grid: NDArray, knots: tuple[list[float], list[float]]) -> list[float]:
    """Edge parameters where the pcurve crosses a knot value of its surface (u = k or v = k), from the sign
    changes on ``grid``, each refined by a few secant steps (exact at once for a straight pcurve)."""
    if not knots[0] and not knots[1]:
        return []
    uv = gp_Pnt2d()
    values = np.empty((len(grid), 2))
    for k, t in enumerate(grid.tolist()):
        pcurve.D0(t, uv)
        values[k] = uv.X(), uv.Y()
    found = []
    for axis in (0, 1):
        for knot in knots[axis]:
            f = values[:, axis] - knot
            for i in np.nonzero(f[:-1] * f[1:] < 0.0)[0].tolist():
                a, b, fa, fb = float(grid[i]), float(grid[i + 1]), float(f[i]), float(f[i + 1])
                t = a
                for _ in range(4):
                    t = a - fa * (b - a) / (fb - fa)
                    pcurve.D0(t, uv)
                    ft = (uv.X(), uv.Y())[axis] - knot
                    if abs(ft) <= 1e-14 * max(1.0, abs(knot)):
                        break
                    a, fa = (t, ft) if (ft < 0) == (fa < 0) else (a, fa)
                    b, fb = (t, ft) if (ft < 0) == (fb < 0) else (b, fb)
                found.append(t)
    return found


# ------------------------------------------------------------ evaluating


def face_derivatives(surface: BRepAdaptor_Surface, uvs: list[tuple[float, float]], out: NDArray) -> None:
    """Fill ``out`` (samples × 18) with the surface point and derivatives (P, Su, Sv, Suu, Svv, Suv) at each (u, v)."""
    p = gp_Pnt()
    su, sv, suu, svv, suv = gp_Vec(), gp_Vec(), gp_Vec(), gp_Vec(), gp_Vec()
    for k, (u, v) in enumerate(uvs):
        if not (math.isfinite(u) and math.isfinite(v)):
            out[k] = math.nan
            continue
        surface.D2(u, v, p, su, sv, suu, svv, suv)
        out[k] = (*p.Coord(), *su.Coord(), *sv.Coord(), *suu.Coord(), *svv.Coord(), *suv.Coord())


def projected(edge: TopoDS_Edge, face: TopoDS_Face, params: list[float]) -> list[tuple[float, float]]:
    """(u, v) on the face's surface of the edge's points at ``params`` (``ShapeAnalysis_Surface``:
    periodic and singular surfaces handled); NaN where no projection is found."""
    from OCP.ShapeAnalysis import ShapeAnalysis_Surface

    curve = BRepAdaptor_Curve(edge)
    analysis = ShapeAnalysis_Surface(BRep_Tool.Surface_s(face))  # located, as the edge's points
    tolerance = BRep_Tool.Tolerance_s(edge)
    found = []
    for t in params:
        try:
            uv = analysis.ValueOfUV(curve.Value(t), tolerance)
            found.append((uv.X(), uv.Y()))
        except Exception:  # noqa: BLE001 - OCCT's Standard_Failure: this sample is not measured
            found.append((math.nan, math.nan))
    return found


def rows_of(raw: NDArray, sign: NDArray, tangents: NDArray) -> NDArray:
    """Point, oriented unit normal and normal curvature across the edge (d = n × t), rows of
    ``FACE_FLOATS``, from rows of surface derivatives — all samples of all edges in one pass."""
    point, su, sv, suu, svv, suv = (raw[:, i : i + 3] for i in range(0, 18, 3))
    with np.errstate(all="ignore"):
        normal = np.cross(su, sv)
        normal *= (sign / norms(normal))[:, None]  # sign −1 for a face REVERSED in its shell
        across = np.cross(normal, tangents)  # d = n × t, in the tangent plane
        e, f, g = (np.einsum("ij,ij->i", x, y) for x, y in ((su, su), (su, sv), (sv, sv)))
        l_, m, n = (np.einsum("ij,ij->i", x, normal) for x in (suu, suv, svv))
        du, dv = np.einsum("ij,ij->i", across, su), np.einsum("ij,ij->i", across, sv)
        det = e * g - f * f
        a, b = (g * du - f * dv) / det, (e * dv - f * du) / det  # d = a Su + b Sv
        kappa = (l_ * a * a + 2.0 * m * a * b + n * b * b) / (e * a * a + 2.0 * f * a * b + g * b * b)
    return np.column_stack([point, normal, kappa])


def measures(rows: NDArray, size: float) -> tuple[NDArray, NDArray, NDArray]:
    """Gap, angle between the oriented normals and relative jump of the normal curvature across the
    edge, per sample, from samples × 2 × ``FACE_FLOATS`` (jump relative to ``max(|κa|, |κb|, 1/size)``)."""
    a, b = rows[:, 0], rows[:, 1]
    with np.errstate(all="ignore"):
        gap = norms(a[:, :3] - b[:, :3])
        dot = np.einsum("si,si->s", a[:, 3:6], b[:, 3:6])
        angle = np.arctan2(norms(np.cross(a[:, 3:6], b[:, 3:6])), dot)
        ka, kb = a[:, 6], b[:, 6]
        floor = 1.0 / size if size > 0.0 else 0.0
        jump = np.abs(ka - kb) / np.maximum(np.maximum(np.abs(ka), np.abs(kb)), floor)
    return gap, angle, jump


class Line:
    """What is sampled: an edge between two faces, or a knot line inside one (a pseudo-edge).

    ``evaluate(params)`` gives the two sides' surface derivatives (n × 2 × 18) and the line's unit
    tangents (n × 3) at the line's parameters; ``start`` the first points; ``lo``, ``hi`` its range.
    """

    lo: float
    hi: float
    signs: tuple[float, float]
    start: list[float]

    def evaluate(self, params: list[float]) -> tuple[NDArray, NDArray]:
        """Surface derivatives of both sides (n × 2 × 18) and the line's unit tangents (n × 3)."""
        raise TypeError(f"{type(self).__name__} does not evaluate")


class EdgeLine(Line):
    """An edge shared by two faces (or a seam: one face twice, the edge used both ways)."""

    def __init__(self, edge: TopoDS_Edge, sides: list[tuple[BRepAdaptor_Surface, TopoDS_Face, TopoDS_Edge]],
                 signs: tuple[float, float], samples: int) -> None:  # fmt: skip
        self.edge, self.sides, self.signs = edge, sides, signs
        self.curve = BRepAdaptor_Curve(edge)
        self.lo, self.hi = self.curve.FirstParameter(), self.curve.LastParameter()
        self.curves_on_faces = [BRep_Tool.CurveOnSurface_s(oriented, face, 0.0, 0.0) for _, face, oriented in sides]
        self.pcurves = [None if on_face is None else BRepAdaptor_Curve2d(oriented, face)
                        for (_, face, oriented), on_face in zip(sides, self.curves_on_faces)]  # fmt: skip
        floor = floor_points(self.lo, self.hi, samples)
        breaks = curve_knots(BRep_Tool.Curve_s(edge, 0.0, 0.0)) if BRep_Tool.IsGeometric_s(edge) else []
        grid = np.unique(np.array(floor + breaks + [self.lo, self.hi]))
        for (_, face, _), pcurve, on_face in zip(sides, self.pcurves, self.curves_on_faces):
            if pcurve is not None:
                breaks += curve_knots(on_face) + _crossings(pcurve, grid, surface_knots(BRep_Tool.Surface_s(face)))
        self.start = floor + span_points(self.lo, self.hi, breaks)

    def evaluate(self, params: list[float]) -> tuple[NDArray, NDArray]:
        """Both faces' derivatives at the pcurves' (u, v) (or the projections of the edge's points), and the
        unit tangents of the edge's 3-D curve."""
        tangents = np.empty((len(params), 3))
        p, d1 = gp_Pnt(), gp_Vec()
        for k, t in enumerate(params):
            self.curve.D1(t, p, d1)
            tangents[k] = d1.Coord()
        with np.errstate(all="ignore"):
            tangents /= norms(tangents)[:, None]
        raw = np.empty((len(params), 2, 18))
        uv = gp_Pnt2d()
        for side, ((surface, face, oriented), pcurve) in enumerate(zip(self.sides, self.pcurves)):
            if pcurve is not None:
                uvs = []
                for t in params:
                    pcurve.D0(t, uv)
                    uvs.append((uv.X(), uv.Y()))
            else:
                uvs = projected(oriented, face, params)
            face_derivatives(surface, uvs, raw[:, side])
        return raw, tangents


class KnotLine(Line):
    """A knot line u = k (``along_u``) or v = k inside one face, across the face's (u, v) bounds (a
    trimmed face's line may be sampled a little beyond its trimming)."""

    def __init__(self, face: TopoDS_Face, surface: BRepAdaptor_Surface, along_u: bool, knot: float, sign: float,
                 samples: int) -> None:  # fmt: skip
        self.surface, self.along_u, self.knot, self.signs = surface, along_u, knot, (sign, sign)
        u0, u1, v0, v1 = BRepTools.UVBounds_s(face)
        self.lo, self.hi = (v0, v1) if along_u else (u0, u1)
        low, high = (u0, u1) if along_u else (v0, v1)
        self.step = KNOT_STEP * (high - low)
        us, vs = surface_knots(BRep_Tool.Surface_s(face))
        self.start = floor_points(self.lo, self.hi, samples) + span_points(self.lo, self.hi, vs if along_u else us)
        geom = BRep_Tool.Surface_s(face)  # located: the points come out where the face is
        self.bspline = geom if isinstance(geom, Geom_BSplineSurface) else None
        self.name = f"{'u' if along_u else 'v'} = {knot:.6g}"
        if self.bspline is not None:
            s = self.bspline
            first, last = (s.FirstUKnotIndex(), s.LastUKnotIndex()) if along_u else (s.FirstVKnotIndex(), s.LastVKnotIndex())
            knot_at = s.UKnot if along_u else s.VKnot
            self.index = min(range(first + 1, last), key=lambda i: abs(knot_at(i) - knot))
            multiplicity = (s.UMultiplicity if along_u else s.VMultiplicity)(self.index)
            self.name += f" (knot of multiplicity {multiplicity})"
            ofirst, olast = (s.FirstVKnotIndex(), s.LastVKnotIndex()) if along_u else (s.FirstUKnotIndex(), s.LastUKnotIndex())
            self.ofirst = ofirst
            self.oknots = np.array([(s.VKnot if along_u else s.UKnot)(i) for i in range(ofirst, olast + 1)])
        else:
            self.name += f" (a knot of the {_kind(surface)} surface's B-spline, below C2)"

    def evaluate(self, params: list[float]) -> tuple[NDArray, NDArray]:
        """The two sides' derivatives on the line: the two spans' polynomials of a B-spline surface, else
        ``KNOT_STEP`` either side moved back onto the line to first order."""
        p = gp_Pnt()
        su, sv, suu, svv, suv = gp_Vec(), gp_Vec(), gp_Vec(), gp_Vec(), gp_Vec()
        raw = np.empty((len(params), 2, 18))
        k = self.knot
        if self.bspline is not None:
            s, i = self.bspline, self.index
            spans = self.ofirst + np.clip(np.searchsorted(self.oknots, params, side="right") - 1, 0, len(self.oknots) - 2)
            for n, (t, j) in enumerate(zip(params, spans.tolist())):
                for side, (a, b) in enumerate(((i - 1, i), (i, i + 1))):
                    if self.along_u:
                        s.LocalD2(k, t, a, b, j, j + 1, p, su, sv, suu, svv, suv)
                    else:
                        s.LocalD2(t, k, j, j + 1, a, b, p, su, sv, suu, svv, suv)
                    raw[n, side] = (*p.Coord(), *su.Coord(), *sv.Coord(), *suu.Coord(), *svv.Coord(), *suv.Coord())
        else:
            for side, h in enumerate((-self.step, self.step)):
                uvs = [(k + h, t) if self.along_u else (t, k + h) for t in params]
                face_derivatives(self.surface, uvs, raw[:, side])
                # back onto the line, to first order in h (x the direction across it): P −= h·S_x,
                # S_u −= h·S_ux, S_v −= h·S_vx
                x, ux, vx = (3, 9, 15) if self.along_u else (6, 15, 12)
                found = raw[:, side].copy()
                for target, derivative in ((0, x), (3, ux), (6, vx)):
                    raw[:, side, target : target + 3] -= h * found[:, derivative : derivative + 3]
        tangents = raw[:, 0, 6:9] if self.along_u else raw[:, 0, 3:6]  # along the line: Sv on a u line, Su on a v line
        with np.errstate(all="ignore"):
            return raw, tangents / norms(tangents)[:, None]


def _kind(surface: BRepAdaptor_Surface) -> str:
    name = surface.GetType().name.removeprefix("GeomAbs_").removesuffix("Surface").removeprefix("SurfaceOf")
    return name.lower() or "other"


def knot_lines(face: TopoDS_Face, surface: BRepAdaptor_Surface, sign: float, samples: int) -> list[KnotLine]:
    """The knot lines inside ``face`` where its surface is less than C2 (a crease or a curvature jump may
    be there): of a B-spline surface, of the B-spline curve of an extrusion or a revolution, of an offset's
    or a trimmed surface's basis."""
    us, vs = surface_breaks(surface, GeomAbs_Shape.GeomAbs_C2)
    return [KnotLine(face, surface, along_u, k, sign, samples) for along_u, ks in ((True, us), (False, vs)) for k in ks]


# ------------------------------------------------------------ sampling in rounds


def sample_lines(lines: list[Line], tolerances: Tolerances) -> tuple[NDArray, list[int]]:
    """The samples of every line (rows of 2 × ``FACE_FLOATS``, line after line, in parameter order along
    each) and how many each line got: its start points, then rounds of bisection where the geometry turns
    or a measure may cross its tolerance between two samples (see the module's description)."""
    if not lines:
        return np.empty((0, 2, FACE_FLOATS)), []
    owner = np.concatenate([np.full(len(line.start), i) for i, line in enumerate(lines)])
    params = np.concatenate([np.asarray(line.start, dtype=float) for line in lines])
    rows, tangents = _evaluate(lines, owner, params)
    width = np.array([line.hi - line.lo for line in lines])
    for _ in range(REFINE_ROUNDS):
        order = np.lexsort((params, owner))
        owner, params, rows, tangents = owner[order], params[order], rows[order], tangents[order]
        mids = _to_bisect(owner, params, rows, tangents, width, tolerances)
        if not mids.any():
            break
        new_owner, new_params = owner[:-1][mids], 0.5 * (params[:-1][mids] + params[1:][mids])
        new_rows, new_tangents = _evaluate(lines, new_owner, new_params)
        owner, params = np.concatenate([owner, new_owner]), np.concatenate([params, new_params])
        rows, tangents = np.concatenate([rows, new_rows]), np.concatenate([tangents, new_tangents])
    order = np.lexsort((params, owner))
    return rows[order], np.bincount(owner, minlength=len(lines)).tolist()


def _evaluate(lines: list[Line], owner: NDArray, params: NDArray) -> tuple[NDArray, NDArray]:
    """Rows (n × 2 × ``FACE_FLOATS``) and line tangents (n × 3) at ``params`` of the lines ``owner``."""
    raw, tangents, sign = np.empty((len(params), 2, 18)), np.empty((len(params), 3)), np.empty((len(params), 2))
    order = np.argsort(owner, kind="stable")
    ids, starts = np.unique(owner[order], return_index=True)
    for i, a, b in zip(ids.tolist(), starts.tolist(), [*starts[1:].tolist(), len(order)]):
        at = order[a:b]
        raw[at], tangents[at] = lines[i].evaluate(params[at].tolist())
        sign[at] = lines[i].signs
    rows = rows_of(raw.reshape(-1, 18), sign.reshape(-1), np.repeat(tangents, 2, axis=0))
    return rows.reshape(-1, 2, FACE_FLOATS), tangents


def _to_bisect(owner: NDArray, params: NDArray, rows: NDArray, tangents: NDArray, width: NDArray,
               tol: Tolerances) -> NDArray:  # fmt: skip
    """Which intervals between consecutive samples (of the same line, not yet too short) to bisect."""
    same = (owner[1:] == owner[:-1]) & (params[1:] - params[:-1] > width[owner[1:]] * 2.0**-16)
    gap, angle, jump = measures(rows, tol.size)
    with np.errstate(all="ignore"):
        turn = np.zeros(len(same), dtype=bool)
        for a, b in ((tangents[:-1], tangents[1:]), (rows[:-1, 0, 3:6], rows[1:, 0, 3:6])):
            cos = np.einsum("ij,ij->i", a, b)
            turn |= np.arctan2(norms(np.cross(a, b)), cos) > TURN
        near = np.zeros(len(same), dtype=bool)
        for value, limit in ((gap, tol.gap), (angle, tol.angle), (jump, tol.curvature)):
            x = value / limit if limit > 0.0 else np.zeros_like(value)
            lo, hi = np.minimum(x[:-1], x[1:]), np.maximum(x[:-1], x[1:])
            near |= (hi <= 1.0) & (2.0 * hi - lo > 1.0)  # both within, but changing enough to leave it
        lo_angle, hi_angle = np.minimum(angle[:-1], angle[1:]), np.maximum(angle[:-1], angle[1:])
        dip = (lo_angle > tol.feature) & (2.0 * lo_angle - hi_angle <= tol.feature)  # sharp at both ends: may dip
    return same & (turn | near | dip)
