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
from functools import partial

import numpy as np
from numpy.typing import NDArray
from OCP.BRep import BRep_Tool
from OCP.BRepAdaptor import BRepAdaptor_Curve, BRepAdaptor_Curve2d, BRepAdaptor_Surface
from OCP.BRepTools import BRepTools
from OCP.Geom import Geom_BSplineCurve, Geom_TrimmedCurve
from OCP.GeomAbs import GeomAbs_Shape
from OCP.gp import gp_Pnt, gp_Pnt2d, gp_Vec
from OCP.TColStd import TColStd_Array1OfReal
from OCP.TopoDS import TopoDS_Edge, TopoDS_Face

from ..continuity.joints import norms
from .batch_bspline import bspline_curve_points, bspline_curves
from .batch_geometry import curve_frame, curve_points
from .face_projection import KNOT_STEP, FaceDomain, FaceTable, curve_knots, evaluate_on_faces

__all__ = ["END_INSET", "FACE_FLOATS", "KNOT_STEP", "REFINE_ROUNDS", "TURN", "EdgeLine", "KnotLine", "Line", "Tolerances",
           "knot_lines", "measures", "sample_lines"]  # fmt: skip

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
    return [lo + END_INSET * width, *(lo + width * (k + 0.5) / samples for k in range(samples)), hi - END_INSET * width]


def _crossings(uv_of: Callable[[list[float]], NDArray], grid: NDArray, knots: tuple[list[float], list[float]]) -> list[float]:
    """Edge parameters where the edge's (u, v) on a face (``uv_of``: its pcurve, or the projections of its
    points) crosses a knot value of the face's surface (u = k or v = k), from the sign changes on ``grid``,
    each refined by a few secant steps (exact at once for a straight pcurve)."""
    if not knots[0] and not knots[1]:
        return []
    values = uv_of(grid.tolist())
    found = []
    for axis in (0, 1):
        for knot in knots[axis]:
            f = values[:, axis] - knot
            for i in np.nonzero(f[:-1] * f[1:] < 0.0)[0].tolist():
                a, b, fa, fb = float(grid[i]), float(grid[i + 1]), float(f[i]), float(f[i + 1])
                t = a
                for _ in range(4):
                    t = a - fa * (b - a) / (fb - fa)
                    ft = float(uv_of([t])[0, axis]) - knot
                    if not math.isfinite(ft) or abs(ft) <= 1e-14 * max(1.0, abs(knot)):
                        break
                    a, fa = (t, ft) if (ft < 0) == (fa < 0) else (a, fa)
                    b, fb = (t, ft) if (ft < 0) == (fb < 0) else (b, fb)
                found.append(t)
    return found


def _pcurve_points(pcurve: BRepAdaptor_Curve2d, params: list[float]) -> NDArray:
    """The pcurve's (u, v) at ``params`` (n × 2)."""
    uv, found = gp_Pnt2d(), []
    for t in params:
        pcurve.D0(t, uv)
        found.append(uv.Coord())
    return np.array(found, dtype=float).reshape(-1, 2)


