"""Horizontal alignments: tangent–spiral–arc–spiral–tangent at every PI.

A road or railway centre line is given by its points of intersection (PIs):
straight tangents between them, and at every interior PI a circular curve of
given radius entered and left through Bézier spirals (Theorem 4.1). The
result is one G2 :class:`~spiral_cad.Chain` plus a stationing table.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.optimize import brentq

from ..core.bezier import curvature_rate, peak_curvature_rate  # noqa: F401  (public here too)
from ..core._inputs import as_float, as_points, as_real_array, per_item
from ..core._kernels import shape_g1
from ..core.factors import length_factor, search_range
from ..core.shapes import SHAPE_CODES, TRANSITION_SHAPES, shape_code, shape_limits
from ..core.chain import JOIN_TOLERANCE, Chain
from ..core.units import DEFAULT_UNITS, length_unit, speed_unit
from .criteria import CRITERIA_DIMENSIONS, Criteria, CriteriaRow, RailCriteria, RoadCriteria
from .tables import text_table, write_csv
from ..core.errors import JointError, NoSolutionError
from ..core.transitions import Transition, line_to_circle

#: |sin(deflection)| at or below this counts as a straight PI.
COLLINEAR_TOL = 1e-12
#: Smallest θ searched when a spiral length is requested.
_THETA_MIN = 1e-7


def theta_for_length(length: float, radius: float, shape: str = "walton-meek") -> float:
    """The θ whose spiral of ``shape`` with end radius ``radius`` has arc length ``length``.

    Length grows monotonically with θ for a fixed radius (and is
    proportional to the radius), so a bracketed 1-D root gives θ.

    Raises:
        NoSolutionError: ``length`` outside the reachable range.
    """

    def excess(theta: float) -> float:
        return float(length_factor(theta, shape)) - length / radius

    largest = shape_limits(shape)["theta"]
    lo, hi = _THETA_MIN, largest * (1.0 - 1e-9) if largest == math.pi / 2 else largest
    if not excess(lo) < 0.0 < excess(hi):
        raise NoSolutionError(
            f"spiral length {length:.6g} is outside the range a spiral onto radius {radius:.6g} "
            f"can have ({radius * (excess(lo) + length / radius):.3g} … {radius * (excess(hi) + length / radius):.3g})"
        )
    return float(brentq(excess, lo, hi, xtol=1e-16, rtol=1e-15, maxiter=200))


# -------------------------------------------------------- the model


@dataclass(frozen=True)
class CurveData:
    """One PI's curve: geometry, stationing and spiral quality numbers.

    Angles are radians; chainages are arc length along the alignment plus
    the alignment's start station.

    Attributes:
        index: the PI's index in the input points.
        pi: the PI coordinates.
        deflection: signed deflection angle at the PI (positive turns left).
        radius: circular radius (> 0).
        center: circle centre.
        theta_in, theta_out: spiral angles of the entry and exit spirals.
        spiral_in_length, spiral_out_length, arc_length: lengths.
        ts, sc, cs, st: chainages of tangent→spiral, spiral→curve,
            curve→spiral and spiral→tangent.
        peak_rate_in, peak_rate_out: the largest |dκ/ds| along each spiral.
        entry, exit: the solved transitions (line→circle, circle→line).
    """

    index: int
    pi: tuple[float, float]
    deflection: float
    radius: float
    center: tuple[float, float]
    theta_in: float
    theta_out: float
    spiral_in_length: float
    spiral_out_length: float
    arc_length: float
    ts: float
    sc: float
    cs: float
    st: float
    peak_rate_in: float
    peak_rate_out: float
    entry: Transition
    exit: Transition

    @property
    def shape(self) -> str:
        """The spiral shape of the curve's transitions."""
        return self.entry.shape

    def row(self) -> dict[str, float]:
        """The table row (Python numbers): lengths, chainages, angles in degrees, rates in 1/length², and the spiral shape."""
        values = {
            "x": self.pi[0],
            "y": self.pi[1],
            "deflection": math.degrees(self.deflection),
            "radius": self.radius,
            "theta_in": math.degrees(self.theta_in),
            "theta_out": math.degrees(self.theta_out),
            "spiral_in_length": self.spiral_in_length,
            "arc_length": self.arc_length,
            "spiral_out_length": self.spiral_out_length,
            "TS": self.ts,
            "SC": self.sc,
            "CS": self.cs,
            "ST": self.st,
            "peak_dk_ds_in": self.peak_rate_in,
            "mean_dk_ds_in": 1.0 / (self.radius * self.spiral_in_length),
            "peak_dk_ds_out": self.peak_rate_out,
            "mean_dk_ds_out": 1.0 / (self.radius * self.spiral_out_length),
        }
        return {"pi": int(self.index), **{key: float(value) for key, value in values.items()}, "spiral_shape": self.shape}


