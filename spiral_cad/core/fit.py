"""Fitting points with few exact G2 pieces: lines, arcs and Bézier spirals within a tolerance.

``fit_points`` finds the lines and circles the points follow, joins each pair
with the exact transition of ``spiral_cad.core.transitions`` (so a spiral's
extent is decided by the line/circle pair it joins), and returns the chain
with every point's measured distance to it. The route:

1. validate (non-finite points, fewer than three distinct points, a trace
   that doubles back) and drop consecutive duplicates;
2. a point-wise curvature estimate: the turn of chords ``h`` long on either
   side of each point, averaged over ``h`` (``h`` grows with the tolerance
   and the point spacing, so noise well inside the tolerance stays small);
3. runs: from the flattest points first (where the estimate changes least),
   each run grows while one line or circle holds its points within a core
   tolerance (an eighth of the tolerance, or six times the measured noise);
4. joins: consecutive runs are joined by the exact transition of their pair
   (line→circle, circle→circle C/S or nested, line→line with the peak
   curvature that fits the points best); runs are then removed, shortest
   first, wherever their neighbours' transition holds the points as well,
   which leaves as few pieces as the tolerance allows;
5. the chain is built (``Chain.join``, G2-checked) and every point's distance
   to it measured (``chain_distances``); a fit that misses the tolerance is
   never returned: the fallback (a polyline within half the tolerance with
   every corner rounded by a spiral pair) is tried, tighter each time, and
   a fit that still misses is refused.
"""

from __future__ import annotations

import bisect
import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .chain import JOIN_TOLERANCE, Chain, g2_mismatch
from .errors import NoSolutionError
from .fit_distances import _as_points, _nearest, chain_distances
from .fit_fallback import _fallback, douglas_peucker
from .segments import Arc, Line, Segment
from .shapes import shape_code
from .spiral import BezierSpiral
from .transitions import Transition, circle_in_circle, circle_to_circle, line_to_circle, line_to_line
from .units import length_unit

__all__ = ["PointFit", "chain_distances", "curvature_estimate", "douglas_peucker", "fit_points"]

#: ``progress(done, total)``: called as the fit's steps complete.
ProgressCallback = Callable[[int, int], None]
_STEPS = 5
#: ``shape="auto"``: each transition in the spiral shape that holds the points best.
_AUTO = "auto"
#: The spiral shapes ``"auto"`` chooses from.
_SHAPES = ("walton-meek", "near-linear")
_TAU = 2.0 * math.pi
#: Turn between chords 2·tolerance long above which the points double back.
_DOUBLE_BACK = math.radians(150.0)
#: Largest coordinate or tolerance, and smallest extent or tolerance, the fit works with: the
#: input is checked with squared lengths, which must stay normal float64 numbers.
_LARGEST, _SMALLEST = 1e150, 1e-150
#: Smallest tolerance relative to the largest coordinate: float64 resolves about 2e-16 of a
#: coordinate, and the solvers and the distance check need room below the tolerance.
_RESOLUTION = 1e-11


@dataclass(frozen=True)
class PointFit:
    """A fitted chain and every input point's distance to it.

    Attributes:
        chain: the 2-D ``Chain`` of ``Line``, ``Arc`` and ``BezierSpiral``
            pieces, G2 at every joint (and at the closing joint when closed).
        residuals: (N,) distance of each input point to the chain, in ``units``.
        stations: (N,) arc length along the chain of each point's foot.
        curvature_estimate: (N,) the point-wise curvature estimate the
            segmentation used (1/``units``; positive turns left).
        tolerance: the tolerance asked for, in ``units``.
        units: the length unit of the points and of the chain.
    """

    chain: Chain
    residuals: NDArray[np.float64]
    stations: NDArray[np.float64]
    curvature_estimate: NDArray[np.float64]
    tolerance: float
    units: str

    @property
    def max_residual(self) -> float:
        """The largest distance of any input point to the chain."""
        return float(self.residuals.max())

    @property
    def pieces(self) -> int:
        """How many pieces (lines, arcs, spirals) the chain has."""
        return len(self.chain)

    @property
    def shapes(self) -> list[str | None]:
        """Each piece's spiral shape (``"walton-meek"`` or ``"near-linear"``), None for a line or an arc."""
        return [piece.shape if isinstance(piece, BezierSpiral) else None for piece in self.chain]


# ------------------------------------------------------------------ input


def _positive(value: Any, name: str) -> float:
    if isinstance(value, (bool, str, bytes)) or value is None:
        raise ValueError(f"{name} must be a positive number; got {value!r:.80}")
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a positive number; got {value!r:.80}") from None
    if not (math.isfinite(number) and number > 0.0):
        raise ValueError(f"{name} must be a finite number > 0; got {number!r}")
    return number


def _check_scale(points: NDArray[np.float64], tolerance: float) -> None:
    """ValueError where the points or the tolerance lie outside what float64 geometry resolves."""
    magnitude = float(np.abs(points).max())
    extent = float(np.hypot(*(points.max(axis=0) - points.min(axis=0))))
    if magnitude > _LARGEST or tolerance > _LARGEST:
        raise ValueError(
            f"points and tolerance must lie within ±{_LARGEST:g}; got coordinates up to {magnitude:g} and tolerance {tolerance:g} "
            f"(scale them, e.g. with other units)"
        )
    if extent < _SMALLEST or tolerance < _SMALLEST:
        raise ValueError(
            f"the points span {extent:g} with tolerance {tolerance:g}: both must be at least {_SMALLEST:g} (scale them, e.g. with other units)"
        )
    if tolerance < _RESOLUTION * magnitude:
        raise ValueError(
            f"tolerance {tolerance:g} is below what float64 resolves at coordinates up to {magnitude:g} "
            f"(at least {_RESOLUTION:g} of them: {_RESOLUTION * magnitude:g}); move the points nearer the origin or loosen the tolerance"
        )


