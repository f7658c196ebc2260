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

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ._fit_joins import _AUTO, _SHAPES, _assemble, _loops, _Unfit
from ._fit_runs import _Primitive, _runs
from .chain import Chain
from .errors import NoSolutionError
from .fit_distances import _arc_lengths, _as_points, chain_distances
from .fit_fallback import _fallback, douglas_peucker
from .segments import Arc, Line, Segment
from .shapes import shape_code
from .spiral import BezierSpiral
from .units import length_unit

__all__ = ["PointFit", "chain_distances", "curvature_estimate", "douglas_peucker", "fit_points"]

#: ``progress(done, total)``: called as the fit's steps complete.
ProgressCallback = Callable[[int, int], None]
_STEPS = 5
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
    if magnitude > _LARGEST or tolerance > _LARGEST:
        raise ValueError(
            f"points and tolerance must lie within ±{_LARGEST:g}; got coordinates up to {magnitude:g} and tolerance {tolerance:g} "
            f"(scale them, e.g. with other units)"
        )
    extent = float(np.hypot(*(points.max(axis=0) - points.min(axis=0))))  # within ±_LARGEST: no overflow
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
                chain = _assemble(prims, work, tol, shape, units, closed, slack, kmax)
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
