"""Clothoids (curvature linear in arc length) evaluated to rounding accuracy for every rate.

A clothoid from (x0, y0) with heading θ0, curvature κ(s) = k0 + c·s, has
heading θ(s) = θ0 + k0·s + c·s²/2 and position (x0, y0) + ∫₀ˢ (cos θ, sin θ).
The textbook closed form by Fresnel integrals completes the square of the
heading, which puts the integral's ends at s0 = k0/c and subtracts values of
size √(π/|c|): for a nearly circular spiral (|c| ≪ k0², common in exported
road maps) that cancels catastrophically — one ulp of rate moves the end of a
20 m spiral by metres. So each piece gets the method that is exact for it:

* ``ARC`` (c = 0): the closed-form arc, ``(sin q, 2 sin²(q/2))/k0`` with
  q = k0·s (no 1 − cos cancellation), by its Taylor series where |q| < 2⁻¹⁶
  (also the line, k0 = 0);
* ``QUADRATURE``: composite Gauss–Legendre quadrature of cos θ and sin θ,
  ``NODES`` nodes per panel, as many equal panels over [0, s] as make each
  panel's heading change (max |κ| · panel length) at most ``PANEL_TURN``
  rad. The integrand is entire and each node's heading is computed directly
  (no rotations accumulated), so the error is a few ulps of s for every
  c — 0, 1e-300 or 1e3 — at a cost linear in the turn;
* ``FRESNEL`` (``scipy.special.fresnel``): only for pieces that turn more
  than ``FRESNEL_TURN`` rad (where quadrature would need many panels) *and*
  whose Fresnel form is well conditioned: its rounding error is about
  ε·(a + 3|s0| + |φ|·L) with a = √(π/|c|), φ = k0²/(2c) and L the piece's
  length, and it is used when that is at most ``FRESNEL_CONDITION``·ε·L.
  A piece that turns so much that quadrature would need more than
  ``MAX_PANELS`` panels falls back to Fresnel whatever its conditioning
  if that error is at most 1e-6·L; otherwise (the heading carries no angle
  in floating point, or overflows) the piece is ``NONE`` and its points are NaN.

``clothoid_method`` tells which method a piece gets; ``clothoid_frames``
evaluates points, headings and curvatures, broadcasting arc lengths
``s`` against per-piece parameters. numpy and scipy only.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.special import fresnel

__all__ = [
    "ARC",
    "FRESNEL",
    "NONE",
    "QUADRATURE",
    "clothoid_frames",
    "clothoid_method",
    "clothoid_points",
]

#: Method codes returned by ``clothoid_method``.
NONE, ARC, QUADRATURE, FRESNEL = -1, 0, 1, 2
#: Gauss–Legendre nodes per panel, and the largest heading change (rad) of a panel: for e^{iθ}
#: on a panel turning by at most 2 rad (|θ'|, |θ''| ≤ 1 in the panel's [-1, 1] units), the rule's
#: remainder 2^{2n+1}(n!)⁴/((2n+1)((2n)!)³)·max|f^{(2n)}| with |f^{(2n)}| ≲ 2^{2n} is below 1e-20 for n = 12.
NODES, PANEL_TURN = 12, 2.0
#: Pieces turning less than this (rad) always take quadrature (at most 16 panels).
FRESNEL_TURN = 32.0
#: Fresnel's error bound in ulps of the length below which it is used for larger turns.
FRESNEL_CONDITION = 16.0
#: Quadrature panels per point beyond which Fresnel is used whatever its conditioning.
MAX_PANELS = 1 << 16
#: Beyond ``MAX_PANELS``, Fresnel's largest error bound (ulps of the length: ≈ 1e-6 of it) still used.
_LAST_RESORT = 1e-6 / np.finfo(float).eps
#: Below this |k0·s| an arc is evaluated by its Taylor series (the 6th-order terms are < 1e-29·s).
_SERIES = 2.0**-16

_X, _W = np.polynomial.legendre.leggauss(NODES)
_U = 0.5 * (_X + 1.0)  # nodes on [0, 1]
_HALF_W = 0.5 * _W  # their weights on [0, 1]


def _turn(s: NDArray[np.float64], k0: NDArray[np.float64], rate: NDArray[np.float64]) -> NDArray[np.float64]:
    """An upper bound of the heading's total variation over [0, s]: max |κ| · s."""
    return np.maximum(np.abs(k0), np.abs(k0 + rate * s)) * np.abs(s)