@dataclass(frozen=True)
class Alignment:
    """A horizontal alignment: the G2 chain from the first to the last PI and its curves.

    Attributes:
        chain: the G2 chain (tangent–spiral–arc–spiral–tangent at every PI).
        curves: one ``CurveData`` per interior PI.
        start_station: chainage of the first PI.
        criteria: the design criteria the curves were chosen or checked by, if any.
        checks: one ``CriteriaRow`` per curve when there are criteria.
        shape: the spiral shape of every transition (``"near-linear"`` or ``"walton-meek"``).
    """

    chain: Chain
    curves: list[CurveData]
    start_station: float = 0.0
    criteria: Criteria | None = None
    checks: tuple[CriteriaRow, ...] = ()
    shape: str = "near-linear"

    @classmethod
    def from_pis(
        cls,
        points: ArrayLike,
        radii: ArrayLike,
        spiral_angles: Any = None,
        spiral_lengths: Any = None,
        start_station: float = 0.0,
        tolerance: float = JOIN_TOLERANCE,
        units: str = DEFAULT_UNITS,
        *,
        design_speed: float | None = None,
        max_jerk: float | None = None,
        criteria: Criteria | None = None,
        strict: bool = False,
        shape: str = "near-linear",
    ) -> Alignment:
        """Build tangent–spiral–arc–spiral–tangent at every interior PI.

        Args:
            points: (n ≥ 3, 2) PIs in travel order; the first and last are the
                alignment's start and end.
            radii: circular radius per interior PI (> 0), or one for all.
            spiral_angles: spiral angle θ (radians, in (0, π/2)): one value for
                all, one per interior PI, or one ``(θ_in, θ_out)`` pair per PI.
            spiral_lengths: spiral arc lengths, shaped like ``spiral_angles``
                (give exactly one of the two).
            start_station: chainage of the first PI.
            tolerance: the chain's relative join tolerance (``Chain``, which
                also allows for the rounding of survey coordinates).
            units: length unit of the PIs, radii and spiral lengths (default
                mm; road designs usually m or ft).
            design_speed: V (km/h for metric units, mph for in/ft): judges
                every curve by ``RoadCriteria(V, max_jerk)``.
            max_jerk: C, the largest rate of change of lateral acceleration
                (m/s³; default 0.6), with ``design_speed``.
            criteria: a ``RoadCriteria`` or ``RailCriteria`` (instead of
                ``design_speed``/``max_jerk``, with every value settable).
            strict: raise when a given spiral or radius violates a criterion
                (by default violations are listed in ``checks``).
            shape: the spiral shape (``spiral_cad.core.shapes``): ``"near-linear"``
                (default: curvature almost linear in arc length, so a spiral
                meets a jerk limit at about the clothoid's length; spiral
                angles up to 50°) or ``"walton-meek"`` (the 1996 spiral: 1.6–1.84×
                longer for the same jerk; any angle below 90°).

        With criteria and neither ``spiral_angles`` nor ``spiral_lengths``,
        each spiral is the shortest that meets every criterion (its peak
        dκ/ds, not the clothoid's mean, sets the jerk); when the criteria
        conflict (the jerk needs more length than p_max or the deflection
        allows) the error names the PI and the numbers.

        The circle centre lies at distance r·g1(θ_in) from the incoming
        tangent and r·g1(θ_out) from the outgoing one (Theorem 4.1), which
        fixes it for symmetric and asymmetric curves alike.

        Raises:
            ValueError: malformed input (fewer than 3 PIs, repeated PIs,
                collinear PIs, bad radius or spiral spec); messages name the PI.
            NoSolutionError: a deflection too small for its spirals, or two
                curves overlapping on their shared tangent.
        """
        pts = as_points(points, "points")
        if pts.ndim != 2 or len(pts) < 3:
            raise ValueError(f"an alignment needs at least 3 PIs as an (n, 2) array; got shape {pts.shape}")
        if not np.isfinite(pts).all():
            raise ValueError("PI coordinates must be finite")
        count = len(pts) - 2
        seg = np.diff(pts, axis=0)
        lengths = np.hypot(seg[:, 0], seg[:, 1])
        for k, length in enumerate(lengths):
            if not length > 0.0:
                raise ValueError(f"PI {k} and PI {k + 1} coincide at {pts[k].tolist()}")
        directions = seg / lengths[:, None]
        radius = _per_pi(radii, count, "radii")
        for j, r in enumerate(radius):
            if not r > 0.0:
                raise ValueError(f"PI {j + 1}: radius must be positive; got {r}")
        units = length_unit(units)
        shape_code(shape, TRANSITION_SHAPES)
        criteria = _criteria(design_speed, max_jerk, criteria)
        if criteria is not None:
            criteria.minimum_radius(units)  # a design speed outside the side friction table is named first
        origin = float(as_float(start_station, "start_station"))
        if spiral_angles is not None and spiral_lengths is not None:
            raise ValueError("give at most one of spiral_angles and spiral_lengths")
        by_length = spiral_lengths is not None
        if spiral_angles is None and spiral_lengths is None:
            if criteria is None:
                raise ValueError("give spiral_angles or spiral_lengths, or design criteria (design_speed) to choose them")
            shortest, longest = criteria.choose(radius, units, shape)
            spec = np.stack([shortest, shortest], axis=1)
        else:
            shortest = longest = None
            spec = _sides(spiral_lengths if by_length else spiral_angles, count, "spiral_lengths" if by_length else "spiral_angles")

        solved = []
        for j in range(count):
            i = j + 1
            r = radius[j]
            t_in, t_out = directions[j], directions[j + 1]
            sin_d = t_in[0] * t_out[1] - t_in[1] * t_out[0]
            cos_d = float(np.dot(t_in, t_out))
            if abs(sin_d) <= COLLINEAR_TOL:
                what = "folds straight back" if cos_d < 0.0 else "is collinear with its neighbours (zero deflection)"
                raise ValueError(f"PI {i} at {pts[i].tolist()} {what}: no curve can be placed there")
            deflection = math.atan2(sin_d, cos_d)
            if shortest is not None:
                _check_choice(i, r, deflection, shortest[j], longest[j], criteria, units, shape)
            if by_length:
                for side, value in zip(("entry", "exit"), spec[j]):
                    if not value > 0.0:
                        raise ValueError(f"PI {i}: {side} spiral length must be positive; got {value}")
                thetas = [_theta_at(value, r, i, side, shape) for side, value in zip(("entry", "exit"), spec[j])]
            else:
                thetas = list(spec[j])
                for side, value in zip(("entry", "exit"), thetas):
                    if not 0.0 < value < math.pi / 2:
                        raise ValueError(f"PI {i}: {side} spiral angle must lie in (0, π/2); got {value}")
            theta_in, theta_out = thetas
            sweep = abs(deflection) - theta_in - theta_out
            if sweep < -1e-12:
                raise NoSolutionError(
                    f"PI {i}: deflection {math.degrees(abs(deflection)):.6g}° is smaller than "
                    f"θ_in + θ_out = {math.degrees(theta_in):.6g}° + {math.degrees(theta_out):.6g}°: the circular arc "
                    f"would have negative sweep {math.degrees(sweep):.4g}°; use shorter spirals or a smaller radius"
                )
            try:
                solved.append(_curve(pts[i], t_in, t_out, deflection, r, theta_in, theta_out, shape))
            except NoSolutionError as error:
                raise NoSolutionError(f"PI {i}: {error}") from None

        _check_tangents(pts, lengths, directions, solved)
        parts: list[Transition] = [t for s in solved for t in s[:2]]
        try:
            chain = Chain.join(parts, pts[0], pts[-1], tolerance, units)
        except JointError as error:
            raise NoSolutionError(f"PI {error.part // 2 + 1}: float64 cannot hold its curve G2 at these coordinates: {error}") from None
        curves = _curve_data(chain, pts, solved, radius, origin)
        checks = () if criteria is None else _judge(curves, criteria, units, shortest, longest, strict, shape)
        return cls(chain, curves, origin, criteria, checks, shape)

    # ------------------------------------------------------- table

    def rows(self) -> list[dict[str, float]]:
        """One dict per curve (see :meth:`CurveData.row`), in travel order; with a design
        speed also the peak lateral jerk (roads) or cant deficiency rate (rail) of each spiral."""
        rows = [c.row() for c in self.curves]
        for row, check in zip(rows, self.checks):
            name = check.quantity.replace(" ", "_")
            row[f"{name}_in"], row[f"{name}_out"] = (float(v) for v in check.peak_rates)
        return rows

    def _dimensions(self) -> dict[str, str]:
        extra = {}
        for check in self.checks[:1]:
            name = check.quantity.replace(" ", "_")
            extra = {f"{name}_in": check.rate_unit, f"{name}_out": check.rate_unit, "limit": check.rate_unit}
            extra["banking"] = "m/m" if check.rate_unit == "m/s³" else "mm"
        return extra

    def criteria_rows(self) -> list[dict[str, Any]]:
        """One dict per curve: R vs R_min, L and its bounds, shifts, peak rates, banking, verdict."""
        return [c.row() for c in self.checks]

    def criteria_table(self, digits: int = 6) -> str:
        """The criteria table as text (empty without criteria)."""
        if not self.checks:
            return ""
        speed = f"design speed {self.criteria.design_speed:g} {speed_unit(self.chain.units)}"
        return f"{type(self.criteria).__name__}, {speed}\n" + text_table(
            self.criteria_rows(), {**CRITERIA_DIMENSIONS, **self._dimensions()}, self.chain.units, digits
        )

    def criteria_to_csv(self, path: str | Path) -> Path:
        """Write the criteria table (units in the headers) to ``path``."""
        return write_csv(path, self.criteria_rows(), {**CRITERIA_DIMENSIONS, **self._dimensions()}, self.chain.units)

    @property
    def end_station(self) -> float:
        return self.start_station + self.chain.length

    def centerline_3d(self, profile: Any, tolerance: float | None = None) -> Any:
        """The 3-D centre line under ``profile`` (see ``spiral_cad.design.centerline``)."""
        from .centerline import centerline_3d

        return centerline_3d(self, profile, tolerance)

    def table(self, digits: int = 8) -> str:
        """The stationing table as aligned text (for printing), units in the headers."""
        units = self.chain.units
        return (
            text_table(self.rows(), {**STATION_DIMENSIONS, **self._dimensions()}, units, digits)
            + f"\nstart {self.start_station:.{digits}g}  end {self.end_station:.{digits}g}  "
            f"length {self.chain.length:.{digits}g} {units}"
        )

    def to_csv(self, path: str | Path) -> Path:
        """Write the stationing table (one row per PI curve, full precision, units in the headers) to ``path``."""
        return write_csv(path, self.rows(), {**STATION_DIMENSIONS, **self._dimensions()}, self.chain.units)


