"""Vertical alignments: grades between points of vertical intersection (PVIs) and parabolic vertical curves.

A road's profile is given, like its plan, by points of intersection: PVIs
(station, elevation) joined by straight grades, and at every interior PVI a
parabolic vertical curve that turns one grade into the next. Stations are
the horizontal alignment's chainages (its ``start_station`` at the first PI),
so plan and profile share them.

* **Symmetric curves** of length L (half before the PVI, half after):
  elevation z = z_BVC + g1·x + (g2 − g1)·x²/(2L), x from the BVC.
* **Asymmetric curves** (L1 before, L2 after): two parabolas meeting below
  the PVI with the common grade g_m = (g1·L1 + g2·L2)/(L1 + L2), so the
  profile stays C1.
* **K** is the length per percent of grade change, K = L/|A| with A = g2 − g1
  in percent (AASHTO's rate of vertical curvature); for an asymmetric curve
  the smaller K of its two parabolas.

Every piece is a polynomial of degree ≤ 2 in station, kept exactly
(``Profile.pieces``): OpenDRIVE's ``elevation`` cubics and the 3-D centre
line are written from them.

With a design speed (``ProfileCriteria``, AASHTO Green Book, metric or US
customary by the design's unit):

* stopping sight distance SSD = 0.278·V·t + 0.039·V²/a (m, V in km/h) or
  1.47·V·t + 1.075·V²/a (ft, V in mph), t = 2.5 s, a = 3.4 m/s² (11.2 ft/s²);
* crest curves (eye 1.08 m, object 0.60 m): K_min = S²/658 (US: S²/2158);
* sag curves (headlights 0.60 m, 1° upward): K_min = S²/(120 + 3.5·S)
  (US: S²/(400 + 3.5·S));
* L = K·|A| (A in percent) at least K_min·|A| — the Green Book's design
  values, which take S < L — and at least 0.6·V m (3·V ft) for appearance;
* maximum grade by design speed and terrain after the Green Book's table for
  rural arterials (level, rolling, mountainous).

An asymmetric curve is judged by the K of its sharper parabola (conservative). Without ``curve_lengths`` or ``k_values``
each curve is the shortest that meets the criteria.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any, cast

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..core.errors import NoSolutionError
from ..core.inputs import as_float, as_points, as_real_array, per_item, shown
from ..core.piecewise import inside, piece_at, piecewise_at, polynomial
from ..core.units import DEFAULT_UNITS, FOOT, IMPERIAL, length_unit, speed_unit, to_metres
from .alignment import Alignment
from .fitting import fit_profile
from .tables import text_table, write_csv

#: AASHTO Green Book, rural arterials: maximum grade (%) by design speed for level, rolling and mountainous terrain
#: (level and rolling as TxDOT's Roadway Design Manual, Table 4-11, reproduces the US customary table).
MAX_GRADE_KMH = ((60, 5, 6, 8), (70, 5, 6, 7), (80, 4, 5, 7), (90, 4, 5, 6), (100, 3, 4, 6), (110, 3, 4, 5),
                 (120, 3, 4, 5), (130, 3, 4, 5))  # fmt: skip
MAX_GRADE_MPH = ((40, 5, 6, 8), (45, 5, 6, 7), (50, 4, 5, 7), (55, 4, 5, 6), (60, 3, 4, 6), (65, 3, 4, 5),
                 (70, 3, 4, 5), (75, 3, 4, 5), (80, 3, 4, 5))  # fmt: skip
TERRAINS = ("level", "rolling", "mountainous")


@dataclass(frozen=True)
class ProfileCriteria:
    """AASHTO's sight-distance and grade criteria for a vertical alignment (see the module docstring).

    Args:
        design_speed: V, km/h for metric designs, mph for in/ft.
        reaction_time: brake reaction time t (s).
        deceleration: a, m/s² (default 3.4 m/s²; US designs 11.2 ft/s²).
        terrain: ``"level"``, ``"rolling"`` or ``"mountainous"`` (for the maximum grade).
        max_grade: the largest grade as a fraction (default: the table's value).
        min_curve_length: the shortest vertical curve, in the design's unit
            (default 0.6·V m or 3·V ft).
    """

    design_speed: float
    reaction_time: float = 2.5
    deceleration: float | None = None
    terrain: str = "rolling"
    max_grade: float | None = None
    min_curve_length: float | None = None

    def __post_init__(self) -> None:
        for name in ("design_speed", "reaction_time"):
            if not as_float(getattr(self, name), name) > 0:
                raise ValueError(f"{name} must be positive; got {shown(getattr(self, name))}")
        for name in ("deceleration", "max_grade"):
            value = getattr(self, name)
            if value is not None and not as_float(value, name) > 0:
                raise ValueError(f"{name} must be positive; got {shown(value)}")
        if self.min_curve_length is not None and not as_float(self.min_curve_length, "min_curve_length") >= 0:
            raise ValueError(f"min_curve_length must be ≥ 0; got {shown(self.min_curve_length)}")
        if self.terrain not in TERRAINS:
            raise ValueError(f"terrain must be one of {', '.join(TERRAINS)}; got {self.terrain!r:.80}")

    def stopping_sight_distance(self, units: str) -> float:
        """SSD in the design's unit (AASHTO's metric or US form)."""
        v, t = float(self.design_speed), float(self.reaction_time)
        if units in IMPERIAL:
            a = 11.2 if self.deceleration is None else float(self.deceleration) / FOOT
            return (1.47 * v * t + 1.075 * v * v / a) * FOOT / to_metres(units)
        a = 3.4 if self.deceleration is None else float(self.deceleration)
        return (0.278 * v * t + 0.039 * v * v / a) / to_metres(units)

    def minimum_k(self, crest: bool, units: str) -> float:
        """K_min = S²/658 (crest) or S²/(120 + 3.5·S) (sag) — US 2158 and 400 + 3.5·S — in design units per percent."""
        native = FOOT if units in IMPERIAL else 1.0
        s = self.stopping_sight_distance(units) * to_metres(units) / native  # in AASHTO's own unit
        if units in IMPERIAL:
            k = s * s / (2158.0 if crest else 400.0 + 3.5 * s)
        else:
            k = s * s / (658.0 if crest else 120.0 + 3.5 * s)
        return k * native / to_metres(units)

    def minimum_length(self, difference: NDArray, units: str) -> NDArray:
        """The shortest curves for grade changes ``difference`` (A = g2 − g1 as fractions; negative:
        crest): L = K_min·|A| (A in percent), at least ``appearance_length``."""
        difference = np.asarray(difference, dtype=float)
        k = np.where(difference < 0.0, self.minimum_k(True, units), self.minimum_k(False, units))
        return np.maximum(k * 100.0 * np.abs(difference), self.appearance_length(units))

    def appearance_length(self, units: str) -> float:
        """The shortest curve for appearance: given, or 0.6·V m (3·V ft), in the design's unit."""
        if self.min_curve_length is not None:
            return float(self.min_curve_length)
        if units in IMPERIAL:
            return 3.0 * self.design_speed * FOOT / to_metres(units)
        return 0.6 * self.design_speed / to_metres(units)

    def grade_limit(self, units: str) -> float:
        """The largest grade (fraction): given, or the table's value at the design speed and terrain."""
        if self.max_grade is not None:
            return float(self.max_grade)
        table = MAX_GRADE_MPH if units in IMPERIAL else MAX_GRADE_KMH
        column = 1 + TERRAINS.index(self.terrain)
        speeds = [row[0] for row in table]
        if not speeds[0] <= self.design_speed <= speeds[-1]:
            raise ValueError(
                f"design_speed {self.design_speed:g} {speed_unit(units)} is outside the maximum grade table "
                f"({speeds[0]}–{speeds[-1]} {speed_unit(units)}); give max_grade"
            )
        # the table's value of the next lower tabulated speed (grades are steps, not interpolated)
        row = max(r for r in table if r[0] <= self.design_speed)
        return row[column] / 100.0


