"""LandXML in: our segments for the file's elements (``read_landxml``'s placement).

``_run`` rebuilds one G2 run of the file's elements: the lines and arcs on the
file's carriers, each run of clothoids replaced by the transition our exact
solvers find between the same neighbours (``spiral_cad.io.landxml_fit``), or
rebuilt with its own length and end curvatures (``_segments``) where none is found.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray
from scipy.optimize import brentq, minimize_scalar

from ..core.clothoid import clothoid_frames
from ..core.factors import length_factor
from ..core.segments import Arc, Line, Segment
from ..core.shapes import shape_limits
from ..core.spiral import BezierSpiral
from .landxml_fit import Carrier, distance_to_file, solve_compound, solve_inflection, solve_run

__all__: list[str] = []


def _heading(t: NDArray) -> float:
    return math.atan2(t[1], t[0])


def _unit(angle: float) -> NDArray[np.float64]:
    return np.array([math.cos(angle), math.sin(angle)])


def _placed_spiral(cp: NDArray, point: NDArray, heading: float, shape: str | None) -> BezierSpiral:
    """A spiral's control points moved rigidly so that it starts at ``point`` along ``heading``."""
    start_heading = _heading(cp[1] - cp[0]) if np.any(cp[1] != cp[0]) else _heading(cp[2] - cp[0])
    turn = heading - start_heading
    c, s = math.cos(turn), math.sin(turn)
    local = cp - cp[0]
    moved = np.column_stack([c * local[:, 0] - s * local[:, 1], s * local[:, 0] + c * local[:, 1]]) + point
    return BezierSpiral.from_control_points(moved, shape)


def _theta(length: float, curvature: float, shape: str) -> float:
    """The turn of our spiral of ``shape`` from 0 to |curvature| with arc length ``length``."""
    from ..design.alignment import theta_for_length  # the one solver of spiral lengths

    return theta_for_length(length, 1.0 / abs(curvature), shape)


def _growing(length: float, k0: float, k1: float, shape: str, theta: float | None = None) -> BezierSpiral:
    """Our spiral from curvature k0 to k1 (same sign, |k0| < |k1|, k0 may be 0), at the origin along +x
    (``theta``: its turn when k0 = 0, if already solved)."""
    sign = math.copysign(1.0, k1)
    if k0 == 0.0:
        return BezierSpiral((0.0, 0.0), (1.0, 0.0), sign * (_theta(length, k1, shape) if theta is None else theta), k1, shape)
    largest = shape_limits(shape)["theta"] * (1.0 - 1e-9)
    longest = float(length_factor(largest, shape)) / abs(k1)

    def start_curvature(full: float) -> float:
        spiral = BezierSpiral((0.0, 0.0), (1.0, 0.0), sign * _theta(full, k1, shape), k1, shape)
        t0 = float(spiral.parameter_at(full - length))
        return abs(float(spiral.curvature(t0))) - abs(k0)

    low = length * (1.0 + 1e-12)
    if not longest > low or start_curvature(longest) < 0.0:
        turn = math.degrees(k1 * k1 * length / (2.0 * abs(k1 - k0)))  # the clothoid's turn from straight to k1
        raise ValueError(f"the clothoid from curvature {k0:.6g} to {k1:.6g} over {length:.6g} is the end of one that turns "
                         f"{turn:.3g}° from straight, and no {shape} spiral piece reaches it (up to {math.degrees(largest):.3g}°)")  # fmt: skip
    full = brentq(start_curvature, low, longest, xtol=1e-12 * length, rtol=1e-14)
    spiral = BezierSpiral((0.0, 0.0), (1.0, 0.0), sign * _theta(full, k1, shape), k1, shape)
    return spiral.piece(float(spiral.parameter_at(full - length)), 1.0)


