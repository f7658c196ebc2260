"""The road body in numbers: the edges of its cross-section swept along plan, profile and banking.

A cross-section is a row of top vertices at lateral offsets o (left
positive; lane and shoulder edges, and the centre line at o = 0) and a
pavement of constant vertical ``depth`` below them. At station s the vertex
at offset o lies at

    C(s) + o·N(s) + (z(s) + h(o, s))·ẑ,     h(o, s) = o·tan φ(s) − c·(1 − w(s))·|o|

with C the alignment, N its left normal, z the profile, φ the roll angle of
the superelevation (OpenDRIVE's sign: positive falls to the right), c the
crossfall of the crown on tangents (both sides falling outwards) and w ∈
[0, 1] the share of its curve's banking the road has reached: on tangents
the crown, on a curve's circle a plane section at slope tan φ_c, and in
between (along the spirals) both sides turn together as smoothly as φ
(C1). Every vertex edge is as smooth as the road, so the surface between
two neighbouring edges is a ruled strip, straight across.

Each edge is built as cubic Bézier pieces in station (Hermite: exact point
and derivative at both ends of every piece), on pieces that end at every
plan segment, profile break and ramp end, and are halved until every edge
of every piece is within the tolerance of the true edge (sampled). The
bottom of the pavement is the top moved down by ``depth``, exactly.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..core.inputs import as_float, as_real_array, shown
from .centerline import FIT_SAMPLES, REPORT_SAMPLES, check_profile, float_floor, refine
from .profile import Profile
from .superelevation import Superelevation


@dataclass(frozen=True)
class Roadway:
    """The edges of a road's cross-section along its alignment (design units).

    Attributes:
        offsets: (v,) lateral offsets of the top vertices, left positive, decreasing (one is 0).
        stations: (n + 1,) chainage of the piece ends.
        segment: (n,) the plan segment each piece lies on.
        edges: (v, n, 4, 3) Bézier control points of every top edge on every piece.
        depth: the pavement's vertical thickness.
        tolerance: the largest distance allowed from the true edges.
        deviation: the largest distance measured (``REPORT_SAMPLES`` per piece and edge).
        units: the length unit.
    """

    offsets: NDArray
    stations: NDArray
    segment: NDArray
    edges: NDArray
    depth: float
    tolerance: float
    deviation: float
    units: str

    @property
    def centre(self) -> int:
        """Index of the vertex on the centre line."""
        return int(np.flatnonzero(self.offsets == 0.0)[0])

    def bottom(self, vertex: int) -> NDArray:
        """(n, 4, 3) control points of the bottom edge under top vertex ``vertex``."""
        return self.edges[vertex] - np.array([0.0, 0.0, self.depth])

    def section(self, end: int) -> NDArray:
        """The closed cross-section polygon at the first (``end`` 0) or last (1) station:
        top vertices left to right, then the bottom right edge, centre and left edge."""
        index = (0, 0) if end == 0 else (-1, 3)
        top = self.edges[:, index[0], index[1]]
        below = top[[len(top) - 1, self.centre, 0]] - np.array([0.0, 0.0, self.depth])
        return np.vstack([top, below])


def _check_inside_curves(alignment: Any, offsets: NDArray) -> None:
    """Refuse a cross-section that reaches a curve's centre: its inner edges would fold back."""
    units = alignment.chain.units
    for curve in alignment.curves:
        side = "left" if curve.deflection > 0.0 else "right"
        inner = float(offsets.max()) if curve.deflection > 0.0 else float(-offsets.min())  # towards the centre
        if inner >= curve.radius:
            raise ValueError(
                f"PI {curve.index}: the cross-section reaches {inner:g} {units} to the {side}, towards the curve's "
                f"centre {curve.radius:g} {units} away: its inner edge would fold back on itself (every offset must "
                f"stay within each curve's radius)"
            )


def roadway(
    alignment: Any,
    profile: Profile,
    offsets: ArrayLike,
    superelevation: Superelevation | None = None,
    crossfall: float = 0.025,
    depth: float = 0.5,
    tolerance: float | None = None,
) -> Roadway:
    """The swept cross-section of a road (see the module docstring).

    Args:
        alignment: the horizontal ``Alignment``.
        profile: its ``Profile`` (same unit, covering it).
        offsets: lateral offsets of the top vertices (design units, left
            positive); 0 is added when missing.
        superelevation: the banking (default: ``Superelevation.from_alignment``).
        crossfall: the crown's cross slope on tangents (m/m, ≥ 0).
        depth: the pavement's thickness (design units, > 0).
        tolerance: the largest distance of every edge from the truth (design
            units; default 1e-6 × the alignment's length).

    Raises:
        ValueError: bad offsets, crossfall, depth or tolerance; offsets that reach
            a curve's centre; a profile that does not fit the alignment; a
            tolerance out of float64's reach.
    """
    chain = alignment.chain
    check_profile(alignment, profile)
    offsets = as_real_array(offsets, "offsets").ravel()
    if not np.isfinite(offsets).all() or len(offsets) == 0:
        raise ValueError(f"offsets must be finite lateral distances; got {offsets.tolist()}")
    offsets = np.unique(np.append(offsets, 0.0))[::-1]
    if len(offsets) < 2:
        raise ValueError("offsets must reach off the centre line on at least one side")
    _check_inside_curves(alignment, offsets)
    crossfall = as_float(crossfall, "crossfall")
    if not 0.0 <= crossfall < 1.0:
        raise ValueError(f"crossfall must lie in [0, 1); got {shown(crossfall)}")
    depth = as_float(depth, "depth")
    if not depth > 0.0:
        raise ValueError(f"depth must be positive; got {shown(depth)}")
    tolerance = 1e-6 * chain.length if tolerance is None else as_float(tolerance, "tolerance")
    if not tolerance > 0.0:
        raise ValueError(f"tolerance must be positive; got {shown(tolerance)}")
    if superelevation is None:
        superelevation = Superelevation.from_alignment(alignment)
    elif not isinstance(superelevation, Superelevation):
        raise ValueError(f"superelevation must be a Superelevation; got {type(superelevation).__name__}")
    sweep = _Sweep(alignment, profile, superelevation, offsets, crossfall)
    floor = float_floor(chain.sample(2), profile.pvis[:, 1], offsets)
    if tolerance < floor:
        raise ValueError(f"tolerance {tolerance:.3g} {chain.units} is below what float64 can hold at these coordinates ({floor:.3g})")

    def halves(piece):
        middle = 0.5 * (piece[0] + piece[1])
        return (piece[0], middle), (middle, piece[1])

    done = refine(sweep.initial_pieces(), lambda pieces: sweep.deviation(pieces, FIT_SAMPLES), halves, tolerance,
                  lambda piece: f"the road's edges near station {piece[0]:.6g}")  # fmt: skip
    ends = np.array(sorted(done))
    edges = sweep.control(ends)
    deviation = float(sweep.deviation(done, REPORT_SAMPLES).max())
    segment = np.clip(np.searchsorted(sweep.boundaries, 0.5 * (ends[:, 0] + ends[:, 1]), "right") - 1, 0, len(chain) - 1)
    return Roadway(offsets, np.append(ends[:, 0], ends[-1, 1]), segment, edges, depth, float(tolerance), deviation, chain.units)


