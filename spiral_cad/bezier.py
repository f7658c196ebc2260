"""Cubic Bézier evaluation over arrays of parameters (pure numpy functions).

Every function takes control points ``cp`` of shape (4, 2) and parameters
``u`` (a float or an array of any shape) and returns arrays whose leading
shape is that of ``u``.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

#: Gauss–Legendre nodes used by :func:`arc_length` (per panel, 4 panels).
_GL_NODES, _GL_WEIGHTS = np.polynomial.legendre.leggauss(16)
_PANELS = 4
_U = ((np.arange(_PANELS)[:, None] + 0.5 * (_GL_NODES[None, :] + 1.0)) / _PANELS).ravel()
_W = np.tile(_GL_WEIGHTS / (2.0 * _PANELS), _PANELS)


def _bernstein(u: NDArray, degree: int) -> NDArray:
    """Bernstein basis of ``degree`` (1, 2 or 3) at ``u``, shape ``u.shape + (degree + 1,)``."""
    v = 1.0 - u
    if degree == 3:
        return np.stack([v**3, 3.0 * u * v * v, 3.0 * u * u * v, u**3], axis=-1)
    if degree == 2:
        return np.stack([v * v, 2.0 * u * v, u * u], axis=-1)
    return np.stack([v, u], axis=-1)


def point(cp: NDArray, u: ArrayLike) -> NDArray:
    """Points Q(u), shape ``u.shape + (2,)``."""
    return _bernstein(np.asarray(u, dtype=float), 3) @ cp


def derivative(cp: NDArray, u: ArrayLike, order: int = 1) -> NDArray:
    """First or second derivative Q'(u) / Q''(u).

    Built from control-point differences (the hodograph), which keeps full
    relative accuracy for small curves far from the origin.
    """
    diff = np.diff(cp, n=order, axis=0)
    scale = 3.0 if order == 1 else 6.0
    return scale * (_bernstein(np.asarray(u, dtype=float), 3 - order) @ diff)


def tangent(cp: NDArray, u: ArrayLike) -> NDArray:
    """Unit tangents Q'(u)/|Q'(u)|."""
    d = derivative(cp, u)
    return d / np.linalg.norm(d, axis=-1, keepdims=True)


def curvature(cp: NDArray, u: ArrayLike) -> NDArray:
    """Signed curvature (Q' × Q'')/|Q'|³ (positive turns left)."""
    d1 = derivative(cp, u, 1)
    d2 = derivative(cp, u, 2)
    cross = d1[..., 0] * d2[..., 1] - d1[..., 1] * d2[..., 0]
    return cross / np.hypot(d1[..., 0], d1[..., 1]) ** 3


def arc_length(cp: NDArray, u: ArrayLike = 1.0) -> NDArray | float:
    """Arc length from 0 to ``u`` by composite Gauss–Legendre (4 panels × 16 nodes).

    The speed |Q'| of a spiral is smooth on [0, 1]: for θ ≤ 80° the rule is
    exact to ~1e-15 relative (checked against adaptive quadrature).
    """
    u = np.asarray(u, dtype=float)
    speed = np.linalg.norm(derivative(cp, u[..., None] * _U), axis=-1)
    result = speed @ _W * u
    return float(result) if result.ndim == 0 else result


def split(cp: NDArray, t0: float, t1: float) -> NDArray:
    """Exact control points of the sub-curve on [t0, t1] (de Casteljau/blossom)."""

    def blossom(a: float, b: float, c: float) -> NDArray:
        pts = cp
        for s in (a, b, c):
            pts = (1.0 - s) * pts[:-1] + s * pts[1:]
        return pts[0]

    return np.array(
        [blossom(t0, t0, t0), blossom(t0, t0, t1), blossom(t0, t1, t1), blossom(t1, t1, t1)]
    )