# ------------------------------------------------------------ evaluating


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
    """An edge shared by two faces (or a seam: one face twice, the edge used both ways).

    Each face is evaluated at the projection of the edge's 3-D point onto its surface, inside its own
    domain (``spiral_cad.cad.face_projection``); its pcurve, where there is one, is the starting guess.
    """

    def __init__(self, edge: TopoDS_Edge, sides: list[tuple[FaceDomain, TopoDS_Edge]], signs: tuple[float, float],
                 samples: int) -> None:  # fmt: skip
        self.edge, self.sides, self.signs = edge, sides, signs
        self.curve = BRepAdaptor_Curve(edge)
        self.tolerance = BRep_Tool.Tolerance_s(edge)
        self.lo, self.hi = self.curve.FirstParameter(), self.curve.LastParameter()
        self.curves_on_faces = [BRep_Tool.CurveOnSurface_s(oriented, domain.face, 0.0, 0.0) for domain, oriented in sides]
        self.pcurves = [None if on_face is None else BRepAdaptor_Curve2d(oriented, domain.face)
                        for (domain, oriented), on_face in zip(sides, self.curves_on_faces)]  # fmt: skip
        frames = [curve_frame(self.curve), *(None if pcurve is None else curve_frame(pcurve) for pcurve in self.pcurves)]
        # the edge and both pcurves lines, circles or ellipses: located in closed form, with other such edges
        self.closed: list[float] | None = None
        if all(frame is not None for frame in frames):
            self.closed = [x for frame in frames for x in frame or ()]
        # else each curve in closed form where it can be, point by point where not
        self.batch = [None if frame is None else partial(curve_points, np.array(frame)) for frame in frames]
        floor = floor_points(self.lo, self.hi, samples)
        # (a line, circle or ellipse, as ``curve_frame`` found, has no knots)
        geometric = frames[0] is None and BRep_Tool.IsGeometric_s(edge)
        three_d = BRep_Tool.Curve_s(edge, 0.0, 0.0) if geometric else None  # located, as the edge
        while isinstance(three_d, Geom_TrimmedCurve):
            three_d = three_d.BasisCurve()
        breaks = curve_knots(three_d) if geometric else []
        # a B-spline edge between faces whose pcurves are lines, circles or ellipses: located with other such edges
        self.spline = (three_d if isinstance(three_d, Geom_BSplineCurve) and not three_d.IsPeriodic()
                       and all(frame is not None for frame in frames[1:]) else None)  # fmt: skip
        self.pcurve_frames = [x for frame in frames[1:] for x in frame or ()]
        grid, own = None, list(breaks)
        for (domain, oriented), pcurve, on_face, frame in zip(sides, self.pcurves, self.curves_on_faces, frames[1:]):
            # where the knot lines of the face's surface cross the edge, in both directions, pcurve or not
            if pcurve is not None and frame is None:
                breaks += curve_knots(on_face)
            knots = domain.surface_knots
            if pcurve is not None:  # a pcurve stays within the face's (u, v) bounds: knots on or past them are not crossed
                knots = ([k for k in knots[0] if domain.lo[0] < k < domain.hi[0]], [k for k in knots[1] if domain.lo[1] < k < domain.hi[1]])
            if not any(knots):
                continue
            if grid is None:
                grid = np.unique(np.array(floor + own + [self.lo, self.hi]))
            uv_of = (partial(_pcurve_points, pcurve) if pcurve is not None
                     else partial(_projected_points, oriented, domain.face))  # fmt: skip
            breaks += _crossings(uv_of, grid, knots)
        self.start = floor + span_points(self.lo, self.hi, breaks)

    def locate(self, params: list[float]) -> tuple[NDArray, NDArray, list[NDArray]]:
        """The edge's points (n × 3) and unit tangents (n × 3) at ``params``, and per face the (u, v) to start
        its projection from: its pcurve's, or OCCT's projection where it has none."""
        if self.closed is not None:
            return located(np.broadcast_to(np.array(self.closed), (len(params), len(self.closed))), np.asarray(params, dtype=float))
        edge, *on_faces = self.batch
        if edge is not None:
            points, tangents = edge(np.asarray(params, dtype=float))
        else:
            p, d1, found = gp_Pnt(), gp_Vec(), []
            for t in params:
                self.curve.D1(t, p, d1)
                found.append((*p.Coord(), *d1.Coord()))
            both = np.array(found, dtype=float).reshape(-1, 6)
            points, tangents = both[:, :3], both[:, 3:]
        with np.errstate(all="ignore"):
            tangents = tangents / norms(tangents)[:, None]
        starts = [_projected_points(oriented, domain.face, params) if pcurve is None
                  else _pcurve_points(pcurve, params) if batch is None else batch(np.asarray(params, dtype=float))[0]
                  for (domain, oriented), pcurve, batch in zip(self.sides, self.pcurves, on_faces)]  # fmt: skip
        return points, tangents, starts

    def evaluate(self, params: list[float]) -> tuple[NDArray, NDArray]:
        """Both faces' derivatives at the projections of the edge's points (from the pcurves' (u, v), or
        OCCT's projection without one), and the unit tangents of the edge's 3-D curve."""
        points, tangents, starts = self.locate(params)
        raw = np.empty((len(params), 2, 18))
        for side, ((domain, _), start) in enumerate(zip(self.sides, starts)):
            domain.evaluate_at(points, start, raw[:, side], self.tolerance)
        return raw, tangents


def located(frames: NDArray, params: NDArray) -> tuple[NDArray, NDArray, list[NDArray]]:
    """``EdgeLine.locate`` of edges whose curve and pcurves are lines, circles or ellipses, one row per
    parameter: ``frames`` (n × 30) the curve's 12 numbers and each pcurve's 9 (``batch_geometry.curve_frame``)."""
    points, tangents = curve_points(frames[:, :12], params)
    with np.errstate(all="ignore"):
        tangents /= norms(tangents)[:, None]
    return points, tangents, [curve_points(frames[:, 12:21], params)[0], curve_points(frames[:, 21:], params)[0]]


