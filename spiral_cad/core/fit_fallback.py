"""The fallback of ``fit_points``: a Douglas–Peucker polyline within half the tolerance with every
corner rounded by a spiral pair (``douglas_peucker`` also serves the profile fit)."""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from .chain import Chain
from .errors import NoSolutionError
from .fit_distances import chain_distances
from .segments import Segment
from .transitions import Transition, line_to_line

__all__ = ["douglas_peucker"]


def douglas_peucker(pts: NDArray[np.float64], epsilon: float, *, vertical: bool = False) -> NDArray[np.int64]:
    """Douglas–Peucker: indices of a polyline through some of ``pts`` (n, 2) within ``epsilon`` of every point,
    measured across each chord, or along y (``vertical``: elevations over increasing stations)."""
    keep = np.zeros(len(pts), dtype=bool)
    keep[0] = keep[-1] = True
    stack = [(0, len(pts) - 1)]
    while stack:
        i, j = stack.pop()
        if j - i < 2:
            continue
        a, b = pts[i], pts[j]
        d = b - a
        length = math.hypot(*d)
        rel = pts[i + 1 : j] - a
        if vertical:
            off = np.abs(rel[:, 1] - rel[:, 0] * (d[1] / d[0]))
        elif length > 0:
            off = np.abs(rel[:, 0] * d[1] - rel[:, 1] * d[0]) / length
        else:
            off = np.hypot(*rel.T)
        k = int(np.argmax(off))
        if off[k] > epsilon:
            m = i + 1 + k
            keep[m] = True
            stack.extend([(i, m), (m, j)])
    return np.flatnonzero(keep)


def _fallback(
    pts: NDArray[np.float64], tol: float, shape: str, units: str, closed: bool
) -> tuple[Chain, NDArray[np.float64], NDArray[np.float64]]:
    """A polyline within half the tolerance, every corner rounded by a spiral pair that cuts it by
    at most a quarter; tighter until every point is within the tolerance."""
    worst = math.inf
    for level in range(6):
        epsilon = tol / 2.0 ** (level + 1)
        ring = np.vstack([pts, pts[:1]]) if closed else pts
        vertices = ring[douglas_peucker(ring, epsilon)]
        if closed:
            vertices = vertices[:-1]
        try:
            chain = _rounded(vertices, epsilon / 2.0, shape, units, closed)
        except ValueError:
            continue
        residual, stations = chain_distances(chain, pts)
        worst = min(worst, float(residual.max()))
        if worst <= tol:
            return chain, residual, stations
    raise NoSolutionError(f"no G2 chain within tolerance {tol:g} was found (closest: {worst:.6g})")


def _rounded(vertices: NDArray[np.float64], cut: float, shape: str, units: str, closed: bool) -> Chain:
    """The polyline ``vertices`` with every corner rounded by a line_to_line pair cutting it by at most ``cut``."""
    if closed:
        if len(vertices) < 3:
            raise ValueError("too few corners")
        # Start half way along the first leg.
        middle = 0.5 * (vertices[0] + vertices[1])
        vertices = np.vstack([middle, vertices[1:], vertices[:1], middle])
    vertices = _split_sharp(vertices, cut)
    mids = 0.5 * (vertices[1:] + vertices[:-1])
    parts: list[Transition | Segment] = []
    for k in range(1, len(vertices) - 1):
        p0 = vertices[0] if k == 1 else mids[k - 1]
        p1 = vertices[-1] if k == len(vertices) - 2 else mids[k]
        a, c, b = (tuple(v.tolist()) for v in (p0, vertices[k], p1))
        try:
            widest = line_to_line(a, c, b, None, shape)
        except ValueError:
            continue  # collinear: no corner
        depth = float(np.hypot(*(np.asarray(widest.joint) - vertices[k])))
        pair = widest if depth <= cut else line_to_line(a, c, b, abs(widest.spirals[0].end_curvature) * depth / cut, shape)
        parts.append(pair)
    start, end = tuple(vertices[0].tolist()), tuple(vertices[-1].tolist())
    return Chain.join(parts, start=start, end=end, units=units)


def _split_sharp(vertices: NDArray[np.float64], cut: float) -> NDArray[np.float64]:
    """Corners turning by more than 90° become two corners ``cut`` from it along its legs (a chamfer)."""
    out = [vertices[0]]
    for k in range(1, len(vertices) - 1):
        u, v = vertices[k] - vertices[k - 1], vertices[k + 1] - vertices[k]
        lu, lv = math.hypot(*u), math.hypot(*v)
        if float(u @ v) < 0.0:
            t = min(cut, 0.25 * lu, 0.25 * lv)
            out.extend([vertices[k] - t * u / lu, vertices[k] + t * v / lv])
        else:
            out.append(vertices[k])
    out.append(vertices[-1])
    return np.array(out)