def _spirals(length: float, k0: float, k1: float, shape: str, theta: float | None = None) -> list[BezierSpiral]:
    """Our spirals (at the origin along +x, in travel order) for a clothoid from k0 to k1 (``theta``:
    the turn of a spiral with one straight end, if already solved)."""
    if abs(k1) >= abs(k0):
        return [_growing(length, k0, k1, shape, theta)]
    backwards = _growing(length, -k1, -k0, shape, theta).reversed()  # travelled backwards, a left turn is a right one
    return [backwards]


@dataclass
class _Element:
    kind: str
    start: NDArray | None
    heading: float | None
    length: float
    k0: float
    k1: float
    station: float | None
    shape: str
    theta: float | None = None
    where: str = ""
    notes: list[str] = field(default_factory=list)
    cubic: BezierSpiral | None = None  # our very cubic, where this package wrote the spiral (its Feature)


def _segments(item: _Element, point: NDArray, heading: float) -> list[Segment]:
    """Our segments for one element, starting at ``point`` along ``heading``."""
    if item.k0 == item.k1 == 0.0:
        return [Line(tuple(point), tuple(point + item.length * _unit(heading)))]
    if item.k0 == item.k1:
        radius = 1.0 / item.k0
        center = point + radius * np.array([-math.sin(heading), math.cos(heading)])
        return [Arc(tuple(center), radius, _heading(point - center), abs(item.length * item.k0))]
    out: list[Segment] = []
    try:
        spirals = _spirals(item.length, item.k0, item.k1, item.shape, item.theta)
    except ValueError as e:  # beyond the shape's turn (a long compound piece): the other shape, which turns up to 90°
        other = "walton-meek" if item.shape == "near-linear" else "near-linear"
        try:
            spirals = _spirals(item.length, item.k0, item.k1, other)
        except ValueError:
            raise ValueError(f"{item.where}: {e}, nor a {other} one") from None
        item.notes.append(f"{item.where}: rebuilt with {other} spirals ({e})")
    for spiral in spirals:
        placed = _placed_spiral(spiral.control_points[:, :2], point, heading, spiral.shape)
        out.append(placed)
        point, heading = placed.end[:2], _heading(placed.end_tangent[:2])
    return out


def _solve_turns(items: list[_Element]) -> None:
    """The turns of every spiral with one straight end, one batch per shape (``thetas_for_lengths``)."""
    from ..design.alignment import thetas_for_lengths

    plain = [i for i in items if i.kind == "Spiral" and (i.k0 == 0.0) != (i.k1 == 0.0)]
    for shape in {i.shape for i in plain}:
        chosen = [i for i in plain if i.shape == shape]
        radii = [1.0 / abs(i.k0 + i.k1) for i in chosen]
        with np.errstate(all="ignore"):  # a length or radius out of range gives NaN: the scalar solver then names it
            thetas = thetas_for_lengths([i.length for i in chosen], radii, shape)
        for item, theta in zip(chosen, thetas):
            item.theta = None if math.isnan(theta) else float(theta)


#: How nearly the middle circle of a compound clothoid touches its neighbours (centre distance over radius difference), tried in turn.
_NEARNESS = (0.9995, 0.999, 0.9998, 0.998)