def _projected_points(edge: TopoDS_Edge, face: TopoDS_Face, params: list[float]) -> NDArray:
    return np.array(projected(edge, face, params), dtype=float).reshape(-1, 2)


class KnotLine(Line):
    """A knot line u = k (``along_u``) or v = k inside one face, across the face's (u, v) bounds (a
    trimmed face's line may be sampled a little beyond its trimming)."""

    def __init__(self, domain: FaceDomain, along_u: bool, knot: float, sign: float, samples: int) -> None:
        self.domain, self.along_u, self.knot, self.signs = domain, along_u, knot, (sign, sign)
        face = domain.face
        u0, u1, v0, v1 = BRepTools.UVBounds_s(face)
        self.lo, self.hi = (v0, v1) if along_u else (u0, u1)
        us, vs = domain.surface_knots
        self.start = floor_points(self.lo, self.hi, samples) + span_points(self.lo, self.hi, vs if along_u else us)
        self.name = f"{'u' if along_u else 'v'} = {knot:.6g}"
        s = domain.bspline
        if s is not None:
            axis = 0 if along_u else 1
            ks = domain.knots[axis]
            period = domain.periods[axis]
            reduced = ks[0] + (knot - ks[0]) % period if period > 0.0 else knot
            index = int(np.argmin(np.abs(ks - reduced))) + 1
            multiplicity = (s.UMultiplicity if along_u else s.VMultiplicity)(index)
            self.name += f" (knot of multiplicity {multiplicity})"
        else:
            self.name += f" (a knot of the {_kind(domain.adaptor)} surface's B-spline, below C2)"

    def evaluate(self, params: list[float]) -> tuple[NDArray, NDArray]:
        """The two sides' derivatives on the line: the two spans' polynomials of a B-spline surface, else
        ``KNOT_STEP`` either side moved back onto the line to first order."""
        raw = np.empty((len(params), 2, 18))
        axis = 0 if self.along_u else 1
        uvs = np.empty((len(params), 2))
        uvs[:, axis], uvs[:, 1 - axis] = self.knot, params
        for side, sign in enumerate((-1.0, 1.0)):
            self.domain.one_sided(uvs, axis, np.full(len(params), sign), raw[:, side])
        tangents = raw[:, 0, 6:9] if self.along_u else raw[:, 0, 3:6]  # along the line: Sv on a u line, Su on a v line
        with np.errstate(all="ignore"):
            return raw, tangents / norms(tangents)[:, None]


def _kind(surface: BRepAdaptor_Surface) -> str:
    name = surface.GetType().name.removeprefix("GeomAbs_").removesuffix("Surface").removeprefix("SurfaceOf")
    return name.lower() or "other"


def knot_lines(domain: FaceDomain, sign: float, samples: int) -> list[KnotLine]:
    """The knot lines inside a face where its surface is less than C2 (a crease or a curvature jump may
    be there): of a B-spline surface, of the B-spline curve of an extrusion or a revolution, of an offset's
    or a trimmed surface's basis."""
    us, vs = surface_breaks(domain.adaptor, GeomAbs_Shape.GeomAbs_C2)
    return [KnotLine(domain, along_u, k, sign, samples) for along_u, ks in ((True, us), (False, vs)) for k in ks]


# ------------------------------------------------------------ sampling in rounds


def sample_lines(lines: list[Line], tolerances: Tolerances) -> tuple[NDArray, list[int]]:
    """The samples of every line (rows of 2 × ``FACE_FLOATS``, line after line, in parameter order along
    each) and how many each line got: its start points, then rounds of bisection where the geometry turns
    or a measure may cross its tolerance between two samples (see the module's description)."""
    if not lines:
        return np.empty((0, 2, FACE_FLOATS)), []
    table = _LineTable(lines)
    owner = np.concatenate([np.full(len(line.start), i) for i, line in enumerate(lines)])
    params = np.concatenate([np.asarray(line.start, dtype=float) for line in lines])
    rows, tangents = table.evaluate(owner, params)
    width = np.array([line.hi - line.lo for line in lines])
    for _ in range(REFINE_ROUNDS):
        order = np.lexsort((params, owner))
        owner, params, rows, tangents = owner[order], params[order], rows[order], tangents[order]
        mids = _to_bisect(owner, params, rows, tangents, width, tolerances)
        if not mids.any():
            break
        new_owner, new_params = owner[:-1][mids], 0.5 * (params[:-1][mids] + params[1:][mids])
        new_rows, new_tangents = table.evaluate(new_owner, new_params)
        owner, params = np.concatenate([owner, new_owner]), np.concatenate([params, new_params])
        rows, tangents = np.concatenate([rows, new_rows]), np.concatenate([tangents, new_tangents])
    order = np.lexsort((params, owner))
    return rows[order], np.bincount(owner, minlength=len(lines)).tolist()


