"""Horizontal alignments: tangent–spiral–arc–spiral–tangent at every PI.

A road or railway centre line is given by its points of intersection (PIs):
straight tangents between them, and at every interior PI a circular curve of
given radius entered and left through Bézier spirals (Theorem 4.1). The
result is one G2 :class:`~spiral_cad.Chain` plus a stationing table.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, cast

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..core import _kernels as K
from ..core import batch
from ..core.bezier import peak_curvature_rate
from ..core.chain import JOIN_TOLERANCE, Chain, PartCircles, join_rows, join_tolerance
from ..core.errors import JointError, NoSolutionError
from ..core.factors import WALTON_MEEK_SEARCH_MAX, length_factor, peak_rate_factor, search_range
from ..core.fit import PointFit
from ..core.inputs import as_float, as_points, as_real_array, per_item
from ..core.kinds import SPIRAL
from ..core.rows import SegmentRows
from ..core.segments import Circle, Ray
from ..core.shapes import SHAPE_CODES, TRANSITION_SHAPES, shape_code, shape_limits
from ..core.spiral import BezierSpiral, turn_angles
from ..core.transitions import Transition
from ..core.units import COLLINEAR_TOL, DEFAULT_UNITS, length_unit, speed_unit
from .criteria import CRITERIA_DIMENSIONS, Criteria, CriteriaRow, RailCriteria, RoadCriteria
from .fitting import fit_alignment
from .tables import text_table, write_csv

#: |sin(deflection)| at or below this counts as a straight PI.
#: Smallest θ searched when a spiral length is requested.
_THETA_MIN = 1e-7


def theta_for_length(length: float, radius: float, shape: str = "walton-meek") -> float:
    """The θ whose spiral of ``shape`` with end radius ``radius`` has arc length ``length``.

    Length grows monotonically with θ for a fixed radius (and is
    proportional to the radius), so a bracketed 1-D root gives θ
    (``thetas_for_lengths`` for many at once).

    Raises:
        NoSolutionError: ``length`` outside the reachable range.
    """
    theta = float(thetas_for_lengths([length], [radius], shape)[0])
    if math.isnan(theta):
        lo, hi = _length_bracket(shape)
        low, high = (radius * float(length_factor(t, shape)) for t in (lo, hi))
        raise NoSolutionError(
            f"spiral length {length:.6g} is outside the range a spiral onto radius {radius:.6g} can have ({low:.3g} … {high:.3g})"
        )
    return theta


def _length_bracket(shape: str) -> tuple[float, float]:
    """The θ range searched for a spiral length: from ``_THETA_MIN`` to the shape's largest angle."""
    largest = shape_limits(shape)["theta"]
    return _THETA_MIN, largest * (1.0 - 1e-9) if largest == math.pi / 2 else largest


