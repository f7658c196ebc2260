"""Road and rail design criteria from a design speed, judged on the real Bézier spiral.

The clothoid rule L = v³/(R·C) assumes that curvature grows linearly with arc
length. A Bézier spiral's curvature does not: its peak dκ/ds is up to ~1.84×
its mean (small θ), so the lateral jerk v³·dκ/ds peaks higher for the same
length. Every criterion here is evaluated on the actual spiral — its peak
dκ/ds, its length and the shift p = r·(g1(θ) − 1) of its circle — and the
spiral chosen for a curve is the shortest that meets all of them.

Units: speeds are km/h for metric designs (mm, cm, m, km) and mph for in/ft;
lengths (radii, shifts) are in the design's unit; the jerk limit is m/s³;
cant values are mm. Everything is converted to SI inside.

Road defaults (each overridable):

* side friction f by design speed after AASHTO's Green Book (Table 3-7,
  limiting values for open highways and streets), interpolated linearly;
* maximum superelevation e_max = 0.08; the superelevation of a curve is
  proportional to its curvature and reaches e_max at R_min (AASHTO's
  method 1): e = e_max·R_min/R;
* maximum rate of change of lateral acceleration C = 0.6 m/s³ (Shortt's
  2 ft/s³; the usual range is 0.3 – 0.9);
* shift bounds p_min = 0.2 m, p_max = 1.0 m.

R_min = V²/(127(e_max + f)) with V in km/h and R in m, or V²/(15(e_max + f))
with V in mph and R in ft.

Rail defaults, after EN 13803-1's recommended limits for conventional lines
(check them against the standard's table for your speed band; each is
overridable): applied cant ≤ 160 mm, cant deficiency ≤ 130 mm, rate of
change of cant ≤ 50 mm/s, rate of change of cant deficiency ≤ 55 mm/s, cant
gradient ≤ 2.25 mm/m, rail-centre distance 1500 mm (standard gauge). The
equilibrium cant is E = G·v²/(g·R); the applied cant D = min(E, cant_max)
ramps along the spiral as a cubic ease (``superelevation``: C1 at both ends,
steepest at mid-spiral with 1.5·D/L, where the cant rate and gradient are
judged), and the cant deficiency I(s) = G·v²·κ(s)/g − D(s) changes at
v·|dI/ds| ≤ v·max(G·v²/g·max dκ/ds, 1.5·D/L), the peak of dκ/ds taken on the
real spiral.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass
from typing import Any, cast

import numpy as np
from numpy.typing import NDArray

from ..core.factors import length_factor, peak_rate_factor, search_range, shift_factor
from ..core.inputs import as_float, shown
from ..core.units import FOOT, IMPERIAL, speed_unit, to_metres

GRAVITY = 9.80665
#: The applied cant ramps along each spiral as the cubic ease D·(3t² − 2t³) of
#: ``superelevation`` (C1 at both ends); its steepest slope, at mid-spiral, is
#: 1.5× the mean D/L, and the rail rates are judged there.
RAMP_PEAK_SLOPE = 1.5
KMH = 1.0 / 3.6
MPH = 0.44704

#: AASHTO Green Book, Table 3-7: limiting side friction factor f by design speed.
SIDE_FRICTION_KMH = ((15, 0.40), (20, 0.35), (30, 0.28), (40, 0.23), (50, 0.19), (60, 0.17), (70, 0.15),
                     (80, 0.14), (90, 0.13), (100, 0.12), (110, 0.11), (120, 0.09), (130, 0.08))  # fmt: skip
SIDE_FRICTION_MPH = ((10, 0.38), (15, 0.32), (20, 0.27), (25, 0.23), (30, 0.20), (35, 0.18), (40, 0.16),
                     (45, 0.15), (50, 0.14), (55, 0.13), (60, 0.12), (65, 0.11), (70, 0.10), (75, 0.09),
                     (80, 0.08))  # fmt: skip


def _smallest_theta(ok, count: int, theta_range: tuple[float, float]) -> NDArray:
    """Vectorised bisection: for each of ``count`` curves the smallest θ in ``theta_range`` with
    ``ok(θ)`` true (``ok`` is monotone: false below, true above); NaN where even the largest θ fails."""
    lo = np.full(count, theta_range[0])
    hi = np.full(count, theta_range[1])
    feasible = ok(hi)
    done = ok(lo)
    for _ in range(64):  # in log θ: the bracket ends within 1e-15 relative
        mid = np.sqrt(lo * hi)
        good = ok(mid)
        hi = np.where(good, mid, hi)
        lo = np.where(good, lo, mid)
    return np.where(done, theta_range[0], np.where(feasible, hi, np.nan))


def _pair(values: Any) -> tuple[float, float]:
    """An (in, out) pair of plain floats."""
    return cast("tuple[float, float]", tuple(map(float, values)))


@dataclass(frozen=True)
class CriteriaRow:
    """The criteria at one PI: what was required, what the curve has, and the verdict.

    Lengths are in the design's unit, speeds in its speed unit, jerk in m/s³
    (roads) or cant-deficiency rate in mm/s (rail). ``banking`` is the
    superelevation e (roads, m/m) or the applied cant (rail, mm), and
    ``cross_slope`` the same as a slope (cant over the rail-centre distance).
    """

    pi: int
    radius: float
    minimum_radius: float
    spiral_lengths: tuple[float, float]
    length_bounds: tuple[float, float]
    shifts: tuple[float, float]
    peak_rates: tuple[float, float]
    limit: float
    banking: float
    cross_slope: float
    violations: tuple[str, ...] = ()
    quantity: str = "peak lateral jerk"
    rate_unit: str = "m/s³"
    shape: str = "near-linear"

    @property
    def ok(self) -> bool:
        return not self.violations

    def row(self) -> dict[str, Any]:
        """The table row: Python numbers, and the verdict as text."""
        values = {
            "radius": self.radius,
            "R_min": self.minimum_radius,
            "L_in": self.spiral_lengths[0],
            "L_out": self.spiral_lengths[1],
            "L_min": self.length_bounds[0],
            "L_max": self.length_bounds[1],
            "p_in": self.shifts[0],
            "p_out": self.shifts[1],
            f"{self.quantity.replace(' ', '_')}_in": self.peak_rates[0],
            f"{self.quantity.replace(' ', '_')}_out": self.peak_rates[1],
            "limit": self.limit,
            "banking": self.banking,
        }
        verdict = "ok" if self.ok else "; ".join(self.violations)
        numbers = {key: float(value) for key, value in values.items()}
        return {"pi": int(self.pi), **numbers, "spiral_shape": self.shape, "verdict": verdict}


@dataclass(frozen=True)
class _Criteria(ABC):
    """What road and rail criteria share: a design speed and the spiral search."""

    design_speed: float

    def __post_init__(self) -> None:
        speed = as_float(self.design_speed, "design_speed")
        if not speed > 0:
            raise ValueError(f"design_speed must be positive; got {speed!r}")
        object.__setattr__(self, "design_speed", speed)  # a plain float (not numpy) in tables and messages

    def _set_floats(self, names: tuple[str, ...], positive: bool) -> None:
        """Each field in ``names`` (None skipped) as a plain float, > 0 (``positive``) or ≥ 0, else ValueError."""
        for name in names:
            value = getattr(self, name)
            if value is None:
                continue
            number = as_float(value, name)
            if not (number > 0.0 if positive else number >= 0.0):
                raise ValueError(f"{name} must be {'positive' if positive else '≥ 0'}; got {shown(value)}")
            object.__setattr__(self, name, number)

    def speed(self, units: str) -> float:
        """The design speed in m/s (given in km/h for metric designs, mph for in/ft)."""
        return self.design_speed * (MPH if units in IMPERIAL else KMH)

    @abstractmethod
    def _lower_ok(self, theta: NDArray, radius: NDArray, units: str, shape: str) -> NDArray:
        """Whether spirals θ of ``shape`` onto ``radius`` meet every criterion that a longer spiral meets too."""

    @abstractmethod
    def _upper_ok(self, theta: NDArray, radius: NDArray, units: str, shape: str) -> NDArray:
        """Whether spirals θ of ``shape`` meet every criterion that a shorter spiral meets too."""

    @abstractmethod
    def minimum_radius(self, units: str) -> float:
        """R_min in the design's unit."""

    @abstractmethod
    def evaluate(self, pis, radii, thetas, units: str, bounds, lengths, peak_rates, shape: str) -> list[CriteriaRow]:
        """The criteria rows of curves at PIs ``pis`` (N,) onto ``radii`` (N,) with entry and exit
        spiral angles ``thetas`` (N, 2) of ``shape``, the length ``bounds`` (N, 2) the criteria allow, and the
        spirals' measured ``lengths`` (N, 2, design units) and ``peak_rates`` of dκ/ds (N, 2, 1/unit²)."""

    @np.errstate(over="ignore", divide="ignore", invalid="ignore")  # inf/NaN fail the bounds; no warnings
    def choose(self, radii: NDArray, units: str, shape: str = "near-linear") -> tuple[NDArray, NDArray]:
        """The shortest spiral angle of ``shape`` meeting every lower bound, and the longest
        meeting every upper bound, for each radius (NaN where none exists).

        Angles are searched in ``core.factors.search_range(shape)``, where a longer
        spiral never has a higher peak dκ/ds."""
        radii = np.asarray(radii, dtype=float)
        theta_range = search_range(shape)
        shortest = _smallest_theta(lambda t: self._lower_ok(t, radii, units, shape), len(radii), theta_range)
        longest_fails = _smallest_theta(lambda t: ~self._upper_ok(t, radii, units, shape), len(radii), theta_range)
        longest = np.where(np.isnan(longest_fails), theta_range[1], longest_fails)
        return shortest, longest

    @staticmethod
    def _shifts(theta: NDArray, radius: NDArray, shape: str) -> NDArray:
        """The shift p = r·(g1(θ) − 1) of each spiral's circle off its tangent (design units; Theorem 4.1).

        p grows with θ, so the shift bounds are bounds on θ."""
        return radius * shift_factor(theta, shape)