def _middle(item: _Element, start: NDArray, heading: float, entry: Carrier, exit_: Carrier, nearness: float) -> Carrier:
    """The circle of the clothoid's middle curvature whose centre is ``nearness`` × the radius difference from
    both neighbours' centres (the one nearer the clothoid's own centre of curvature there), as a carrier
    at its point nearest the clothoid's middle.

    Raises:
        ValueError: no such centre.
    """
    curvature = 0.5 * (item.k0 + item.k1)
    (mid,), (mid_heading,), _ = clothoid_frames([0.5 * item.length], item.k0, (item.k1 - item.k0) / item.length, x0=start[0],
                                                y0=start[1], hdg=heading, length=item.length)  # fmt: skip
    own = Carrier(mid, float(mid_heading), curvature, 0.0).center
    c0, c1, r = entry.center, exit_.center, 1.0 / abs(curvature)
    d0, d1 = nearness * abs(abs(entry.radius) - r), nearness * abs(r - abs(exit_.radius))
    span = float(np.hypot(*(c1 - c0)))
    along = (span * span + d0 * d0 - d1 * d1) / (2.0 * span)
    if not d0 * d0 - along * along > 0.0:
        raise ValueError(f"no middle circle of radius {r:.6g} is {nearness} nested in both neighbours")
    axis = (c1 - c0) / span
    normal = np.array([-axis[1], axis[0]])
    centers = [c0 + along * axis + side * math.sqrt(d0 * d0 - along * along) * normal for side in (1.0, -1.0)]
    center = min(centers, key=lambda c: float(np.hypot(*(c - own))))
    out = (mid - center) / float(np.hypot(*(mid - center)))
    point = center + r * out
    return Carrier(point, math.atan2(out[1], out[0]) + math.copysign(math.pi / 2, curvature), curvature, 0.0)


def _division(item: _Element, pieces: int) -> list[float]:
    """The curvatures of a clothoid at its start, ``pieces - 1`` equally spaced points and its end."""
    return list(item.k0 + (item.k1 - item.k0) * np.linspace(0.0, 1.0, pieces + 1))


def _inner(item: _Element, start: NDArray, heading: float, pieces: int) -> list[Carrier]:
    """The file's clothoid at ``pieces - 1`` equally spaced interior points, as carriers of its osculating circles."""
    s = item.length * np.linspace(0.0, 1.0, pieces + 1)[1:-1]
    points, headings, curvatures = clothoid_frames(s, item.k0, (item.k1 - item.k0) / item.length, x0=start[0], y0=start[1],
                                                   hdg=heading, length=item.length)  # fmt: skip
    return [Carrier(p, float(h), float(k), 0.0) for p, h, k in zip(points, headings, curvatures)]