@dataclass(frozen=True)
class VerticalCurve:
    """The vertical curve at one interior PVI (lengths in the design's unit, grades as fractions).

    Attributes:
        index: the PVI's index.
        station, elevation: the PVI.
        grade_in, grade_out: the grades before and after.
        length_in, length_out: BVC→PVI and PVI→EVC (equal for a symmetric curve).
    """

    index: int
    station: float
    elevation: float
    grade_in: float
    grade_out: float
    length_in: float
    length_out: float

    @property
    def length(self) -> float:
        return self.length_in + self.length_out

    @property
    def difference(self) -> float:
        """A = g2 − g1 (fraction): negative for a crest, positive for a sag."""
        return self.grade_out - self.grade_in

    @property
    def kind(self) -> str:
        return "crest" if self.difference < 0 else "sag"

    @property
    def bvc(self) -> float:
        return self.station - self.length_in

    @property
    def evc(self) -> float:
        return self.station + self.length_out

    @property
    def middle_grade(self) -> float:
        """The grade below the PVI where the two parabolas of an asymmetric curve meet."""
        return (self.grade_in * self.length_in + self.grade_out * self.length_out) / self.length

    @property
    def rates(self) -> tuple[float, float]:
        """d²z/ds² of the two parabolas (equal for a symmetric curve)."""
        g = self.middle_grade
        return cast("tuple[float, float]", tuple((b - a) / length for a, b, length in
                     ((self.grade_in, g, self.length_in), (g, self.grade_out, self.length_out))))  # fmt: skip

    @property
    def k(self) -> float:
        """K = 1/(100·max|d²z/ds²|): length per percent of grade change."""
        return 1.0 / (100.0 * max(abs(r) for r in self.rates))

    def extreme_point(self) -> float:
        """Station of the curve's highest point (crest) or lowest (sag): where the grade is 0 on
        it, else the end that is higher (crest) or lower (sag)."""
        sign = 1.0 if self.kind == "crest" else -1.0
        for (s0, _, g0), rate, length in zip(self._starts(), self.rates, (self.length_in, self.length_out)):
            if rate != 0.0 and 0.0 <= -g0 / rate <= length:  # rate 0: a straight piece (grades equal to the last ulp)
                return s0 - g0 / rate
        rising = sign * self.grade_out > 0.0  # no level point: the curve climbs (crest) or falls (sag) throughout
        return self.evc if rising else self.bvc

    def _starts(self) -> tuple[tuple[float, float, float], tuple[float, float, float]]:
        """(station, elevation, grade) at the start of each parabola."""
        z_bvc = self.elevation - self.grade_in * self.length_in
        g = self.middle_grade
        z_mid = z_bvc + 0.5 * (self.grade_in + g) * self.length_in
        return (self.bvc, z_bvc, self.grade_in), (self.station, z_mid, g)


