"""The joins of a point fit: the exact transitions between consecutive runs, and the choice of runs.

Consecutive runs are joined by the exact transition of their pair (line→circle,
circle→circle C/S or nested, line→line with the peak curvature that fits the
points best); a dynamic programme over the runs keeps the cheapest sequence
whose joins hold the points, runs are refitted and settled, and the chain is
built from the transitions and the runs' lines and arcs (``fit_points`` steps 4 and 5).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ._fit_runs import _fit_circle, _foot, _Primitive
from .chain import JOIN_TOLERANCE, Chain, g2_mismatch
from .fit_distances import _arc_lengths, _nearest, chain_distances
from .segments import Arc, Line, Segment
from .spiral import BezierSpiral
from .transitions import Transition, circle_in_circle, circle_to_circle, line_to_circle, line_to_line

#: ``shape="auto"``: each transition in the spiral shape that holds the points best.
_AUTO = "auto"
#: The spiral shapes ``"auto"`` chooses from.
_SHAPES = ("walton-meek", "near-linear")
_TAU = 2.0 * math.pi


def _join(p: _Primitive, q: _Primitive, points: NDArray[np.float64], shape: str, tolerance: float,
          p_from: NDArray[np.float64], q_to: NDArray[np.float64], kmax: float | None = None) -> Transition | None:  # fmt: skip
    """The exact transition from ``p`` to ``q`` (None where none exists). Between two lines the
    pair's peak curvature is the one whose spirals hold ``points`` best, at most ``kmax``;
    ``shape="auto"``: the shape whose transition holds them best."""
    if shape != _AUTO:
        return _join_shaped(p, q, points, shape, tolerance, p_from, q_to, kmax)
    best: tuple[float, Transition | None] = (math.inf, None)
    for each in _SHAPES:
        t = _join_shaped(p, q, points, each, tolerance, p_from, q_to, kmax)
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


def _join_shaped(p: _Primitive, q: _Primitive, points: NDArray[np.float64], shape: str, tolerance: float,
                 p_from: NDArray[np.float64], q_to: NDArray[np.float64], kmax: float | None = None) -> Transition | None:  # fmt: skip
    """The exact transition from ``p`` to ``q`` in one spiral shape (None where none exists)."""
    try:
        if p.line and q.line:
            return _corner(p, q, points, shape, tolerance, p_from, q_to, kmax)
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


def _corner(p: _Primitive, q: _Primitive, points: NDArray[np.float64], shape: str, tolerance: float,
            p_from: NDArray[np.float64], q_to: NDArray[np.float64], kmax: float | None = None) -> Transition | None:  # fmt: skip
    """line_to_line between two fitted lines, its curvature chosen (from the largest pair the runs
    allow up to 1000× its curvature, and up to ``kmax``) to hold ``points`` best, finely enough that
    the pair's points move by less than a fraction of ``tolerance`` within the last step."""
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
    top = math.log(1000.0)
    if kmax is not None:
        if lowest > kmax * (1.0 + 1e-9):
            return None  # even the widest pair the runs allow is too tight
        top = min(top, math.log(max(kmax / lowest, 1.0)))

    def attempt(log_factor: float) -> tuple[float, Transition | None]:
        try:
            trial = line_to_line(a, c, b, lowest * math.exp(log_factor), shape) if log_factor > 0 else widest
        except ValueError:
            return math.inf, None
        return _miss(trial.spirals, points), trial

    # The pair scales as 1/κ about the corner: the κ whose apex lies as near the corner as the
    # nearest point does is the first guess. Sparse points may sit well away from the apex, so the
    # window around it walks downhill (doubling its step) until the least miss lies inside, then a
    # golden-section search on log κ narrows it until a step in log κ moves the pair's farthest
    # point (its start, ``reach`` from the corner at the widest) by a small part of the tolerance.
    apex = math.hypot(*(np.asarray(widest.joint) - corner))
    reach = math.hypot(*(np.asarray(widest.start) - corner))
    nearest = float(np.hypot(*(points - corner).T).min())
    guess = min(math.log(max(apex / max(nearest, 1e-300), 1.0)), top)
    lo, hi = _bracket(lambda x: attempt(x)[0], guess, 0.3, 0.0, top)
    ratio = (math.sqrt(5.0) - 1.0) / 2.0
    x1, x2 = hi - ratio * (hi - lo), lo + ratio * (hi - lo)
    f1, f2 = attempt(x1)[0], attempt(x2)[0]
    for _ in range(_GOLDEN_STEPS):
        if (hi - lo) * reach * math.exp(-lo) <= _CORNER_PRECISION * tolerance:
            break
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


