"""Biarcs along a smooth plane curve given by its points and unit tangents: the G1 path of arcs (and lines where
straight) that ``make_g2`` then makes G2, for the free-form curves of a document (a LinuxCNC NURBS block, a DXF
``SPLINE`` or ``ELLIPSE``).

Between two points of the curve with its tangents there, the biarc of equal legs (as ``gcode_write`` fits them to
cubics); the parameter interval is halved until the biarc lies within the tolerance of ``PROBES`` points of the
curve between its ends.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from ..core.segments import Arc, Line, Segment
from .gcode_write import _arcs_through, _distances, _equal_legs

if TYPE_CHECKING:
    from scipy.interpolate import BSpline

__all__ = ["BIARC_SHARE", "MAX_BIARCS", "PROBES", "curve_biarcs", "rational_spline_at"]

#: The share of a document's bound its biarcs may use (``make_g2`` uses the rest).
BIARC_SHARE = 0.3

#: The most biarcs along one curve (a longer curve is refused).
MAX_BIARCS = 20_000
#: Points probed between a biarc's ends.
PROBES = 9

#: A curve's points and unit tangents (n × 2 each) at parameters (n).
Evaluator = Callable[[NDArray[np.float64]], tuple[NDArray[np.float64], NDArray[np.float64]]]


def curve_biarcs(at: Evaluator, breaks: NDArray[np.float64], tolerance: float) -> list[Segment]:
    """Biarcs (lines where straight) within ``tolerance`` of the curve ``at``, tangent to it at their ends, from
    its first parameter of ``breaks`` to its last (every one of them an end of a biarc: the knots of a spline).

    Raises:
        ValueError: more than ``MAX_BIARCS`` biarcs needed.
    """
    u0, u1 = np.asarray(breaks[:-1], dtype=float), np.asarray(breaks[1:], dtype=float)
    keep = u1 > u0
    u0, u1 = u0[keep], u1[keep]
    inside = np.linspace(0.0, 1.0, PROBES + 2)[1:-1]
    found: list[tuple[float, list[Segment]]] = []
    while len(u0):
        if len(found) + len(u0) > MAX_BIARCS:
            raise ValueError(f"the curve needs more than {MAX_BIARCS} biarcs within {tolerance:.3g}")
        ends, tangents = at(np.stack([u0, u1], axis=1).ravel())
        ends, tangents = ends.reshape(-1, 2, 2), tangents.reshape(-1, 2, 2)
        probes = at((u0[:, None] + (u1 - u0)[:, None] * inside).ravel())[0].reshape(-1, PROBES, 2)
        p0, p1, t0, t1 = ends[:, 0], ends[:, 1], tangents[:, 0], tangents[:, 1]
        leg, joint, middle = _equal_legs(p0, p1, t0, t1)
        with np.errstate(divide="ignore", invalid="ignore"):
            first, second = _arcs_through(p0, t0, joint), _arcs_through(joint, middle, p1)
            error = np.minimum(_distances(probes, p0, joint, *first), _distances(probes, joint, p1, *second)).max(axis=1)
        good = (leg > 0.0) & np.isfinite(error) & (error <= tolerance)
        for k in np.flatnonzero(good):
            pieces = [_piece(p0[k], joint[k], first, int(k)), _piece(joint[k], p1[k], second, int(k))]
            found.append((float(u0[k]), [piece for piece in pieces if piece is not None]))
        bad = ~good
        half = (u0[bad] + u1[bad]) / 2.0
        u0, u1 = np.ravel(np.stack([u0[bad], half], axis=1)), np.ravel(np.stack([half, u1[bad]], axis=1))
    return [piece for _, pieces in sorted(found, key=lambda f: f[0]) for piece in pieces]


def rational_spline_at(curve: BSpline, u: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Points and unit tangents at ``u`` of a plane rational B-spline held in homogeneous coordinates (w x, w y, w)
    (where the derivative vanishes, as at a repeated control point, the tangent a millionth of the parameter range
    inwards, then a ten-thousandth)."""
    u = np.asarray(u, dtype=float)
    h = curve(u)
    point = h[..., :2] / h[..., 2:]
    k = curve.k
    lo, hi = float(curve.t[k]), float(curve.t[len(curve.t) - k - 1])
    inward = np.where(u < (lo + hi) / 2.0, 1.0, -1.0) * (hi - lo)
    slope = curve.derivative()
    tangent = np.full(point.shape, np.nan)
    for v in (u, u + 1e-6 * inward, u + 1e-4 * inward):
        hv, dh = curve(v), slope(v)
        t = (dh[..., :2] * hv[..., 2:] - hv[..., :2] * dh[..., 2:]) / hv[..., 2:] ** 2
        norm = np.linalg.norm(t, axis=-1, keepdims=True)
        usable = (norm > 1e-12 * max(1.0, float(np.abs(point).max()))) & np.isnan(tangent[..., :1])
        with np.errstate(invalid="ignore", divide="ignore"):
            tangent = np.where(usable, t / norm, tangent)
    return point, tangent


def _piece(start: NDArray[np.float64], end: NDArray[np.float64], arcs: tuple[NDArray, NDArray, NDArray], k: int) -> Segment | None:
    """One piece of a biarc: a line, or the arc about its centre from ``start`` to ``end`` (None: no length)."""
    centre, radius, line = arcs[0][k], float(arcs[1][k]), bool(arcs[2][k])
    if float(np.linalg.norm(end - start)) <= 1e-12 * max(1.0, float(np.abs(start).max())):
        return None
    if line:
        return Line(tuple(start), tuple(end))
    a0 = math.atan2(start[1] - centre[1], start[0] - centre[0])
    a1 = math.atan2(end[1] - centre[1], end[0] - centre[0])
    sweep = ((a1 - a0) if radius > 0 else (a0 - a1)) % (2.0 * math.pi)
    return Arc(tuple(centre), radius, a0, sweep if sweep > 0.0 else 2.0 * math.pi)