#: Dimension of each stationing column (``L`` the design's length unit).
STATION_DIMENSIONS = {
    **dict.fromkeys(["x", "y", "radius", "spiral_in_length", "arc_length", "spiral_out_length"], "L"),
    **dict.fromkeys(["deflection", "theta_in", "theta_out"], "deg"),
    **dict.fromkeys(["TS", "SC", "CS", "ST"], "L"),
    **dict.fromkeys(["peak_dk_ds_in", "mean_dk_ds_in", "peak_dk_ds_out", "mean_dk_ds_out"], "1/L²"),
}


def _criteria(design_speed: Any, max_jerk: Any, criteria: Any) -> Criteria | None:
    """The criteria object from ``criteria`` or from ``design_speed``/``max_jerk``."""
    if criteria is not None:
        if design_speed is not None or max_jerk is not None:
            raise ValueError("give criteria, or design_speed and max_jerk, not both")
        if not isinstance(criteria, (RoadCriteria, RailCriteria)):
            raise ValueError(f"criteria must be a RoadCriteria or RailCriteria; got {type(criteria).__name__}")
        return criteria
    if design_speed is None:
        if max_jerk is not None:
            raise ValueError("max_jerk needs a design_speed")
        return None
    return RoadCriteria(design_speed) if max_jerk is None else RoadCriteria(design_speed, max_jerk)