@dataclass(frozen=True)
class RoadCriteria(_Criteria):
    """Road criteria (see the module docstring); ``None`` fields take the documented defaults.

    Args:
        design_speed: V, km/h (metric designs) or mph (in/ft).
        max_jerk: C, the largest rate of change of lateral acceleration, m/s³.
        superelevation_max: e_max (m/m).
        side_friction: f; default from AASHTO's table by speed.
        shift_min, shift_max: bounds of the shift p of each circle, in the
            design's unit (default 0.2 m and 1.0 m).
    """

    max_jerk: float = 0.6
    superelevation_max: float = 0.08
    side_friction: float | None = None
    shift_min: float | None = None
    shift_max: float | None = None

    def __post_init__(self) -> None:
        super().__post_init__()
        self._set_floats(("max_jerk", "superelevation_max"), positive=True)
        self._set_floats(("side_friction", "shift_min", "shift_max"), positive=False)

    def friction(self, units: str) -> float:
        """f: given, or AASHTO's table value at the design speed (linear between rows)."""
        if self.side_friction is not None:
            return float(self.side_friction)
        table = SIDE_FRICTION_MPH if units in IMPERIAL else SIDE_FRICTION_KMH
        speeds, values = zip(*table)
        if not speeds[0] <= self.design_speed <= speeds[-1]:
            raise ValueError(
                f"design_speed {self.design_speed:g} {speed_unit(units)} is outside the side friction table "
                f"({speeds[0]}–{speeds[-1]} {speed_unit(units)}); give side_friction"
            )
        return float(np.interp(self.design_speed, speeds, values))

    def minimum_radius(self, units: str) -> float:
        """R_min in the design's unit."""
        e_f = self.superelevation_max + self.friction(units)
        if units in IMPERIAL:
            return self.design_speed * self.design_speed / (15.0 * e_f) * FOOT / to_metres(units)
        return self.design_speed * self.design_speed / (127.0 * e_f) / to_metres(units)

    def superelevation(self, radius: float | NDArray, units: str) -> float | NDArray:
        """e = e_max·R_min/R, at most e_max (AASHTO's method 1); one radius or an array of them."""
        e = np.minimum(self.superelevation_max, self.superelevation_max * self.minimum_radius(units) / np.asarray(radius, dtype=float))
        return float(e) if e.ndim == 0 else e

    def shifts(self, units: str) -> tuple[float, float]:
        metres = to_metres(units)
        low = 0.2 / metres if self.shift_min is None else float(self.shift_min)
        high = 1.0 / metres if self.shift_max is None else float(self.shift_max)
        return low, high

    def _jerk(self, theta: NDArray, radius: NDArray, units: str, shape: str) -> NDArray:
        v = self.speed(units)  # v·v·v: inf, not OverflowError, for a design speed of 1e300
        return v * v * v * peak_rate_factor(theta, shape) / (radius * to_metres(units)) ** 2

    def _lower_ok(self, theta, radius, units, shape):
        low = self.shifts(units)[0]
        return (self._jerk(theta, radius, units, shape) <= self.max_jerk) & (self._shifts(theta, radius, shape) >= low)

    def _upper_ok(self, theta, radius, units, shape):
        return self._shifts(theta, radius, shape) <= self.shifts(units)[1]

    @np.errstate(over="ignore", divide="ignore", invalid="ignore")  # inf/NaN rates are violations (``not x <= limit``)
    def evaluate(self, pis, radii, thetas, units: str, bounds, lengths, peak_rates, shape) -> list[CriteriaRow]:
        radii = np.asarray(radii, dtype=float)
        shifts = self._shifts(np.asarray(thetas), radii[:, None], shape)
        v = self.speed(units)
        jerks = v * v * v * np.asarray(peak_rates) / to_metres(units) ** 2
        low, high = self.shifts(units)
        r_min = self.minimum_radius(units)
        banking = cast(NDArray, self.superelevation(radii, units)).tolist()  # radii is 1-D: an array back
        rows = []
        columns = (np.asarray(a, dtype=float).tolist() for a in (radii, lengths, shifts, jerks, bounds))  # plain floats: cheap rows
        for pi, radius, length, shift, jerk, bound, e in zip(pis, *columns, banking):
            violations = [f"R = {radius:.6g} < R_min = {r_min:.6g}"] if not radius >= r_min * (1 - 1e-12) else []
            for side, j, p in zip(("in", "out"), jerk, shift):
                if not j <= self.max_jerk * (1 + 1e-9):
                    violations.append(f"{side}: peak jerk {j:.4g} m/s³ > C = {self.max_jerk:g}")
                if not p >= low * (1 - 1e-9):
                    violations.append(f"{side}: shift p = {p:.4g} < p_min = {low:.4g}")
                if not p <= high * (1 + 1e-9):
                    violations.append(f"{side}: shift p = {p:.4g} > p_max = {high:.4g}")
            rows.append(CriteriaRow(int(pi), float(radius), r_min, _pair(length), _pair(bound),
                                    _pair(shift), _pair(jerk), self.max_jerk, e, e, tuple(violations),
                                    shape=shape))  # fmt: skip
        return rows


