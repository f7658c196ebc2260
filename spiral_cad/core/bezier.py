"""Cubic Bézier evaluation over arrays of parameters.

Every function takes control points ``cp`` of shape (4, 2) and parameters
``u`` (a float or an array of any shape) and returns arrays whose leading
shape is that of ``u``. One curve is evaluated by compiled loops
(``spiral_cad.core._kernels``: each value in registers, written once), many
curves by numpy broadcasting.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import _kernel_spiral as KS

#: Gauss–Legendre nodes used by :func:`arc_length` (per panel, 4 panels).
_GL_NODES, _GL_WEIGHTS = np.polynomial.legendre.leggauss(16)
_PANELS = 4
_U = ((np.arange(_PANELS)[:, None] + 0.5 * (_GL_NODES[None, :] + 1.0)) / _PANELS).ravel()
_W = np.tile(_GL_WEIGHTS / (2.0 * _PANELS), _PANELS)


def _power_coefficients(cp: NDArray[np.float64], order: int = 0) -> NDArray[np.float64]:
    """Power-basis coefficients of Q (order 0) or of its derivative of order 1-3, lowest first.

    ``cp`` is one curve (4, 2) or many (…, 4, 2); the result is (…, k, 2).
    Formed from control-point differences, so they keep full relative
    accuracy for small curves far from the origin.
    """
    d1 = cp[..., 1:, :] - cp[..., :-1, :]  # ΔP0..ΔP2 (slicing: np.diff costs more on 4 points)
    d2 = d1[..., 1:, :] - d1[..., :-1, :]  # Δ²P0, Δ²P1
    d3 = d2[..., 1, :] - d2[..., 0, :]
    if order == 0:
        terms: tuple[NDArray[np.float64], ...] = (cp[..., 0, :], 3.0 * d1[..., 0, :], 3.0 * d2[..., 0, :], d3)
    elif order == 1:
        terms = (3.0 * d1[..., 0, :], 6.0 * d2[..., 0, :], 3.0 * d3)
    elif order == 2:
        terms = (6.0 * d2[..., 0, :], 6.0 * d3)
    else:
        terms = (6.0 * d3,)
    return np.stack(terms, axis=-2)


def _horner(coefficients: NDArray[np.float64], u: ArrayLike) -> NDArray[np.float64]:
    """Evaluate polynomials with 2-D coefficients (…, k, 2), lowest first, at ``u``.

    One curve (k, 2) gives ``u.shape + (2,)``; N curves (N, k, 2) broadcast
    against ``u`` of shape (N, m) or (m,) and give (N, m, 2).
    """
    u = np.asarray(u, dtype=float)
    if coefficients.ndim == 2:  # one curve: a compiled loop, each value in registers
        flat = _parameters(u)
        out = np.empty((flat.size, coefficients.shape[1]))
        KS.polynomial_values(np.ascontiguousarray(coefficients, dtype=float), flat, out)
        return out.reshape(u.shape + coefficients.shape[1:])
    u = u[..., None]
    terms = coefficients[..., None, :, :]  # an axis for the samples
    acc = np.broadcast_to(terms[..., -1, :], np.broadcast_shapes(u.shape, terms[..., -1, :].shape)).copy()
    for j in range(coefficients.shape[-2] - 2, -1, -1):
        acc *= u
        acc += terms[..., j, :]
    return acc


def _parameters(u: NDArray[np.float64]) -> NDArray[np.float64]:
    """``u`` as a flat contiguous float64 array (the one type the kernels compile for)."""
    return np.ascontiguousarray(u, dtype=float).reshape(-1)


def point(cp: NDArray[np.float64], u: ArrayLike) -> NDArray[np.float64]:
    """Points Q(u), shape ``u.shape + (2,)``."""
    return _horner(_power_coefficients(cp), u)


def derivative(cp: NDArray[np.float64], u: ArrayLike, order: int = 1) -> NDArray[np.float64]:
    """Derivative of ``order`` 1, 2 or 3 at ``u``."""
    return _horner(_power_coefficients(cp, order), u)


def _scale(coefficients: NDArray[np.float64]) -> float:
    """A power of two near the largest coefficient (1 for zeros): dividing by it
    is exact and keeps squares and cubes of curves from 1e-300 to 1e300 in range."""
    big = float(np.abs(coefficients).max())
    return math.ldexp(1.0, math.frexp(big)[1]) if 0.0 < big < math.inf else 1.0


def tangent(cp: NDArray[np.float64], u: ArrayLike) -> NDArray[np.float64]:
    """Unit tangents Q'(u)/|Q'(u)|."""
    coefficients = _power_coefficients(cp, 1)
    d = _horner(coefficients / _scale(coefficients), u)
    unit: NDArray[np.float64] = d / np.linalg.norm(d, axis=-1, keepdims=True)
    return unit


def curvature(cp: NDArray[np.float64], u: ArrayLike) -> NDArray[np.float64]:
    """Signed curvature (Q' × Q'')/|Q'|³ (positive turns left)."""
    u = np.asarray(u, dtype=float)
    first, second = _power_coefficients(cp, 1), _power_coefficients(cp, 2)
    scale = _scale(first)
    flat = _parameters(u)
    out = np.empty(flat.size)
    KS.plane_curvatures(first / scale, second / scale, scale, flat, out)
    return out.reshape(u.shape)


def arc_length(cp: ArrayLike, u: ArrayLike = 1.0) -> NDArray[np.float64] | float:
    """Arc length from 0 to ``u`` by composite Gauss–Legendre (4 panels × 16 nodes).

    ``cp`` is one curve (4, 2) or N curves (N, 4, 2), broadcast against ``u``.
    The speed |Q'| of a spiral is smooth on [0, 1]: for θ ≤ 80° the rule is
    exact to ~1e-15 relative (checked against adaptive quadrature).
    """
    u = np.asarray(u, dtype=float)
    coefficients = _power_coefficients(np.asarray(cp, dtype=float), 1)
    scale = _scale(coefficients)
    speed = np.linalg.norm(_horner(coefficients / scale, u[..., None] * _U), axis=-1)
    result = speed @ _W * u * scale
    return float(result) if result.ndim == 0 else result


def arc_lengths_at(first: NDArray[np.float64], scale: NDArray[np.float64], u: NDArray[np.float64]) -> NDArray[np.float64]:
    """Arc length from 0 to ``u[i]`` of curve i, many curves at once, by :func:`arc_length`'s rule.

    The batch form of :func:`arc_length` for one parameter per curve: the
    same composite Gauss–Legendre nodes, taken one node at a time over all
    curves, so the temporaries stay a few arrays of the curves' size.

    Args:
        first: (n, 3, d) power coefficients of each curve's first derivative
            (``_power_coefficients(cp, 1)``), each divided by its ``scale``.
        scale: (n,) the factor (a power of two) each curve was divided by.
        u: (n,) the end parameter of each curve.

    Returns:
        (n,) arc lengths.
    """
    u = np.asarray(u, dtype=float)
    columns = [[np.ascontiguousarray(first[:, j, k]) for j in range(first.shape[1])] for k in range(first.shape[2])]
    total = np.zeros(len(u))
    for node, weight in zip(_U.tolist(), _W.tolist()):
        t = u * node
        square = np.zeros(len(u))
        for c0, c1, c2 in columns:
            value = c2 * t
            value += c1
            value *= t
            value += c0
            square += value * value
        total += weight * np.sqrt(square)
    result: NDArray[np.float64] = total * u * scale
    return result


def split(cp: NDArray[np.float64], t0: float, t1: float) -> NDArray[np.float64]:
    """Exact control points of the sub-curve on [t0, t1] (de Casteljau/blossom)."""

    def blossom(a: float, b: float, c: float) -> NDArray[np.float64]:
        pts = cp
        for s in (a, b, c):
            pts = (1.0 - s) * pts[:-1] + s * pts[1:]
        point: NDArray[np.float64] = pts[0]  # the blossom: one point (2,)
        return point

    points: NDArray[np.float64] = np.array([blossom(t0, t0, t0), blossom(t0, t0, t1), blossom(t0, t1, t1), blossom(t1, t1, t1)])
    return points


def curvature_rate(cp: ArrayLike, u: ArrayLike) -> NDArray[np.float64]:
    """dκ/ds at parameters ``u``.

    dκ/ds = κ'(u)/|Q'| with κ = (Q' × Q'')/|Q'|³, i.e.
    ((Q' × Q‴)|Q'|² − 3 (Q' × Q'')(Q' · Q'')) / |Q'|⁶. For a Bézier spiral
    this is not constant: curvature is not linear in arc length. ``cp`` is
    one curve (4, 2) or N curves (N, 4, 2), broadcast against ``u`` as in
    ``_horner``.
    """
    cp = np.asarray(cp, dtype=float)
    first = _power_coefficients(cp, 1)
    scale = _scale(first)
    d1, d2, d3 = (_horner(_power_coefficients(cp, order) / scale, u) for order in (1, 2, 3))
    cross12 = d1[..., 0] * d2[..., 1] - d1[..., 1] * d2[..., 0]
    cross13 = d1[..., 0] * d3[..., 1] - d1[..., 1] * d3[..., 0]
    speed2 = d1[..., 0] ** 2 + d1[..., 1] ** 2
    dot12 = d1[..., 0] * d2[..., 0] + d1[..., 1] * d2[..., 1]
    rate: NDArray[np.float64] = (cross13 * speed2 - 3.0 * cross12 * dot12) / speed2**3 / (scale * scale)
    return rate


def peak_curvature_rate(cp: ArrayLike, samples: int = 257) -> tuple[Any, Any]:
    """The largest |dκ/ds| of one curve (cp (4, 2)) or of N curves (cp (N, 4, 2)), and the u where it occurs.

    A grid of ``samples`` parameters finds each peak's neighbourhood, then a
    golden-section search (vectorised over the curves) refines it to ~1e-12
    in u; the peak may sit at an end (for small θ it is at κ = 0). Returns
    floats for one curve, (N,) arrays for N.
    """
    cp = np.asarray(cp, dtype=float)
    single = cp.ndim == 2
    cp = cp.reshape(-1, 4, 2)
    grid = np.linspace(0.0, 1.0, samples)
    rate = np.abs(curvature_rate(cp, grid))
    j = np.argmax(rate, axis=1)
    best_rate, best_u = rate[np.arange(len(cp)), j], grid[j]
    lo, hi = grid[np.maximum(j - 1, 0)], grid[np.minimum(j + 1, samples - 1)]
    ratio = (math.sqrt(5.0) - 1.0) / 2.0
    for _ in range(50):  # the bracket shrinks by 0.618 per step: 1/128 → 3e-13
        a, b = hi - ratio * (hi - lo), lo + ratio * (hi - lo)
        fa, fb = (np.abs(curvature_rate(cp, x[:, None]))[:, 0] for x in (a, b))
        left = fa > fb
        hi = np.where(left, b, hi)
        lo = np.where(left, lo, a)
    middle = 0.5 * (lo + hi)
    refined = np.abs(curvature_rate(cp, middle[:, None]))[:, 0]
    better = refined > best_rate
    best_rate, best_u = np.where(better, refined, best_rate), np.where(better, middle, best_u)
    return (float(best_rate[0]), float(best_u[0])) if single else (best_rate, best_u)


#: A cubic whose speed |B'| dips inside below this share of its largest is near a cusp: its curvature peaks there,
#: and may turn, within a small part of a grid step, so ``monotone_pieces`` samples about the dip ever closer.
NEAR_CUSP = 1e-2


def _refined_at_dips(cp: NDArray[np.float64], grid: NDArray[np.float64], speed: NDArray[np.float64], top: float) -> NDArray[np.float64]:
    """``grid`` with, about each interior minimum of ``speed`` below ``NEAR_CUSP`` of ``top``, the minimum itself (found
    by golden sections) and points at halving distances from it down to 1e-15: the curvature's peak and any turn
    near it lie between two of them."""
    inner = speed[1:-1]
    dips = np.flatnonzero((inner <= speed[:-2]) & (inner <= speed[2:]) & (inner < NEAR_CUSP * top)) + 1
    if not len(dips):
        return grid
    ratio = 0.5 * (math.sqrt(5.0) - 1.0)
    added = []
    for i in dips.tolist():
        lo, hi = float(grid[i - 1]), float(grid[i + 1])
        for _ in range(80):  # golden sections on the speed (smooth, one minimum in the bracket): to ~1e-16
            a, b = hi - ratio * (hi - lo), lo + ratio * (hi - lo)
            if np.linalg.norm(derivative(cp, a)) <= np.linalg.norm(derivative(cp, b)):
                hi = b
            else:
                lo = a
        at = 0.5 * (lo + hi)
        steps = (grid[i + 1] - grid[i - 1]) * 2.0 ** -np.arange(0.0, 50.0, 0.25)
        added.append(np.concatenate([[at], at - steps, at + steps]))
    both = np.concatenate([grid, *added])
    return np.unique(both[(both >= 0.0) & (both <= 1.0)])


def monotone_pieces(cp: ArrayLike, samples: int = 513) -> list[tuple[float, float]]:
    """Parameter intervals [u0, u1] covering [0, 1] on which a plane cubic's curvature is one-signed and monotone.

    Any cubic (a G5 spline, a general Bézier) is cut at its inflections (κ = 0) and curvature
    extrema (dκ/ds = 0); each interval is then a spiral piece whose curvature peaks at an end.
    Sign changes are found on a grid of ``samples`` parameters (values within 1e-9 of the
    largest are rounding, not a sign) and refined by bisection to ~1e-15 in u; two roots
    closer than a grid step may be missed together (a wiggle far below the grid's resolution).

    Args:
        cp: (4, 2) control points.
        samples: grid parameters for the sign search.

    Raises:
        ValueError: a cusp or a stop: the tangent vanishes inside the curve (its curvature
            is unbounded there), naming the parameter.
    """
    cp = np.asarray(cp, dtype=float)
    grid = np.linspace(0.0, 1.0, samples)
    speed = np.linalg.norm(derivative(cp, grid), axis=-1)
    top = float(speed.max())
    if top > 0.0:
        grid = _refined_at_dips(cp, grid, speed, top)
        speed = np.linalg.norm(derivative(cp, grid), axis=-1)
    if top == 0.0 or float(speed[1:-1].min(initial=top)) <= 1e-9 * top:
        at = float(grid[1 + int(np.argmin(speed[1:-1]))]) if len(grid) > 2 else 0.0
        raise ValueError(f"the cubic {cp.tolist()} has a cusp: its tangent vanishes near u = {at:.6g}, where its curvature is unbounded")
    cuts: list[float] = []
    coarse = np.isin(grid, np.linspace(0.0, 1.0, samples))  # the even grid: its values set the rounding's scale
    for function in (curvature, curvature_rate):
        with np.errstate(invalid="ignore", divide="ignore"):  # a leg of zero length: no tangent at that end
            values = np.nan_to_num(np.asarray(function(cp, grid), dtype=float), nan=0.0, posinf=0.0, neginf=0.0)
        # (not the near-cusp samples': a peak of 1e11 there does not make a real peak of 100 elsewhere rounding)
        noise = 1e-9 * float(np.abs(values[coarse]).max())
        signs = np.where(np.abs(values) <= noise, 0.0, np.sign(values))
        kept = np.flatnonzero(signs)
        flips = np.flatnonzero(signs[kept[:-1]] != signs[kept[1:]])  # consecutive signed samples that differ
        for a, b in zip(kept[flips].tolist(), kept[flips + 1].tolist(), strict=True):
            lo, hi = float(grid[a]), float(grid[b])
            for _ in range(60):  # bisection: the bracket halves to ~1e-15 in u
                middle = 0.5 * (lo + hi)
                if np.sign(float(function(cp, middle))) == signs[a]:
                    lo = middle
                else:
                    hi = middle
            cuts.append(0.5 * (lo + hi))
    ends = [0.0] + [u for u in sorted(cuts) if 1e-9 < u < 1.0 - 1e-9] + [1.0]
    kept_ends = [ends[0]] + [u for previous, u in zip(ends[:-1], ends[1:], strict=True) if u - previous > 1e-9]
    kept_ends[-1] = 1.0
    return list(zip(kept_ends[:-1], kept_ends[1:], strict=True))


def plain_spirals(cps: NDArray[np.float64], samples: int = 513) -> NDArray[np.bool_]:
    """Which cubics (N, 4, 2) are one spiral piece on ``monotone_pieces``' own grid: no cusp, and neither
    the curvature nor its rate changes sign there (values within 1e-9 of the largest are rounding) — where
    monotone_pieces finds nothing to cut. All at once, in blocks; the others go through monotone_pieces."""
    u = np.linspace(0.0, 1.0, samples)
    basis1 = 3.0 * np.stack([(1.0 - u) ** 2, 2.0 * u * (1.0 - u), u * u])  # Q' on the legs
    basis2 = 6.0 * np.stack([1.0 - u, u])  # Q'' on the second differences
    out = np.zeros(len(cps), dtype=bool)
    for block in np.array_split(np.arange(len(cps)), max(1, -(-len(cps) // 512))):
        legs, bends = np.diff(cps[block], axis=1), np.diff(cps[block], 2, axis=1)  # (B, 3, 2), (B, 2, 2)
        x1, y1 = legs[..., 0] @ basis1, legs[..., 1] @ basis1
        x2, y2 = bends[..., 0] @ basis2, bends[..., 1] @ basis2
        x3, y3 = (6.0 * (bends[:, 1] - bends[:, 0])).T[:, :, None]
        speed2 = x1 * x1 + y1 * y1
        cross12 = x1 * y2 - y1 * x2
        with np.errstate(invalid="ignore", divide="ignore"):
            kappa = cross12 / (speed2 * np.sqrt(speed2))
            rate = ((x1 * y3 - y1 * x3) * speed2 - 3.0 * cross12 * (x1 * x2 + y1 * y2)) / (speed2 * speed2 * speed2)
        plain = speed2[:, 1:-1].min(axis=1) > 1e-18 * speed2.max(axis=1)  # |Q'| above 1e-9 of its largest
        inner = speed2[:, 1:-1]
        dips = (inner <= speed2[:, :-2]) & (inner <= speed2[:, 2:]) & (inner < NEAR_CUSP**2 * speed2.max(axis=1, keepdims=True))
        plain &= ~dips.any(axis=1)  # near a cusp: monotone_pieces samples closer there
        for values in (kappa, rate):
            values = np.nan_to_num(values, nan=0.0, posinf=0.0, neginf=0.0)
            noise = 1e-9 * np.abs(values).max(axis=1, keepdims=True)
            plain &= ~((values > noise).any(axis=1) & (values < -noise).any(axis=1))
        out[block] = plain
    return out