def thetas_for_lengths(lengths: ArrayLike, radii: ArrayLike, shape: str = "walton-meek") -> NDArray:
    """``theta_for_length`` for arrays (broadcast): θ with ℓ(θ)·r = length, NaN where out of range.

    Illinois regula falsi on the bracket of ``_length_bracket``, vectorised
    over the rows still moving (ℓ(θ) is smooth and monotone: about eight
    evaluations of ``length_factor`` per row), to |Δθ| ≤ 1e-16 + 1e-15·θ.
    """
    lengths, radii = np.broadcast_arrays(np.asarray(lengths, dtype=float), np.asarray(radii, dtype=float))
    target = (lengths / radii).ravel()
    lo_t, hi_t = _length_bracket(shape)
    lo, hi = np.full(target.shape, lo_t), np.full(target.shape, hi_t)
    with np.errstate(invalid="ignore"):
        f_lo = length_factor(lo_t, shape) - target
        f_hi = length_factor(hi_t, shape) - target
        theta = np.full(target.shape, np.nan)
        active = np.flatnonzero((f_lo < 0.0) & (f_hi > 0.0))
        side = np.zeros(target.shape, dtype=np.int8)
        for _ in range(200):
            if not len(active):
                break
            a, b, fa, fb = lo[active], hi[active], f_lo[active], f_hi[active]
            x = np.clip(b - fb * (b - a) / (fb - fa), a, b)
            fx = length_factor(x, shape) - target[active]
            below, above = fx < 0.0, fx > 0.0
            # Illinois: halve the value at the end that stays, so both ends converge.
            f_hi[active] = np.where(below, np.where(side[active] == -1, fb / 2.0, fb), np.where(above, fx, fb))
            f_lo[active] = np.where(above, np.where(side[active] == 1, fa / 2.0, fa), np.where(below, fx, fa))
            lo[active] = np.where(below, x, a)
            hi[active] = np.where(above, x, b)
            side[active] = np.where(below, -1, np.where(above, 1, 0))
            done = (~below & ~above) | (hi[active] - lo[active] <= 1e-16 + 1e-15 * x)
            theta[active[done]] = x[done]
            active = active[~done]
    return theta.reshape(lengths.shape)


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

    def row(self) -> dict[str, Any]:
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
        curves: one ``CurveData`` per interior PI (a ``CurveList``: a sequence made when read).
        start_station: chainage of the first PI.
        criteria: the design criteria the curves were chosen or checked by, if any.
        checks: one ``CriteriaRow`` per curve when there are criteria.
        shape: the spiral shape of every transition (``"near-linear"`` or ``"walton-meek"``).
        point_fit: ``Alignment.fit``: the ``PointFit`` of the points the curves were read from
            (its residuals, stations and point-wise ``curvature_estimate``); None otherwise.
    """

    chain: Chain
    curves: Sequence[CurveData]
    start_station: float = 0.0
    criteria: Criteria | None = None
    checks: tuple[CriteriaRow, ...] = ()
    shape: str = "near-linear"
    point_fit: PointFit | None = field(default=None, compare=False, repr=False)

    @classmethod
    def fit(
        cls,
        points: ArrayLike,
        tolerance: float,
        design_speed: float | None = None,
        *,
        units: str = DEFAULT_UNITS,
        shape: str = "near-linear",
        start_station: float = 0.0,
        max_jerk: float | None = None,
        criteria: Criteria | None = None,
        progress: Any = None,
    ) -> Alignment:
        """The alignment through measured plan points: ``spiral_cad.fit_points`` read as curves.

        The points (a survey or GPS trace of an existing road, a centre line from a map) are
        fitted within ``tolerance`` by tangents, spirals and arcs; the PIs are where the fitted
        tangents meet, each curve keeps its fitted radius and spiral angles, and the alignment is
        built from them by ``from_pis`` (with ``design_speed``, its ``checks`` say which fitted
        curves meet the road criteria) and measured against the points again.

        Args:
            points: (N, 2) plan points in travel order, in ``units``.
            tolerance: the largest distance of any point to the alignment.
            design_speed, max_jerk, criteria: as ``from_pis`` (judged, never enforced).
            units, shape, start_station: as ``from_pis``.
            progress: ``progress(done, total)`` (``fit_points``).

        Raises:
            ValueError: malformed points or tolerance (``fit_points``).
            NoSolutionError: the points double back, the fit is not tangent–spiral–arc–spiral–tangent
                at every curve (naming the segment), or the rebuilt alignment misses a point (naming it).
        """
        return fit_alignment(cls, points, tolerance, design_speed, units=units, shape=shape, start_station=start_station,
                             max_jerk=max_jerk, criteria=criteria, progress=progress)  # fmt: skip

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
        shortest: NDArray | None  # spiral angle bounds per curve, when the criteria choose the spirals
        longest: NDArray | None
        if spiral_angles is None and spiral_lengths is None:
            if criteria is None:
                raise ValueError("give spiral_angles or spiral_lengths, or design criteria (design_speed) to choose them")
            shortest, longest = _choose(criteria, radius, units, shape)
            spec = np.stack([shortest, shortest], axis=1)
        else:
            shortest = longest = None
            spec = _sides(spiral_lengths if by_length else spiral_angles, count, "spiral_lengths" if by_length else "spiral_angles")

        solved = _solve_curves(pts, directions, radius, spec, by_length, shortest, longest, criteria, units, shape)
        _check_tangents(pts, lengths, directions, solved)
        tolerance = join_tolerance(tolerance)
        try:
            chain = join_rows(*_chain_rows(solved, shape), tuple(pts[0].tolist()), tuple(pts[-1].tolist()), tolerance, units)
        except JointError as error:
            assert error.part is not None  # join_rows names the part
            raise NoSolutionError(f"PI {error.part // 2 + 1}: float64 cannot hold its curve G2 at these coordinates: {error}") from None
        curves = CurveList(chain, pts, solved, radius, origin, shape)
        checks = () if criteria is None else _judge(curves, criteria, units, shortest, longest, strict, shape)
        return cls(chain, curves, origin, criteria, checks, shape)

    # ------------------------------------------------------- table

    def rows(self) -> list[dict[str, Any]]:
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
        assert self.criteria is not None  # checks come only with criteria
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


class _FirstProblem:
    """The error the PIs raise, in PI order and, within a PI, in the order the checks run."""

    def __init__(self) -> None:
        self.found: tuple[int, float, Any] | None = None

    def flag(self, failing: NDArray, step: float, make) -> None:
        """Record ``make(j)`` (an exception) for the first PI index j where ``failing`` holds."""
        hit = np.flatnonzero(failing)
        if len(hit) and (self.found is None or (int(hit[0]), step) < self.found[:2]):
            self.found = (int(hit[0]), step, make)

    def raise_first(self) -> None:
        if self.found is not None:
            j, _, make = self.found
            raise make(j)


@dataclass(frozen=True)
class _Solved:
    """Every PI's curve as arrays: deflection, centre, the spirals' θ and control points (N, 4, 2)
    in travel order (the exit reversed), the entry/exit solvers' θ and the turn side."""

    deflection: NDArray
    center: NDArray
    side: NDArray
    radius: NDArray
    entry: NDArray
    exit: NDArray
    theta: NDArray
    directions: NDArray