def _check_choice(
    i: int, r: float, deflection: float, shortest: float, longest: float, criteria: Criteria, units: str, shape: str
) -> None:
    """Refuse, naming the PI and the numbers, when no spiral meets every criterion of curve ``i``."""
    length = lambda theta: float(length_factor(theta, shape) * r)  # noqa: E731
    if math.isnan(shortest):
        raise NoSolutionError(
            f"PI {i}: no spiral onto R = {r:.6g} {units} ({shape}, up to θ = {math.degrees(search_range(shape)[1]):.3g}°) meets the "
            f"criteria at {criteria.design_speed:g} {speed_unit(units)}; use a larger radius"
        )
    if shortest > longest * (1 + 1e-12):
        raise NoSolutionError(
            f"PI {i}: the criteria conflict at R = {r:.6g} {units}: the rate limits need spirals of at least "
            f"{length(shortest):.6g} {units} (θ ≥ {math.degrees(shortest):.4g}°), the shift limit allows at most "
            f"{length(longest):.6g} {units} (θ ≤ {math.degrees(longest):.4g}°); use a larger radius or relax the limits"
        )
    if 2.0 * shortest > abs(deflection):
        raise NoSolutionError(
            f"PI {i}: the shortest spirals that meet the criteria turn 2 × {math.degrees(shortest):.4g}° but the "
            f"deflection is only {math.degrees(abs(deflection)):.4g}°; use a larger radius"
        )


