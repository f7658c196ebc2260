"""Points and derivatives of B-spline surfaces and curves, rational or not, many of them and many
parameters at once.

OCCT evaluates a B-spline one point per call (``D2``, ``D1``); here the samples of every surface of one
degree pair (every curve of one degree) are a few numpy expressions: the basis functions and their first two derivatives at every
sample (Piegl and Tiller, *The NURBS Book*, algorithm A2.3, each sample on its own surface's knots), their
tensor product with the homogeneous poles, and the quotient rule of a rational surface (A4.4). Each sample
is evaluated on the polynomial span that holds it: ``U[i] ≤ u < U[i+1]``, the last span at the end of the
range. (On a knot line below C2 the spans on either side differ; the face checker evaluates those samples
one-sided, from the face's side, through OCCT's ``LocalD2``.) Periodic surfaces are left to OCCT.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from OCP.Geom import Geom_BSplineCurve, Geom_BSplineSurface

__all__ = ["BSplineCurves", "BSplineSurfaces", "bspline_curve_points", "bspline_curves", "bspline_derivatives",
           "bspline_surfaces"]  # fmt: skip


@dataclass(frozen=True)
class BSplineSurfaces:
    """B-spline surfaces of one degree pair as arrays, one row per surface.

    Attributes:
        degrees: the degrees in u and v.
        knots: the flat knot vectors in u and v (each knot repeated by its multiplicity), padded with inf.
        spans: per direction, the first and the last span index of each surface's flat knots.
        poles: every surface's homogeneous poles (w·P, w), one after another, rows of 4.
        first_pole: where each surface's poles start in ``poles``.
        columns: each surface's number of poles in v (its poles are stored u-major).
    """

    degrees: tuple[int, int]
    knots: tuple[NDArray, NDArray]
    spans: tuple[NDArray, NDArray]
    poles: NDArray
    first_pole: NDArray
    columns: NDArray


def _padded(rows: list[NDArray]) -> NDArray:
    out = np.full((len(rows), max(len(r) for r in rows)), np.inf)
    for k, row in enumerate(rows):
        out[k, : len(row)] = row
    return out


def _homogeneous(points: list[tuple[float, float, float]], weights: list[float]) -> NDArray:
    """Rows (w·P, w) of the poles ``points`` with their ``weights``."""
    rows = np.empty((len(weights), 4))
    rows[:, 3] = weights
    rows[:, :3] = points
    rows[:, :3] *= rows[:, 3:]
    return rows


def bspline_surfaces(surfaces: list[Geom_BSplineSurface]) -> dict[tuple[int, int], tuple[BSplineSurfaces, list[int]]]:
    """The surfaces that are not periodic, grouped by degree pair: per pair the table and the positions of
    its surfaces in ``surfaces`` (their poles where they are: a located copy gives located ones)."""
    groups: dict[tuple[int, int], list[int]] = {}
    for k, s in enumerate(surfaces):
        if not (s.IsUPeriodic() or s.IsVPeriodic()):
            groups.setdefault((s.UDegree(), s.VDegree()), []).append(k)
    found = {}
    for degrees, members in groups.items():
        knots: tuple[list[NDArray], list[NDArray]] = ([], [])
        poles, columns = [], []
        for k in members:
            s = surfaces[k]
            for axis, (count, knot, multiplicity) in enumerate(((s.NbUKnots(), s.UKnot, s.UMultiplicity),
                                                                (s.NbVKnots(), s.VKnot, s.VMultiplicity))):  # fmt: skip
                values = [knot(i) for i in range(1, count + 1)]
                knots[axis].append(np.repeat(values, [multiplicity(i) for i in range(1, count + 1)]))
            rational = s.IsURational() or s.IsVRational()
            nu, nv = s.NbUPoles(), s.NbVPoles()
            cells = [(i, j) for i in range(1, nu + 1) for j in range(1, nv + 1)]
            weights = [s.Weight(i, j) for i, j in cells] if rational else [1.0] * len(cells)
            poles.append(_homogeneous([s.Pole(i, j).Coord() for i, j in cells], weights))
            columns.append(nv)
        (p, q), sizes = degrees, [np.array([len(k) for k in knots[axis]]) for axis in (0, 1)]
        spans = ((np.full(len(members), p), sizes[0] - p - 2), (np.full(len(members), q), sizes[1] - q - 2))
        first = np.concatenate([[0], np.cumsum([len(b) for b in poles])[:-1]])
        table = BSplineSurfaces(degrees, (_padded(knots[0]), _padded(knots[1])), (np.stack(spans[0]), np.stack(spans[1])),
                                np.vstack(poles), first, np.array(columns))  # fmt: skip
        found[degrees] = (table, members)
    return found


def _basis(knots: NDArray, degree: int, span: NDArray, t: NDArray) -> NDArray:
    """(n, 3, degree + 1): the non-zero basis functions of each sample's span and their first two
    derivatives at ``t``, each sample on its own row of ``knots`` (A2.3; a derivative beyond the degree is 0)."""
    n, p = len(t), degree

    def knot(offset: int) -> NDArray:
        return np.take_along_axis(knots, (span + offset)[:, None], axis=1)[:, 0]

    ndu = np.zeros((n, p + 1, p + 1))
    ndu[:, 0, 0] = 1.0
    left, right = np.zeros((n, p + 1)), np.zeros((n, p + 1))
    for j in range(1, p + 1):
        left[:, j] = t - knot(1 - j)
        right[:, j] = knot(j) - t
        saved = np.zeros(n)
        for r in range(j):
            ndu[:, j, r] = right[:, r + 1] + left[:, j - r]  # the knot differences, below the diagonal
            temp = ndu[:, r, j - 1] / ndu[:, j, r]
            ndu[:, r, j] = saved + right[:, r + 1] * temp
            saved = left[:, j - r] * temp
        ndu[:, j, j] = saved
    ders = np.zeros((n, 3, p + 1))
    ders[:, 0] = ndu[:, :, p]
    for r in range(p + 1):
        a = np.zeros((2, n, p + 1))
        a[0, :, 0] = 1.0
        s1, s2 = 0, 1
        for k in range(1, min(2, p) + 1):
            d = np.zeros(n)
            rk, pk = r - k, p - k
            if r >= k:
                a[s2, :, 0] = a[s1, :, 0] / ndu[:, pk + 1, rk]
                d = a[s2, :, 0] * ndu[:, rk, pk]
            for j in range(1 if rk >= -1 else -rk, (k - 1 if r - 1 <= pk else p - r) + 1):
                a[s2, :, j] = (a[s1, :, j] - a[s1, :, j - 1]) / ndu[:, pk + 1, rk + j]
                d = d + a[s2, :, j] * ndu[:, rk + j, pk]
            if r <= pk:
                a[s2, :, k] = -a[s1, :, k - 1] / ndu[:, pk + 1, r]
                d = d + a[s2, :, k] * ndu[:, r, pk]
            ders[:, k, r] = d
            s1, s2 = s2, s1
    ders[:, 1] *= p
    ders[:, 2] *= p * (p - 1)
    return ders


def bspline_derivatives(table: BSplineSurfaces, which: NDArray, uvs: NDArray) -> NDArray:
    """Rows (n × 18) of P, Su, Sv, Suu, Svv, Suv at ``uvs`` (n × 2), each on the surface ``which`` of ``table``."""
    which = np.asarray(which, dtype=int)
    uvs = np.asarray(uvs, dtype=float).reshape(-1, 2)
    ders, spans = [], []
    for axis in (0, 1):
        knots, degree, t = table.knots[axis][which], table.degrees[axis], uvs[:, axis]
        first, last = table.spans[axis][0][which], table.spans[axis][1][which]
        span = np.clip((knots <= t[:, None]).sum(axis=1) - 1, first, last)
        ders.append(_basis(knots, degree, span, t))
        spans.append(span)
    (p, q), (su, sv) = table.degrees, spans
    rows = (su[:, None] - p + np.arange(p + 1))[:, :, None] * table.columns[which][:, None, None]
    index = table.first_pole[which][:, None, None] + rows + (sv[:, None] - q + np.arange(q + 1))[:, None, :]
    along_v = np.matmul(ders[1][:, None], table.poles[index])  # (n, p + 1, 3, 4): each row of poles along v
    skl = np.matmul(ders[0], along_v.reshape(len(uvs), p + 1, 12)).reshape(-1, 3, 3, 4)  # the homogeneous derivatives
    a, w = skl[..., :3], skl[..., 3:]
    with np.errstate(all="ignore"):
        s00 = a[:, 0, 0] / w[:, 0, 0]
        s10 = (a[:, 1, 0] - w[:, 1, 0] * s00) / w[:, 0, 0]
        s01 = (a[:, 0, 1] - w[:, 0, 1] * s00) / w[:, 0, 0]
        s20 = (a[:, 2, 0] - 2.0 * w[:, 1, 0] * s10 - w[:, 2, 0] * s00) / w[:, 0, 0]
        s02 = (a[:, 0, 2] - 2.0 * w[:, 0, 1] * s01 - w[:, 0, 2] * s00) / w[:, 0, 0]
        s11 = (a[:, 1, 1] - w[:, 1, 0] * s01 - w[:, 0, 1] * s10 - w[:, 1, 1] * s00) / w[:, 0, 0]
    return np.concatenate([s00, s10, s01, s20, s02, s11], axis=1)


@dataclass(frozen=True)
class BSplineCurves:
    """3-D B-spline curves of one degree as arrays, one row per curve.

    Attributes:
        degree: their degree.
        knots: the flat knot vectors (each knot repeated by its multiplicity), padded with inf.
        spans: the first and the last span index of each curve's flat knots.
        poles: every curve's homogeneous poles (w·P, w), one after another, rows of 4.
        first_pole: where each curve's poles start in ``poles``.
    """

    degree: int
    knots: NDArray
    spans: NDArray
    poles: NDArray
    first_pole: NDArray


def bspline_curves(curves: list[Geom_BSplineCurve]) -> dict[int, tuple[BSplineCurves, list[int]]]:
    """The curves that are not periodic, grouped by degree: per degree the table and the positions of its
    curves in ``curves``."""
    groups: dict[int, list[int]] = {}
    for k, c in enumerate(curves):
        if not c.IsPeriodic():
            groups.setdefault(c.Degree(), []).append(k)
    found = {}
    for degree, members in groups.items():
        knots, poles = [], []
        for k in members:
            c = curves[k]
            count = c.NbKnots()
            knots.append(np.repeat([c.Knot(i) for i in range(1, count + 1)], [c.Multiplicity(i) for i in range(1, count + 1)]))
            cells = range(1, c.NbPoles() + 1)
            weights = [c.Weight(i) for i in cells] if c.IsRational() else [1.0] * len(cells)
            poles.append(_homogeneous([c.Pole(i).Coord() for i in cells], weights))
        sizes = np.array([len(k) for k in knots])
        first = np.concatenate([[0], np.cumsum([len(b) for b in poles])[:-1]])
        spans = np.stack([np.full(len(members), degree), sizes - degree - 2])
        found[degree] = (BSplineCurves(degree, _padded(knots), spans, np.vstack(poles), first), members)
    return found


def bspline_curve_points(table: BSplineCurves, which: NDArray, ts: NDArray) -> tuple[NDArray, NDArray]:
    """Points and first derivatives (n × 3 each) at ``ts``, each on the curve ``which`` of ``table``."""
    which, ts = np.asarray(which, dtype=int), np.asarray(ts, dtype=float)
    knots, p = table.knots[which], table.degree
    span = np.clip((knots <= ts[:, None]).sum(axis=1) - 1, table.spans[0][which], table.spans[1][which])
    ders = _basis(knots, p, span, ts)[:, :2]
    index = table.first_pole[which][:, None] + span[:, None] - p + np.arange(p + 1)
    ck = np.matmul(ders, table.poles[index])  # (n, 2, 4): the homogeneous point and derivative
    a, w = ck[..., :3], ck[..., 3:]
    with np.errstate(all="ignore"):
        point = a[:, 0] / w[:, 0]
        return point, (a[:, 1] - w[:, 1] * point) / w[:, 0]