def _solve_curves(pts, directions, radius, spec, by_length, shortest, longest, criteria, units, shape) -> _Solved:
    """Every PI's centre and spirals in two batch calls (entry and exit); the first failing check raises."""
    count = len(radius)
    t_in, t_out = directions[:-1], directions[1:]
    sin_d = t_in[:, 0] * t_out[:, 1] - t_in[:, 1] * t_out[:, 0]
    cos_d = t_in[:, 0] * t_out[:, 0] + t_in[:, 1] * t_out[:, 1]
    deflection = np.array([math.atan2(y, x) for y, x in zip(sin_d.tolist(), cos_d.tolist())])
    problem = _FirstProblem()

    def straight(j: int) -> ValueError:
        what = "folds straight back" if cos_d[j] < 0.0 else "is collinear with its neighbours (zero deflection)"
        return ValueError(f"PI {j + 1} at {pts[j + 1].tolist()} {what}: no curve can be placed there")

    problem.flag(np.abs(sin_d) <= COLLINEAR_TOL, 0, straight)
    if shortest is not None:
        _check_choices(problem, radius, deflection, shortest, longest, criteria, units, shape)
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        if by_length:
            for k, side_name in enumerate(("entry", "exit")):
                problem.flag(~(spec[:, k] > 0.0), 1 + k, lambda j, k=k, n=side_name: ValueError(
                    f"PI {j + 1}: {n} spiral length must be positive; got {spec[j, k]}"))  # fmt: skip
            thetas = np.where(spec > 0.0, thetas_for_lengths(spec, radius[:, None], shape), np.nan)
            for k, side_name in enumerate(("entry", "exit")):
                problem.flag((spec[:, k] > 0.0) & np.isnan(thetas[:, k]), 3 + k, lambda j, k=k, n=side_name: _length_error(
                    j, n, spec[j, k], radius[j], shape))  # fmt: skip
        else:
            thetas = spec
            for k, side_name in enumerate(("entry", "exit")):
                problem.flag(~((thetas[:, k] > 0.0) & (thetas[:, k] < math.pi / 2)), 1 + k, lambda j, k=k, n=side_name: ValueError(
                    f"PI {j + 1}: {n} spiral angle must lie in (0, π/2); got {spec[j, k]}"))  # fmt: skip
        sweep = np.abs(deflection) - thetas[:, 0] - thetas[:, 1]
        problem.flag(sweep < -1e-12, 5, lambda j: NoSolutionError(
            f"PI {j + 1}: deflection {math.degrees(abs(deflection[j])):.6g}° is smaller than "
            f"θ_in + θ_out = {math.degrees(thetas[j, 0]):.6g}° + {math.degrees(thetas[j, 1]):.6g}°: the circular arc "
            f"would have negative sweep {math.degrees(sweep[j]):.4g}°; use shorter spirals or a smaller radius"))  # fmt: skip
        # Theorem 4.1: offset d = r·g1(θ) of the centre from each tangent.
        side = np.copysign(1.0, deflection)
        offsets = radius[:, None] * _g1(thetas, shape)
        normals = side[:, None, None] * np.stack([np.stack([-t_in[:, 1], t_in[:, 0]], 1), np.stack([-t_out[:, 1], t_out[:, 0]], 1)], 1)
        usable = np.isfinite(offsets).all(axis=1) & (np.abs(sin_d) > COLLINEAR_TOL)
        center = np.full((count, 2), np.nan)
        if usable.any():
            center[usable] = pts[1:-1][usable] + np.linalg.solve(normals[usable], offsets[usable][..., None])[..., 0]
    entry = batch.line_to_circle(pts[1:-1], t_in, center, radius, shape=shape)
    exit_ = batch.line_to_circle(pts[1:-1], -t_out, center, radius, shape=shape)
    for step, result in ((6, entry), (7, exit_)):
        problem.flag(~result.ok, step, lambda j, result=result: _solver_error(j, result))
    problem.raise_first()
    spirals_out = exit_.spirals[0][:, ::-1]
    return _Solved(deflection, center, side, radius, entry.spirals[0], spirals_out, np.stack([entry.theta, exit_.theta], 1), directions)