def _judge(
    curves: list[CurveData], criteria: Criteria, units: str, shortest, longest, strict: bool, shape: str
) -> tuple[CriteriaRow, ...]:
    """The criteria row of every curve; with ``strict`` any violation raises."""
    radii = np.array([c.radius for c in curves])
    if shortest is None:
        shortest, longest = criteria.choose(radii, units, shape)
    largest = search_range(shape)[1]
    spirals_low, spirals_high = (length_factor(np.nan_to_num(t, nan=largest), shape) * radii for t in (shortest, longest))
    thetas = np.array([(c.theta_in, c.theta_out) for c in curves])
    lengths = np.array([(c.spiral_in_length, c.spiral_out_length) for c in curves])
    rates = np.array([(c.peak_rate_in, c.peak_rate_out) for c in curves])
    bounds = np.stack([spirals_low, spirals_high], axis=1)
    rows = tuple(criteria.evaluate([c.index for c in curves], radii, thetas, units, bounds, lengths, rates, shape))
    broken = [f"PI {row.pi}: {'; '.join(row.violations)}" for row in rows if row.violations]
    if strict and broken:
        raise NoSolutionError("design criteria violated: " + " | ".join(broken))
    return rows


def _per_pi(value: Any, count: int, name: str) -> NDArray:
    return per_item(value, count, name, "interior PI")


def _sides(value: Any, count: int, name: str) -> NDArray:
    """(count, 2) entry/exit values from a scalar, one per PI, or (in, out) pairs."""
    if not isinstance(value, (list, tuple, np.ndarray)):
        array = np.full((count, 2), as_float(value, name))
    else:
        try:  # each entry a number (both sides) or an (in, out) pair
            array = np.array([np.broadcast_to(as_real_array(v, f"{name}[{i}]"), (2,)) for i, v in enumerate(value)])
        except ValueError as error:
            raise ValueError(f"{name} entries must be numbers or (in, out) pairs: {error}") from None
    if array.shape != (count, 2):
        raise ValueError(f"{name} needs one value, one per interior PI ({count}) or ({count}, 2) in/out pairs; got shape {array.shape}")
    if not np.isfinite(array).all():
        raise ValueError(f"{name} must be finite; got {array.tolist()}")
    return array