def _fresnel_condition(length: NDArray[np.float64], k0: NDArray[np.float64], rate: NDArray[np.float64]) -> NDArray[np.float64]:
    """Fresnel's rounding error over a piece of ``length``, in units of ε·length (inf where c = 0)."""
    with np.errstate(all="ignore"):
        safe = np.where(rate == 0.0, np.inf, rate)
        a = np.sqrt(math.pi / np.abs(safe))
        s0 = k0 / safe
        phase = k0 * k0 / (2.0 * np.abs(safe))
        condition = (a + 3.0 * np.abs(s0)) / length + phase + 1.0
    return np.where((rate == 0.0) | ~np.isfinite(condition), np.inf, condition)


def clothoid_method(length: ArrayLike, k0: ArrayLike, rate: ArrayLike) -> NDArray[np.int64]:
    """Which method (``ARC``, ``QUADRATURE``, ``FRESNEL`` or ``NONE``) evaluates each piece.

    Args:
        length: the pieces' lengths (the largest arc length evaluated), any unit.
        k0: their start curvatures (1/unit).
        rate: their curvature rates dκ/ds (1/unit²).

    Returns:
        An integer array of the broadcast shape (see the module docstring for the criterion).
    """
    length, k0, rate = (np.asarray(v, dtype=float) for v in (length, k0, rate))
    with np.errstate(all="ignore"):
        turn = _turn(length, k0, rate)
        method = np.where(rate == 0.0, ARC, QUADRATURE)
        large = (turn > FRESNEL_TURN) & (rate != 0.0)  # only these may take Fresnel: its criterion is skipped for the rest
        if large.any():
            condition = _fresnel_condition(length, k0, rate)
            panels = np.ceil(turn / PANEL_TURN)
            fallback = np.where(panels <= MAX_PANELS, QUADRATURE, np.where(condition <= _LAST_RESORT, FRESNEL, NONE))
            method = np.where(large, np.where(condition <= FRESNEL_CONDITION, FRESNEL, fallback), method)
        bad = ~np.isfinite(length + k0 + rate)  # inf − inf is NaN: any non-finite input
    return np.where(bad, NONE, method)  # an arc whose turn overflows is evaluated: its points are NaN


def clothoid_points(s: ArrayLike, k0: ArrayLike, rate: ArrayLike, method: ArrayLike | None = None) -> NDArray[np.float64]:
    """Local points (..., 2) at arc lengths ``s`` of clothoids starting at the origin along +x.

    ``s``, ``k0`` and ``rate`` broadcast together; ``method`` (as from
    ``clothoid_method`` of each piece's length, broadcastable too) defaults
    to the method for length ``s`` itself. Points of ``NONE`` pieces are NaN.
    """
    s, k0, rate = np.broadcast_arrays(*(np.asarray(v, dtype=float) for v in (s, k0, rate)))
    method = np.broadcast_to(clothoid_method(s, k0, rate) if method is None else np.asarray(method), s.shape)
    with np.errstate(all="ignore"):
        for code, evaluate in ((ARC, _arc), (QUADRATURE, _quadrature), (FRESNEL, _fresnel)):
            if (method == code).all():  # one method for all: no gathering
                return evaluate(s.ravel(), k0.ravel(), rate.ravel()).reshape(s.shape + (2,))
        points = np.full(s.shape + (2,), np.nan)
        for code, evaluate in ((ARC, _arc), (QUADRATURE, _quadrature), (FRESNEL, _fresnel)):
            chosen = method == code
            if chosen.any():
                points[chosen] = evaluate(s[chosen], k0[chosen], rate[chosen])
    return points