def _g1(thetas: NDArray, shape: str) -> NDArray:
    """g1(θ) of every spiral angle (math.sin/cos per value: the same bits as the scalar solvers)."""
    flat = thetas.ravel().tolist()
    sin_t = np.array([math.sin(t) for t in flat])
    cos_t = np.array([math.cos(t) for t in flat])
    e1 = np.empty(len(flat))
    K.shape_offsets_batch(SHAPE_CODES[shape], sin_t, cos_t, e1, np.empty(len(flat)))
    return (1.0 + sin_t * sin_t * e1).reshape(thetas.shape)


def _solver_error(j: int, result: batch.BatchResult) -> ValueError:
    error = result.error(j)
    return NoSolutionError(f"PI {j + 1}: {error}") if isinstance(error, NoSolutionError) else error


def _length_error(j: int, side: str, length: float, radius: float, shape: str) -> NoSolutionError:
    try:
        theta_for_length(length, radius, shape)
    except NoSolutionError as error:
        return NoSolutionError(f"PI {j + 1}: {side} {error}")
    return NoSolutionError(f"PI {j + 1}: {side} spiral length {length:.6g} has no spiral angle")


def _check_choices(problem: _FirstProblem, radius, deflection, shortest, longest, criteria: Criteria, units: str, shape: str) -> None:
    """Flag, naming the PI and the numbers, the curves where no spiral meets every criterion."""
    length = lambda theta, r: float(length_factor(theta, shape) * r)  # noqa: E731
    speed = f"{criteria.design_speed:g} {speed_unit(units)}"
    problem.flag(np.isnan(shortest), 0.1, lambda j: NoSolutionError(
        f"PI {j + 1}: no spiral onto R = {radius[j]:.6g} {units} ({shape}, up to θ = {math.degrees(search_range(shape)[1]):.3g}°) "
        f"meets the criteria at {speed}; use a larger radius"))  # fmt: skip
    with np.errstate(invalid="ignore"):
        conflict = shortest > longest * (1 + 1e-12)
        narrow = ~conflict & (2.0 * shortest > np.abs(deflection))
    problem.flag(conflict, 0.2, lambda j: NoSolutionError(
        f"PI {j + 1}: the criteria conflict at R = {radius[j]:.6g} {units}: the rate limits need spirals of at least "
        f"{length(shortest[j], radius[j]):.6g} {units} (θ ≥ {math.degrees(shortest[j]):.4g}°), the shift limit allows at most "
        f"{length(longest[j], radius[j]):.6g} {units} (θ ≤ {math.degrees(longest[j]):.4g}°); use a larger radius or relax the limits"))  # fmt: skip
    problem.flag(narrow, 0.3, lambda j: NoSolutionError(
        f"PI {j + 1}: the shortest spirals that meet the criteria turn 2 × {math.degrees(shortest[j]):.4g}° but the "
        f"deflection is only {math.degrees(abs(deflection[j])):.4g}°; use a larger radius"))  # fmt: skip


