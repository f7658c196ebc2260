"""Roads from points: the plan (``Alignment.fit``), the profile (``Profile.fit``); a 3-D survey is both (``spiral_cad.design.survey``).

The plan is ``spiral_cad.fit_points`` read as tangent–spiral–arc–spiral–tangent curves: the PIs
are where consecutive fitted tangents meet, each curve keeps its fitted radius and spiral angles,
and the alignment is built again from them by ``Alignment.from_pis`` (so the road criteria judge
it) and measured against the points once more. The profile is read from the grade change rate
(zero on grades, constant on curves); failing that (noise), it is a polyline of grades within half
the vertical tolerance (Douglas–Peucker on elevation) whose PVIs get the longest parabolic
vertical curves that keep every point within the tolerance.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..core.errors import NoSolutionError
from ..core.fit import PointFit, chain_distances, douglas_peucker, fit_points
from ..core.inputs import as_real_array
from ..core.segments import Arc, Line
from ..core.spiral import BezierSpiral
from ..core.units import DEFAULT_UNITS

if TYPE_CHECKING:
    from .alignment import Alignment
    from .profile import Profile

__all__ = ["fit_alignment", "fit_profile", "plan_curves"]


def plan_curves(fit: PointFit) -> tuple[NDArray[np.float64], NDArray[np.float64], list[tuple[float, float]]]:
    """The PIs, radii and (θ_in, θ_out) spiral angles of a fitted chain of tangent–spiral–arc–spiral–tangent curves.

    Raises:
        NoSolutionError: the chain is not of that form (no curve, a compound or reverse curve
            without a tangent between, or a spiral pair without an arc), naming the segment.
    """
    segments = fit.chain.segments
    if not isinstance(segments[0], Line) or not isinstance(segments[-1], Line):
        raise NoSolutionError("the fitted plan must start and end on a tangent (a Line); it starts or ends on a curve")
    pis = [fit.chain.start]
    radii: list[float] = []
    angles: list[tuple[float, float]] = []
    k = 1
    while k < len(segments):
        window = segments[k : k + 4]
        kinds = [type(s) for s in window]
        if kinds != [BezierSpiral, Arc, BezierSpiral, Line]:
            names = "–".join(type(s).__name__ for s in window)
            raise NoSolutionError(
                f"segment {k} of the fitted plan begins {names}: Alignment.fit needs tangent–spiral–arc–spiral–tangent "
                f"at every curve (fit_points gives curves without an arc or tangent between them)"
            )
        before, entry, arc, leave, after = segments[k - 1], *window
        assert isinstance(entry, BezierSpiral) and isinstance(arc, Arc) and isinstance(leave, BezierSpiral)
        a, d = before.end, before.end_tangent
        b, e = after.start, after.start_tangent
        cross = d[0] * e[1] - d[1] * e[0]
        t = ((b - a)[0] * e[1] - (b - a)[1] * e[0]) / cross
        pis.append(a + t * d)
        radii.append(abs(arc.radius))
        angles.append((abs(entry.theta), abs(leave.theta)))
        k += 4
    if not radii:
        raise NoSolutionError("the fitted plan is one straight line: an alignment needs at least one curve")
    pis.append(fit.chain.end)
    return np.array(pis), np.array(radii), angles


def fit_alignment(
    cls: type[Alignment],
    points: ArrayLike,
    tolerance: float,
    design_speed: float | None = None,
    *,
    units: str = DEFAULT_UNITS,
    shape: str = "near-linear",
    start_station: float = 0.0,
    max_jerk: float | None = None,
    criteria: Any = None,
    progress: Callable[[int, int], None] | None = None,
) -> Alignment:
    """``Alignment.fit`` (see there)."""
    plan = np.asarray(points, dtype=float)
    fit = fit_points(plan, tolerance, shape=shape, units=units, progress=progress)
    pis, radii, angles = plan_curves(fit)
    alignment = cls.from_pis(pis, radii, spiral_angles=angles, start_station=start_station, units=units,
                             design_speed=design_speed, max_jerk=max_jerk, criteria=criteria, shape=shape)  # fmt: skip
    residuals, _ = chain_distances(alignment.chain, plan)
    worst = int(np.argmax(residuals))
    if residuals[worst] > tolerance:
        raise NoSolutionError(
            f"the alignment rebuilt from the fitted PIs misses points[{worst}] by {float(residuals[worst]):.6g} "
            f"(tolerance {tolerance:g} {units})"
        )
    return dataclasses.replace(alignment, point_fit=fit)


def _segmented_profile(cls: type[Profile], s: NDArray[np.float64], z: NDArray[np.float64], tolerance: float, units: str,
                       design_speed: float | None) -> Profile | None:  # fmt: skip
    """The profile read from its grade change rate z'' (the second difference): runs where it is
    zero are grades, runs where it is a constant are parabolic curves (as the plan fit reads its
    curvature). PVIs where consecutive grade lines meet (two curves meeting without a grade between
    share the line tangent to both), each curve as long as its grade change over its rate. None where
    the points are not of that form, or the profile misses a point by more than ``tolerance``."""
    if len(s) < 5:
        return None
    grade = np.diff(z) / np.diff(s)
    middle = 0.5 * (s[1:] + s[:-1])  # a parabola's chord slope is its grade at the chord's middle
    rate = np.diff(grade) / np.diff(middle)
    # Equal rates within what the points resolve: the tolerance over the span, as a second difference.
    eps = max(4.0 * tolerance / float(s[-1] - s[0]) ** 2, 1e-9 * float(np.abs(rate).max()))
    runs: list[tuple[int, int, float]] = []  # rate indices [a, b) and the run's rate
    a = 0
    for j in range(1, len(rate) + 1):
        if j == len(rate) or abs(rate[j] - rate[a]) > eps:
            runs.append((a, j, float(np.median(rate[a:j]))))
            a = j
    # A single rate between two runs straddles their boundary: not a piece of its own.
    runs = [r for r in runs if r[1] - r[0] > 1]
    if not runs or abs(runs[0][2]) > eps or abs(runs[-1][2]) > eps:
        return None  # a profile starts and ends on a grade
    # Each run as a polynomial in s over its points (rate index j spans points j .. j + 2).
    fits = []
    for a, b, r in runs:
        flat = abs(r) <= eps
        coefficients = np.polyfit(s[a : b + 2], z[a : b + 2], 1 if flat else 2)
        fits.append((flat, np.pad(coefficients, (1, 0)) if flat else coefficients))  # (c2, c1, c0)
    lines: list[tuple[float, float]] = []  # (grade, elevation at s = 0) of each grade line, in order
    curves: list[float] = []  # each curve's z'' (2 c2)
    for k, (flat, c) in enumerate(fits):
        if flat:
            lines.append((float(c[1]), float(c[2])))
            continue
        curves.append(2.0 * float(c[0]))
        after_flat, after = fits[k + 1]
        if not after_flat:
            # Two parabolas touching: their difference has a double root where the shared line touches both.
            d = c - after
            if abs(d[0]) <= 0.0:
                return None
            touch = -d[1] / (2.0 * d[0])
            slope = 2.0 * c[0] * touch + c[1]
            lines.append((float(slope), float(np.polyval(c, touch) - slope * touch)))
    if len(lines) != len(curves) + 1:
        return None
    pvis = [(float(s[0]), float(lines[0][0] * s[0] + lines[0][1]))]
    lengths = []
    for (g1, b1), (g2, b2), rate_k in zip(lines, lines[1:], curves):
        if g1 == g2:
            return None
        at = (b2 - b1) / (g1 - g2)
        pvis.append((at, g1 * at + b1))
        lengths.append((g2 - g1) / rate_k)
    pvis.append((float(s[-1]), float(lines[-1][0] * s[-1] + lines[-1][1])))
    try:
        profile = cls.from_pvis(np.array(pvis), curve_lengths=lengths if lengths else None, units=units, design_speed=design_speed)
    except ValueError:
        return None
    if float(np.abs(profile.elevation(s) - z).max()) > tolerance:
        return None
    return profile


def fit_profile(
    cls: type[Profile],
    stations: ArrayLike,
    elevations: ArrayLike,
    tolerance: float,
    *,
    units: str = DEFAULT_UNITS,
    design_speed: float | None = None,
) -> Profile:
    """``Profile.fit`` (see there)."""
    s = as_real_array(stations, "stations").ravel()
    z = as_real_array(elevations, "elevations").ravel()
    if len(s) != len(z):
        raise ValueError(f"stations and elevations must have the same length; got {len(s)} and {len(z)}")
    if not (isinstance(tolerance, (int, float)) and math.isfinite(tolerance) and tolerance > 0):
        raise ValueError(f"tolerance must be a finite number > 0; got {tolerance!r}")
    bad = np.flatnonzero(~np.isfinite(s) | ~np.isfinite(z))
    if len(bad):
        raise ValueError(f"stations/elevations[{int(bad[0])}] is not finite")
    order = np.argsort(s, kind="stable")
    s, z = s[order], z[order]
    if len(s) < 2 or s[-1] <= s[0]:
        raise ValueError("Profile.fit needs at least 2 distinct stations")
    # Points at one station: their mean (a survey may repeat a station).
    unique, first = np.unique(s, return_index=True)
    z = np.add.reduceat(z, first) / np.diff(np.append(first, len(s)))
    s, zs = unique, z
    segmented = _segmented_profile(cls, s, zs, tolerance, units, design_speed)
    if segmented is not None:
        return segmented
    worst = math.inf
    for level in range(6):
        keep = douglas_peucker(np.column_stack([s, zs]), tolerance / 2.0 ** (level + 1), vertical=True)
        pvis = np.c_[s[keep], zs[keep]]
        if len(pvis) == 2:
            profile = cls.from_pvis(pvis, units=units)
            miss = np.abs(profile.elevation(s) - zs)
            if float(miss.max()) <= tolerance:
                return profile
            continue
        legs = np.diff(pvis[:, 0])
        # Half of each inner tangent for each of its two curves; all of the first and last.
        before = np.r_[legs[0], legs[1:-1] / 2.0]
        after = np.r_[legs[1:-1] / 2.0, legs[-1]]
        lengths = 2.0 * np.minimum(before, after) * (1.0 - 1e-9)
        for _ in range(40):
            profile = cls.from_pvis(pvis, curve_lengths=lengths, units=units)
            miss = np.abs(profile.elevation(s) - zs)
            worst = min(worst, float(miss.max()))
            if float(miss.max()) <= tolerance:
                break
            # Shorten the curves whose span holds a missed point.
            missed = s[miss > tolerance]
            centre = pvis[1:-1, 0]
            hit = np.any(np.abs(missed[:, None] - centre[None, :]) <= lengths[None, :] / 2.0 + 1e-12, axis=0)
            if not hit.any():
                break
            lengths = np.where(hit, lengths * 0.7, lengths)
        else:
            continue
        if float(miss.max()) <= tolerance:
            if design_speed is not None:
                profile = cls.from_pvis(pvis, curve_lengths=lengths, units=units, design_speed=design_speed)
            return profile
    raise NoSolutionError(f"no profile of grades and parabolic curves within tolerance {tolerance:g} was found (closest {worst:.6g})")