@dataclass(frozen=True)
class ProfileRow:
    """The criteria at one PVI: what was required and the verdict (lengths in design units)."""

    pvi: int
    sight_distance: float
    minimum_k: float
    minimum_length: float
    max_grade: float
    violations: tuple[str, ...] = ()

    @property
    def ok(self) -> bool:
        return not self.violations


@dataclass(frozen=True)
class Profile:
    """A vertical alignment: PVIs, their vertical curves and the exact piecewise polynomial z(station).

    Attributes:
        pvis: (n, 2) stations and elevations.
        curves: one ``VerticalCurve`` per interior PVI.
        units: the length unit of stations and elevations.
        stations: (m + 1,) piece boundaries from the first to the last PVI.
        coefficients: (m, 3) each piece's z = a + b·d + c·d², d = station − its start.
        criteria: the ``ProfileCriteria`` the curves were chosen or checked by, if any.
        checks: one ``ProfileRow`` per PVI when there are criteria.
    """

    pvis: NDArray
    curves: tuple[VerticalCurve, ...]
    units: str
    stations: NDArray
    coefficients: NDArray
    criteria: ProfileCriteria | None = None
    checks: tuple[ProfileRow, ...] = ()

    @classmethod
    def fit(
        cls, stations: ArrayLike, elevations: ArrayLike, tolerance: float, *, units: str = DEFAULT_UNITS, design_speed: float | None = None
    ) -> Profile:
        """The profile through measured (station, elevation) points: grades and parabolic vertical curves.

        The grade change rate (the points' second difference) is read first: runs where it is zero
        are grades, runs where it is constant are parabolic curves, so points of a designed profile
        give back its PVIs and curves. Where that misses the tolerance (noise), the PVIs are the
        corners of a polyline of grades within half the tolerance (Douglas–Peucker on elevation,
        tighter if needed); each interior PVI gets the longest symmetric vertical curve its tangents
        allow, shortened where a point would miss the tolerance.

        Args:
            stations: (N,) stations (any order; repeated stations are averaged).
            elevations: (N,) elevations, in ``units``.
            tolerance: the largest |elevation − profile| of any point.
            units: the length unit.
            design_speed: judges every curve and grade (``ProfileCriteria``); never enforced.

        Raises:
            ValueError: malformed input (lengths differ, non-finite values, fewer than 2 stations).
            NoSolutionError: no profile within the tolerance was found.
        """
        return fit_profile(cls, stations, elevations, tolerance, units=units, design_speed=design_speed)

    @classmethod
    def from_pvis(
        cls,
        points: ArrayLike,
        curve_lengths: Any = None,
        k_values: Any = None,
        units: str = DEFAULT_UNITS,
        *,
        design_speed: float | None = None,
        criteria: ProfileCriteria | None = None,
        strict: bool = False,
        alignment: Any = None,
    ) -> Profile:
        """Grades between PVIs and a parabolic vertical curve at every interior PVI.

        Args:
            points: (n ≥ 2, 2) stations (increasing) and elevations of the PVIs;
                the first and last are the profile's ends.
            curve_lengths: per interior PVI a length (symmetric) or an
                ``(L_in, L_out)`` pair (asymmetric); one number for all.
            k_values: per interior PVI the K (length per percent of grade
                change) of a symmetric curve; one number for all. Give at most
                one of ``curve_lengths`` and ``k_values``.
            units: the length unit (with ``alignment``: the alignment's).
            design_speed: judges every curve and grade by ``ProfileCriteria(V)``.
            criteria: a ``ProfileCriteria`` (instead of ``design_speed``).
            strict: raise when a given curve or grade violates a criterion
                (by default violations are listed in ``checks``).
            alignment: the horizontal ``Alignment`` whose stations the profile
                shares: it must cover the alignment, and no vertical curve may
                run past the alignment's ends.

        Without lengths and K values, each curve is the shortest that meets the
        criteria (which are then required).

        Raises:
            ValueError: malformed input (fewer than 2 PVIs, stations not
                increasing, bad lengths), naming the PVI.
            NoSolutionError: curves that overlap or run past the profile's or
                the alignment's ends, a profile that does not cover the
                alignment, or (``strict``) violated criteria — naming the PVIs
                and the numbers.
        """
        if alignment is not None and not isinstance(alignment, Alignment):
            raise ValueError(f"alignment must be an Alignment; got {type(alignment).__name__}")
        if not isinstance(strict, bool):
            raise ValueError(f"strict must be True or False; got {shown(strict):.80}")
        if alignment is not None:
            own = alignment.chain.units
            if units not in (DEFAULT_UNITS, own):
                raise ValueError(f"the alignment is in {own}; units={units!r} would mislabel the profile")
            units = own
        units = length_unit(units)
        pvis = as_points(points, "points")
        if pvis.ndim != 2 or len(pvis) < 2:
            raise ValueError(f"a profile needs at least 2 PVIs as an (n, 2) array of (station, elevation); got shape {pvis.shape}")
        if not np.isfinite(pvis).all():
            k = int(np.flatnonzero(~np.isfinite(pvis).all(axis=1))[0])
            raise ValueError(f"PVI {k}: station and elevation must be finite; got {pvis[k].tolist()}")
        with np.errstate(all="ignore"):
            steps = np.diff(pvis[:, 0])
            grades = np.diff(pvis[:, 1]) / steps
        for k, step in enumerate(steps.tolist()):
            if not step > 0.0:
                raise ValueError(f"PVI {k + 1}: station {float(pvis[k + 1, 0])!r} must be after PVI {k}'s station {float(pvis[k, 0])!r}")
            if not math.isfinite(step) or not math.isfinite(grades[k]):
                raise ValueError(f"PVI {k} and PVI {k + 1}: the stations and elevations give a grade float64 cannot hold")
        count = len(pvis) - 2
        criteria = _criteria(design_speed, criteria)
        if curve_lengths is not None and k_values is not None:
            raise ValueError("give at most one of curve_lengths and k_values")
        differences = grades[1:] - grades[:-1]
        for j in np.flatnonzero(differences == 0.0).tolist():
            raise ValueError(
                f"PVI {j + 1} at station {float(pvis[j + 1, 0])!r} lies on the grade of its neighbours "
                f"({100 * float(grades[j])!r} %): no vertical curve can be placed there; remove it"
            )
        if count == 0 and curve_lengths is None and k_values is None:
            halves = np.zeros((0, 2))  # one grade: nothing to choose
        elif curve_lengths is not None:
            halves = _curve_halves(curve_lengths, count)
        elif k_values is not None:
            ks = per_item(k_values, count, "k_values", "interior PVI")
            for j, value in enumerate(ks):
                if not value > 0.0:
                    raise ValueError(f"PVI {j + 1}: K must be positive; got {value}")
            full = 100.0 * np.abs(differences) * ks
            halves = np.stack([full / 2.0, full / 2.0], axis=1)
        else:
            if criteria is None:
                raise ValueError("give curve_lengths or k_values, or design criteria (design_speed) to choose them")
            full = criteria.minimum_length(differences, units)
            halves = np.stack([full / 2.0, full / 2.0], axis=1)
        for j in np.flatnonzero(~np.isfinite(halves).all(axis=1)).tolist():
            raise NoSolutionError(f"PVI {j + 1}: its vertical curve would be longer than float64 can hold "
                                  f"(A = {100 * float(differences[j]):.4g} %)")  # fmt: skip
        curves = tuple(
            VerticalCurve(j + 1, float(pvis[j + 1, 0]), float(pvis[j + 1, 1]), float(grades[j]), float(grades[j + 1]),
                          float(halves[j, 0]), float(halves[j, 1]))
            for j in range(count)
        )  # fmt: skip
        _check_room(pvis, curves, units, chosen=curve_lengths is None and k_values is None)
        if alignment is not None:
            _check_alignment(pvis, curves, alignment, units)
        stations, coefficients = _pieces(pvis, grades, curves)
        _verify(stations, coefficients, pvis, units)
        checks = () if criteria is None else _judge(curves, grades, criteria, units, strict)
        return cls(pvis.copy(), curves, units, stations, coefficients, criteria, checks)

    # ------------------------------------------------------- evaluation

    @property
    def start(self) -> float:
        return float(self.pvis[0, 0])

    @property
    def end(self) -> float:
        return float(self.pvis[-1, 0])

    @property
    def grades(self) -> NDArray:
        """The grade of every tangent between consecutive PVIs (fractions)."""
        return np.diff(self.pvis[:, 1]) / np.diff(self.pvis[:, 0])

    def _at(self, station: ArrayLike, derivative: int) -> NDArray:
        s = inside(station, self.start, self.end, "profile")
        return piecewise_at(self.stations[:-1], self.coefficients, s, derivative)

    def elevation(self, station: ArrayLike) -> NDArray:
        """z at ``station`` (vectorised)."""
        return self._at(station, 0)

    def grade(self, station: ArrayLike) -> NDArray:
        """dz/ds at ``station`` (on a boundary: the grade of the piece that starts there)."""
        return self._at(station, 1)

    def grade_rate(self, station: ArrayLike) -> NDArray:
        """d²z/ds² at ``station``."""
        return self._at(station, 2)

    def records(self, start: float, end: float) -> NDArray:
        """(m, 4) rows (s, a, b, c) of the pieces from station ``start`` to ``end``, with s and the
        polynomials measured from ``start`` (OpenDRIVE's ``elevation`` records of a road starting there).

        Raises:
            ValueError: ``start`` or ``end`` outside the profile.
        """
        inside([start, end], self.start, self.end, "profile")
        first = int(piece_at(self.stations[:-1], start)[0])
        last = int(np.searchsorted(self.stations, end, side="left"))
        coefficients = self.coefficients[first : max(last, first + 1)].copy()
        starts = self.stations[first : first + len(coefficients)] - start
        shift = -starts[0]  # re-centre the first piece on ``start``: its value, slope and curvature there
        coefficients[0] = [polynomial(coefficients[0], shift, k) / (1.0, 1.0, 2.0)[k] for k in range(3)]
        starts[0] = 0.0
        return np.column_stack([starts, coefficients])

    # ------------------------------------------------------------ table

    def rows(self) -> list[dict[str, Any]]:
        """One dict per vertical curve (interior PVI): station, elevation, grades in and out (%),
        A (%), kind, lengths, K, BVC/EVC, the station of the curve's highest (crest) or lowest
        (sag) point, and with criteria SSD, K_min, L_min, the grade limit and the verdict (of the
        curve and its grades: the first row also judges the first grade)."""
        rows = []
        for curve in self.curves:
            row: dict[str, Any] = {
                "pvi": curve.index, "station": curve.station, "elevation": curve.elevation,
                "grade_in": 100.0 * curve.grade_in, "grade_out": 100.0 * curve.grade_out, "A": 100.0 * curve.difference,
                "kind": curve.kind, "L_in": curve.length_in, "L_out": curve.length_out, "K": curve.k,
                "BVC": curve.bvc, "EVC": curve.evc, "extreme_point": curve.extreme_point(),
            }  # fmt: skip
            if self.checks:
                check = self.checks[curve.index]
                violations = check.violations + (self.checks[0].violations if curve.index == 1 else ())
                row.update({
                    "SSD": check.sight_distance, "K_min": check.minimum_k, "L_min": check.minimum_length,
                    "max_grade": 100.0 * check.max_grade, "verdict": "; ".join(violations) or "ok",
                })  # fmt: skip
            rows.append(row)
        return rows

    def table(self, digits: int = 8) -> str:
        """The profile table as text (with its criteria when there are any), units in the headers."""
        head = ""
        if self.criteria is not None:
            head = f"ProfileCriteria, design speed {self.criteria.design_speed:g} {speed_unit(self.units)}\n"
        return head + text_table(self.rows(), PROFILE_DIMENSIONS, self.units, digits)

    def to_csv(self, path: str | Path) -> Path:
        """Write the profile table (criteria columns included when there are criteria) to ``path``."""
        return write_csv(path, self.rows(), PROFILE_DIMENSIONS, self.units)


