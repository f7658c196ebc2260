"""Where a face is evaluated along an edge: on its own surface, at the projection of the edge's 3-D points,
from inside its own parameter domain.

A file's pcurves are not exact: a pcurve may sit 1e-13 outside its face's parameter bound, on the knot line
where the face ends, and its surface is then read from the neighbouring polynomial patch (a G1 join read as
G2); or its parameter may be shifted along the edge, so that two faces evaluated at "the same" pcurve
parameter are at two different points of the edge (a gap where there is none). Here each face is evaluated
where the edge really is on it and as the face itself sees it:

* **projection**: the edge's 3-D point is projected onto the face's surface by Gauss–Newton steps from the
  pcurve's (u, v) (or from OCCT's ``ShapeAnalysis_Surface`` where there is no pcurve, or the steps do not
  settle); a step below ``SETTLED`` of the face's parameter range is taken to first order on the
  derivatives already evaluated (no second evaluation), so a clean file costs one evaluation per sample;
* **the face's own domain**: the (u, v) is clamped into the face's bounds, and where it lies on a knot line
  of the surface below C2 (a crease or a curvature jump may be there: ``FaceDomain.breaks``), the surface is
  evaluated one-sided, from the span on the face's side of the line: exactly by the span's polynomial for a
  B-spline surface (``LocalD2``), else ``KNOT_STEP`` of the range to that side with a first-order correction
  back onto the line. The face's side is the one its bounds lie on, or, for a knot line inside the bounds,
  the one OCCT's classifier finds inside the face. Periodic surfaces are read modulo their period.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import NDArray
from OCP.BRep import BRep_Tool
from OCP.BRepAdaptor import BRepAdaptor_Surface
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
from OCP.GeomAdaptor import GeomAdaptor_Surface
from OCP.gp import gp_Pnt, gp_Pnt2d, gp_Vec
from OCP.TColStd import TColStd_Array1OfReal
from OCP.TopAbs import TopAbs_IN
from OCP.TopoDS import TopoDS_Face

from spiral_cad.cad.batch_bspline import BSplineSurfaces, bspline_derivatives, bspline_surfaces
from spiral_cad.cad.batch_geometry import surface_derivatives, surface_frame

__all__ = [
    "KNOT_STEP",
    "NEAR_KNOT",
    "SETTLED",
    "FaceDomain",
    "curve_knots",
    "derivatives",
    "evaluate_on_faces",
    "shifted_back",
    "surface_knots",
]

#: Where no one-sided evaluation exists, a knot line's side is evaluated this far from it (relative to the
#: face's parameter range) and moved back onto it to first order.
KNOT_STEP = 1e-9

#: A (u, v) this close to a knot line (relative to the face's range) is on it: evaluated one-sided.
NEAR_KNOT = 1e-9

#: A Gauss–Newton step below this (relative to the face's range) is taken to first order.
SETTLED = 1e-7

#: Gauss–Newton steps at most before OCCT's projection is asked.
_STEPS = 8


def derivatives(surface: BRepAdaptor_Surface, uvs: NDArray, out: NDArray) -> None:
    """Fill ``out`` (n × 18) with the point and derivatives (P, Su, Sv, Suu, Svv, Suv) at each (u, v) row."""
    p = gp_Pnt()
    su, sv, suu, svv, suv = gp_Vec(), gp_Vec(), gp_Vec(), gp_Vec(), gp_Vec()
    rows, nan = [], (math.nan,) * 18
    for u, v in uvs.tolist():
        if not (math.isfinite(u) and math.isfinite(v)):
            rows.append(nan)
            continue
        surface.D2(u, v, p, su, sv, suu, svv, suv)
        rows.append((*p.Coord(), *su.Coord(), *sv.Coord(), *suu.Coord(), *svv.Coord(), *suv.Coord()))
    out[:] = np.array(rows, dtype=float).reshape(-1, 18)


def shifted_back(raw: NDArray, axis: int, h: float | NDArray) -> None:
    """Move rows of derivatives evaluated ``h`` away along ``axis`` (0: u, 1: v) back by ``h``, to first
    order: P −= h·S_x, S_u −= h·S_ux, S_v −= h·S_vx (x the parameter along ``axis``)."""
    x, ux, vx = (3, 9, 15) if axis == 0 else (6, 15, 12)
    h = np.broadcast_to(np.asarray(h, dtype=float), raw.shape[:1])[:, None]
    found = raw.copy()
    for target, derivative in ((0, x), (3, ux), (6, vx)):
        raw[:, target : target + 3] -= h * found[:, derivative : derivative + 3]


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


def _knots(surface: Geom_BSplineSurface, axis: int) -> NDArray:
    count = surface.NbUKnots() if axis == 0 else surface.NbVKnots()
    knot = surface.UKnot if axis == 0 else surface.VKnot
    return np.array([knot(i) for i in range(1, count + 1)])


class FaceDomain:
    """A face's surface with its parameter bounds, periods and the knot lines where it is below C2.

    Attributes:
        lo, hi: the face's (u, v) bounds.
        width: their extent (a floor of 1e-300).
        periods: the surface's period in u and v (0: not periodic).
        breaks: per direction, the knot values where the surface is below C2 (over its whole domain; a
            periodic surface's values within one period).
        bspline: the located B-spline surface (through a rectangular trim), or None.
        surface_knots: every u and v knot of the surface's B-spline (``surface_knots``).
        frame: a plane's, cylinder's, cone's, sphere's or torus's numbers (``batch_geometry.surface_frame``), or None.
    """

    def __init__(self, face: TopoDS_Face, adaptor: BRepAdaptor_Surface) -> None:
        self.face, self.adaptor = face, adaptor
        self.frame = surface_frame(adaptor)  # an elementary surface's numbers (evaluated in closed form), or None
        geom = BRep_Tool.Surface_s(face)  # located: its points are where the face is
        self.surface_knots = surface_knots(geom)
        u0, u1, v0, v1 = BRepTools.UVBounds_s(face)
        self.lo, self.hi = np.array([u0, v0]), np.array([u1, v1])
        self.width = np.maximum(self.hi - self.lo, 1e-300)
        self.periods = np.array([geom.UPeriod() if geom.IsUPeriodic() else 0.0, geom.VPeriod() if geom.IsVPeriodic() else 0.0])
        basis = geom
        while isinstance(basis, Geom_RectangularTrimmedSurface):
            basis = basis.BasisSurface()
        self.bspline = basis if isinstance(basis, Geom_BSplineSurface) else None
        self.breaks: list[NDArray] = []
        if self.bspline is not None:
            s = self.bspline
            self.knots = [_knots(s, 0), _knots(s, 1)]
            for axis in (0, 1):
                degree = s.UDegree() if axis == 0 else s.VDegree()
                multiplicity = s.UMultiplicity if axis == 0 else s.VMultiplicity
                periodic = s.IsUPeriodic() if axis == 0 else s.IsVPeriodic()
                ks = self.knots[axis]
                inner = range(len(ks) - 1) if periodic else range(1, len(ks) - 1)  # a periodic one's first knot is a seam
                self.breaks.append(np.array([ks[i] for i in inner if multiplicity(i + 1) > degree - 2]))
        else:
            whole = GeomAdaptor_Surface(geom)
            for axis in (0, 1):
                count = whole.NbUIntervals(GeomAbs_Shape.GeomAbs_C2) if axis == 0 else whole.NbVIntervals(GeomAbs_Shape.GeomAbs_C2)
                values: list[float] = []
                if count > 1:
                    array = TColStd_Array1OfReal(1, count + 1)
                    (whole.UIntervals if axis == 0 else whole.VIntervals)(array, GeomAbs_Shape.GeomAbs_C2)
                    values = [array.Value(i) for i in range(2, count + 1)]
                self.breaks.append(np.array(values))
        self._classifier: Any = None  # OCCT's classifier of (u, v) in the face, made when first needed

    # ------------------------------------------------------------ one-sided evaluation

    def _offset(self, values: NDArray, knot: float, axis: int) -> NDArray:
        """values − knot, modulo the period in a periodic direction (the nearest representative)."""
        d = values - knot
        period = self.periods[axis]
        return d - period * np.round(d / period) if period > 0.0 else d

    def on_knot(self, uvs: NDArray) -> list[tuple[NDArray, NDArray]]:
        """Per direction, (which rows lie on a knot line below C2, the knot value there; NaN elsewhere)."""
        found = []
        for axis in (0, 1):
            knot_at = np.full(len(uvs), np.nan)
            for knot in self.breaks[axis].tolist():
                d = self._offset(uvs[:, axis], knot, axis)
                near = np.abs(d) <= NEAR_KNOT * self.width[axis]
                knot_at[near] = uvs[near, axis] - d[near]  # the line's value in the face's own period
            found.append((np.isfinite(knot_at), knot_at))
        return found

    def side(self, uv: tuple[float, float], axis: int) -> float:
        """+1 if the face lies on the side of growing parameter ``axis`` of a line through ``uv``, else −1:
        from the face's bounds where the line is one of them, else from OCCT's classifier."""
        value, edge = uv[axis], 1e-7 * self.width[axis]
        if abs(self._offset(np.array([value]), self.lo[axis], axis)[0]) <= edge:
            return 1.0
        if abs(self._offset(np.array([value]), self.hi[axis], axis)[0]) <= edge:
            return -1.0
        if self._classifier is None:
            from OCP.BRepTopAdaptor import BRepTopAdaptor_FClass2d

            self._classifier = BRepTopAdaptor_FClass2d(self.face, 1e-9)
        step = 1e-5 * self.width[axis]
        for sign in (1.0, -1.0):
            probe = list(uv)
            probe[axis] += sign * step
            if self._classifier.Perform(gp_Pnt2d(*probe)) == TopAbs_IN:
                return sign
        return 1.0

    def one_sided(self, uvs: NDArray, axis: int, sides: NDArray, out: NDArray) -> None:
        """Fill ``out`` (n × 18) with the derivatives at ``uvs`` (each on a knot line along ``axis``) from
        the span on side ``sides`` (±1) of that line; in the other direction from the span holding the value
        (one-sided too where it lies on a knot line there, from the face's side)."""
        if self.bspline is None:
            h = sides * KNOT_STEP * self.width[axis]
            moved = uvs.copy()
            moved[:, axis] += h
            derivatives(self.adaptor, moved, out)
            shifted_back(out, axis, h)
            return
        s, p = self.bspline, gp_Pnt()
        su, sv, suu, svv, suv = gp_Vec(), gp_Vec(), gp_Vec(), gp_Vec(), gp_Vec()
        other = 1 - axis
        other_lines = self.on_knot(uvs)[other][0]
        spans = []
        for a, side in ((axis, sides), (other, None)):
            ks, period, last = self.knots[a], self.periods[a], len(self.knots[a]) - 2
            values = uvs[:, a].copy()
            if period > 0.0:
                values = ks[0] + np.mod(values - ks[0], period)
            start = np.clip(np.searchsorted(ks, values, side="right") - 1, 0, last)  # ks[start] ≤ value < ks[start + 1]
            nearest = np.where(np.abs(ks[start + 1] - values) < np.abs(ks[start] - values), start + 1, start)
            on = np.abs(ks[nearest] - values) <= NEAR_KNOT * self.width[a]
            if side is None:
                side = np.array([self.side(tuple(uv), a) if hit else 1.0 for uv, hit in zip(uvs.tolist(), on & other_lines)])
            # on a knot: the span on the chosen side of it, evaluated at the knot itself
            chosen = np.where(side > 0, nearest, nearest - 1)
            values = np.where(on, ks[nearest], values)
            if period > 0.0:  # past the ends of one period: the span on the other end, the knot one period on
                values = np.where(on & (chosen < 0), ks[-1], np.where(on & (chosen > last), ks[0], values))
                chosen = np.where(chosen < 0, last, np.where(chosen > last, 0, chosen))
            start = np.where(on, np.clip(chosen, 0, last), start)
            spans.append((values, start + 1))  # OCCT's knot indices start at 1
        (av, ai), (bv, bi) = spans
        uu, ui = (av, ai) if axis == 0 else (bv, bi)
        vv, vi = (bv, bi) if axis == 0 else (av, ai)
        for k, (u, v, i, j) in enumerate(zip(uu.tolist(), vv.tolist(), ui.tolist(), vi.tolist())):
            s.LocalD2(u, v, i, i + 1, j, j + 1, p, su, sv, suu, svv, suv)
            out[k] = (*p.Coord(), *su.Coord(), *sv.Coord(), *suu.Coord(), *svv.Coord(), *suv.Coord())

    def fallback(self, points: NDArray, tolerance: float) -> NDArray:
        """OCCT's projection of ``points`` (n × 3) on the surface (periodic and singular surfaces handled)."""
        from OCP.ShapeAnalysis import ShapeAnalysis_Surface

        analysis = ShapeAnalysis_Surface(BRep_Tool.Surface_s(self.face))
        found = np.full((len(points), 2), np.nan)
        for k, xyz in enumerate(points.tolist()):
            if all(map(math.isfinite, xyz)):
                try:
                    uv = analysis.ValueOfUV(gp_Pnt(*xyz), tolerance)
                    found[k] = uv.X(), uv.Y()
                except Exception:  # noqa: BLE001,S112 - OCCT's Standard_Failure: this sample is not measured
                    continue
        return found

    def evaluate_at(self, points: NDArray, starts: NDArray, out: NDArray, tolerance: float = 1e-7) -> None:
        """Fill ``out`` (n × 18) with the face's derivatives at the projections of ``points`` (n × 3) on its
        surface, starting from ``starts`` (n × 2, NaN: none), inside the face's own domain (see the module)."""
        evaluate_on_faces([self], np.zeros(len(points), dtype=int), points, starts, np.full(len(points), tolerance), out)


# ------------------------------------------------------------ projection, all samples of all faces at once


def _clamp(uvs: NDArray, lo: NDArray, hi: NDArray, periods: NDArray) -> NDArray:
    """``uvs`` moved by whole periods to the representative nearest the bounds (a value just outside stays
    just outside), then clamped into them; all arrays n × 2."""
    with np.errstate(all="ignore"):
        moved = uvs - periods * np.round((uvs - 0.5 * (lo + hi)) / np.where(periods > 0.0, periods, 1.0))
    outside = np.maximum(lo - uvs, 0.0) + np.maximum(uvs - hi, 0.0)
    better = (periods > 0.0) & (np.maximum(lo - moved, 0.0) + np.maximum(moved - hi, 0.0) < outside)
    return np.clip(np.where(better, moved, uvs), lo, hi)


class FaceTable:
    """Faces' domains as arrays (one row per face), built once for many evaluations of the same faces."""

    def __init__(self, domains: list[FaceDomain]) -> None:
        self.domains = domains
        self.lo, self.hi = np.array([d.lo for d in domains]), np.array([d.hi for d in domains])
        self.width, self.periods = np.array([d.width for d in domains]), np.array([d.periods for d in domains])
        self.closed = np.array([d.frame is not None for d in domains])
        self.frames = np.array([np.zeros(17) if d.frame is None else d.frame for d in domains])
        # B-spline surfaces that are not periodic, one table per degree pair (batch_bspline)
        splines = [k for k, d in enumerate(domains) if d.frame is None and d.bspline is not None]
        self.tables: list[BSplineSurfaces] = []
        self.group, self.slot = np.full(len(domains), -1), np.zeros(len(domains), dtype=int)
        for table, members in bspline_surfaces([domains[k].bspline for k in splines]).values():
            faces = [splines[m] for m in members]
            self.group[faces], self.slot[faces] = len(self.tables), np.arange(len(faces))
            self.tables.append(table)

    def derivatives(self, owner: NDArray, uvs: NDArray) -> NDArray:
        """Derivatives (n × 18) at ``uvs``, each on the face ``owner``: elementary surfaces all at once in
        closed form, B-spline surfaces that are not periodic all at once per degree pair, the others point by
        point through OCCT."""
        out = np.empty((len(uvs), 18))
        closed = self.closed[owner]
        if closed.any():
            out[closed] = surface_derivatives(self.frames[owner[closed]], uvs[closed])
        group = self.group[owner]
        for g, table in enumerate(self.tables):
            rows = np.flatnonzero(group == g)
            if len(rows):
                out[rows] = bspline_derivatives(table, self.slot[owner[rows]], uvs[rows])
        rest = np.flatnonzero(~closed & (group < 0))
        for f in np.unique(owner[rest]).tolist():
            rows = rest[owner[rest] == f]
            found = np.empty((len(rows), 18))
            derivatives(self.domains[f].adaptor, uvs[rows], found)
            out[rows] = found
        return out


def evaluate_on_faces(faces: list[FaceDomain] | FaceTable, owner: NDArray, points: NDArray, starts: NDArray,
                      tolerances: NDArray, out: NDArray) -> None:  # fmt: skip
    """Fill ``out`` (n × 18) with the derivatives of face ``faces[owner[k]]`` at the projection of
    ``points[k]`` on its surface, from ``starts[k]`` (the pcurve's (u, v); NaN: OCCT's projection within
    ``tolerances[k]``), inside the face's own domain: Gauss–Newton steps (below ``SETTLED`` taken to first
    order), clamped into the face's bounds, one-sided on a knot line below C2 (see the module)."""
    table = faces if isinstance(faces, FaceTable) else FaceTable(faces)
    domains = table.domains
    n = len(points)
    lo, hi, width, periods = table.lo[owner], table.hi[owner], table.width[owner], table.periods[owner]
    uvs = np.array(starts, dtype=float).reshape(n, 2)

    def fallback(rows: NDArray) -> None:
        for k in rows.tolist():
            uvs[k] = domains[owner[k]].fallback(points[k : k + 1], float(tolerances[k]))[0]

    fallback(np.flatnonzero(~np.isfinite(uvs).all(axis=1)))
    uvs = _clamp(uvs, lo, hi, periods)
    todo = np.arange(n)
    for step in range(2 * _STEPS):
        if not len(todo):
            break
        if step == _STEPS:  # the steps did not settle: from OCCT's projection once more
            fallback(todo)
            uvs[todo] = _clamp(uvs[todo], lo[todo], hi[todo], periods[todo])
        raw = table.derivatives(owner[todo], uvs[todo])
        delta = _gauss_newton(raw, points[todo])
        target = _clamp(uvs[todo] + np.nan_to_num(delta), lo[todo], hi[todo], periods[todo])
        move = target - uvs[todo]
        settled = (np.abs(move) <= SETTLED * width[todo]).all(axis=1) | ~np.isfinite(delta).all(axis=1)
        if step == 2 * _STEPS - 1:
            settled[:] = True  # where it is: never left unfilled
            move[:] = 0.0
        first, (du, dv) = raw[settled], (move[settled, :1], move[settled, 1:])
        # to first order: P += Su du + Sv dv, Su += Suu du + Suv dv, Sv += Suv du + Svv dv
        first[:, 0:3] += first[:, 3:6] * du + first[:, 6:9] * dv
        first[:, 3:6] += first[:, 9:12] * du + first[:, 15:18] * dv
        first[:, 6:9] += first[:, 15:18] * du + first[:, 12:15] * dv
        out[todo[settled]] = first
        uvs[todo] = uvs[todo] + move
        todo = todo[~settled]
    for f in np.unique(owner).tolist():
        domain = domains[f]
        if not any(len(b) for b in domain.breaks):
            continue
        rows = np.flatnonzero(owner == f)
        for axis, (on, knot_at) in enumerate(domain.on_knot(uvs[rows])):
            if on.any():
                at = uvs[rows[on]].copy()
                at[:, axis] = knot_at[on]
                sides = np.array([domain.side(tuple(uv), axis) for uv in at.tolist()])
                found = np.empty((len(at), 18))
                domain.one_sided(at, axis, sides, found)
                out[rows[on]] = found


def _gauss_newton(raw: NDArray, points: NDArray) -> NDArray:
    """The (du, dv) that moves each surface point towards ``points`` to first order (least squares)."""
    su, sv = raw[:, 3:6], raw[:, 6:9]
    r = points - raw[:, 0:3]
    with np.errstate(all="ignore"):
        e, f, g = (np.einsum("ij,ij->i", a, b) for a, b in ((su, su), (su, sv), (sv, sv)))
        a, b = np.einsum("ij,ij->i", su, r), np.einsum("ij,ij->i", sv, r)
        det = e * g - f * f
        return np.column_stack([(g * a - f * b) / det, (e * b - f * a) / det])