class _LineTable:
    """What ``sample_lines`` needs of every line as arrays (one row per line), so that each round
    evaluates all samples together: the faces along every edge are projected on all at once
    (``evaluate_on_faces``), and edges whose curve and pcurves are lines, circles or ellipses are located
    all at once (``located``), as are B-spline edges whose pcurves are (``bspline_curve_points``)."""

    def __init__(self, lines: list[Line]) -> None:
        self.lines = lines
        self.signs = np.array([line.signs for line in lines])
        self.on_edge = np.array([isinstance(line, EdgeLine) for line in lines])
        self.closed = np.array([isinstance(line, EdgeLine) and line.closed is not None for line in lines])
        self.tolerance = np.array([line.tolerance if isinstance(line, EdgeLine) else 0.0 for line in lines])
        none = [0.0] * 30
        self.frames = np.array([line.closed if isinstance(line, EdgeLine) and line.closed is not None else none for line in lines])
        splines = [(k, line) for k, line in enumerate(lines) if isinstance(line, EdgeLine) and line.spline is not None]
        self.splines = bspline_curves([edge.spline for _, edge in splines])
        self.spline_row = np.full((len(lines), 2), -1)  # (degree, row in its table) of a B-spline edge's curve
        for degree, (_, members) in self.splines.items():
            for row, m in enumerate(members):
                k, edge = splines[m]
                self.spline_row[k] = degree, row
                self.frames[k, 12:] = edge.pcurve_frames
        self.face_of = np.zeros((len(lines), 2), dtype=int)
        places: dict[int, int] = {}  # id of a face's domain → its place in ``domains``
        self.domains: list[FaceDomain] = []
        for i, line in enumerate(lines):
            if not isinstance(line, EdgeLine):
                continue
            for side, (domain, _) in enumerate(line.sides):
                if id(domain) not in places:
                    places[id(domain)] = len(self.domains)
                    self.domains.append(domain)
                self.face_of[i, side] = places[id(domain)]
        self.faces = FaceTable(self.domains)

    def evaluate(self, owner: NDArray, params: NDArray) -> tuple[NDArray, NDArray]:
        """Rows (n × 2 × ``FACE_FLOATS``) and line tangents (n × 3) at ``params`` of the lines ``owner``."""
        n = len(params)
        raw, tangents = np.empty((n, 2, 18)), np.empty((n, 3))
        points, uvs = np.empty((n, 3)), np.empty((2, n, 2))
        closed = self.closed[owner]
        if closed.any():
            at = np.flatnonzero(closed)
            points[at], tangents[at], (uvs[0, at], uvs[1, at]) = located(self.frames[owner[at]], params[at])
        degrees = self.spline_row[owner, 0]
        for degree, (table, _) in self.splines.items():
            at = np.flatnonzero(degrees == degree)
            points[at], tangents[at] = bspline_curve_points(table, self.spline_row[owner[at], 1], params[at])
            with np.errstate(all="ignore"):
                tangents[at] /= norms(tangents[at])[:, None]
            frames = self.frames[owner[at]]
            uvs[0, at], uvs[1, at] = curve_points(frames[:, 12:21], params[at])[0], curve_points(frames[:, 21:], params[at])[0]
        rest = np.flatnonzero(~closed & (degrees < 0))
        order = rest[np.argsort(owner[rest], kind="stable")]
        ids, starts = np.unique(owner[order], return_index=True)
        for i, a, b in zip(ids.tolist(), starts.tolist(), [*starts[1:].tolist(), len(order)]):
            at, line = order[a:b], self.lines[i]
            if isinstance(line, EdgeLine):
                points[at], tangents[at], (uvs[0, at], uvs[1, at]) = line.locate(params[at].tolist())
            else:
                raw[at], tangents[at] = line.evaluate(params[at].tolist())
        rows = np.flatnonzero(self.on_edge[owner])
        for side in (0, 1) if len(rows) else ():
            found = np.empty((len(rows), 18))
            evaluate_on_faces(self.faces, self.face_of[owner[rows], side], points[rows], uvs[side, rows],
                              self.tolerance[owner[rows]], found)  # fmt: skip
            raw[rows, side] = found
        sign = self.signs[owner]
        found = rows_of(raw.reshape(-1, 18), sign.reshape(-1), np.repeat(tangents, 2, axis=0))
        return found.reshape(-1, 2, FACE_FLOATS), tangents


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
