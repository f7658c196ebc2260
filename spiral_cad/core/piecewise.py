"""Piecewise polynomials in one variable (profiles, superelevation, OpenDRIVE records), over arrays.

A piece is a row of coefficients, lowest power first, in the distance from
the piece's start; a value belongs to the last piece that starts at or
before it (and to the first piece before the first start).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .inputs import as_real_array


def polynomial(coefficients: NDArray[np.float64], x: NDArray[np.float64], derivative: int = 0) -> NDArray[np.float64]:
    """Each row of ``coefficients`` (…, k) — or its ``derivative`` 0, 1 or 2 — at ``x`` (Horner)."""
    if derivative not in (0, 1, 2):
        raise ValueError(f"derivative must be 0, 1 or 2; got {derivative!r}")
    coefficients = np.asarray(coefficients, dtype=float)
    powers = np.arange(coefficients.shape[-1])
    factors = np.ones_like(powers, dtype=float)
    for k in range(derivative):
        factors = factors * (powers - k)
    terms = (coefficients * factors)[..., derivative:]
    result = np.zeros(np.broadcast_shapes(terms.shape[:-1], np.shape(x)))
    for k in range(terms.shape[-1] - 1, -1, -1):
        result = result * x + terms[..., k]
    return result


def piece_at(starts: NDArray[np.float64], s: ArrayLike) -> tuple[NDArray[np.intp], NDArray[np.float64]]:
    """(index of the piece, distance from its start) for every ``s`` given the pieces' ``starts``."""
    s = np.asarray(s, dtype=float)
    index = np.clip(np.searchsorted(starts, s, side="right") - 1, 0, len(starts) - 1)
    return index, s - starts[index]


def piecewise_at(starts: NDArray[np.float64], coefficients: NDArray[np.float64], s: ArrayLike, derivative: int = 0) -> NDArray[np.float64]:
    """The piecewise polynomial (``starts`` (m,), ``coefficients`` (m, k)) or its ``derivative`` at ``s``."""
    index, x = piece_at(starts, s)
    return polynomial(coefficients[index], x, derivative)


def inside(s: ArrayLike, first: float, last: float, what: str) -> NDArray[np.float64]:
    """``s`` as a float array, every value within [first, last] (to 1e-12 of their size), else
    ValueError naming the first outside and the range of ``what``."""
    s = as_real_array(s, "station")
    slack = 1e-12 * max(last - first, abs(first), abs(last))
    outside = ~((s >= first - slack) & (s <= last + slack))
    if outside.any():
        raise ValueError(f"station {float(s[outside].ravel()[0])!r} is outside the {what} ({first!r} … {last!r})")
    return s