#: Dimension of each profile-table column (``L`` the design's length unit).
PROFILE_DIMENSIONS = {
    **dict.fromkeys(["station", "elevation", "L_in", "L_out", "BVC", "EVC", "extreme_point", "SSD", "L_min"], "L"),
    **dict.fromkeys(["grade_in", "grade_out", "A", "max_grade"], "%"),
    **dict.fromkeys(["K", "K_min"], "L/%"),
}


def _criteria(design_speed: Any, criteria: Any) -> ProfileCriteria | None:
    if criteria is not None:
        if design_speed is not None:
            raise ValueError("give criteria or design_speed, not both")
        if not isinstance(criteria, ProfileCriteria):
            raise ValueError(f"criteria must be a ProfileCriteria; got {type(criteria).__name__}")
        return criteria
    return None if design_speed is None else ProfileCriteria(as_float(design_speed, "design_speed"))


def _curve_halves(value: Any, count: int) -> NDArray:
    """(count, 2) lengths before and after each PVI from one number, one per PVI, or (L_in, L_out) pairs."""
    if not isinstance(value, (list, tuple, np.ndarray)):
        total = as_float(value, "curve_lengths")
        halves = np.full((count, 2), total / 2.0)
    else:
        if len(value) != count:
            raise ValueError(f"curve_lengths needs one value or one per interior PVI ({count}); got {len(value)}")
        halves = np.empty((count, 2))
        for j, item in enumerate(value):
            entry = as_real_array(item, f"curve_lengths[{j}]")
            if entry.shape == ():
                halves[j] = float(entry) / 2.0
            elif entry.shape == (2,):
                halves[j] = entry
            else:
                raise ValueError(f"curve_lengths[{j}] (PVI {j + 1}) must be a length or an (L_in, L_out) pair; got shape {entry.shape}")
    for j, (before, after) in enumerate(halves.tolist()):
        if not (math.isfinite(before) and math.isfinite(after)):
            raise ValueError(f"PVI {j + 1}: curve lengths must be finite; got {shown(before + after)}")
        if not (before > 0.0 and after > 0.0):
            raise ValueError(f"PVI {j + 1}: curve lengths must be positive; got L_in = {shown(before)}, L_out = {shown(after)}")
    return halves


