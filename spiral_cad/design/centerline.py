"""The 3-D centre line of a road: its plan (an alignment) lifted by its profile.

The curve is (x(u), y(u), z(s(u))): the alignment's own segments in plan and
the profile's elevation at their arc length s. It is built as rational cubic
Bézier pieces, one or more per plan segment, whose plan projection **is the
segment itself** (the same Bézier, line or rational arc, split exactly at
the piece ends), so the plan stays exactly the G2 alignment. Only z can
differ from the truth, and only where it has to:

* on a line, s is proportional to the curve parameter and z(s) is a
  parabola or a grade line, so z(s(u)) is a polynomial of degree ≤ 2 and
  the piece is **exact**; the same holds wherever the profile is level;
* on arcs and spirals under a grade or a vertical curve z(s(u)) is not a
  polynomial: each piece takes the exact z and dz/ds at its ends (so the
  curve is exactly G1 in 3-D, and C1 in z like the profile itself) and is
  split until the distance to (x(u), y(u), z(s(u))), sampled on every
  piece, is within the tolerance (default 1e-6 × the alignment's length).

Pieces also end at every profile break (BVC, EVC), where z'' jumps. The
measured worst distance is ``Centerline3D.deviation``; nothing is returned
without it being within ``tolerance``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..core import bezier
from ..core._inputs import as_float
from ..core.nurbs import MAX_ARC_PIECE, _pieces
from ..core.segments import Arc, Line
from .profile import Profile, check_coverage

#: Samples per piece while refining, and for the reported deviation.
FIT_SAMPLES, REPORT_SAMPLES = 16, 64
#: Halvings of one piece, and pieces in all, before a tolerance counts as out of reach.
MAX_SPLITS, MAX_PIECES = 40, 200_000


@dataclass(frozen=True)
class Centerline3D:
    """A road's 3-D centre line as rational cubic Bézier pieces (see the module docstring).

    Attributes:
        control_points: (n, 4, 3) control points of the pieces in travel order.
        weights: (n, 4) their weights (1 except on arcs).
        segment: (n,) the plan segment each piece lies on.
        parameters: (n, 2) the piece's range of that segment's parameter u.
        stations: (n + 1,) chainage at each piece end.
        exact: (n,) True where the piece is the exact curve (z polynomial in u).
        tolerance: the largest distance allowed from (x(u), y(u), z(s(u))).
        deviation: the largest distance measured (``REPORT_SAMPLES`` per piece).
        units: the length unit.
    """

    control_points: NDArray
    weights: NDArray
    segment: NDArray
    parameters: NDArray
    stations: NDArray
    exact: NDArray
    tolerance: float
    deviation: float
    units: str

    def __len__(self) -> int:
        return len(self.control_points)

    def point(self, t: ArrayLike) -> NDArray:
        """(n, m, 3) points of every piece at its parameters ``t`` (m,) ∈ [0, 1]."""
        return _rational_points(self.control_points, self.weights, np.asarray(t, dtype=float))

    def describe(self) -> str:
        """One line: pieces, how many are exact, the tolerance and the measured deviation."""
        exact = int(self.exact.sum())
        return (
            f"3-D centre line: {len(self)} pieces ({exact} exact, {len(self) - exact} with z fitted); "
            f"deviation {self.deviation:.2g} {self.units} (tolerance {self.tolerance:.2g} {self.units}); plan exact"
        )


def centerline_3d(alignment: Any, profile: Profile, tolerance: float | None = None) -> Centerline3D:
    """The 3-D centre line of ``alignment`` under ``profile`` (see the module docstring).

    Args:
        alignment: the horizontal ``Alignment``.
        profile: its ``Profile`` (same stations and unit), covering the alignment.
        tolerance: the largest distance from the exact curve (design units;
            default 1e-6 × the alignment's length).

    Raises:
        ValueError: a profile in another unit or not covering the alignment,
            a bad tolerance, or a tolerance that float64 cannot reach (naming
            the station and the distance reached).
    """
    chain = alignment.chain
    check_profile(alignment, profile)
    tolerance = 1e-6 * chain.length if tolerance is None else as_float(tolerance, "tolerance")
    if not tolerance > 0.0:
        raise ValueError(f"tolerance must be positive; got {tolerance!r}")
    lift = _Lift(alignment, profile)
    floor = float_floor(lift.chain.sample(2), profile.pvis[:, 1])
    if tolerance < floor:
        raise ValueError(
            f"tolerance {tolerance:.3g} {chain.units} is below what float64 can hold at these coordinates ({floor:.3g})"
        )

    def halves(piece):
        k, u0, u1 = piece
        middle = 0.5 * (u0 + u1)
        return (k, u0, middle), (k, middle, u1)

    done = refine(lift.initial_pieces(), lambda pieces: lift.deviation(pieces, FIT_SAMPLES), halves, tolerance,
                  lambda piece: f"the 3-D centre line near station {lift.station(np.array([piece[0]]), np.array([piece[1]]))[0]:.6g}")  # fmt: skip
    return lift.assemble(sorted(done), tolerance)


def float_floor(*coordinates: NDArray) -> float:
    """A distance float64 rounding can hide among these coordinates: 64 ulp of the largest."""
    return 64.0 * float(np.finfo(float).eps) * max(float(np.abs(c).max(initial=1.0)) for c in coordinates)


def refine(pending: list, deviation, halves, tolerance: float, where) -> list:
    """Halve pieces until ``deviation(pieces)`` is within ``tolerance`` for each; ValueError naming
    ``where(piece)`` when ``MAX_SPLITS`` halvings or ``MAX_PIECES`` pieces do not reach it."""
    done: list = []
    for _ in range(MAX_SPLITS):
        if not pending:
            return done
        bad = deviation(pending) > tolerance
        done += [p for p, b in zip(pending, bad) if not b]
        pending = [half for p, b in zip(pending, bad) if b for half in halves(p)]
        if len(done) + len(pending) > MAX_PIECES:
            break
    if not pending:
        return done
    worst = float(deviation(pending[:1])[0])
    raise ValueError(f"{where(pending[0])} cannot be fitted within {tolerance:.3g}: a piece still deviates {worst:.3g}")


def check_profile(alignment: Any, profile: Any) -> None:
    """``profile`` must be a Profile in the alignment's unit that covers it (ValueError/NoSolutionError naming the numbers)."""
    chain = alignment.chain
    if not isinstance(profile, Profile):
        raise ValueError(f"profile must be a Profile; got {type(profile).__name__}")
    if profile.units != chain.units:
        raise ValueError(f"the profile is in {profile.units} but the alignment in {chain.units}")
    check_coverage(profile.start, profile.end, alignment, chain.units)


class _Lift:
    """The alignment and profile, and the pieces (segment, u0, u1) built and measured on them."""

    def __init__(self, alignment: Any, profile: Profile):
        self.chain = alignment.chain
        self.profile = profile
        self.start = alignment.start_station
        self.local = self.chain.stations  # arc length at each segment start

    def initial_pieces(self) -> list[tuple[int, float, float]]:
        """One piece per plan segment, split at the profile's breaks and into arcs of at most 90°."""
        pieces = []
        breaks = self.profile.stations[1:-1] - self.start
        for k, segment in enumerate(self.chain):
            s0, s1 = self.local[k], self.local[k + 1]
            inside = breaks[(breaks > s0 + 1e-9 * (s1 - s0)) & (breaks < s1 - 1e-9 * (s1 - s0))] - s0
            cuts = [0.0, *np.atleast_1d(segment.parameter_at(inside)).tolist(), 1.0] if len(inside) else [0.0, 1.0]
            if isinstance(segment, Arc):
                count = max(1, math.ceil(segment.sweep / MAX_ARC_PIECE - 1e-12))
                cuts = sorted(set(cuts) | {i / count for i in range(1, count)})
            pieces += [(k, a, b) for a, b in zip(cuts, cuts[1:]) if b > a]
        return pieces

    def station(self, segment: NDArray, u: NDArray) -> NDArray:
        """Chainage at parameter ``u`` of plan segments ``segment`` (elementwise)."""
        out = np.empty(len(u))
        for k in np.unique(segment):
            mask = segment == k
            seg = self.chain[int(k)]
            uk = u[mask]
            if isinstance(seg, (Line, Arc)):
                local = uk * seg.length
            else:
                local = bezier.arc_length(seg.control_points, uk)
            out[mask] = np.where(uk == 1.0, self.local[k + 1], self.local[k] + local)
        return out + self.start

    def control(self, pieces: list[tuple[int, float, float]]) -> tuple[NDArray, NDArray]:
        """(n, 4, 3) control points and (n, 4) weights: the exact plan piece and Hermite z."""
        plan, weights = [], []
        for k, u0, u1 in pieces:
            segment = self.chain[k]
            part = segment if (u0, u1) == (0.0, 1.0) else segment.piece(u0, u1)
            ((points, w, _),) = _pieces(part)
            plan.append(points)
            weights.append(w)
        plan, weights = np.array(plan), np.array(weights)
        segment = np.array([p[0] for p in pieces])
        ends = self.station(np.repeat(segment, 2), np.array([(p[1], p[2]) for p in pieces]).ravel()).reshape(-1, 2)
        z = self.profile.elevation(ends)
        g = self.profile.grade(ends)
        legs = np.linalg.norm(plan[:, [1, 3]] - plan[:, [0, 2]], axis=-1)  # |Q1 − Q0|, |Q3 − Q2|
        heights = np.stack([z[:, 0], z[:, 0] + g[:, 0] * legs[:, 0], z[:, 1] - g[:, 1] * legs[:, 1], z[:, 1]], axis=1)
        return np.concatenate([plan, heights[..., None]], axis=2), weights

    def exact_points(self, pieces, t: NDArray, points: NDArray) -> NDArray:
        """The exact curve at the pieces' parameters ``t``: on the plan segment where the piece's
        plan point is (lines and spirals: at the same segment parameter; arcs: on the circle
        at the piece point's polar angle), lifted to z of its station."""
        exact = np.empty_like(points)
        segment = np.array([p[0] for p in pieces])
        u = np.array([(p[1], p[2]) for p in pieces])
        stations = np.empty(points.shape[:2])
        for k in np.unique(segment):
            rows = np.flatnonzero(segment == k)
            seg = self.chain[int(k)]
            if isinstance(seg, Arc):
                center = seg.center
                angle = np.arctan2(points[rows, :, 1] - center[1], points[rows, :, 0] - center[0])
                turned = np.mod(math.copysign(1.0, seg.radius) * (angle - seg.start_angle), 2.0 * math.pi)
                turned = np.where(turned > 0.5 * (seg.sweep + 2.0 * math.pi), turned - 2.0 * math.pi, turned)
                along = turned / seg.sweep
                exact[rows, :, :2] = seg.point(along)
            else:
                along = u[rows, :1] + t[None, :] * (u[rows, 1:] - u[rows, :1])
                exact[rows, :, :2] = seg.point(along)
            stations[rows] = self.station(np.full(along.size, k), along.ravel()).reshape(along.shape)
        exact[..., 2] = self.profile.elevation(np.clip(stations, self.profile.start, self.profile.end))
        return exact

    def deviation(self, pieces, samples: int) -> NDArray:
        """The largest distance of each piece from the exact curve at ``samples`` interior parameters."""
        cp, w = self.control(pieces)
        t = (np.arange(samples) + 0.5) / samples
        points = _rational_points(cp, w, t)
        return np.linalg.norm(points - self.exact_points(pieces, t, points), axis=-1).max(axis=1)

    def assemble(self, pieces, tolerance: float) -> Centerline3D:
        cp, w = self.control(pieces)
        segment = np.array([p[0] for p in pieces])
        u = np.array([(p[1], p[2]) for p in pieces])
        ends = self.station(np.repeat(segment, 2), u.ravel()).reshape(-1, 2)
        deviation = self.deviation(pieces, REPORT_SAMPLES)
        stations = np.append(ends[:, 0], ends[-1, 1])
        # exact: a line (z is a polynomial of degree ≤ 2 in u) or a level stretch of the profile
        rates = np.abs(self.profile.coefficients[:, 1:]).max(axis=1)
        level = np.array([
            rates[max(0, np.searchsorted(self.profile.stations, a, "right") - 1):
                  np.searchsorted(self.profile.stations, b, "left")].max(initial=0.0) == 0.0
            for a, b in ends
        ])  # fmt: skip
        lines = np.array([isinstance(self.chain[int(k)], Line) for k in segment])
        return Centerline3D(cp, w, segment, u, stations, lines | level, float(tolerance), float(deviation.max()),
                            self.chain.units)  # fmt: skip


def _rational_points(cp: NDArray, weights: NDArray, t: NDArray) -> NDArray:
    """(n, m, 3) points of n rational cubic Béziers at m parameters ``t``."""
    b = np.stack([(1 - t) ** 3, 3 * t * (1 - t) ** 2, 3 * t * t * (1 - t), t**3], axis=1)  # (m, 4)
    homogeneous = np.einsum("mj,nj,njd->nmd", b, weights, cp)
    return homogeneous / (b @ weights.T).T[..., None]