class _Sweep:
    """Evaluates the true edges and fits Hermite pieces to them."""

    def __init__(self, alignment: Any, profile: Profile, superelevation: Superelevation, offsets: NDArray, crossfall: float):
        self.chain = alignment.chain
        self.start = alignment.start_station
        self.profile = profile
        self.banking = superelevation
        self.offsets = offsets
        self.crossfall = crossfall
        self.boundaries = self.chain.stations + self.start  # chainage of the plan segment ends

    def initial_pieces(self) -> list[tuple[float, float]]:
        first, last = self.boundaries[0], self.boundaries[-1]
        cuts = np.concatenate([self.boundaries, self.profile.stations, self.banking.stations])
        cuts = np.unique(cuts[(cuts >= first) & (cuts <= last)])
        # drop cuts that rounding put next to a plan boundary
        keep = np.append(np.diff(cuts) > 1e-9 * (last - first), True)
        keep[-1] = True
        cuts = np.unique(np.append(cuts[keep], [first, last]))
        return list(zip(cuts[:-1].tolist(), cuts[1:].tolist()))

    def edges(self, stations: NDArray) -> tuple[NDArray, NDArray]:
        """(v, m, 3) points and derivatives d/ds of every top edge at ``stations`` (m,)."""
        local = np.clip(stations - self.start, 0.0, self.chain.length)
        c = self.chain.point_at(local)
        t = self.chain.tangent_at(local)
        kappa = self.chain.curvature_at(local)
        normal = np.stack([-t[:, 1], t[:, 0]], axis=1)
        z, grade = self.profile.elevation(stations), self.profile.grade(stations)
        roll, roll_rate = self.banking.roll(stations), self.banking.roll(stations, 1)
        share, share_rate = self.banking.share(stations), self.banking.share(stations, 1)
        o = self.offsets[:, None]
        height = o * np.tan(roll) - self.crossfall * (1.0 - share) * np.abs(o)
        height_rate = o * roll_rate / np.cos(roll) ** 2 + self.crossfall * share_rate * np.abs(o)
        points = np.empty((len(o), len(stations), 3))
        points[..., :2] = c + o[..., None] * normal
        points[..., 2] = z + height
        slopes = np.empty_like(points)
        slopes[..., :2] = (1.0 - kappa * o)[..., None] * t
        slopes[..., 2] = grade + height_rate
        return points, slopes

    def control(self, pieces: NDArray) -> NDArray:
        """(v, n, 4, 3) Hermite Bézier control points of every edge on pieces (n, 2) of stations.

        Every piece end is evaluated once, so neighbouring pieces share their
        end points bit for bit (the derivatives are continuous at every end).
        """
        pieces = np.asarray(pieces, dtype=float)
        stations, where = np.unique(pieces, return_inverse=True)
        points, slopes = self.edges(stations)
        where = where.reshape(pieces.shape)
        span = (pieces[:, 1] - pieces[:, 0])[None, :, None]
        start, end = points[:, where[:, 0]], points[:, where[:, 1]]
        start_slope, end_slope = slopes[:, where[:, 0]], slopes[:, where[:, 1]]
        return np.stack([start, start + span * start_slope / 3.0, end - span * end_slope / 3.0, end], axis=2)

    def deviation(self, pieces, samples: int) -> NDArray:
        """The largest distance of any edge of each piece from the true edges (pointwise in station)."""
        pieces = np.asarray(pieces, dtype=float)
        cp = self.control(pieces)
        t = (np.arange(samples) + 0.5) / samples
        basis = np.stack([(1 - t) ** 3, 3 * t * (1 - t) ** 2, 3 * t * t * (1 - t), t**3], axis=1)  # (m, 4)
        fitted = np.einsum("mj,vnjd->vnmd", basis, cp)
        stations = pieces[:, :1] + t[None, :] * (pieces[:, 1:] - pieces[:, :1])
        truth, _ = self.edges(stations.ravel())
        truth = truth.reshape(len(self.offsets), len(pieces), samples, 3)
        return np.linalg.norm(fitted - truth, axis=-1).max(axis=(0, 2))