def _check_room(pvis: NDArray, curves: tuple[VerticalCurve, ...], units: str, chosen: bool) -> None:
    """Curves must not overlap each other or run past the first or last PVI."""
    what = "the shortest curve that meets the criteria" if chosen else "the curve"
    fix = "reduce the grade change" if chosen else "shorten it"
    start, end = float(pvis[0, 0]), float(pvis[-1, 0])
    previous_end, previous = start, None
    for curve in curves:
        if curve.bvc < previous_end - 1e-12 * max(abs(previous_end), curve.length):
            if previous is None:
                raise NoSolutionError(
                    f"PVI {curve.index}: {what} ({curve.length:.6g} {units}) starts at {curve.bvc:.6g}, before the "
                    f"profile's start PVI 0 at {start:.6g}; {fix} or move PVI 0 back"
                )
            raise NoSolutionError(
                f"PVI {previous.index} and PVI {curve.index}: the vertical curves overlap: PVI {previous.index}'s ends at "
                f"{previous.evc:.6g} {units} and PVI {curve.index}'s ({what}, {curve.length:.6g} {units}) starts at "
                f"{curve.bvc:.6g}; {'reduce the grade changes' if chosen else 'shorten them'} or move the PVIs apart"
            )
        previous_end, previous = curve.evc, curve
    if previous is not None and previous_end > end + 1e-12 * max(abs(end), previous.length):  # set by any curve
        raise NoSolutionError(
            f"PVI {previous.index}: {what} ({previous.length:.6g} {units}) ends at {previous_end:.6g}, past the "
            f"profile's end PVI {len(pvis) - 1} at {end:.6g}; {fix} or move the last PVI on"
        )


