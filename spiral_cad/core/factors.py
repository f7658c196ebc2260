"""What a spiral's angle θ alone decides, for each shape, over arrays of θ.

A spiral of shape S turning by θ onto radius R is the unit spiral (R = 1)
scaled by R, so its length is R·ℓ(θ), its circle's shift off the start line
R·(g1(θ) − 1) and its peak |dκ/ds| F(θ)/R². Design tools search θ with
these (criteria, spiral lengths) and then measure the spirals they build.

F(θ) is exact or interpolated to ~1e-12 relative:

* the 1996 spiral: the rate at its start u = 0, (2/9)·c·sin θ/a³ in its legs,
  below θ ≈ 26.7° where an interior maximum takes over (a spline of 2 049
  measured spirals above);
* the near-linear spiral with equal legs (θ ≤ 33.56°): with k = sin²(θ/2)
  and m = u², R²·dκ/ds = (1 + 8km − 20km²)/(2 sin θ·(1 − 4km(1 − m))³),
  largest where 5 − 16m + 16km − 60km² + 80km³ = 0 (a cubic in m, solved by
  Newton from m = 5/16); past the equal legs a spline of measured spirals
  until the start rate takes over again at ≈ 46.0°, where F is smallest.
"""

from __future__ import annotations

import math
from functools import cache
from typing import cast

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.interpolate import CubicSpline

from . import _kernel_spiral as KS
from . import _kernels as K
from . import batch
from .bezier import arc_length, peak_curvature_rate
from .shapes import SHAPE_CODES

#: Smallest spiral angle the design searches consider.
THETA_MIN = 1e-6
#: Beyond ~80° the 1996 spiral's legs explode.
WALTON_MEEK_SEARCH_MAX = math.radians(80.0)
EQUAL_LEG_THETA = math.acos(K.EQUAL_LEG_COS)


def unit_spirals(theta: ArrayLike, shape: str = "walton-meek") -> NDArray[np.float64]:
    """Control points (N, 4, 2) of spirals of ``shape`` turning left by ``theta`` from the origin along +x to end radius 1."""
    theta = np.asarray(theta, dtype=float).ravel()
    out = np.empty((len(theta), 4, 2))
    KS.unit_spirals_batch(np.sin(theta), np.cos(theta), SHAPE_CODES[shape], out)
    return out


def length_factor(theta: ArrayLike, shape: str = "walton-meek") -> NDArray[np.float64]:
    """ℓ(θ): the length of unit spirals; a spiral onto radius r is r·ℓ long."""
    theta = np.asarray(theta, dtype=float)
    lengths = cast("NDArray[np.float64]", arc_length(unit_spirals(theta, shape)))  # N curves: an array
    return lengths.reshape(theta.shape)


def shift_factor(theta: ArrayLike, shape: str = "walton-meek") -> NDArray[np.float64]:
    """g1(θ) − 1: a spiral onto radius r shifts its circle r·(g1 − 1) off the start line (Theorem 4.1)."""
    theta = np.asarray(theta, dtype=float)
    flat = theta.ravel()
    e1 = np.empty(flat.shape)
    K.shape_offsets_batch(SHAPE_CODES[shape], np.sin(flat), np.cos(flat), e1, np.empty(flat.shape))
    factor: NDArray[np.float64] = (np.sin(flat) ** 2 * e1).reshape(theta.shape)
    return factor


def shift_angle(shift: ArrayLike, radius: ArrayLike, shape: str = "walton-meek") -> NDArray[np.float64]:
    """The θ whose spiral shifts its circle ``shift`` off the tangent (p = r·(g1(θ) − 1));
    0 for a shift ≤ 0 (every spiral shifts its circle), NaN beyond the shape's reach."""
    shift, radius = np.broadcast_arrays(np.asarray(shift, dtype=float), np.asarray(radius, dtype=float))
    relative = np.maximum(shift, 0.0) / radius
    centres = np.stack([np.zeros(shift.size), (1.0 + relative).ravel()], axis=1)
    theta = batch.line_to_circle([0.0, 0.0], [1.0, 0.0], centres, 1.0, shape=shape).theta.reshape(shift.shape)
    return np.where(shift > 0.0, theta, 0.0)


def _start_rate(theta: NDArray[np.float64], shape: str) -> NDArray[np.float64]:
    """|dκ/ds| at u = 0 of unit spirals: κ'(0)/|Q'(0)| = (2/9)·c·sin θ / a³ (legs a, c)."""
    legs = np.diff(unit_spirals(theta, shape), axis=1)
    a = np.hypot(legs[:, 0, 0], legs[:, 0, 1])
    c = np.hypot(legs[:, 2, 0], legs[:, 2, 1])
    rate: NDArray[np.float64] = (2.0 / 9.0 * c * np.sin(theta.ravel()) / a**3).reshape(theta.shape)
    return rate