def _check_tangents(pts: NDArray, lengths: NDArray, directions: NDArray, solved: _Solved) -> None:
    """Each tangent must hold the ST of one curve before the TS of the next (§5)."""
    inner = pts[1:-1]
    back = np.concatenate([[0.0], np.einsum("ij,ij->i", inner - solved.entry[:, 0], directions[:-1])])
    ahead = np.concatenate([np.einsum("ij,ij->i", solved.exit[:, 3] - inner, directions[1:]), [0.0]])
    used_all = np.concatenate([[0.0], ahead[:-1]])  # ST of the curve before tangent k
    used_next_all = np.concatenate([back[1:], [0.0]])  # TS of the curve after it
    over = np.flatnonzero(used_all + used_next_all > lengths * (1.0 + 1e-12))
    if not len(over):
        return
    k, last = int(over[0]), len(pts) - 1
    used, used_next, length = float(used_all[k]), float(used_next_all[k]), float(lengths[k])
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
        f"{where}; together {used + used_next:.6g} > tangent length {length:.6g}. Move the PIs apart, or reduce the radii or spiral lengths"
    )


def _chain_rows(solved: _Solved, shape: str) -> tuple[SegmentRows, NDArray, PartCircles]:
    """The parts of the alignment's ``Chain.join``: entry and exit spiral of every PI, the entry
    ending on the PI's circle (the arc between them follows from it)."""
    count = len(solved.entry)
    spirals = np.empty((2 * count, 4, 2))
    spirals[0::2], spirals[1::2] = solved.entry, solved.exit
    circles = PartCircles(2 * count)
    circles.present[0::2] = True
    circles.center[0::2, :2] = solved.center
    circles.radius[0::2] = solved.side * solved.radius
    return SegmentRows.spirals(spirals, shape), np.ones(2 * count, dtype=np.int64), circles


