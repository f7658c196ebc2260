"""LandXML in: the file's lines and arcs kept, only its clothoids replaced by our spirals (``read_landxml``).

A run of clothoids between two of the file's lines or arcs (its *neighbours*)
becomes the transition that our exact solvers find between the SAME two
elements: line → spiral → arc ``line_to_circle``; arc → spiral → arc of one
sense ``circle_in_circle`` (compound curves); arc → spiral → spiral → arc
``circle_to_circle`` (S- and C-curves through a straight point); line →
spiral → spiral → line ``line_to_line`` (the file's peak curvature at the
joint). A run of more spirals is split where the file's curvature passes
through zero, at the tangent there. Where the run has no neighbour (the
alignment starts or ends with a spiral, or the file breaks G2 there), the
neighbour is the line or circle that osculates the file's clothoid at that end.

The lines and arcs then keep the file's carrier (point and direction, centre
and radius) and are trimmed to the spirals' contact points; our spirals have
the length of the solution, which differs slightly from the file's. Where no
solution exists with the element's shape the other shape is tried, then the
clothoid is rebuilt with its own length and end curvatures continuing from
the element before (``landxml_read``), with a note.

The offset of each element is measured both ways (Hausdorff-like): the
largest distance from a sample of ours to the file's geometry and from a
sample of the file's element to ours, each against the element and its two
neighbours, every foot refined by Newton steps on the exact curves (the
file's clothoids by ``spiral_cad.core.clothoid``, ours as Bézier curves and
arcs).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import NDArray
from scipy.optimize import brentq

from ..core.chain import Chain
from ..core.clothoid import clothoid_frames
from ..core.segments import Arc, Line, Segment
from ..core.spiral import BezierSpiral
from ..core.transitions import circle_in_circle, circle_to_circle, line_to_circle, line_to_line
from .landxml import CHUNK, segment_samples

__all__: list[str] = []

#: Samples per element at which offsets are measured, and grid points per curve for the first foot.
SAMPLES = 17
_GRID = 17
#: Newton steps refining each foot.
_STEPS = 3


@dataclass(frozen=True)
class Carrier:
    """The line or circle an element lies on, placed at its start.

    Attributes:
        point: the element's start (our placement).
        heading: the direction there (rad).
        curvature: 0 for a line, else 1/radius signed (positive: counter-clockwise).
        length: the element's length in the file (0 for an implied neighbour).
    """

    point: NDArray[np.float64]
    heading: float
    curvature: float
    length: float

    @property
    def direction(self) -> NDArray[np.float64]:
        return np.array([math.cos(self.heading), math.sin(self.heading)])

    @property
    def radius(self) -> float:
        return 1.0 / self.curvature

    @property
    def center(self) -> NDArray[np.float64]:
        return self.point + self.radius * np.array([-math.sin(self.heading), math.cos(self.heading)])

    def station(self, p: NDArray) -> float:
        """The arc length from the start to the foot of ``p`` (near the element: arcs are read around their middle)."""
        if self.curvature == 0.0:
            return float(np.dot(p[:2] - self.point, self.direction))
        c, r = self.center, abs(self.radius)
        turn = math.copysign(1.0, self.curvature) * (
            math.atan2(p[1] - c[1], p[0] - c[0]) - math.atan2(self.point[1] - c[1], self.point[0] - c[0])
        )
        middle = self.length / (2.0 * r)
        return r * (math.remainder(turn - middle, 2.0 * math.pi) + middle)

    def piece(self, begin: float, end: float) -> Segment:
        """Our segment of the carrier from arc length ``begin`` to ``end``."""
        if self.curvature == 0.0:
            return Line(tuple(self.point + begin * self.direction), tuple(self.point + end * self.direction))
        c, r = self.center, self.radius
        start = math.atan2(self.point[1] - c[1], self.point[0] - c[0]) + begin * self.curvature
        return Arc(tuple(c), r, start, (end - begin) * abs(self.curvature))


def solve_run(entry: Carrier, exit_: Carrier, curvatures: Sequence[float], shape: str) -> tuple[str, list[BezierSpiral]]:
    """Our spirals between two carriers for a run of clothoids with ``curvatures`` (start, joints, end).

    Returns:
        (the solver's name, the spirals in travel order).

    Raises:
        ValueError: no solver for this pair and count, or it has no solution (``NoSolutionError``).
    """
    count = len(curvatures) - 1
    lines = (entry.curvature == 0.0, exit_.curvature == 0.0)
    if count == 1 and lines == (True, False):
        spirals = line_to_circle(entry.point, entry.direction, exit_.center, abs(exit_.radius), shape).spirals
        name = "line_to_circle"
    elif count == 1 and lines == (False, True):
        spirals = line_to_circle(exit_.point, -exit_.direction, entry.center, abs(entry.radius), shape).reversed().spirals
        name = "line_to_circle"
    elif count == 1 and lines == (False, False) and entry.curvature * exit_.curvature > 0.0:
        spirals = circle_in_circle(entry.center, entry.radius, exit_.center, exit_.radius, shape).spirals
        name = "circle_in_circle"
    elif count == 2 and lines == (False, False) and curvatures[1] == 0.0:
        spirals = circle_to_circle(entry.center, entry.radius, exit_.center, exit_.radius, shape).spirals
        name = "circle_to_circle"
    elif count == 2 and lines == (True, True) and curvatures[1] != 0.0:
        d0, d1 = entry.direction, exit_.direction
        cross = d0[0] * d1[1] - d0[1] * d1[0]
        if abs(cross) < 1e-12:
            raise ValueError("the two lines are parallel: no corner")
        w = exit_.point - entry.point
        corner = entry.point + (w[0] * d1[1] - w[1] * d1[0]) / cross * d0
        reach = 4.0 * (float(np.hypot(*w)) + entry.length + exit_.length) + 1.0  # the legs' far ends: never binding
        spirals = line_to_line(corner - reach * d0, corner, corner + reach * d1, abs(curvatures[1]), shape).spirals
        name = "line_to_line"
    else:
        kinds = "-".join("line" if line else "arc" for line in lines)
        raise ValueError(f"no solver joins a {kinds} pair with {count} spiral(s) through curvatures {[f'{k:.6g}' for k in curvatures]}")
    # the solution must turn as the file does at both ends
    scale = max(abs(k) for k in curvatures)
    for got, want in ((spirals[0].start_curvature, curvatures[0]), (spirals[-1].end_curvature, curvatures[-1])):
        if abs(got - want) > 1e-6 * scale:
            raise ValueError(f"the solution's end curvature {got:.6g} is not the file's {want:.6g}")
    return name, list(spirals)


def solve_compound(entry: Carrier, exit_: Carrier, inner: Sequence[Carrier], curvatures: Sequence[float],
                   shape: str) -> list[tuple[int, Segment]]:  # fmt: skip
    """One clothoid between two arcs of one sense as several ``circle_in_circle`` spirals, through the
    circles that osculate it at ``inner`` points (a compound clothoid too long for one nested spiral).

    Args:
        entry, exit_: the arcs before and after.
        inner: the file's clothoid at each division point (``length`` 0).
        curvatures: the curvature at the start, each division point and the end.
        shape: the spirals' shape.

    Returns:
        The spirals in travel order, with the short arcs (or lines) of the inner carriers where two
        spirals do not meet on one, each with the index of its piece (a short arc: the piece before it).

    Raises:
        ValueError: a piece has no solution, or two pieces overlap on an inner circle.
    """
    out: list[tuple[int, Segment]] = []
    current, begin = entry, 0.0
    for n, target in enumerate([*inner, exit_]):
        _, (spiral,) = solve_run(current, target, curvatures[n : n + 2], shape)
        if n:
            gap = current.station(spiral.start) - begin
            size = abs(current.radius) if current.curvature else spiral.length
            if gap < -1e-9 * size:
                raise ValueError(f"two spirals overlap by {-gap:.6g} on the {'circle' if current.curvature else 'line'} between them")
            if gap > 1e-9 * size:
                out.append((n - 1, current.piece(begin, begin + gap)))
        out.append((n, spiral))
        current, begin = target, target.station(spiral.end)
    return out


def solve_inflection(
    entry: Carrier, exit_: Carrier, tangent: Carrier, curvatures: Sequence[float], shape: str, turn: float = 0.0
) -> list[tuple[int, Segment]]:
    """An S (or C) of two spirals through a straight point between two arcs, asymmetric as the file's: each
    spiral ``line_to_circle`` between its arc and the file's tangent at the inflection, that tangent moved
    along its normal until the two spirals meet on it (the file's clothoids have the same lengths' ratio).

    ``turn`` (rad) turns the tangent about its point first.

    Raises:
        ValueError: no shift of the tangent joins the two spirals.
    """
    tangent = replace(tangent, heading=tangent.heading + turn)
    normal = np.array([-math.sin(tangent.heading), math.cos(tangent.heading)])

    def gap(shift: float) -> float:
        moved = replace(tangent, point=tangent.point + shift * normal)
        _, (first,) = solve_run(entry, moved, curvatures[:2], shape)
        _, (second,) = solve_run(moved, exit_, curvatures[1:], shape)
        return moved.station(second.start) - moved.station(first.end)

    try:
        at_zero = gap(0.0)
    except ValueError as e:
        raise ValueError(f"no spiral reaches the file's inflection tangent ({e})") from None
    scale = max(abs(at_zero), 1e-12)
    for step in scale * 1e-3 * 2.0 ** np.arange(16):  # a bracket of the shift that closes the gap, either way
        for shift in (step, -step):
            try:
                if gap(shift) * at_zero <= 0.0:
                    root = brentq(gap, 0.0, shift, xtol=1e-13 * scale + 1e-15, maxiter=200)
                    moved = replace(tangent, point=tangent.point + root * normal)
                    return solve_compound(entry, exit_, [moved], curvatures, shape)
            except ValueError:
                continue
    raise ValueError(f"no shift of the file's inflection tangent joins the two spirals (apart by {at_zero:.6g} on it)")


def _bezier(cp: NDArray, u: NDArray) -> tuple[NDArray, NDArray]:
    """Points and derivatives of cubic Béziers ``cp`` (..., 4, 2) at ``u`` (...)."""
    v = 1.0 - u
    b = np.stack([v**3, 3 * v * v * u, 3 * v * u * u, u**3], axis=-1)
    d = np.stack([-3 * v * v, 3 * v * v - 6 * u * v, 6 * u * v - 3 * u * u, 3 * u * u], axis=-1)
    return np.einsum("...k,...kj->...j", b, cp), np.einsum("...k,...kj->...j", d, cp)


class _Ours:
    """Our segments of every chain as curves of a parameter u ∈ [0, 1]: lines and spirals as cubic
    Béziers, arcs by angle."""

    def __init__(self, segments: list[Segment]):
        n = len(segments)
        self.cp = np.zeros((n, 4, 2))
        self.arc = np.zeros((n, 5))  # cx, cy, r (unsigned), start angle, signed sweep
        self.is_arc = np.zeros(n, bool)
        for k, s in enumerate(segments):
            if isinstance(s, Arc):
                c = s.center[:2]
                a0 = math.atan2(s.start[1] - c[1], s.start[0] - c[0])
                self.arc[k] = (c[0], c[1], abs(s.radius), a0, math.copysign(s.length / abs(s.radius), s.radius))
                self.is_arc[k] = True
            elif isinstance(s, BezierSpiral):
                self.cp[k] = s.control_points[:, :2]
            else:
                a, b = s.start[:2], s.end[:2]
                self.cp[k] = [a, a + (b - a) / 3.0, a + 2.0 * (b - a) / 3.0, b]

    def __call__(self, index: NDArray, u: NDArray) -> tuple[NDArray, NDArray]:
        point, der = _bezier(self.cp[index], u)
        a = self.arc[index]
        angle = a[..., 3] + u * a[..., 4]
        circle = a[..., :2] + a[..., 2, None] * np.stack([np.cos(angle), np.sin(angle)], axis=-1)
        tangent = (a[..., 2] * a[..., 4])[..., None] * np.stack([-np.sin(angle), np.cos(angle)], axis=-1)
        arc = self.is_arc[index][..., None]
        return np.where(arc, circle, point), np.where(arc, tangent, der)


class _Theirs:
    """The file's elements (exact clothoids at their own placement) as curves of u ∈ [0, 1]."""

    def __init__(self, starts: NDArray, headings: NDArray, k0: NDArray, k1: NDArray, lengths: NDArray):
        self.starts, self.headings, self.k0, self.lengths = starts, headings, k0, lengths
        self.rate = (k1 - k0) / lengths

    def __call__(self, index: NDArray, u: NDArray) -> tuple[NDArray, NDArray]:
        length = self.lengths[index]
        points, heading, _ = clothoid_frames(u * length, self.k0[index], self.rate[index], x0=self.starts[index, 0],
                                             y0=self.starts[index, 1], hdg=self.headings[index], length=length)  # fmt: skip
        return points, length[..., None] * np.stack([np.cos(heading), np.sin(heading)], axis=-1)


def distance_to_file(segments: Sequence[Segment], elements: Sequence[int], starts: NDArray, headings: NDArray, k0: NDArray,
                     k1: NDArray, lengths: NDArray) -> float:  # fmt: skip
    """The largest distance from samples of ``segments`` to the file's ``elements`` (to choose between solutions)."""
    with np.errstate(all="ignore"):  # a distance that overflows: the worst choice
        ours = _Ours(list(segments))
        u = np.linspace(0.0, 1.0, SAMPLES)
        points, _ = ours(np.repeat(np.arange(len(segments)), SAMPLES), np.tile(u, len(segments)))
        theirs = _Theirs(starts, headings, k0, k1, lengths)
        found = float(_distances(points, np.broadcast_to(np.asarray(elements), (len(points), len(elements))), theirs).max())
    return found if math.isfinite(found) else math.inf


def _distances(points: NDArray, window: NDArray, curve: Callable[[NDArray, NDArray], tuple[NDArray, NDArray]]) -> NDArray:
    """The distance from each point (P, 2) to the nearest of its window's curves (P, W): the nearest grid
    point, then Gauss–Newton steps on u clamped to [0, 1]."""
    out = np.empty(len(points))
    grid = np.linspace(0.0, 1.0, _GRID)
    used = np.unique(window)
    on_grid = np.empty((int(used.max()) + 1, _GRID, 2))
    on_grid[used] = curve(np.repeat(used, _GRID).reshape(-1, _GRID), np.broadcast_to(grid, (len(used), _GRID)))[0]  # once per curve
    for block in np.array_split(np.arange(len(points)), max(1, -(-len(points) * window.shape[1] // (16 * CHUNK)))):
        p, w = points[block, None, :], window[block]
        sampled = on_grid[w]
        u = grid[np.argmin(np.hypot(*(sampled - p[:, :, None, :]).transpose(3, 0, 1, 2)), axis=2)]
        for _ in range(_STEPS):
            at, der = curve(w, u)
            speed = np.einsum("...j,...j->...", der, der)
            step = np.einsum("...j,...j->...", p - at, der) / np.where(speed > 0.0, speed, 1.0)  # a point-like piece: no step
            u = np.clip(u + step, 0.0, 1.0)
        at, _ = curve(w, u)
        out[block] = np.hypot(*(p - at).transpose(2, 0, 1)).min(axis=1)
    return out


def offsets(chains: Sequence[Chain], owners: Sequence[NDArray], starts: NDArray, headings: NDArray, k0: NDArray, k1: NDArray,
            lengths: NDArray, runs: NDArray) -> NDArray[np.float64]:  # fmt: skip
    """Per file element the largest distance, either way, between its clothoid and our segments.

    Args:
        chains: our chains; ``owners[c]`` gives the file element of each segment of ``chains[c]``.
        starts, headings, k0, k1, lengths: the file's elements at their own placement.
        runs: the chain of each element.

    Raises:
        ValueError: the geometry is too large to measure in floating point (a distance overflows).
    """
    with np.errstate(all="ignore"):
        found = _offsets(chains, owners, starts, headings, k0, k1, lengths, runs)
    if not np.isfinite(found).all():
        raise ValueError("the offsets from the file's elements overflow in floating point")
    return found


def _offsets(chains: Sequence[Chain], owners: Sequence[NDArray], starts: NDArray, headings: NDArray, k0: NDArray, k1: NDArray,
            lengths: NDArray, runs: NDArray) -> NDArray[np.float64]:  # fmt: skip
    count = len(lengths)
    theirs = _Theirs(starts, headings, k0, k1, lengths)
    segments = [s for chain in chains for s in chain.segments]
    owner = np.concatenate(owners)
    ours = _Ours(segments)
    result = np.zeros(count)
    # ours → theirs: each sample of a segment against the file's element and its neighbours in the same run
    points = np.concatenate([segment_samples(chain, SAMPLES)[0] for chain in chains])  # (segments, SAMPLES, 2)
    near = np.clip(owner[:, None] + np.arange(-1, 2), 0, count - 1)
    near = np.where(runs[near] == runs[owner, None], near, owner[:, None])
    found = _distances(points.reshape(-1, 2), np.repeat(near, SAMPLES, axis=0), theirs).reshape(-1, SAMPLES).max(axis=1)
    np.maximum.at(result, owner, found)
    # theirs → ours: each sample of a file element against our segments of it and its neighbours
    first = np.searchsorted(owner, np.arange(count), side="left")  # owners are ascending along the chains
    last = np.searchsorted(owner, np.arange(count), side="right")
    lo = first[np.maximum(np.arange(count) - 1, 0)]
    hi = last[np.minimum(np.arange(count) + 1, count - 1)]
    lo = np.where(runs[np.maximum(np.arange(count) - 1, 0)] == runs, lo, first)
    hi = np.where(runs[np.minimum(np.arange(count) + 1, count - 1)] == runs, hi, last)
    width = int((hi - lo).max())
    window = np.minimum(lo[:, None] + np.arange(width), hi[:, None] - 1)
    u = np.linspace(0.0, 1.0, SAMPLES)
    index = np.broadcast_to(np.arange(count)[:, None], (count, SAMPLES))
    samples, _ = theirs(index, np.broadcast_to(u, (count, SAMPLES)))
    found = _distances(samples.reshape(-1, 2), np.repeat(window, SAMPLES, axis=0), ours).reshape(count, SAMPLES).max(axis=1)
    return np.maximum(result, found)