def _equal_leg_peak(theta: NDArray[np.float64]) -> NDArray[np.float64]:
    """F(θ) of the equal-leg near-linear spiral in closed form (module docstring)."""
    k = np.sin(theta / 2.0) ** 2
    m = np.full(theta.shape, 5.0 / 16.0)
    for _ in range(8):  # Newton on the cubic; m moves from 5/16 by O(k)
        f = 5.0 - 16.0 * m + 16.0 * k * m - 60.0 * k * m * m + 80.0 * k * m**3
        m -= f / (-16.0 + 16.0 * k - 120.0 * k * m + 240.0 * k * m * m)
    base = 1.0 - 4.0 * k * m * (1.0 - m)
    peak: NDArray[np.float64] = (1.0 + 8.0 * k * m - 20.0 * k * m * m) / (2.0 * np.sin(theta) * base**3)
    return peak


def _peak_switch(lo: float, hi: float, shape: str, inside_at_hi: bool) -> tuple[float, float]:
    """The bracket, ~1e-13 rad wide, where the peak |dκ/ds| of unit spirals moves between
    the start (u = 0) and the inside: inside at ``hi`` and not at ``lo`` if
    ``inside_at_hi``, else the reverse. Each round measures 33 angles at once."""
    for _ in range(8):  # 32× narrower per round: 10° → 1.6e-13 rad
        theta = np.linspace(lo, hi, 33)
        far_side = (peak_curvature_rate(unit_spirals(theta, shape))[1] > 1e-6) == inside_at_hi
        k = int(np.argmax(far_side))  # the first angle on hi's side (the sides are contiguous)
        if not (far_side[-1] and k > 0):
            raise ArithmeticError(f"no switch of the peak's place between {lo} and {hi} rad ({shape})")
        lo, hi = float(theta[k - 1]), float(theta[k])
    return lo, hi


@cache
def _interior_branch(shape: str) -> tuple[float, float, CubicSpline]:
    """(θ_a, θ_b, spline of log F on [θ_a, θ_b]) where an interior maximum of |dκ/ds| is the peak.

    1996 spiral: from where the interior maximum overtakes the start rate up to
    80°. Near-linear: from the end of the equal legs to where the start rate
    overtakes the interior maximum again. The ends are found by bisection on
    where the measured peak sits (u > 0 or u = 0).
    """
    if shape == "walton-meek":
        lo, hi = 0.2, 0.8  # the peak leaves the start between these
        lo, hi = _peak_switch(lo, hi, shape, inside_at_hi=True)
        start, stop = hi, WALTON_MEEK_SEARCH_MAX
    else:
        lo, hi = math.radians(40.0), math.radians(50.0)  # the start takes over between these
        lo, hi = _peak_switch(lo, hi, shape, inside_at_hi=False)
        start, stop = EQUAL_LEG_THETA, lo
    theta = np.linspace(start, stop, 1025)  # the spline's error is ~1e-12 relative
    return start, stop, CubicSpline(theta, np.log(peak_curvature_rate(unit_spirals(theta, shape))[0]))


def peak_rate_factor(theta: ArrayLike, shape: str = "walton-meek") -> NDArray[np.float64]:
    """F(θ): the peak |dκ/ds| of unit spirals; a spiral onto radius r peaks at F/r² (module docstring)."""
    theta = np.asarray(theta, dtype=float)
    low, high, spline = _interior_branch(shape)
    start = _start_rate(theta, shape)
    inside = (theta >= low) & (theta <= high)
    interior = np.exp(spline(np.clip(theta, low, high)))
    if shape == "walton-meek":
        return np.where(inside, np.maximum(start, interior), start)
    equal = theta <= EQUAL_LEG_THETA
    return np.where(equal, _equal_leg_peak(np.where(equal, theta, 0.1)), np.where(inside, np.maximum(start, interior), start))


def search_range(shape: str) -> tuple[float, float]:
    """The θ range design searches use: there a longer spiral (larger θ) never has a higher peak dκ/ds.

    1996 spiral: up to 80°. Near-linear: up to ≈ 46.0°, where F is smallest.
    """
    if shape == "walton-meek":
        return THETA_MIN, WALTON_MEEK_SEARCH_MAX
    return THETA_MIN, _interior_branch(shape)[1]