def check_coverage(start: float, end: float, alignment: Any, units: str) -> float:
    """A profile from ``start`` to ``end`` must cover the alignment (NoSolutionError naming the stations);
    returns the slack allowed for rounding."""
    first, last = alignment.start_station, alignment.end_station
    slack = 1e-9 * max(alignment.chain.length, abs(first), abs(last))
    if start > first + slack or end < last - slack:
        raise NoSolutionError(
            f"the profile runs from station {start:.6g} to {end:.6g} {units} but the alignment from "
            f"{first:.6g} to {last:.6g}: the profile must cover the alignment"
        )
    return slack


def _check_alignment(pvis: NDArray, curves: tuple[VerticalCurve, ...], alignment: Any, units: str) -> None:
    """The profile must cover the alignment, and its curves must lie on it."""
    first, last = alignment.start_station, alignment.end_station
    slack = check_coverage(float(pvis[0, 0]), float(pvis[-1, 0]), alignment, units)
    for curve in curves:
        if curve.bvc < first - slack or curve.evc > last + slack:
            raise NoSolutionError(
                f"PVI {curve.index}: its vertical curve ({curve.bvc:.6g} … {curve.evc:.6g} {units}) runs past the "
                f"alignment's {'start' if curve.bvc < first - slack else 'end'} ({first:.6g} … {last:.6g})"
            )


