"""Superelevation that is smooth: the roll angle of the road along an alignment, C1 at every ramp end.

Each curve's banking — the superelevation e = e_max·R_min/R of AASHTO's
method 1 for roads, the applied cant D for rail (``Alignment.checks``), or
values given per curve — is reached along the entry spiral and removed
along the exit spiral. The ramp is a **cubic ease**: with t the share of the
spiral's length travelled, the roll angle is

    φ(t) = φ_c·(3t² − 2t³)        (entry; 1 − that on the exit)

so φ and dφ/ds are continuous everywhere (dφ/ds = 0 at TS, SC, CS and ST:
C1, where a linear ramp kinks); its peak rate, at mid-spiral, is 1.5× the
linear ramp's mean. The roll is a cubic in station on every piece, so
OpenDRIVE's ``lateralProfile`` holds it exactly as ``superelevation``
polynomials.

Sign and size follow OpenDRIVE: the roll angle is positive when the road
falls to the right, so a left-turning curve (centre on the left) rolls
negative. A road's roll is φ_c = atan(e); a track's is asin(D/G) (cant D
over the rail-centre distance G).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..core.inputs import as_real_array, shown
from ..core.piecewise import inside, piece_at, piecewise_at
from .criteria import RailCriteria


@dataclass(frozen=True)
class Superelevation:
    """The roll angle φ(station) of an alignment as exact cubic pieces.

    Attributes:
        start: the alignment's start station.
        local: (m + 1,) piece boundaries as arc length from the alignment's start (its
            chain's own stations at TS, SC, CS and ST), ending at its length.
        coefficients: (m, 4) φ = a + b·d + c·d² + e·d³ on each piece, d = distance from its start (radians).
        full: (m,) the roll angle of the curve a piece belongs to (0 on tangents), for ``share``.
        units: the alignment's length unit.
    """

    start: float
    local: NDArray
    coefficients: NDArray
    full: NDArray
    units: str

    @property
    def stations(self) -> NDArray:
        """(m + 1,) piece boundaries as chainages."""
        return self.start + self.local

    @classmethod
    def from_alignment(cls, alignment: Any, cross_slopes: ArrayLike | None = None) -> Superelevation:
        """The smooth superelevation of ``alignment``'s curves.

        Args:
            alignment: an ``Alignment``.
            cross_slopes: per curve the cross slope e (m/m, ≥ 0) reached on its
                circle; default: the alignment's criteria (road: e; rail: D/G).
                Without either, the road stays level.

        Raises:
            ValueError: a cross slope that is negative, not finite or ≥ 1, or
                not one per curve, naming the PI.
        """
        curves = alignment.curves
        rail = isinstance(alignment.criteria, RailCriteria)
        if cross_slopes is None:
            slopes = np.array([check.cross_slope for check in alignment.checks]) if alignment.checks else np.zeros(len(curves))
        else:
            slopes = as_real_array(cross_slopes, "cross_slopes")
            if slopes.ndim == 0:
                slopes = np.full(len(curves), float(slopes))
            if slopes.shape != (len(curves),):
                raise ValueError(f"cross_slopes needs one value per curve ({len(curves)}); got shape {slopes.shape}")
        for curve, e in zip(curves, slopes.tolist()):
            if not (math.isfinite(e) and 0.0 <= e < 1.0):
                raise ValueError(f"PI {curve.index}: the cross slope must lie in [0, 1); got {shown(e)}")
        chain = alignment.chain
        stations = chain.stations
        if not curves:
            return cls(alignment.start_station, stations[[0, -1]], np.zeros((1, 4)), np.zeros(1), chain.units)
        turn = np.array([math.copysign(1.0, c.deflection) for c in curves])
        roll = -turn * (np.arcsin(slopes) if rail else np.arctan(slopes))
        # TS, SC, CS, ST as the chain's own stations (ramps end exactly on segment ends)
        wanted = np.array([(c.ts, c.sc, c.cs, c.st) for c in curves]) - alignment.start_station
        index = np.clip(np.searchsorted(stations, wanted), 1, len(stations) - 1)
        index -= np.abs(stations[index - 1] - wanted) <= np.abs(stations[index] - wanted)
        ts, sc, cs, st = stations[index].T
        entry, exit_ = sc - ts, st - cs
        zero = np.zeros(len(curves))
        pieces = np.stack([
            np.stack([zero, zero, 3.0 * roll / entry**2, -2.0 * roll / entry**3], axis=1),  # cubic ease in
            np.stack([roll, zero, zero, zero], axis=1),  # the circle
            np.stack([roll, zero, -3.0 * roll / exit_**2, 2.0 * roll / exit_**3], axis=1),  # cubic ease out
            np.zeros((len(curves), 4)),  # the tangent after
        ], axis=1)  # fmt: skip
        starts = np.concatenate([[0.0], np.stack([ts, sc, cs, st], axis=1).ravel()])
        coefficients = np.concatenate([np.zeros((1, 4)), pieces.reshape(-1, 4)])
        full = np.concatenate([[0.0], np.stack([roll, roll, roll, zero], axis=1).ravel()])
        ends = np.append(starts, chain.length)
        keep = np.diff(ends) > 0.0  # empty pieces: no arc between the spirals, no tangent between curves
        return cls(alignment.start_station, np.append(starts[keep], chain.length), coefficients[keep], full[keep],
                   chain.units)  # fmt: skip

    def roll(self, station: ArrayLike, derivative: int = 0) -> NDArray:
        """φ (radians) or its ``derivative`` (1: dφ/ds, 2: d²φ/ds²) at ``station``; on a boundary,
        the piece that starts there."""
        s = inside(station, float(self.stations[0]), float(self.stations[-1]), "alignment")
        return piecewise_at(self.stations[:-1], self.coefficients, s, derivative)

    def cross_slope(self, station: ArrayLike) -> NDArray:
        """tan φ: the fall of the road across per unit width (positive falling to the right)."""
        return np.tan(self.roll(station))

    def share(self, station: ArrayLike, derivative: int = 0) -> NDArray:
        """w = φ/φ_c ∈ [0, 1]: how much of its curve's banking the road has at ``station`` (0 on tangents),
        or its ``derivative`` in station."""
        s = inside(station, float(self.stations[0]), float(self.stations[-1]), "alignment")
        full = self.full[piece_at(self.stations[:-1], s)[0]]
        safe = np.where(full == 0.0, 1.0, full)
        return np.where(full == 0.0, 0.0, self.roll(station, derivative) / safe)

    def records(self) -> NDArray:
        """(m, 5) rows (s, a, b, c, d): each piece's cubic with s from the alignment's start
        (OpenDRIVE's ``superelevation`` records)."""
        return np.column_stack([self.local[:-1], self.coefficients])

    def ramp_ends(self) -> NDArray:
        """The stations where a ramp starts or ends (every interior piece boundary)."""
        return self.stations[1:-1]