def clothoid_frames(
    s: ArrayLike,
    k0: ArrayLike,
    rate: ArrayLike,
    *,
    x0: ArrayLike = 0.0,
    y0: ArrayLike = 0.0,
    hdg: ArrayLike = 0.0,
    length: ArrayLike | None = None,
    method: ArrayLike | None = None,
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """Points, headings and curvatures of clothoids at arc lengths ``s``.

    Every argument broadcasts against the others, so ``s`` of shape (n, m)
    with per-piece parameters of shape (n, 1) evaluates n pieces at m arc
    lengths each.

    Args:
        s: arc lengths from each piece's start (any unit; may be negative).
        k0: start curvatures (1/unit; positive turns left).
        rate: curvature rates dκ/ds (1/unit²).
        x0, y0: start points.
        hdg: start headings (rad, from +x counter-clockwise).
        length: the pieces' lengths, which choose the method (see
            ``clothoid_method``) so that all points of a piece agree; by
            default each point's own ``s``.
        method: the pieces' methods, if already known (``clothoid_method``
            of their lengths); overrides ``length``.

    Returns:
        (points (..., 2), headings (...), curvatures (...)); points of a piece
        that cannot be evaluated (``NONE``: its heading overflows or holds no angle) are NaN.
    """
    s, k0, rate = (np.asarray(v, dtype=float) for v in (s, k0, rate))
    if method is None and length is not None:
        method = clothoid_method(length, k0, rate)
    points = clothoid_points(s, k0, rate, method)
    with np.errstate(all="ignore"):
        heading = s * (k0 + 0.5 * rate * s)
        curvature = k0 + rate * s
        if not (np.ndim(x0) == np.ndim(y0) == np.ndim(hdg) == 0 and x0 == y0 == hdg == 0.0):  # placed
            x0, y0, hdg = (np.asarray(v, dtype=float) for v in (x0, y0, hdg))
            c, n = np.cos(hdg), np.sin(hdg)
            x, y = points[..., 0], points[..., 1]
            points = np.stack([x0 + c * x - n * y, y0 + n * x + c * y], axis=-1)
            heading = hdg + heading
    return points, heading, curvature


def _arc(s: NDArray[np.float64], k: NDArray[np.float64], _rate: NDArray[np.float64]) -> NDArray[np.float64]:
    """Points of arcs (lines where k = 0) of curvature ``k`` at arc lengths ``s`` (1-d arrays)."""
    q = k * s
    small = np.abs(q) < _SERIES
    q2 = q * q
    x = np.where(small, s * (1.0 - q2 / 6.0 * (1.0 - q2 / 20.0)), np.sin(q) / np.where(small, 1.0, k))
    half = np.sin(0.5 * q)
    y = np.where(small, 0.5 * s * q * (1.0 - q2 / 12.0 * (1.0 - q2 / 30.0)), 2.0 * half * half / np.where(small, 1.0, k))
    return np.stack([x, y], axis=-1)


def _quadrature(s: NDArray[np.float64], k0: NDArray[np.float64], rate: NDArray[np.float64]) -> NDArray[np.float64]:
    """Points by composite Gauss–Legendre quadrature of (cos θ, sin θ), θ = k0·t + rate·t²/2, over
    [0, s] in equal panels turning by at most ``PANEL_TURN`` each (1-d arrays; ragged panel counts
    are flattened into one array)."""
    panels = np.maximum(np.ceil(_turn(s, k0, rate) / PANEL_TURN), 1.0).astype(np.int64)
    if len(s) and panels.max() == 1:  # one panel each: no flattening
        t = s[:, None] * _U
        theta = t * (k0[:, None] + 0.5 * rate[:, None] * t)
        return np.stack([np.cos(theta) @ _HALF_W * s, np.sin(theta) @ _HALF_W * s], axis=-1)
    owner = np.repeat(np.arange(len(s)), panels)
    first = np.cumsum(panels) - panels
    index = np.arange(len(owner)) - first[owner]  # each panel's number within its point
    h = (s / panels)[owner]
    t = (index[:, None] + _U[None, :]) * h[:, None]  # (panels, NODES)
    kk, cc = k0[owner][:, None], rate[owner][:, None]
    theta = t * (kk + 0.5 * cc * t)
    x = (np.cos(theta) @ _HALF_W) * h
    y = (np.sin(theta) @ _HALF_W) * h
    return np.stack([np.bincount(owner, x, len(s)), np.bincount(owner, y, len(s))], axis=-1)


def _fresnel(s: NDArray[np.float64], k0: NDArray[np.float64], rate: NDArray[np.float64]) -> NDArray[np.float64]:
    """Points by Fresnel integrals after completing the square of the heading (1-d arrays;
    rate ≠ 0): θ = (c/2)(t + s0)² − φ with s0 = k0/c, φ = k0²/(2c)."""
    sign = np.sign(rate)
    a = np.sqrt(math.pi / np.abs(rate))
    s0 = k0 / rate
    phase = k0 * k0 / (2.0 * rate)
    S1, C1 = fresnel((s + s0) / a)
    S0, C0 = fresnel(s0 / a)
    dC, dS = C1 - C0, sign * (S1 - S0)
    cp, sp = np.cos(phase), np.sin(phase)
    return np.stack([a * (cp * dC + sp * dS), a * (cp * dS - sp * dC)], axis=-1)