#: The most golden-section steps of a corner's search, and the part of the tolerance its last step may move the pair.
_GOLDEN_STEPS, _CORNER_PRECISION = 60, 1.0 / 32.0


def _bracket(cost: Callable[[float], float], middle: float, step: float, low: float, high: float) -> tuple[float, float]:
    """An interval of [low, high] around ``middle`` whose inner point costs no more than its ends:
    the window moves towards the cheaper end, its step doubling, until it holds the least cost."""
    fm = cost(middle)
    left, right = max(low, middle - step), min(high, middle + step)
    fl, fr = cost(left), cost(right)
    while (fl < fm and left > low) or (fr < fm and right < high):
        step *= 2.0
        if fl < fr:
            right, middle, fm = middle, left, fl
            left = max(low, middle - step)
            fl = cost(left)
        else:
            left, middle, fm = middle, right, fr
            right = min(high, middle + step)
            fr = cost(right)
    return left, right


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


class _Unfit(Exception):
    """The runs cannot be joined (the fallback takes over)."""


@dataclass
class _Gap:
    transition: Transition | None
    miss: float


#: How many runs ahead a join may reach (the runs skipped between are left to its spirals).
_REACH = 64


def _assemble(prims: list[_Primitive], pts: NDArray[np.float64], tol: float, shape: str, units: str, closed: bool,
              slack: float = 1.0, kmax: float | None = None) -> Chain:  # fmt: skip
    """Choose the runs to keep, fewest pieces first (dynamic programming over the runs in order,
    each join reaching up to ``_REACH`` runs ahead, its points within ``slack`` tolerances, no
    corner's peak curvature over ``kmax``), and build the chain."""
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
            gaps[(i, j)] = _evaluate(order[i], order[j], pts, shape, tol, kmax)
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
    refined = _refine(kept, pts, shapes, tol, closed, kmax)
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
    return _settled(chain, kept, pts, shapes, tol, units, closed, kmax)


#: Passes of refitting each kept line or circle to the points its own piece holds.
_SETTLE_PASSES = 8


def _settled(chain: Chain, kept: list[_Primitive], pts: NDArray[np.float64], shapes: list[str], tol: float, units: str,
             closed: bool, kmax: float | None = None) -> Chain:  # fmt: skip
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
                t = _join(p, q, between[:: max(1, len(between) // 4000)], shapes[k], tol, p.split_point(pts), q.split_point(pts), kmax)
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


def _refine(prims: list[_Primitive], pts: NDArray[np.float64], shapes: list[str], tol: float, closed: bool,
            kmax: float | None = None) -> tuple[list[_Primitive], list[Transition]] | None:  # fmt: skip
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
                t = _join(before, prim, local, shapes[(k - 1) % count], tol, before.split_point(pts), prim.split_point(pts), kmax)
                if t is None:
                    raise ValueError
                pieces += [_clipped(before, t.start, True, far), *t.spirals, _clipped(prim, t.end, False, far)]
            if after is not None:
                t = _join(prim, after, local, shapes[k], tol, prim.split_point(pts), after.split_point(pts), kmax)
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
        t = _join(p, q, between[:: max(1, len(between) // 4000)], shapes[k], tol, p.split_point(pts), q.split_point(pts), kmax)
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


def _evaluate(p: _Primitive, q: _Primitive, pts: NDArray[np.float64], shape: str, tol: float, kmax: float | None = None) -> _Gap:
    """The transition from run p to run q and the largest distance of the points between their
    middles to it, the runs' lines and circles clipped at its ends."""
    start, stop = (p.a + p.b) // 2, (q.a + q.b) // 2 + 1
    local = pts[start:stop] if stop > start else np.vstack([pts[start:], pts[:stop]])
    # Choosing runs needs a gap's shape, not every point (the chain is measured at every point after).
    local = local[:: max(1, len(local) // 4000)]
    # A corner's spirals may reach the split point of either run, no further (the next corner owns the rest).
    transition = _join(p, q, local, shape, tol, p.split_point(pts), q.split_point(pts), kmax)
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