def _distinct(points: NDArray[np.float64], tolerance: float, closed: bool) -> NDArray[np.int64]:
    """Indices of the points kept: consecutive duplicates (within 1e-9 · tolerance) dropped,
    and for a closed trace a last point repeating the first."""
    step = np.hypot(*np.diff(points, axis=0).T)
    keep = np.concatenate([[True], step > 1e-9 * tolerance])
    kept = np.flatnonzero(keep)
    if closed and len(kept) > 1 and math.hypot(*(points[kept[-1]] - points[0])) <= 1e-9 * tolerance:
        kept = kept[:-1]
    return kept


def _arc_lengths(points: NDArray[np.float64]) -> NDArray[np.float64]:
    return np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(points, axis=0).T))])


def _check_doubling_back(points: NDArray[np.float64], s: NDArray[np.float64], tolerance: float, kept: NDArray[np.int64]) -> None:
    """NoSolutionError where the trace turns back by more than 150° within chords 2·tolerance long."""
    bucket = np.floor(s / (2.0 * tolerance))
    first = np.flatnonzero(np.concatenate([[True], bucket[1:] != bucket[:-1]]))
    if len(first) < 3:
        return
    chords = np.diff(points[first], axis=0)
    a, b = chords[:-1], chords[1:]
    cross = a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]
    dot = (a * b).sum(axis=1)
    turn = np.abs(np.arctan2(cross, dot))
    bad = np.flatnonzero(turn > _DOUBLE_BACK)
    if len(bad):
        i = int(kept[first[bad[0] + 1]])
        raise NoSolutionError(
            f"the points double back at points[{i}]: they turn by {math.degrees(turn[bad[0]]):.1f}° "
            f"within {2 * tolerance:g} (twice the tolerance), which no G2 curve within the tolerance follows"
        )


# -------------------------------------------------------- curvature estimate


def _window(s: NDArray[np.float64], tolerance: float) -> float:
    """The estimate's half window: 8 tolerances, at least 3 point spacings, at most a tenth of the length."""
    spacing = float(np.median(np.diff(s)))
    return float(min(max(8.0 * tolerance, 3.0 * spacing), s[-1] / 10.0))


def curvature_estimate(points: NDArray[np.float64], s: NDArray[np.float64], h: float) -> NDArray[np.float64]:
    """Point-wise curvature: the Menger curvature of the points at s − h, s, s + h on the polyline,
    averaged over [s − h, s + h] (near the ends the window shifts inside)."""
    total = float(s[-1])
    centre = np.clip(s, h, total - h) if total > 2 * h else np.full_like(s, total / 2)
    a, b, c = (np.stack([np.interp(centre + d, s, points[:, 0]), np.interp(centre + d, s, points[:, 1])], axis=1) for d in (-h, 0.0, h))
    u, v, w = b - a, c - b, c - a
    cross = u[:, 0] * v[:, 1] - u[:, 1] * v[:, 0]
    denominator = np.hypot(*u.T) * np.hypot(*v.T) * np.hypot(*w.T)
    with np.errstate(invalid="ignore", divide="ignore"):
        kappa = np.where(denominator > 0.0, 2.0 * cross / denominator, 0.0)
    # The running integral of κ gives the window average in one pass.
    integral = np.concatenate([[0.0], np.cumsum(0.5 * (kappa[1:] + kappa[:-1]) * np.diff(s))])
    lo, hi = np.clip(s - h, 0.0, total), np.clip(s + h, 0.0, total)
    width = np.maximum(hi - lo, 1e-300)
    smooth: NDArray[np.float64] = (np.interp(hi, s, integral) - np.interp(lo, s, integral)) / width
    return smooth


def _noise(points: NDArray[np.float64]) -> float:
    """Robust noise level σ: each point's offset across the chord of its neighbours, less the mean
    of its neighbours' offsets (which takes out the curve's own bending), as a median."""
    if len(points) < 5:
        return 0.0
    chord = points[2:] - points[:-2]
    offset = points[1:-1] - 0.5 * (points[2:] + points[:-2])
    length = np.hypot(*chord.T)
    with np.errstate(invalid="ignore", divide="ignore"):
        across = (chord[:, 0] * offset[:, 1] - chord[:, 1] * offset[:, 0]) / length
    detrended = across[1:-1] - 0.5 * (across[2:] + across[:-2])
    detrended = detrended[np.isfinite(detrended)]
    # The detrended offset is 1.5·p(i) − p(i±1) + p(i±2)/4 across: variance 4.375 σ²;
    # 1.4826 · median = σ of a normal distribution.
    return float(1.4826 * np.median(np.abs(detrended)) / math.sqrt(4.375)) if len(detrended) else 0.0


# ------------------------------------------------------------- primitives


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


# ------------------------------------------------------------------ joins


def _foot(prim: _Primitive, point: NDArray[np.float64]) -> NDArray[np.float64]:
    """The point of the primitive's line or circle nearest ``point``."""
    if prim.line:
        return prim.point + float(np.dot(point - prim.point, prim.direction)) * prim.direction
    rel = point - prim.center
    return prim.center + abs(prim.radius) * rel / math.hypot(*rel)


def _join(p: _Primitive, q: _Primitive, points: NDArray[np.float64], shape: str, tolerance: float,
          p_from: NDArray[np.float64], q_to: NDArray[np.float64]) -> Transition | None:  # fmt: skip
    """The exact transition from ``p`` to ``q`` (None where none exists). Between two lines the
    pair's peak curvature is the one whose spirals hold ``points`` best; ``shape="auto"``: the shape
    whose transition holds them best."""
    if shape != _AUTO:
        return _join_shaped(p, q, points, shape, p_from, q_to)
    best: tuple[float, Transition | None] = (math.inf, None)
    for each in _SHAPES:
        t = _join_shaped(p, q, points, each, p_from, q_to)
        if t is not None:
            miss = _transition_miss(p, q, t, points)
            if miss < best[0] or best[1] is None:
                best = (miss, t)
    return best[1]