class CurveList(Sequence):
    """The curves of an alignment, one ``CurveData`` per interior PI, made when read (a long
    alignment is built as arrays; its curve records cost nothing until a table asks for them).

    Attributes (arrays over the curves): ``radius``, ``thetas`` (N, 2), ``lengths`` (N, 2),
    ``peak_rates`` (N, 2) — what the criteria judge, measured on the chain's spirals.
    """

    def __init__(self, chain: Chain, pts: NDArray, solved: _Solved, radius: NDArray, origin: float, shape: str):
        spiral_rows = np.flatnonzero(chain.rows.kind == SPIRAL)
        self._chain, self._pts, self._solved, self._shape = chain, pts, solved, shape
        self._first, self._last = spiral_rows[0::2], spiral_rows[1::2]
        stations = origin + chain.stations
        self._stations = np.stack([stations[self._first], stations[self._first + 1], stations[self._last], stations[self._last + 1]], 1)
        self.radius = radius
        self.lengths = np.stack([chain.lengths[self._first], chain.lengths[self._last]], 1)
        self.thetas = np.abs(np.stack([turn_angles(solved.entry), turn_angles(solved.exit)], 1))
        self.peak_rates = _peak_rates(self.thetas, radius, np.stack([solved.entry, solved.exit], 1), shape)
        self._made: list[CurveData | None] = [None] * len(radius)

    def __len__(self) -> int:
        return len(self._made)

    def __getitem__(self, index):
        if isinstance(index, slice):
            return [self[j] for j in range(*index.indices(len(self)))]
        curve = self._made[index]
        if curve is None:
            curve = self._made[index] = self._curve(range(len(self))[index])
        return curve

    def __eq__(self, other: object) -> bool:
        return list(self) == list(other) if isinstance(other, Sequence) else NotImplemented

    def __repr__(self) -> str:
        return f"CurveList({len(self)} curves)"

    def _curve(self, j: int) -> CurveData:
        solved, chain, shape = self._solved, self._chain, self._shape
        i = j + 1
        pi = tuple(self._pts[i].tolist())
        center = tuple(solved.center[j].tolist())
        circle = Circle(center, float(solved.side[j] * self.radius[j]))
        t_in, t_out = (tuple(solved.directions[k].tolist()) for k in (j, j + 1))
        entry = Transition("line-circle", [cast(BezierSpiral, chain[int(self._first[j])])], float(solved.theta[j, 0]), end_circle=circle,
                           start_line=Ray(pi, t_in), shape=shape)  # fmt: skip
        exit_ = Transition("circle-line", [cast(BezierSpiral, chain[int(self._last[j])])], float(solved.theta[j, 1]), start_circle=circle,
                           end_line=Ray(pi, t_out), shape=shape)  # fmt: skip
        ts, sc, cs, st = self._stations[j].tolist()
        (theta_in, theta_out), (length_in, length_out), (rate_in, rate_out) = (
            a[j].tolist() for a in (self.thetas, self.lengths, self.peak_rates)
        )
        return CurveData(i, pi, float(solved.deflection[j]), float(self.radius[j]), center, theta_in, theta_out, length_in,
                         length_out, float(self._stations[j, 2] - self._stations[j, 1]), ts, sc, cs, st, rate_in, rate_out,
                         entry, exit_)  # fmt: skip


def _peak_rates(thetas: NDArray, radius: NDArray, spirals: NDArray, shape: str) -> NDArray:
    """Peak |dκ/ds| of every spiral (N, 2): F(θ)/R² (``factors.peak_rate_factor``) — the spirals are
    full spirals of ``shape`` onto R — and measured (``peak_curvature_rate``) where F is not tabulated
    (the 1996 spiral beyond 80°)."""
    with np.errstate(over="ignore", divide="ignore", invalid="ignore"):  # 1/R² beyond float64 is inf
        rates = peak_rate_factor(thetas, shape) / (radius * radius)[:, None]
        if shape == "walton-meek":
            measured = thetas > WALTON_MEEK_SEARCH_MAX
            if measured.any():
                rates[measured] = peak_curvature_rate(spirals[measured])[0]
    return rates


def _choose(criteria: Criteria, radii: NDArray, units: str, shape: str) -> tuple[NDArray, NDArray]:
    """``criteria.choose`` once per distinct radius (a road has few), spread to every curve."""
    unique, inverse = np.unique(radii, return_inverse=True)
    shortest, longest = criteria.choose(unique, units, shape)
    return shortest[inverse], longest[inverse]


def _judge(curves: CurveList, criteria: Criteria, units: str, shortest, longest, strict: bool, shape: str) -> tuple[CriteriaRow, ...]:
    """The criteria row of every curve; with ``strict`` any violation raises."""
    radii = curves.radius
    if shortest is None:
        shortest, longest = _choose(criteria, radii, units, shape)
    largest = search_range(shape)[1]
    # The length bounds: ℓ(θ)·R for each distinct (θ, R) (one quadrature for all).
    both = np.stack([np.nan_to_num(shortest, nan=largest), np.nan_to_num(longest, nan=largest)], axis=1)
    pairs, inverse = np.unique(both, axis=0, return_inverse=True)
    bounds = (length_factor(pairs, shape)[inverse.ravel()]) * radii[:, None]
    index = np.arange(1, len(radii) + 1)
    rows = tuple(criteria.evaluate(index, radii, curves.thetas, units, bounds, curves.lengths, curves.peak_rates, shape))
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