def _run(items: list[_Element], mine: list[int], starts: list[NDArray], headings: list[float], ends: list[tuple[NDArray, float]],
         placement: str, file: tuple[NDArray, ...]) -> tuple[list[Segment], list[int], dict[int, str]]:  # fmt: skip
    """Our segments for one G2 run of the file's elements ``mine``, each segment's element and each
    spiral's method (see ``landxml_fit``): the file's lines and arcs kept, the spirals solved between them."""
    entries: list[tuple[str, list[int]]] = []  # ("fixed", [k]), ("spirals", [k, ...]) or ("implied", [k]): the tangent after spiral k
    for k in mine:
        if items[k].kind == "Spiral" and entries and entries[-1][0] == "spirals":
            entries[-1][1].append(k)
        else:
            entries.append(("spirals" if items[k].kind == "Spiral" else "fixed", [k]))
    split: list[tuple[str, list[int]]] = []
    for n, (kind, ks) in enumerate(entries):
        between_arcs = 0 < n < len(entries) - 1 and all(
            entries[m][0] == "fixed" and items[entries[m][1][0]].k0 != 0.0 for m in (n - 1, n + 1)
        )
        if kind != "spirals" or (len(ks) == 2 and between_arcs):
            split.append((kind, ks))
            continue
        part: list[int] = []
        for k in ks:  # split where the file's curvature passes through zero: the tangent there is a neighbour of both parts
            part.append(k)
            if items[k].k1 == 0.0 and k != ks[-1]:
                split += [("spirals", part), ("implied", [k])]
                part = []
        split.append(("spirals", part))

    def carrier(k: int, at_end: bool = False) -> Carrier:
        if at_end:  # osculating the file's element at its end
            return Carrier(ends[k][0], ends[k][1], items[k].k1, 0.0)
        return Carrier(starts[k], headings[k], items[k].k0, 0.0 if items[k].kind == "Spiral" else items[k].length)

    segments: list[Segment] = []
    owner: list[int] = []
    methods: dict[int, str] = {}
    pending: tuple[Carrier, int, float] | None = None  # a line or arc whose end is not known yet: carrier, element, begin
    point, heading = starts[mine[0]], headings[mine[0]]
    solved_end: NDArray | None = None  # where the last solved transition ended

    def emit(segs: list[Segment], k: int) -> None:
        nonlocal point, heading
        segments.extend(segs)
        owner.extend([k] * len(segs))
        point, heading = segs[-1].end[:2], _heading(segs[-1].end_tangent[:2])

    def close(end: float) -> None:
        nonlocal pending
        if pending is not None:
            c, k, begin = pending
            if end - begin > 1e-12 * max(c.length, 1.0):
                emit([c.piece(begin, end)], k)
            pending = None

    for n, (kind, ks) in enumerate(split):
        if kind in ("fixed", "implied"):
            if pending is not None:  # a line or arc after another (two arcs of one centre, two lines): kept whole
                close(pending[0].length)
            c = carrier(ks[0], at_end=kind == "implied")
            if solved_end is None:  # after a fallback (or at the start): continue from our chain
                c = Carrier(point, heading, c.curvature, c.length)
            pending, solved_end = (c, ks[0], c.station(solved_end) if solved_end is not None else 0.0), None
            continue
        entry = pending[0] if pending is not None else carrier(ks[0])
        after = split[n + 1] if n + 1 < len(split) else None
        exit_ = carrier(ks[-1], at_end=True) if after is None else carrier(after[1][0], at_end=after[0] == "implied")
        curvatures = [items[ks[0]].k0, *(items[k].k1 for k in ks)]
        candidates: list[tuple[str, str, list[tuple[int, Segment]]]] = []
        problems: list[str] = []
        shapes = [items[ks[0]].shape, "walton-meek" if items[ks[0]].shape == "near-linear" else "near-linear"]
        attempts: list[tuple[str, str, float]] = [(shape, "one", 1.0) for shape in shapes]
        # also through the circles (or, at an inflection, the tangent) osculating the file's joints: an asymmetric S
        # between arcs is two line_to_circle spirals on the file's inflection tangent, not circle_to_circle's symmetric one
        if len(ks) > 1:
            attempts += [(shape, "joints", 0.0) for shape in shapes]
        if len(ks) == 2 and curvatures[1] == 0.0 and entry.curvature and exit_.curvature:
            attempts += [(shape, "inflection", 0.0) for shape in shapes]
        if len(ks) == 2 and entry.curvature == exit_.curvature == 0.0:  # a C between lines: also as long as the file's
            attempts += [(shape, "one", -1.0) for shape in shapes]
        if len(ks) == 1 and entry.curvature * exit_.curvature > 0.0:  # a compound clothoid: through a middle circle if need be
            attempts += [(shape, "middle", nearness) for nearness in _NEARNESS for shape in shapes]
        lone = pending is None and after is None  # no line or arc of the file to keep: its own length is nearer
        if all(items[k].cubic is not None for k in ks):  # our own spirals: the very cubics, nothing to solve
            candidates.append(
                ("spiral_cad cubic", items[ks[0]].shape, [(i, cubic) for i, k in enumerate(ks) if (cubic := items[k].cubic) is not None])
            )
            attempts = []
        for shape, how, value in attempts if placement == "neighbours" and not lone else ():
            try:
                if how == "one":
                    name, solved = solve_run(entry, exit_, curvatures, shape)
                    if value < 0.0:  # a symmetric C: its peak curvature chosen nearest the file's (asymmetric) pair
                        near = list(range(max(ks[0] - 1, mine[0]), min(ks[-1] + 2, mine[-1] + 1)))  # a run is consecutive elements

                        def apart(log_scale: float) -> float:
                            try:
                                trial = solve_run(entry, exit_, [0.0, curvatures[1] * math.exp(log_scale), 0.0], shape)[1]
                            except ValueError:
                                return math.inf
                            return distance_to_file(trial, near, *file)

                        best = minimize_scalar(apart, bounds=(-0.7, 0.7), method="bounded", options={"xatol": 1e-4})
                        name, solved = solve_run(entry, exit_, [0.0, curvatures[1] * math.exp(best.x), 0.0], shape)
                        name += f" (peak curvature ×{math.exp(best.x):.3g})"
                    found: list[tuple[int, Segment]] = list(enumerate(solved))
                elif how == "inflection":
                    name = "line_to_circle ×2 (inflection tangent)"
                    tangent = carrier(ks[0], at_end=True)
                    near = list(range(max(ks[0] - 1, mine[0]), min(ks[-1] + 2, mine[-1] + 1)))

                    def off(turn: float) -> float:  # the tangent turned a little nearer the file's pair
                        try:
                            trial = solve_inflection(entry, exit_, tangent, curvatures, shape, turn)
                        except ValueError:
                            return 1e300  # no solution: the worst, finite for the bounded search's arithmetic
                        return distance_to_file([segment for _, segment in trial], near, *file)

                    best = minimize_scalar(off, bounds=(-0.02, 0.02), method="bounded", options={"xatol": 1e-6})
                    turn = float(best.x) if off(float(best.x)) < off(0.0) else 0.0
                    found = solve_inflection(entry, exit_, tangent, curvatures, shape, turn)
                    name += f" (turned {turn:.3g} rad)" if turn else ""
                elif how == "joints":
                    name = "through its joints"
                    found = solve_compound(entry, exit_, [carrier(k, at_end=True) for k in ks[:-1]], curvatures, shape)
                else:
                    name = "circle_in_circle ×2"
                    middle = _middle(items[ks[0]], starts[ks[0]], headings[ks[0]], entry, exit_, value)
                    found = [(0, segment) for _, segment in
                             solve_compound(entry, exit_, [middle], [curvatures[0], middle.curvature, curvatures[-1]], shape)]  # fmt: skip
                first, last = found[0][1].start, found[-1][1].end
                if pending is not None and not pending[0].station(first) - pending[2] > -1e-9 * max(pending[0].length, 1.0):
                    raise ValueError(f"the spirals would start {pending[2] - pending[0].station(first):.6g} before the end of the element before them")  # fmt: skip
                if exit_.length and not exit_.station(last) < exit_.length:
                    raise ValueError(f"the spirals would end beyond the element after them ({exit_.station(last):.6g} of {exit_.length:.6g})")  # fmt: skip
                candidates.append((name, shape, found))
                if len(ks) == 1 and how == "one":  # the one transition of a single spiral: nothing to choose
                    break
            except ValueError as e:
                problems.append(f"{shape}: {e}")
        if candidates:
            near = list(range(max(ks[0] - 1, mine[0]), min(ks[-1] + 2, mine[-1] + 1)))  # a run is consecutive elements
            name, shape, found = (
                candidates[0]
                if len(candidates) == 1
                else min(candidates, key=lambda c: distance_to_file([seg for _, seg in c[2]], near, *file))
            )
            close(pending[0].station(found[0][1].start) if pending is not None else 0.0)
            for i, segment in found:
                emit([segment], ks[i])
            for k in ks:
                methods[k] = name + ("" if shape == items[k].shape else f" ({shape})")
            solved_end = found[-1][1].end[:2]
            continue
        if pending is not None:
            close(pending[0].length)
        for k in ks:  # the file's length and end curvatures, continuing from our chain
            try:
                emit(_segments(items[k], point, heading), k)
            except ValueError as e:
                why = f"; no transition joins its neighbours either ({'; '.join(problems)})" if problems else ""
                raise ValueError(f"{e}{why}") from None
            methods[k] = "length"
            if problems:
                items[k].notes.append(f"{items[k].where}: rebuilt with its own length ({'; '.join(problems)})")
        solved_end = None
    if pending is not None:
        close(pending[0].length)
    return segments, owner, methods
