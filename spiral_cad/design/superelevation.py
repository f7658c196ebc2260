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

from ..core._inputs import as_real_array
from .criteria import RailCriteria


@dataclass(frozen=True)
class Superelevation:
    """The roll angle φ(station) of an alignment as exact cubic pieces.

    Attributes:
        stations: (m + 1,) piece boundaries (chainages) from the alignment's start to its end.
        coefficients: (m, 4) φ = a + b·d + c·d² + e·d³ on each piece, d = station − its start (radians).
        full: (m,) the roll angle of the curve a piece belongs to (0 on tangents), for ``share``.
        units: the alignment's length unit.
    """

    stations: NDArray
    coefficients: NDArray
    full: NDArray
    units: str

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
                raise ValueError(f"PI {curve.index}: the cross slope must lie in [0, 1); got {e!r}")
        start, end = alignment.start_station, alignment.end_station
        starts, coefficients, full = [start], [(0.0, 0.0, 0.0, 0.0)], [0.0]
        for curve, e in zip(curves, slopes.tolist()):
            roll = -math.copysign(1.0, curve.deflection) * (math.asin(e) if rail else math.atan(e))
            for s0, s1, polynomial in (
                (curve.ts, curve.sc, _ease(roll, curve.sc - curve.ts, rising=True)),
                (curve.sc, curve.cs, (roll, 0.0, 0.0, 0.0)),
                (curve.cs, curve.st, _ease(roll, curve.st - curve.cs, rising=False)),
                (curve.st, None, (0.0, 0.0, 0.0, 0.0)),
            ):
                if s1 is not None and not s1 > s0:
                    continue  # an empty piece (no arc between the spirals)
                starts.append(s0)
                coefficients.append(polynomial)
                full.append(roll if s1 is not None else 0.0)
        stations = np.array(starts + [end])
        keep = np.diff(stations) > 0.0  # the first tangent is empty when the alignment starts on a curve
        return cls(np.append(stations[:-1][keep], end), np.array(coefficients)[keep], np.array(full)[keep],
                   alignment.chain.units)  # fmt: skip

    def _locate(self, station: ArrayLike) -> tuple[NDArray, NDArray]:
        s = as_real_array(station, "station")
        first, last = float(self.stations[0]), float(self.stations[-1])
        slack = 1e-12 * max(last - first, abs(first), abs(last))
        outside = ~((s >= first - slack) & (s <= last + slack))
        if outside.any():
            raise ValueError(f"station {float(s[outside].ravel()[0])!r} is outside the alignment ({first!r} … {last!r})")
        index = np.clip(np.searchsorted(self.stations, s, side="right") - 1, 0, len(self.coefficients) - 1)
        return index, s - self.stations[index]

    def roll(self, station: ArrayLike, derivative: int = 0) -> NDArray:
        """φ (radians) or its ``derivative`` (1: dφ/ds, 2: d²φ/ds²) at ``station``; on a boundary,
        the piece that starts there."""
        index, d = self._locate(station)
        a, b, c, e = (self.coefficients[index, k] for k in range(4))
        if derivative == 0:
            return a + d * (b + d * (c + d * e))
        if derivative == 1:
            return b + d * (2.0 * c + 3.0 * d * e)
        if derivative == 2:
            return 2.0 * c + 6.0 * d * e
        raise ValueError(f"derivative must be 0, 1 or 2; got {derivative!r}")

    def cross_slope(self, station: ArrayLike) -> NDArray:
        """tan φ: the fall of the road across per unit width (positive falling to the right)."""
        return np.tan(self.roll(station))

    def share(self, station: ArrayLike, derivative: int = 0) -> NDArray:
        """w = φ/φ_c ∈ [0, 1]: how much of its curve's banking the road has at ``station`` (0 on tangents),
        or its ``derivative`` in station."""
        index, _ = self._locate(station)
        full = self.full[index]
        safe = np.where(full == 0.0, 1.0, full)
        return np.where(full == 0.0, 0.0, self.roll(station, derivative) / safe)

    def ramp_ends(self) -> NDArray:
        """The stations where a ramp starts or ends (every interior piece boundary)."""
        return self.stations[1:-1].copy()


def _ease(roll: float, length: float, rising: bool) -> tuple[float, float, float, float]:
    """The cubic ease from 0 to ``roll`` (or back) over ``length``, in powers of the distance from its start."""
    c, e = 3.0 * roll / length**2, -2.0 * roll / length**3
    return (0.0, 0.0, c, e) if rising else (roll, 0.0, -c, -e)