@dataclass(frozen=True)
class RailCriteria(_Criteria):
    """Rail criteria (see the module docstring); cant values in mm, rates in mm/s."""

    cant_max: float = 160.0
    cant_deficiency_max: float = 130.0
    cant_rate_max: float = 50.0
    cant_deficiency_rate_max: float = 55.0
    cant_gradient_max: float = 2.25
    gauge: float = 1500.0
    cant: float | None = None

    def __post_init__(self) -> None:
        super().__post_init__()
        limits = ("cant_max", "cant_deficiency_max", "cant_rate_max", "cant_deficiency_rate_max", "cant_gradient_max", "gauge")
        self._set_floats(limits, positive=True)
        self._set_floats(("cant",), positive=False)

    def minimum_radius(self, units: str) -> float:
        """R_min = G·v²/(g·(D_max + I_max)), in the design's unit."""
        metres = self.gauge * self.speed(units) * self.speed(units) / (GRAVITY * (self.cant_max + self.cant_deficiency_max))
        return metres / to_metres(units)

    def equilibrium_cant(self, radius: NDArray, units: str) -> NDArray:
        """E = G·v²/(g·R) in mm."""
        return self.gauge * self.speed(units) * self.speed(units) / (GRAVITY * np.asarray(radius) * to_metres(units))

    def applied_cant(self, radius: NDArray, units: str) -> NDArray:
        """D: the given cant, else min(E, cant_max), in mm."""
        if self.cant is not None:
            return np.full(np.shape(radius), float(self.cant))
        return np.minimum(self.equilibrium_cant(radius, units), self.cant_max)

    def _rates(self, theta: NDArray, radius: NDArray, units: str, shape: str, factors=None):
        """(cant rate, cant gradient, peak cant deficiency rate) of spirals θ onto radius, from
        their peak dκ/ds (1/m²) and length (m): the given ``factors``, else from F(θ), ℓ(θ)."""
        metres = np.asarray(radius) * to_metres(units)
        if factors is None:
            peak, length = peak_rate_factor(theta, shape) / metres**2, length_factor(theta, shape) * metres
        else:
            peak, length = factors
        v = self.speed(units)
        cant = self.applied_cant(radius, units)
        steepest = RAMP_PEAK_SLOPE * cant / length  # the cant's ramp at mid-spiral
        # dI/ds = (G v²/g)·dκ/ds − dD/ds with both rates ≥ 0: at most the larger of the two peaks
        deficiency_rate = v * np.maximum(self.gauge * v * v / GRAVITY * peak, steepest)
        return v * steepest, steepest, deficiency_rate

    def _lower_ok(self, theta, radius, units, shape):
        cant_rate, gradient, deficiency_rate = self._rates(theta, radius, units, shape)
        return (cant_rate <= self.cant_rate_max) & (gradient <= self.cant_gradient_max) & (deficiency_rate <= self.cant_deficiency_rate_max)

    def _upper_ok(self, theta, radius, units, shape):
        return np.ones(np.shape(theta), dtype=bool)

    @np.errstate(over="ignore", divide="ignore", invalid="ignore")  # inf/NaN rates are violations (``not x <= limit``)
    def evaluate(self, pis, radii, thetas, units: str, bounds, lengths, peak_rates, shape) -> list[CriteriaRow]:
        radii = np.asarray(radii, dtype=float)
        thetas = np.asarray(thetas)
        lengths = np.asarray(lengths)
        shifts = self._shifts(thetas, radii[:, None], shape)
        metres = to_metres(units)
        factors = (np.asarray(peak_rates) / metres**2, lengths * metres)
        cant_rates, gradients, deficiency_rates = self._rates(thetas, radii[:, None], units, shape, factors)
        cants = self.applied_cant(radii, units)
        deficiencies = self.equilibrium_cant(radii, units) - cants
        r_min = self.minimum_radius(units)
        limits = (("cant rate", self.cant_rate_max), ("cant gradient", self.cant_gradient_max),
                  ("cant deficiency rate", self.cant_deficiency_rate_max))  # fmt: skip
        rows = []
        for k, (pi, radius) in enumerate(zip(pis, radii)):
            violations = [f"R = {radius:.6g} < R_min = {r_min:.6g}"] if not radius >= r_min * (1 - 1e-12) else []
            if not deficiencies[k] <= self.cant_deficiency_max * (1 + 1e-9):
                violations.append(f"cant deficiency {deficiencies[k]:.4g} mm > {self.cant_deficiency_max:g}")
            for j, side in enumerate(("in", "out")):
                for values, (what, limit) in zip((cant_rates, gradients, deficiency_rates), limits):
                    if not values[k, j] <= limit * (1 + 1e-9):
                        violations.append(f"{side}: {what} {values[k, j]:.4g} > {limit:g}")
            rows.append(CriteriaRow(int(pi), float(radius), r_min, _pair(lengths[k]), _pair(bounds[k]),
                                    _pair(shifts[k]), _pair(deficiency_rates[k]),
                                    self.cant_deficiency_rate_max, float(cants[k]), float(cants[k]) / self.gauge,
                                    tuple(violations), "peak cant deficiency rate", "mm/s", shape))  # fmt: skip
        return rows


Criteria = RoadCriteria | RailCriteria

#: Dimension of each criteria-table column (``L`` the design's length unit).
CRITERIA_DIMENSIONS = {**dict.fromkeys(["radius", "R_min", "L_in", "L_out", "L_min", "L_max", "p_in", "p_out"], "L")}
