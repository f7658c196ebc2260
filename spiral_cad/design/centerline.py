"""The 3-D centre line of a road: its plan (an alignment) lifted by its profile.

The curve is (x(u), y(u), z(s(u))): the alignment's own segments in plan and
the profile's elevation at their arc length s. It is built as rational
Bézier pieces of degree 5, one or more per plan segment, whose plan
projection **is the segment itself** (the same Bézier, line or rational arc,
split exactly at the piece ends and raised to degree 5 without change), so
the plan stays exactly the G2 alignment. Only z can differ from the truth,
and only where it has to:

* on a line, s is proportional to the curve parameter and z(s) is a
  parabola or a grade line, so z(s(u)) is a polynomial of degree ≤ 2 and
  the piece is **exact**; the same holds wherever the profile is level;
* on arcs and spirals under a grade or a vertical curve z(s(u)) is not a
  polynomial: each piece takes the exact z, dz/ds and d²z/ds² at its ends
  (a quintic Hermite in the homogeneous height) and is split until the
  distance to (x(u), y(u), z(s(u))), sampled on every piece, is within the
  tolerance (default 1e-6 × the alignment's length).

Point, tangent and d²r/ds² (s the plan length) are therefore those of the
exact road at every piece end, so the 3-D curvature vector is continuous —
the curve is **G2** — wherever the plan is G2 and the profile C2. Pieces
also end at every profile break (BVC, EVC): there the parabola's z'' jumps
(the profile itself is only C1), and so does the 3-D curvature: those
joints are **G1**, as the road is (``Centerline3D.g1_stations``). The
measured worst distance is ``Centerline3D.deviation``; nothing is returned
without it being within ``tolerance``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..core import bezier
from ..core.inputs import as_float
from ..core.nurbs import MAX_ARC_PIECE, _pieces
from ..core.segments import Arc, Line
from .profile import Profile, check_coverage

#: Samples per piece while refining (the roadway), and for the reported deviation (which the centre line also refines on).
FIT_SAMPLES, REPORT_SAMPLES = 16, 64
#: Halvings of one piece, and pieces in all, before a tolerance counts as out of reach.
MAX_SPLITS, MAX_PIECES = 40, 200_000


@dataclass(frozen=True)
class Centerline3D:
    """A road's 3-D centre line as rational quintic Bézier pieces (see the module docstring).

    Attributes:
        control_points: (n, 6, 3) control points of the pieces in travel order.
        weights: (n, 6) their weights (1 except on arcs).
        segment: (n,) the plan segment each piece lies on.
        parameters: (n, 2) the piece's range of that segment's parameter u.
        stations: (n + 1,) chainage at each piece end.
        exact: (n,) True where the piece is the exact curve (z polynomial in u).
        tolerance: the largest distance allowed from (x(u), y(u), z(s(u))).
        deviation: the largest distance measured (``REPORT_SAMPLES`` per piece).
        units: the length unit.
        g1_stations: the piece ends where the 3-D curvature jumps: the BVCs and EVCs inside the
            road, where the profile's z'' jumps (every other joint is G2).
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
    g1_stations: NDArray = field(default_factory=lambda: np.empty(0))

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

    def continuity(self) -> str:
        """One line (printable ASCII) naming the joints that are G1 and why; every other is G2."""
        if not len(self.g1_stations):
            return "G2 at every joint"
        where = ", ".join(f"{s:.6g}" for s in self.g1_stations)
        return (f"G2 at every joint but G1 at stations {where} {self.units} (vertical curve ends BVC and EVC, "
                "where the second derivative of the profile jumps)")  # fmt: skip


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
        raise ValueError(f"tolerance {tolerance:.3g} {chain.units} is below what float64 can hold at these coordinates ({floor:.3g})")

    def halves(piece):
        k, u0, u1 = piece
        middle = 0.5 * (u0 + u1)
        return (k, u0, middle), (k, middle, u1)

    done = refine(lift.initial_pieces(), lambda pieces: lift.deviation(pieces, REPORT_SAMPLES), halves, tolerance,
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
        """(n, 6, 3) control points and (n, 6) weights: the exact plan piece raised to degree 5 and a
        quintic Hermite z taking the profile's z, dz/ds and d²z/ds² at both ends (so pieces meet G2)."""
        plan_pieces, weight_pieces = [], []
        for k, u0, u1 in pieces:
            segment = self.chain[k]
            part = segment if (u0, u1) == (0.0, 1.0) else segment.piece(u0, u1)
            ((points, w, _),) = _pieces(part)
            plan_pieces.append(points)
            weight_pieces.append(w)
        homogeneous = _raise_degree(np.concatenate([np.array(plan_pieces) * np.array(weight_pieces)[..., None],
                                                    np.array(weight_pieces)[..., None]], axis=2), 2)  # fmt: skip
        weights = homogeneous[..., 2]
        plan = homogeneous[..., :2] / weights[..., None]
        segment = np.array([p[0] for p in pieces])
        ends = self.station(np.repeat(segment, 2), np.array([(p[1], p[2]) for p in pieces]).ravel()).reshape(-1, 2)
        z = self.profile.elevation(ends)
        g = self.profile.grade(ends)
        # d²z/ds² of the profile piece the whole piece lies in (pieces end at every BVC and EVC)
        which = np.clip(np.searchsorted(self.profile.stations, ends.mean(axis=1), "right") - 1, 0,
                        len(self.profile.coefficients) - 1)  # fmt: skip
        bend = 2.0 * self.profile.coefficients[which, 2]
        heights = np.empty(weights.shape)
        for end, (i0, i1, i2, sign) in enumerate(((0, 1, 2, 1.0), (5, 4, 3, -1.0))):
            # plan derivatives in t at this end (rational: X = A / W), then s_t = |X'|, s_tt = X'·X'' / |X'|
            a = homogeneous[:, [i0, i1, i2], :2]
            w = weights[:, [i0, i1, i2]]
            x = a[:, 0] / w[:, :1]
            a1, w1 = 5.0 * sign * (a[:, 1] - a[:, 0]), 5.0 * sign * (w[:, 1] - w[:, 0])
            a2, w2 = 20.0 * (a[:, 2] - 2.0 * a[:, 1] + a[:, 0]), 20.0 * (w[:, 2] - 2.0 * w[:, 1] + w[:, 0])
            x1 = (a1 - x * w1[:, None]) / w[:, :1]
            x2 = (a2 - 2.0 * x1 * w1[:, None] - x * w2[:, None]) / w[:, :1]
            s_t = np.linalg.norm(x1, axis=1)
            s_tt = np.einsum("ij,ij->i", x1, x2) / s_t
            z_t = g[:, end] * s_t
            z_tt = bend * s_t**2 + g[:, end] * s_tt
            # the homogeneous height above this end, Z = (z − z_end) W (0 here: a level piece stays exactly
            # level), its derivatives, then the three Bézier ordinates from this end
            h1 = z_t * w[:, 0]
            h2 = z_tt * w[:, 0] + 2.0 * z_t * w1
            c1 = sign * h1 / 5.0
            c2 = h2 / 20.0 + 2.0 * c1
            heights[:, i0], heights[:, i1], heights[:, i2] = z[:, end], z[:, end] + c1 / w[:, 1], z[:, end] + c2 / w[:, 2]
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
        # interior profile breaks where z'' (twice the quadratic coefficient) changes
        jumps = self.profile.stations[1:-1][np.diff(self.profile.coefficients[:, 2]) != 0.0]
        inside = (jumps > stations[0]) & (jumps < stations[-1])
        return Centerline3D(cp, w, segment, u, stations, lines | level, float(tolerance), float(deviation.max()),
                            self.chain.units, jumps[inside])  # fmt: skip


def _raise_degree(points: NDArray, times: int) -> NDArray:
    """(n, p + times, d) control points of n Bézier curves (n, p, d) of one degree raised ``times`` times (the same curves)."""
    for _ in range(times):
        degree = points.shape[1]  # the raised degree n + 1
        i = np.arange(degree + 1)[None, :, None] / degree
        padded = np.pad(points, ((0, 0), (1, 1), (0, 0)))
        points = i * padded[:, :-1] + (1.0 - i) * padded[:, 1:]
    return points


def _rational_points(cp: NDArray, weights: NDArray, t: NDArray) -> NDArray:
    """(n, m, 3) points of n rational Béziers (any one degree) at m parameters ``t``."""
    degree = cp.shape[1] - 1
    i = np.arange(degree + 1)
    b = np.array([math.comb(degree, k) for k in i]) * t[:, None] ** i * (1 - t[:, None]) ** (degree - i)  # (m, p + 1)
    homogeneous = np.einsum("mj,nj,njd->nmd", b, weights, cp)
    return homogeneous / (b @ weights.T).T[..., None]
