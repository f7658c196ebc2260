"""The runs of a point fit: the lines and circles the points follow, grown from the flattest points.

Each run is the longest stretch of consecutive points one line or circle holds
within a core tolerance (``fit_points`` step 3); a primitive knows the foot of
a point on its line or circle, where the joins (``_fit_joins``) meet it.
"""

from __future__ import annotations

import bisect
import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray


@dataclass
class _Primitive:
    """A line (point, unit direction) or circle (centre, signed radius) fitted to points [a, b)."""

    a: int
    b: int
    line: bool
    point: NDArray[np.float64]
    direction: NDArray[np.float64]
    center: NDArray[np.float64]
    radius: float
    span: float  # arc: the angle the run's points travel; line: their length
    split: int = -1  # a line's point up to which the corner before it may reach, and from which the one after it

    def split_point(self, points: NDArray[np.float64]) -> NDArray[np.float64]:
        return _foot(self, points[self.split if self.split >= 0 else (self.a + self.b - 1) // 2])

    @property
    def curvature(self) -> float:
        return 0.0 if self.line else 1.0 / self.radius


def _fit(
    points: NDArray[np.float64], a: int, b: int, tau: float, max_curvature: float | None, kind: bool | None = None
) -> _Primitive | None:
    """A line, else a circle, holding points [a, b) within ``tau``; None if neither does
    (``kind``: True for a line only, False for a circle only)."""
    run = points[a:b]
    if len(run) < 3:
        return None
    step = max(1, len(run) // 2048)
    sample = run[::step]
    origin = sample.mean(axis=0)
    local, sample_local = run - origin, sample - origin
    covariance = sample_local.T @ sample_local
    _, vectors = np.linalg.eigh(covariance)
    direction = vectors[:, 1]
    if float(np.dot(direction, run[-1] - run[0])) < 0.0:
        direction = -direction
    off = np.abs(local[:, 0] * direction[1] - local[:, 1] * direction[0])
    if kind is not False and float(off.max()) <= tau:
        along = local @ direction
        return _Primitive(a, b, True, origin, direction, origin, math.inf, float(along.max() - along.min()))
    if kind is True:
        return None
    circle = _fit_circle(sample_local)
    if circle is None:
        return None
    center, radius = circle
    if max_curvature is not None and 1.0 / radius > max_curvature:
        return None
    rho = np.hypot(*(local - center).T)
    if float(np.abs(rho - radius).max()) > tau:
        return None
    rel = local - center
    angles = np.arctan2(rel[:, 1], rel[:, 0])
    turns = np.diff(np.unwrap(angles))
    travel = float(turns.sum())
    if travel == 0.0:
        return None
    sense = 1.0 if travel > 0 else -1.0
    return _Primitive(a, b, False, origin, direction, center + origin, sense * radius, abs(travel))


def _fit_circle(local: NDArray[np.float64]) -> tuple[NDArray[np.float64], float] | None:
    """Kåsa's algebraic circle, then Gauss–Newton on the geometric distances (points centred)."""
    scale = float(np.abs(local).max()) or 1.0
    p = local / scale
    design = np.column_stack([p, np.ones(len(p))])
    rhs = -(p * p).sum(axis=1)
    (d, e, f), *_ = np.linalg.lstsq(design, rhs, rcond=None)
    center = np.array([-d / 2.0, -e / 2.0])
    r2 = float(center @ center - f)
    if not (math.isfinite(r2) and r2 > 0.0):
        return None
    radius = math.sqrt(r2)
    for _ in range(4):
        rel = p - center
        rho = np.hypot(*rel.T)
        if not np.all(rho > 0):
            return None
        jac = np.column_stack([-rel / rho[:, None], -np.ones(len(p))])
        delta, *_ = np.linalg.lstsq(jac, -(rho - radius), rcond=None)
        center, radius = center + delta[:2], radius + float(delta[2])
        if float(np.abs(delta).max()) < 1e-13:
            break
    if not (math.isfinite(radius) and radius > 0.0) or radius > 1e7:
        return None
    return center * scale, radius * scale


def _runs(points: NDArray[np.float64], order: NDArray[np.int64], tau: float, max_curvature: float | None) -> list[_Primitive]:
    """Maximal runs grown from the flattest points first, each held by one line or circle within ``tau``."""
    n = len(points)
    starts: list[int] = []  # sorted run starts
    runs: dict[int, _Primitive] = {}
    covered = np.zeros(n, dtype=bool)
    for seed in order.tolist():
        if covered[seed]:
            continue
        k = bisect.bisect_right(starts, seed)
        left = runs[starts[k - 1]].b if k else 0
        right = starts[k] if k < len(starts) else n
        if right - left < 3:
            covered[left:right] = True
            continue
        a, b = max(left, seed - 1), min(right, seed + 2)
        if b - a < 3:
            a, b = (left, left + 3) if seed - left < right - seed else (right - 3, right)
        # Grow a line and a circle from the seed; the longer run wins (a line on a tie).
        grown = []
        for kind in (True, False):
            start = _fit(points, a, b, tau, max_curvature, kind)
            if start is not None:
                grown.append(_grow(points, a, b, left, right, start, tau, max_curvature))
        if not grown:
            covered[seed] = True
            continue
        a, b, best = max(grown, key=lambda g: g[1] - g[0])
        if not best.line and len(grown) == 2:
            # A circle little further than tau from its chord is a line's business (an inflection, a
            # near-straight), when a line holds most of its points.
            chord = math.hypot(*(points[b - 1] - points[a]))
            line_run = grown[0][1] - grown[0][0]
            if chord * chord / (8.0 * abs(best.radius)) <= 2.0 * tau and line_run >= 0.5 * (b - a):
                a, b, best = grown[0]
        covered[a:b] = True
        bisect.insort(starts, a)
        runs[a] = best
    found = [runs[a] for a in starts]
    # Neighbours one line or circle holds together become one run.
    merged = True
    while merged:
        merged = False
        for k in range(len(found) - 1):
            p, q = found[k], found[k + 1]
            if p.line == q.line and q.a - p.b <= 1:
                joined = _fit(points, p.a, q.b, tau, max_curvature, p.line)
                if joined is not None:
                    found[k : k + 2] = [joined]
                    merged = True
                    break
    return found


def _grow(points: NDArray[np.float64], a: int, b: int, left: int, right: int, best: _Primitive, tau: float,
          max_curvature: float | None) -> tuple[int, int, _Primitive]:  # fmt: skip
    """Move the run's ends out to ``left`` and ``right`` as far as a fit of the same kind holds:
    doubling steps on alternate sides (so neither side takes the whole tolerance), then bisection."""
    kind = best.line
    ends = [a, b]
    limits = (left, right)
    steps = [1, 1]
    failed: list[int | None] = [None, None]
    growing = [True, True]
    while any(growing):
        for side in (1, 0):
            if not growing[side]:
                continue
            sign = 1 if side else -1
            trial = ends[side] + sign * steps[side]
            trial = min(trial, limits[1]) if side else max(trial, limits[0])
            if trial == ends[side]:
                growing[side] = False
                continue
            lo, hi = (ends[0], trial) if side else (trial, ends[1])
            fitted = _fit(points, lo, hi, tau, max_curvature, kind)
            if fitted is None:
                failed[side], growing[side] = trial, False
            else:
                ends[side], best, steps[side] = trial, fitted, steps[side] * 2
    for side in (1, 0):
        bad = failed[side]
        while bad is not None and abs(bad - ends[side]) > 1:
            middle = (ends[side] + bad) // 2
            lo, hi = (ends[0], middle) if side else (middle, ends[1])
            fitted = _fit(points, lo, hi, tau, max_curvature, kind)
            if fitted is None:
                bad = middle
            else:
                ends[side], best = middle, fitted
    return ends[0], ends[1], best


def _foot(prim: _Primitive, point: NDArray[np.float64]) -> NDArray[np.float64]:
    """The point of the primitive's line or circle nearest ``point``."""
    if prim.line:
        return prim.point + float(np.dot(point - prim.point, prim.direction)) * prim.direction
    rel = point - prim.center
    return prim.center + abs(prim.radius) * rel / math.hypot(*rel)