def _pieces(pvis: NDArray, grades: NDArray, curves: tuple[VerticalCurve, ...]) -> tuple[NDArray, NDArray]:
    """Piece boundaries and (a, b, c) per piece: grade lines and parabolas, in station order.

    Each piece starts from the exact elevation of its own defining element
    (the PVI line or the curve's BVC), so rounding does not accumulate.
    """
    starts, coefficients = [], []

    def grade_line(k: int, from_station: float) -> None:
        s0, z0 = pvis[k]
        starts.append(from_station)
        coefficients.append((z0 + grades[k] * (from_station - s0), grades[k], 0.0))

    grade_line(0, float(pvis[0, 0]))
    for curve in curves:
        k = curve.index
        parabolas = list(zip(curve._starts(), curve.rates))
        for (s0, z0, g0), rate in parabolas[:1] if curve.length_in == curve.length_out else parabolas:
            starts.append(s0)  # a symmetric curve is one parabola
            coefficients.append((z0, g0, 0.5 * rate))
        grade_line(k, curve.evc)
    stations = np.array(starts + [float(pvis[-1, 0])])
    table = np.array(coefficients, dtype=float)
    keep = np.diff(stations) > 0.0  # a curve ending exactly where the next begins leaves an empty grade line
    return np.append(stations[:-1][keep], stations[-1]), table[keep]


