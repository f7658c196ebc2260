"""A 3-D survey (x, y, z) fitted as a road: the plan by ``Alignment.fit``, the profile by
``Profile.fit`` of every point's station on that plan and its z, so plan and profile share stations."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..core.fit import chain_distances
from ..core.units import DEFAULT_UNITS
from .alignment import Alignment
from .profile import Profile

__all__ = ["SurveyFit", "fit_survey"]


@dataclass(frozen=True)
class SurveyFit:
    """A 3-D survey fitted as a road: plan and profile sharing stations.

    Attributes:
        alignment: the plan (``Alignment.fit`` of x, y).
        profile: the profile (``Profile.fit`` of each point's station and z).
        stations: (N,) each point's station on the alignment (its foot, plus ``start_station``).
        plan_residuals: (N,) horizontal distance of each point to the plan.
        vertical_residuals: (N,) |z − profile elevation at its station|.
    """

    alignment: Alignment
    profile: Profile
    stations: NDArray[np.float64]
    plan_residuals: NDArray[np.float64]
    vertical_residuals: NDArray[np.float64]


def fit_survey(
    points: ArrayLike,
    tolerance: float,
    vertical_tolerance: float | None = None,
    design_speed: float | None = None,
    *,
    units: str = DEFAULT_UNITS,
    shape: str = "near-linear",
    start_station: float = 0.0,
    progress: Callable[[int, int], None] | None = None,
) -> SurveyFit:
    """Plan and profile of a road from surveyed (x, y, z) points in travel order.

    Args:
        points: (N, 3) points, in ``units``.
        tolerance: the largest horizontal distance of any point to the plan.
        vertical_tolerance: the largest |z − profile| (default: ``tolerance``).
        design_speed: judges the curves (plan and profile) by the road criteria.
        units, shape, start_station, progress: as ``Alignment.fit``.

    Returns:
        A ``SurveyFit``; its alignment and profile write every road file (OpenDRIVE, LandXML, STEP
        through ``centerline_3d``) as designed ones do.

    Raises:
        ValueError: malformed points (not (N, 3), non-finite) or tolerances.
        NoSolutionError: as ``Alignment.fit`` and ``Profile.fit``.
    """
    xyz = np.asarray(points, dtype=float)
    if xyz.ndim != 2 or xyz.shape[1] != 3:
        raise ValueError(f"fit_survey takes (N, 3) points x, y, z; got shape {xyz.shape}")
    alignment = Alignment.fit(xyz[:, :2], tolerance, design_speed, units=units, shape=shape,
                              start_station=start_station, progress=progress)  # fmt: skip
    plan_residuals, feet = chain_distances(alignment.chain, xyz[:, :2])
    stations = feet + start_station
    profile = Profile.fit(stations, xyz[:, 2], vertical_tolerance or tolerance, units=units, design_speed=design_speed)
    vertical = np.abs(profile.elevation(np.clip(stations, profile.pvis[0, 0], profile.pvis[-1, 0])) - xyz[:, 2])
    return SurveyFit(alignment, profile, stations, plan_residuals, vertical)