def _theta_at(length: float, radius: float, index: int, side: str, shape: str) -> float:
    try:
        return theta_for_length(length, radius, shape)
    except NoSolutionError as error:
        raise NoSolutionError(f"PI {index}: {side} {error}") from None


def _curve(pi: NDArray, t_in: NDArray, t_out: NDArray, deflection: float, r: float, theta_in: float, theta_out: float, shape: str):
    """Entry and exit transitions at one PI, and the circle centre."""
    side = math.copysign(1.0, deflection)
    n_in = side * np.array([-t_in[1], t_in[0]])
    n_out = side * np.array([-t_out[1], t_out[0]])
    # Theorem 4.1: offset d = r·g1(θ) of the centre from each tangent.
    code = SHAPE_CODES[shape]
    d_in = r * shape_g1(code, math.sin(theta_in), math.cos(theta_in))
    d_out = r * shape_g1(code, math.sin(theta_out), math.cos(theta_out))
    center = pi + np.linalg.solve(np.array([n_in, n_out]), np.array([d_in, d_out]))
    entry = line_to_circle(pi, t_in, center, r, shape=shape)
    exit_ = line_to_circle(pi, -t_out, center, r, shape=shape).reversed()
    return entry, exit_, center, deflection


def _check_tangents(pts: NDArray, lengths: NDArray, directions: NDArray, solved) -> None:
    """Each tangent must hold the ST of one curve before the TS of the next (§5)."""
    back = [0.0] + [float(np.dot(pts[j + 1] - s[0].start, directions[j])) for j, s in enumerate(solved)]
    ahead = [float(np.dot(s[1].end - pts[j + 1], directions[j + 1])) for j, s in enumerate(solved)] + [0.0]
    last = len(pts) - 1
    for k, length in enumerate(lengths):
        used = ahead[k - 1] if k > 0 else 0.0
        used_next = back[k + 1] if k + 1 < len(back) else 0.0
        if used + used_next > length * (1.0 + 1e-12):
            if k == 0:
                where = f"the TS of PI 1 lies {used_next:.6g} before PI 1, beyond the start point PI 0"
            elif k + 1 == last:
                where = f"the ST of PI {k} lies {used:.6g} after PI {k}, beyond the end point PI {last}"
            else:
                where = (
                    f"the curves at PI {k} and PI {k + 1} overlap on their shared tangent: the ST of PI {k} is "
                    f"{used:.6g} after PI {k} and the TS of PI {k + 1} is {used_next:.6g} before PI {k + 1}"
                )
            raise NoSolutionError(
                f"{where}; together {used + used_next:.6g} > tangent length {length:.6g}. "
                "Move the PIs apart, or reduce the radii or spiral lengths"
            )


def _curve_data(chain: Chain, pts: NDArray, solved, radius: NDArray, origin: float) -> list[CurveData]:
    stations = chain.stations
    spirals = np.array([[s[0].spirals[0].control_points, s[1].spirals[0].control_points] for s in solved])
    with np.errstate(over="ignore", divide="ignore", invalid="ignore"):  # 1/L² beyond float64 is inf
        peaks = peak_curvature_rate(spirals.reshape(-1, 4, 2))[0] if len(spirals) else []
    where = {id(seg): k for k, seg in enumerate(chain.segments)}
    curves = []
    for j, (entry, exit_, center, deflection) in enumerate(solved):
        first, last = entry.spirals[0], exit_.spirals[0]
        a, b = where[id(first)], where[id(last)]
        ts, sc, cs, st = (origin + stations[k] for k in (a, a + 1, b, b + 1))
        curves.append(
            CurveData(
                index=j + 1,
                pi=(float(pts[j + 1][0]), float(pts[j + 1][1])),
                deflection=deflection,
                radius=float(radius[j]),
                center=(float(center[0]), float(center[1])),
                theta_in=abs(first.theta),
                theta_out=abs(last.theta),
                spiral_in_length=first.length,
                spiral_out_length=last.length,
                arc_length=float(cs - sc),
                ts=float(ts),
                sc=float(sc),
                cs=float(cs),
                st=float(st),
                peak_rate_in=float(peaks[2 * j]),
                peak_rate_out=float(peaks[2 * j + 1]),
                entry=entry,
                exit=exit_,
            )
        )
    return curves