def _transition_miss(p: _Primitive, q: _Primitive, transition: Transition, local: NDArray[np.float64]) -> float:
    """The largest distance of ``local`` to the transition with p's and q's line or circle clipped at its ends."""
    if not len(local):
        return 0.0
    far = 2.0 * float(np.hypot(*(local.max(axis=0) - local.min(axis=0)))) + 1.0
    try:
        pieces: list[Segment] = [_clipped(p, transition.start, True, far), *transition.spirals, _clipped(q, transition.end, False, far)]
    except ValueError:
        return math.inf
    return float(_nearest(pieces, local).max())


def _join_shaped(p: _Primitive, q: _Primitive, points: NDArray[np.float64], shape: str, p_from: NDArray[np.float64],
                 q_to: NDArray[np.float64]) -> Transition | None:  # fmt: skip
    """The exact transition from ``p`` to ``q`` in one spiral shape (None where none exists)."""
    try:
        if p.line and q.line:
            return _corner(p, q, points, shape, p_from, q_to)
        if p.line:
            return line_to_circle(tuple(p.point.tolist()), tuple(p.direction.tolist()), tuple(q.center.tolist()), abs(q.radius), shape)
        if q.line:
            back = line_to_circle(tuple(q.point.tolist()), tuple((-q.direction).tolist()), tuple(p.center.tolist()), abs(p.radius), shape)
            return back.reversed()
        distance = math.hypot(*(q.center - p.center))
        if (p.radius > 0) == (q.radius > 0) and distance < abs(abs(p.radius) - abs(q.radius)):
            return circle_in_circle(tuple(p.center.tolist()), p.radius, tuple(q.center.tolist()), q.radius, shape)
        return circle_to_circle(tuple(p.center.tolist()), p.radius, tuple(q.center.tolist()), q.radius, shape)
    except ValueError:  # NoSolutionError included: this pair has no transition
        return None