def _verify(stations: NDArray, coefficients: NDArray, pvis: NDArray, units: str) -> None:
    """The pieces as built must meet: value and grade continuous at every boundary (to 1e-9 of the
    profile's own scale) and every number finite — else the numbers are beyond float64's reach."""
    with np.errstate(all="ignore"):
        span = float(pvis[-1, 0] - pvis[0, 0])
        grade_scale = max(float(np.abs(coefficients[:, 1]).max()), 1e-300)
        height_scale = max(float(np.abs(pvis[:, 1]).max()), span * grade_scale)
        ends = np.diff(stations)[:-1]
        jumps = [np.abs(polynomial(coefficients[:-1], ends, k) - coefficients[1:, k]) for k in (0, 1)]
        bad = ~np.isfinite(coefficients).all(axis=1)[1:] | ~(jumps[0] <= 1e-9 * height_scale) | ~(jumps[1] <= 1e-9 * grade_scale)
    if not np.isfinite(coefficients[0]).all() or bad.any():
        where = float(stations[1 + int(np.argmax(bad))]) if bad.any() else float(stations[0])
        raise NoSolutionError(
            f"the profile cannot be held in float64 at these numbers: its pieces do not meet at station {where:.6g} "
            f"{units} (elevations up to {height_scale:.3g}, grades up to {grade_scale:.3g})"
        )


def _judge(curves, grades: NDArray, criteria: ProfileCriteria, units: str, strict: bool) -> tuple[ProfileRow, ...]:
    """The criteria row of every PVI (its curve and the grade leaving it); ``strict`` raises on a violation."""
    sight = criteria.stopping_sight_distance(units)
    limit = criteria.grade_limit(units)
    by_pvi = {c.index: c for c in curves}
    needed = dict(zip(by_pvi, criteria.minimum_length(np.array([c.difference for c in curves]), units)))
    rows = []
    for k in range(len(grades) + 1):
        violations = []
        curve = by_pvi.get(k)
        k_min = length_min = 0.0
        if curve is not None:
            k_min = criteria.minimum_k(curve.kind == "crest", units)
            length_min = float(needed[k])
            if curve.k < k_min * (1 - 1e-9):
                violations.append(f"{curve.kind} K = {curve.k:.4g} < K_min = {k_min:.4g} {units}/% (SSD {sight:.4g} {units})")
            if curve.length < criteria.appearance_length(units) * (1 - 1e-9):
                violations.append(f"L = {curve.length:.6g} < {criteria.appearance_length(units):.6g} {units} (appearance)")
        if k < len(grades) and abs(grades[k]) > limit * (1 + 1e-12):
            violations.append(f"grade {100 * grades[k]:.4g} % > {100 * limit:.4g} %")
        rows.append(ProfileRow(k, sight, k_min, length_min, limit, tuple(violations)))
    broken = [f"PVI {row.pvi}: {'; '.join(row.violations)}" for row in rows if row.violations]
    if strict and broken:
        raise NoSolutionError("profile criteria violated: " + " | ".join(broken))
    return tuple(rows)
