"""Roads from points: the plan (``Alignment.fit``), the profile (``Profile.fit``); a 3-D survey is both (``spiral_cad.design.survey``).

The plan is ``spiral_cad.fit_points`` read as tangent–spiral–arc–spiral–tangent curves: the PIs
are where consecutive fitted tangents meet, each curve keeps its fitted radius and spiral angles,
and the alignment is built again from them by ``Alignment.from_pis`` (so the road criteria judge
it) and measured against the points once more. The profile is a polyline of grades within half
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

from ..core._inputs import as_real_array
from ..core.errors import NoSolutionError
from ..core.fit import PointFit, chain_distances, fit_points
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


def _vertical_polyline(stations: NDArray[np.float64], z: NDArray[np.float64], epsilon: float) -> NDArray[np.int64]:
    """Douglas–Peucker on elevation: indices of a polyline within ``epsilon`` (vertically) of every point."""
    keep = np.zeros(len(z), dtype=bool)
    keep[0] = keep[-1] = True
    stack = [(0, len(z) - 1)]
    while stack:
        i, j = stack.pop()
        if j - i < 2:
            continue
        line = z[i] + (z[j] - z[i]) * (stations[i + 1 : j] - stations[i]) / (stations[j] - stations[i])
        off = np.abs(z[i + 1 : j] - line)
        m = int(np.argmax(off))
        if off[m] > epsilon:
            keep[i + 1 + m] = True
            stack.extend([(i, i + 1 + m), (i + 1 + m, j)])
    return np.flatnonzero(keep)


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
    worst = math.inf
    for level in range(6):
        keep = _vertical_polyline(s, zs, tolerance / 2.0 ** (level + 1))
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