def _corner(p: _Primitive, q: _Primitive, points: NDArray[np.float64], shape: str, p_from: NDArray[np.float64],
            q_to: NDArray[np.float64]) -> Transition | None:  # fmt: skip
    """line_to_line between two fitted lines, its curvature chosen (from the largest pair the runs
    allow up to 1000× its curvature) to hold ``points`` best."""
    cross = p.direction[0] * q.direction[1] - p.direction[1] * q.direction[0]
    if abs(cross) < 1e-12:
        return None
    # Intersection of the two lines.
    t = float(((q.point - p.point)[0] * q.direction[1] - (q.point - p.point)[1] * q.direction[0]) / cross)
    corner = p.point + t * p.direction
    a, c, b = tuple(p_from.tolist()), tuple(corner.tolist()), tuple(q_to.tolist())
    points = points[:: max(1, len(points) // 500)]  # the search needs the shape, not every point
    try:
        widest = line_to_line(a, c, b, None, shape)
    except ValueError:
        return None
    lowest = abs(widest.spirals[0].end_curvature)

    def attempt(log_factor: float) -> tuple[float, Transition | None]:
        try:
            trial = line_to_line(a, c, b, lowest * math.exp(log_factor), shape) if log_factor > 0 else widest
        except ValueError:
            return math.inf, None
        return _miss(trial.spirals, points), trial

    # The pair scales as 1/κ about the corner: the κ whose apex lies as near the corner as the
    # nearest point does, then golden-section search on log κ around it.
    apex = math.hypot(*(np.asarray(widest.joint) - corner))
    nearest = float(np.hypot(*(points - corner).T).min())
    guess = math.log(max(apex / max(nearest, 1e-300), 1.0))
    lo, hi = max(0.0, guess - 0.3), min(math.log(1000.0), guess + 0.3)
    ratio = (math.sqrt(5.0) - 1.0) / 2.0
    x1, x2 = hi - ratio * (hi - lo), lo + ratio * (hi - lo)
    f1, f2 = attempt(x1)[0], attempt(x2)[0]
    for _ in range(16):
        if f1 <= f2:
            hi, x2, f2 = x2, x1, f1
            x1 = hi - ratio * (hi - lo)
            f1 = attempt(x1)[0]
        else:
            lo, x1, f1 = x1, x2, f2
            x2 = lo + ratio * (hi - lo)
            f2 = attempt(x2)[0]
    candidates = [(attempt(guess)[0], guess), (attempt(0.0)[0], 0.0), (f1, x1), (f2, x2)]
    return attempt(min(candidates)[1])[1]


def _miss(spirals: list[BezierSpiral], points: NDArray[np.float64]) -> float:
    """The largest distance from ``points`` to the spirals (with the lines beyond them, as rays)."""
    if not len(points):
        return 0.0
    first, last = spirals[0], spirals[-1]
    pieces: list[Segment] = list(spirals)
    far = 1e3 * (first.length + last.length + 1.0)
    pieces.append(Line(first.start - far * first.start_tangent, first.start))
    pieces.append(Line(last.end, last.end + far * last.end_tangent))
    return float(_nearest(pieces, points).max())


def _clipped(prim: _Primitive, at: NDArray[np.float64], before: bool, far: float) -> Segment:
    """The primitive's line or circle ending (``before``) or starting at ``at``: a ray ``far`` long, or half a circle."""
    if prim.line:
        return Line(at - far * prim.direction, at) if before else Line(at, at + far * prim.direction)
    rel = at - prim.center
    angle = math.atan2(rel[1], rel[0])
    sense = 1.0 if prim.radius > 0 else -1.0
    return Arc(tuple(prim.center.tolist()), prim.radius, angle - sense * math.pi if before else angle, math.pi)


# ---------------------------------------------------------------- the fit


def fit_points(
    points: ArrayLike,
    tolerance: float,
    *,
    closed: bool = False,
    shape: str = _AUTO,
    units: str = "mm",
    max_curvature: float | None = None,
    progress: ProgressCallback | None = None,
) -> PointFit:
    """The fewest lines, arcs and Bézier spirals, G2 everywhere, within ``tolerance`` of every point.

    Args:
        points: (N, 2) points in travel order (a survey or GPS trace, a
            digitised sketch, a CNC point list), in ``units``.
        tolerance: the largest distance allowed from any point to the chain (> 0).
        closed: the points go round a closed shape: the chain closes on its
            start, G2 at the closing joint too (a last point repeating the
            first is dropped).
        shape: the spiral shape: ``"auto"`` (the default: each transition in
            the shape that holds the points best, so that fewer pieces are
            needed; ``PointFit.shapes`` says which), ``"walton-meek"`` or
            ``"near-linear"`` (``spiral_cad.core.shapes``).
        units: the length unit of the points (default mm).
        max_curvature: the largest curvature any arc may have (1/``units``);
            None: no bound.
        progress: ``progress(done, total)``, called as the fit's steps
            complete (``total`` steps in all).

    Returns:
        A ``PointFit``: the chain, every point's residual and station, and
        the curvature estimate. Every residual is measured and at most
        ``tolerance``.

    Raises:
        ValueError: non-finite points (naming the first), fewer than three
            distinct points, a tolerance ≤ 0, an unknown shape or unit.
        NoSolutionError: points that double back (naming the point), or no
            fit within the tolerance (the closest residual named).
    """
    raw = _as_points(points)
    tol = _positive(tolerance, "tolerance")
    if shape != _AUTO:
        shape_code(shape)
    units = length_unit(units)
    kmax = None if max_curvature is None else _positive(max_curvature, "max_curvature")
    report = progress or (lambda done, total: None)
    with np.errstate(over="ignore"):  # differences beyond ±1e308 are inf: distinct, and refused by scale next
        kept = _distinct(raw, tol, bool(closed))
    if len(kept) < 3:
        raise ValueError(f"fit_points needs at least 3 distinct points; got {len(kept)} (of {len(raw)} points)")
    _check_scale(raw, tol)
    pts = raw[kept]
    s = _arc_lengths(pts)
    _check_doubling_back(
        np.vstack([pts, pts[:2]]) if closed else pts,
        _arc_lengths(np.vstack([pts, pts[:2]])) if closed else s,
        tol,
        np.concatenate([kept, kept[:2]]) if closed else kept,
    )
    report(1, _STEPS)
    # The fit works on points scaled by a power of two to an extent near 1 (exact both ways, where a
    # move would round the short legs of tiny pieces), so that its thresholds hold at any scale.
    factor = 2.0 ** -round(math.log2(float(np.hypot(*(pts.max(axis=0) - pts.min(axis=0))))))
    raw_pts, raw_tol, raw_kmax = pts, tol, kmax
    pts, tol = pts * factor, tol * factor
    kmax = None if kmax is None else kmax / factor
    s = _arc_lengths(pts)
    chain: Chain | None = None
    if len(pts) > _REDUCED:
        # Many points: fit their block means (the noise averaged, the work bounded), then measure every point.
        reduced, reduced_s = _reduce(pts, s, bool(closed))
        chain, reduced_kappa = _fit_chain(reduced, tol, shape, units, bool(closed), kmax, report)
        kappa = np.interp(s, reduced_s, reduced_kappa, period=s[-1] + math.hypot(*(pts[0] - pts[-1])) if closed else None)
        chain, residual, stations = _measured(chain, factor, raw_pts, raw_tol)
    if chain is None:
        chain, kappa = _fit_chain(pts, tol, shape, units, bool(closed), kmax, report if len(pts) <= _REDUCED else None)
        chain, residual, stations = _measured(chain, factor, raw_pts, raw_tol)
    for tighter in _TIGHTER:
        # Runs chosen at a loose tolerance may not join where tighter ones do (their lines and
        # circles take in more of the spirals): a fit within a tenth of the tolerance is within it.
        if chain is not None or len(pts) > _REDUCED:
            break
        chain, _ = _fit_chain(pts, tol * tighter, shape, units, bool(closed), kmax, None)
        chain, residual, stations = _measured(chain, factor, raw_pts, raw_tol)
    if chain is None:
        fallback, _, _ = _fallback(pts, tol, _SHAPES[1] if shape == _AUTO else shape, units, bool(closed))
        chain, residual, stations = _measured(fallback, factor, raw_pts, raw_tol)
        if chain is None:
            raise NoSolutionError(
                f"the fit misses a point by more than the tolerance {raw_tol:g} once scaled back "
                f"(float64 rounding at coordinates up to {float(np.abs(raw_pts).max()):g}); move the points nearer the origin"
            )
    assert residual is not None and stations is not None
    kappa, tol, kmax = kappa * factor, raw_tol, raw_kmax
    if kmax is not None:
        _check_max_curvature(chain, kmax)
    report(5, _STEPS)
    # Every input point (duplicates included) gets the values of the kept point it repeats.
    index = np.maximum.accumulate(np.where(np.isin(np.arange(len(raw)), kept), np.arange(len(raw)), 0))
    slot = np.searchsorted(kept, index)
    slot = np.minimum(slot, len(kept) - 1)
    return PointFit(chain, residual[slot], stations[slot], kappa[slot], tol, units)


#: Tolerances (as fractions of the one asked for) tried before the fallback.
_TIGHTER = (0.1,)
#: Above this many points the fit works on block means of the points (about this many).
_REDUCED = 20_000


def _reduce(pts: NDArray[np.float64], s: NDArray[np.float64], closed: bool) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Means of consecutive blocks of points (and of their arc lengths), about ``_REDUCED`` of them;
    an open trace keeps its first and last point, where the chain ends."""
    block = math.ceil(len(pts) / _REDUCED)
    inner = slice(0, len(pts)) if closed else slice(1, len(pts) - 1)
    body, body_s = pts[inner], s[inner]
    starts = np.arange(0, len(body), block)
    sizes = np.diff(np.append(starts, len(body)))[:, None]
    means = np.add.reduceat(body, starts, axis=0) / sizes
    means_s = np.add.reduceat(body_s, starts) / sizes[:, 0]
    if closed:
        return means, means_s
    return np.vstack([pts[:1], means, pts[-1:]]), np.concatenate([s[:1], means_s, s[-1:]])


#: How far beyond the tolerance (as a factor) a join may miss the points when the runs are chosen.
_SLACKS = (1.0, 16.0, 256.0)


def _fit_chain(pts: NDArray[np.float64], tol: float, shape: str, units: str, closed: bool, kmax: float | None,
               report: ProgressCallback | None) -> tuple[Chain | None, NDArray[np.float64]]:  # fmt: skip
    """The chain of runs and transitions (not yet measured; None where the runs cannot be joined)
    and the point-wise curvature estimate."""
    report = report or (lambda done, total: None)
    s = _arc_lengths(pts)
    h = _window(s, tol)
    n = len(pts)
    if closed:
        # Round a closed trace the estimate wraps, and the runs start where the curvature changes
        # most (inside a transition), so that no line or arc is cut in two by the array's ends.
        pad = min(n, int(np.searchsorted(s, 3.0 * h)) + 2)
        ring = np.vstack([pts[-pad:], pts, pts[:pad]])
        kappa = curvature_estimate(ring, _arc_lengths(ring), h)[pad : pad + n]
        change = np.abs(np.roll(kappa, -1) - np.roll(kappa, 1))
        shift = int(np.argmax(change)) if float(change.max()) > 0.0 else 0
    else:
        kappa = curvature_estimate(pts, s, h)
        shift = 0
    work, work_kappa = np.roll(pts, -shift, axis=0), np.roll(kappa, -shift)
    report(2, _STEPS)
    sigma = _noise(pts)
    core = min(max(tol / 8.0, 6.0 * sigma), tol / 2.0)
    work_s = _arc_lengths(work)
    chain = None
    # Runs too short for the transitions between them (sparse points round a tight smooth shape,
    # where every arc is short) cannot be joined: looser runs are longer, and fewer.
    # A run's line or circle is a core tolerance off the design, and the spirals it decides several
    # tolerances off until the chain is settled: the joins are first judged within the tolerance,
    # then looser (the settled chain measured against the tolerance itself).
    for tau in sorted({core, min(2.0 * core, tol / 2.0), tol / 2.0}):
        prims = None
        for slack in _SLACKS:
            try:
                if prims is None:
                    prims = _segment(work, work_s, work_kappa, h, tau, kmax, closed)
                    report(3, _STEPS)
                chain = _assemble(prims, work, tol, shape, units, closed, slack)
            except (ValueError, _Unfit):
                chain = None
                continue
            if not _loops(chain, pts, closed) and float(chain_distances(chain, pts)[0].max()) <= tol:
                break
            chain = None
        if chain is not None:
            break
    report(4, _STEPS)
    return chain, kappa


def _measured(chain: Chain | None, factor: float, points: NDArray[np.float64], tolerance: float
              ) -> tuple[Chain | None, NDArray[np.float64] | None, NDArray[np.float64] | None]:  # fmt: skip
    """The chain scaled back to the points' coordinates with every point's distance and station,
    or Nones where it misses a point by more than ``tolerance``."""
    if chain is None:
        return None, None, None
    if factor != 1.0:
        chain = _scaled(chain, 1.0 / factor)
    residual, stations = chain_distances(chain, points)
    if float(residual.max()) > tolerance:
        return None, None, None
    return chain, residual, stations


def _scaled(chain: Chain, scale: float) -> Chain:
    """The chain scaled by ``scale`` (a power of two: exact) about the origin."""
    pieces: list[Segment] = []
    for piece in chain:
        if isinstance(piece, Line):
            pieces.append(Line(tuple((piece.start * scale).tolist()), tuple((piece.end * scale).tolist())))
        elif isinstance(piece, Arc):
            center = tuple((piece.center * scale).tolist())
            pieces.append(Arc(center, piece.radius * scale, piece.start_angle, piece.sweep))
        else:
            assert isinstance(piece, BezierSpiral)
            pieces.append(BezierSpiral.from_control_points(piece.control_points * scale, piece.shape))
    return Chain(pieces, chain.tolerance, chain.units)


class _Unfit(Exception):
    """The runs cannot be joined (the fallback takes over)."""


def _check_max_curvature(chain: Chain, kmax: float) -> None:
    worst = max(max(abs(seg.start_curvature), abs(seg.end_curvature)) for seg in chain)
    if worst > kmax * (1 + 1e-9):
        raise NoSolutionError(f"no fit within the tolerance keeps the curvature ≤ max_curvature {kmax:g}: it reaches {worst:.6g}")


def _segment(pts: NDArray[np.float64], s: NDArray[np.float64], kappa: NDArray[np.float64], h: float, tau: float,
             kmax: float | None, closed: bool) -> list[_Primitive]:  # fmt: skip
    """The runs, grown from the points where the curvature estimate changes least."""
    change = np.abs(np.interp(s + 2 * h, s, kappa) - np.interp(s - 2 * h, s, kappa))
    order = np.argsort(change, kind="stable")
    runs = _runs(pts, order, tau, kmax)
    for run in runs:
        if not run.line:
            continue
        if run.a == 0 and not closed:
            run.split = 0
        elif run.b == len(pts) and not closed:
            run.split = run.b - 1
        elif kappa[run.a] * kappa[run.b - 1] < 0:
            # Between corners that turn opposite ways: the inflection, where both pairs may meet.
            # The zero of the estimate's straight-line trend over the run (robust to its noise).
            index = np.arange(run.a, run.b, dtype=float)
            slope, offset = np.polyfit(index, kappa[run.a : run.b], 1)
            zero = -offset / slope if slope != 0.0 else 0.5 * (run.a + run.b - 1)
            run.split = int(np.clip(round(zero), run.a, run.b - 1))
    return runs


@dataclass
class _Gap:
    transition: Transition | None
    miss: float


#: How many runs ahead a join may reach (the runs skipped between are left to its spirals).
_REACH = 64


def _assemble(prims: list[_Primitive], pts: NDArray[np.float64], tol: float, shape: str, units: str, closed: bool,
              slack: float = 1.0) -> Chain:  # fmt: skip
    """Choose the runs to keep, fewest pieces first (dynamic programming over the runs in order,
    each join reaching up to ``_REACH`` runs ahead, its points within ``slack`` tolerances), and build
    the chain."""
    if not prims:
        raise _Unfit
    if len(prims) == 1:
        return _single(prims[0], pts, units, closed)
    if closed:
        anchor = max(range(len(prims)), key=lambda k: prims[k].b - prims[k].a)
        ring = prims[anchor:] + prims[:anchor]
        order = ring + ring[:1]
    else:
        order = list(prims)
    gaps: dict[tuple[int, int], _Gap] = {}

    def gap(i: int, j: int) -> _Gap:
        if (i, j) not in gaps:
            gaps[(i, j)] = _evaluate(order[i], order[j], pts, shape, tol)
        return gaps[(i, j)]

    def usable(i: int, j: int) -> Transition | None:
        g = gap(i, j)
        return g.transition if g.miss <= slack * tol else None

    last = len(order) - 1
    best_cost, best_path = math.inf, None
    firsts = range(1, min(_REACH, last) + 1) if closed else [None]
    for first in firsts:
        cost, path = _cheapest(order, pts, usable, last, first, closed)
        if cost < best_cost:
            best_cost, best_path = cost, path
    if best_path is None:
        raise _Unfit
    kept = [order[k] for k in best_path]
    transitions = [usable(i, j) for i, j in zip(best_path, best_path[1:])]
    if closed:
        kept = kept[:-1]
    joins = [t for t in transitions if t is not None]
    chain = _build(kept, joins, pts, units, closed)
    # Each join keeps the shape the runs were chosen with ("auto" decided it there): a shape that
    # switched between the refinement's steps would make its least squares jump.
    shapes = [t.spirals[0].shape or shape for t in joins]
    refined = _refine(kept, pts, shapes, tol, closed)
    if refined is not None:
        try:
            better = _build(*refined, pts, units, closed)
        except (ValueError, _Unfit):
            better = None
        if (
            better is not None
            and not _loops(better, pts, closed)
            and float(chain_distances(better, pts)[0].max()) <= float(chain_distances(chain, pts)[0].max())
        ):
            chain, kept = better, refined[0]
    return _settled(chain, kept, pts, shapes, tol, units, closed)


#: Passes of refitting each kept line or circle to the points its own piece holds.
_SETTLE_PASSES = 8


def _settled(chain: Chain, kept: list[_Primitive], pts: NDArray[np.float64], shapes: list[str], tol: float, units: str,
             closed: bool) -> Chain:  # fmt: skip
    """The chain with every kept line and circle refitted to the points its own piece of the chain
    holds (the ends' tenth left out), the transitions solved again, while the largest miss drops.

    A run grown within a core tolerance takes in points of the spirals beside it, and a spiral
    between a line and a circle moves with the square root of their offset: a line or circle a
    core tolerance off puts the spiral several tolerances off. Points the chain gives to a line or
    an arc lie on the designed line or circle, and each pass takes fewer spiral points in."""
    best, worst = chain, float(chain_distances(chain, pts)[0].max())
    prims = list(kept)
    for _ in range(_SETTLE_PASSES):
        if worst <= 1e-3 * tol:
            break
        _, stations = chain_distances(best, pts)
        owner = np.clip(np.searchsorted(best.stations, stations, side="right") - 1, 0, len(best) - 1)
        moved = [_refitted(prim, best, owner, pts) for prim in prims]
        try:
            joins = []
            for k in range(len(moved) if closed else len(moved) - 1):
                p, q = moved[k], moved[(k + 1) % len(moved)]
                lo, hi = (p.a + p.b) // 2, (q.a + q.b) // 2 + 1
                between = pts[lo:hi] if hi > lo else np.vstack([pts[lo:], pts[:hi]])
                t = _join(p, q, between[:: max(1, len(between) // 4000)], shapes[k], tol, p.split_point(pts), q.split_point(pts))
                if t is None:
                    return best
                joins.append(t)
            trial = _build(moved, joins, pts, units, closed)
        except (ValueError, _Unfit):
            return best
        miss = float(chain_distances(trial, pts)[0].max())
        if not miss < worst or _loops(trial, pts, closed):
            break
        best, worst, prims = trial, miss, moved
    return best


def _loops(chain: Chain, pts: NDArray[np.float64], closed: bool) -> bool:
    """The chain is much longer than the points' polyline: an arc goes round where the points do not
    (every point is still near the chain, so the residuals alone do not tell)."""
    travel = float(_arc_lengths(np.vstack([pts, pts[:1]]) if closed else pts)[-1])
    return chain.length > 1.05 * travel


def _refitted(prim: _Primitive, chain: Chain, owner: NDArray[np.int64], pts: NDArray[np.float64]) -> _Primitive:
    """The primitive fitted again to the points on the chain's pieces of its kind that lie on it."""
    mine = np.zeros(len(pts), dtype=bool)
    for number, piece in enumerate(chain):
        if prim.line and isinstance(piece, Line):
            rel = 0.5 * (piece.start + piece.end) - prim.point
            on = abs(float(prim.direction[0] * rel[1] - prim.direction[1] * rel[0]))
            if on <= 1e-3 * max(piece.length, 1e-300) + 1e-9:
                mine |= owner == number
        elif not prim.line and isinstance(piece, Arc):
            near = 1e-3 * abs(prim.radius)
            if math.hypot(*(piece.center - prim.center)) <= near and abs(piece.radius - prim.radius) <= near:
                mine |= owner == number
    index = np.flatnonzero(mine)
    if len(index) < 8:
        return prim
    # The ends' tenth left out of each stretch of the primitive's points.
    breaks = np.flatnonzero(np.diff(index) > 1) + 1
    inner = []
    for stretch in np.split(index, breaks):
        cut = max(1, len(stretch) // 10)
        inner.append(stretch[cut:-cut])
    chosen = pts[np.concatenate(inner)] if inner else pts[:0]
    if len(chosen) < 5:
        return prim
    origin = chosen.mean(axis=0)
    local = chosen - origin
    if prim.line:
        _, vectors = np.linalg.eigh(local.T @ local)
        direction = vectors[:, 1]
        if float(direction @ prim.direction) < 0.0:
            direction = -direction
        return _Primitive(prim.a, prim.b, True, origin, direction, origin, math.inf, prim.span, prim.split)
    circle = _fit_circle(local)
    if circle is None:
        return prim
    center, radius = circle
    sense = 1.0 if prim.radius > 0 else -1.0
    return _Primitive(prim.a, prim.b, False, prim.point, prim.direction, center + origin, sense * radius, prim.span, prim.split)


#: Gauss–Newton iterations (scipy ``least_squares`` evaluations) per line or circle refined, and
#: the sweeps over all of them (each moves its neighbours' optimum a little).
_REFINE_EVALUATIONS, _REFINE_SWEEPS = 20, 3


def _refine(prims: list[_Primitive], pts: NDArray[np.float64], shapes: list[str], tol: float, closed: bool
            ) -> tuple[list[_Primitive], list[Transition]] | None:  # fmt: skip
    """The kept lines and circles adjusted, one at a time, to the least squares of every point of
    their run and of the spirals on either side (the spirals solved again at each step): a line or
    circle fitted to its run alone is pulled by the spiral points the run took in, and the spirals it
    decides carry that error as a bump. None where a transition fails."""
    from scipy.optimize import least_squares

    prims = list(prims)
    count = len(prims)
    if count < 2:
        return None
    ring = closed

    def neighbours(k: int) -> tuple[_Primitive | None, _Primitive | None]:
        before = prims[k - 1] if (k > 0 or ring) else None
        after = prims[(k + 1) % count] if (k < count - 1 or ring) else None
        return before, after

    def moved(prim: _Primitive, x: NDArray[np.float64]) -> _Primitive:
        if prim.line:
            c, s_ = math.cos(x[1]), math.sin(x[1])
            d = np.array([c * prim.direction[0] - s_ * prim.direction[1], s_ * prim.direction[0] + c * prim.direction[1]])
            normal = np.array([-prim.direction[1], prim.direction[0]])
            return _Primitive(prim.a, prim.b, True, prim.point + x[0] * normal, d, prim.center, prim.radius, prim.span, prim.split)
        sense = 1.0 if prim.radius > 0 else -1.0
        return _Primitive(prim.a, prim.b, False, prim.point, prim.direction, prim.center + x[:2], prim.radius + sense * x[2],
                          prim.span, prim.split)  # fmt: skip

    def local_points(k: int) -> NDArray[np.float64]:
        before, after = neighbours(k)
        lo = (before.a + before.b) // 2 if before is not None else prims[k].a
        hi = (after.a + after.b) // 2 + 1 if after is not None else prims[k].b
        window = pts[lo:hi] if hi > lo else np.vstack([pts[lo:], pts[:hi]])
        return window[:: max(1, len(window) // 1000)]

    def distances(k: int, prim: _Primitive, local: NDArray[np.float64]) -> NDArray[np.float64]:
        before, after = neighbours(k)
        far = 2.0 * float(np.hypot(*(local.max(axis=0) - local.min(axis=0)))) + 1.0
        pieces: list[Segment] = []
        try:
            if before is not None:
                t = _join(before, prim, local, shapes[(k - 1) % count], tol, before.split_point(pts), prim.split_point(pts))
                if t is None:
                    raise ValueError
                pieces += [_clipped(before, t.start, True, far), *t.spirals, _clipped(prim, t.end, False, far)]
            if after is not None:
                t = _join(prim, after, local, shapes[k], tol, prim.split_point(pts), after.split_point(pts))
                if t is None:
                    raise ValueError
                pieces += [_clipped(prim, t.start, True, far), *t.spirals, _clipped(after, t.end, False, far)]
        except ValueError:
            return np.full(len(local), 1e3 * tol)
        return _nearest(pieces, local)

    gains = [0.0] * count  # each sweep: how much each line or circle lowered its cost
    for k in list(range(count)) * _REFINE_SWEEPS:
        if k == 0 and gains[0] >= 0.0 and any(gains) and max(gains) < 0.05:
            break  # the last sweep moved nothing by 5 %: settled
        prim = prims[k]
        if prim.line and any(n is not None and n.line for n in neighbours(k)):
            continue  # beside a corner the line's own fit stands (corner pairs are searched, not solved)
        local = local_points(k)
        start = distances(k, prim, local)
        if float(start.max()) >= 1e3 * tol:
            return None
        size = 3 if not prim.line else 2
        result = least_squares(lambda x: distances(k, moved(prim, x), local), np.zeros(size), max_nfev=_REFINE_EVALUATIONS,
                               x_scale=np.full(size, tol), ftol=1e-4, xtol=1e-4)  # fmt: skip
        before_cost = 0.5 * float(start @ start)
        gains[k] = 1.0 - float(result.cost) / before_cost if before_cost > 0.0 else 0.0
        if float(result.cost) < before_cost:
            prims[k] = moved(prim, result.x)
    joins: list[Transition] = []
    for k in range(count if ring else count - 1):
        p, q = prims[k], prims[(k + 1) % count]
        # The points between the two runs' middles, as _evaluate gives them (round the ring's end too).
        lo, hi = (p.a + p.b) // 2, (q.a + q.b) // 2 + 1
        between = pts[lo:hi] if hi > lo else np.vstack([pts[lo:], pts[:hi]])
        t = _join(p, q, between[:: max(1, len(between) // 4000)], shapes[k], tol, p.split_point(pts), q.split_point(pts))
        if t is None:
            return None
        joins.append(t)
    return prims, joins


def _cheapest(order: list[_Primitive], pts: NDArray[np.float64], usable: Callable[[int, int], Transition | None], last: int,
              first: int | None, closed: bool) -> tuple[float, list[int] | None]:  # fmt: skip
    """The fewest pieces from run 0 to run ``last`` (states: the last two runs kept), each kept run's
    transition in ending before its transition out starts. ``first``: the run kept after run 0 (closed)."""
    cost: dict[tuple[int, int], float] = {}
    back: dict[tuple[int, int], tuple[int, int] | None] = {}
    starts = [first] if first is not None else range(1, min(_REACH, last) + 1)
    for j in starts:
        t = usable(0, j)
        if t is None:
            continue
        enter = None if closed else _foot(order[0], pts[0])
        if enter is not None and not _ahead(order[0], enter, t.start):
            continue
        cost[(0, j)] = 2 + len(t.spirals)
        back[(0, j)] = None
    for j in range(1, last + 1):
        for i in range(max(0, j - _REACH), j):
            if (i, j) not in cost:
                continue
            into = usable(i, j)
            assert into is not None
            for k in range(j + 1, min(j + _REACH, last) + 1):
                out = usable(j, k)
                if out is None or not _ahead(order[j], into.end, out.start):
                    continue
                total = cost[(i, j)] + 1 + len(out.spirals) - (1 if k == last and closed else 0)
                if total < cost.get((j, k), math.inf):
                    cost[(j, k)], back[(j, k)] = total, (i, j)
    best, end = math.inf, None
    for i in range(max(0, last - _REACH), last):
        if (i, last) not in cost:
            continue
        into = usable(i, last)
        assert into is not None
        if closed:
            assert first is not None
            out = usable(0, first)
            assert out is not None
            fits = _ahead(order[last], into.end, out.start)
        else:
            fits = _ahead(order[last], into.end, _foot(order[last], pts[-1]))
        if fits and cost[(i, last)] < best:
            best, end = cost[(i, last)], (i, last)
    if end is None:
        return math.inf, None
    path = [end[1]]
    state: tuple[int, int] | None = end
    while state is not None:
        path.append(state[0])
        state = back[state]
    return best, path[::-1]


def _evaluate(p: _Primitive, q: _Primitive, pts: NDArray[np.float64], shape: str, tol: float) -> _Gap:
    """The transition from run p to run q and the largest distance of the points between their
    middles to it, the runs' lines and circles clipped at its ends."""
    start, stop = (p.a + p.b) // 2, (q.a + q.b) // 2 + 1
    local = pts[start:stop] if stop > start else np.vstack([pts[start:], pts[:stop]])
    # Choosing runs needs a gap's shape, not every point (the chain is measured at every point after).
    local = local[:: max(1, len(local) // 4000)]
    # A corner's spirals may reach the split point of either run, no further (the next corner owns the rest).
    transition = _join(p, q, local, shape, tol, p.split_point(pts), q.split_point(pts))
    if transition is None:
        return _Gap(None, math.inf)
    miss = _transition_miss(p, q, transition, local)
    return _Gap(transition if math.isfinite(miss) else None, miss)


def _ahead(prim: _Primitive, enter: NDArray[np.float64], leave: NDArray[np.float64]) -> bool:
    """``leave`` lies at or after ``enter`` along the primitive (on a circle: within the run's travel and a half turn)."""
    if prim.line:
        return float(np.dot(leave - enter, prim.direction)) >= -1e-9 * (1.0 + float(np.abs(enter).max()))
    sense = 1.0 if prim.radius > 0 else -1.0
    a0 = math.atan2(*(enter - prim.center)[::-1])
    a1 = math.atan2(*(leave - prim.center)[::-1])
    travel = (sense * (a1 - a0)) % _TAU
    return travel <= min(prim.span + 0.5 * (_TAU - prim.span), _TAU) or travel > _TAU - 1e-9


def _single(prim: _Primitive, pts: NDArray[np.float64], units: str, closed: bool) -> Chain:
    """One line or one arc through every point."""
    first, last = _foot(prim, pts[0]), _foot(prim, pts[-1])
    if prim.line:
        if closed:
            raise _Unfit
        return Chain([Line(tuple(first.tolist()), tuple(last.tolist()))], JOIN_TOLERANCE, units)
    rel = first - prim.center
    start = math.atan2(rel[1], rel[0])
    sweep = _TAU if closed else min(prim.span, _TAU)
    return Chain([Arc(tuple(prim.center.tolist()), prim.radius, start, sweep)], JOIN_TOLERANCE, units)


def _arc_between(prim: _Primitive, a: NDArray[np.float64], b: NDArray[np.float64]) -> Arc | None:
    """The primitive's arc from a to b in its travel sense (None when they coincide)."""
    if math.hypot(*(a - b)) <= 1e-12 * abs(prim.radius):
        return None
    return Arc.between(tuple(prim.center.tolist()), prim.radius, tuple(a.tolist()), tuple(b.tolist()))


def _build(prims: list[_Primitive], transitions: list[Transition], pts: NDArray[np.float64], units: str, closed: bool) -> Chain:
    """The chain: the transitions joined by the runs' lines and arcs (``Chain.join``)."""
    parts: list[Transition | Segment] = list(transitions)
    first, last = prims[0], prims[-1] if not closed else prims[0]
    if closed:
        # Start and end half way along the first run's line or arc, between the closing and the first transition.
        enter, leave = transitions[-1].end, transitions[0].start
        if first.line:
            middle = 0.5 * (enter + leave)
            chain = Chain.join(parts, start=tuple(middle.tolist()), end=tuple(middle.tolist()), units=units)
        else:
            sense = 1.0 if first.radius > 0 else -1.0
            a0 = math.atan2(*(enter - first.center)[::-1])
            travel = (sense * (math.atan2(*(leave - first.center)[::-1]) - a0)) % _TAU
            half = a0 + sense * travel / 2
            middle = first.center + abs(first.radius) * np.array([math.cos(half), math.sin(half)])
            head, tail = _arc_between(first, middle, leave), _arc_between(first, enter, middle)
            parts = ([head] if head else []) + parts + ([tail] if tail else [])
            chain = Chain.join(parts, units=units)
        if g2_mismatch(chain[len(chain) - 1], chain[0], chain.tolerance) is not None:
            raise _Unfit
        return chain
    start, end = _foot(first, pts[0]), _foot(last, pts[-1])
    head_point = tail_point = None
    if first.line:
        head_point = tuple(start.tolist())
    else:
        arc = _arc_between(first, start, transitions[0].start)
        if arc is not None:
            parts.insert(0, arc)
    if last.line:
        tail_point = tuple(end.tolist())
    else:
        arc = _arc_between(last, transitions[-1].end, end)
        if arc is not None:
            parts.append(arc)
    return Chain.join(parts, start=head_point, end=tail_point, units=units)
