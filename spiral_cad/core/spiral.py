"""The cubic Bézier spiral (Walton & Meek's Theorem 3.1, or another shape) as a path segment."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import bezier
from ._inputs import as_float, as_xy
from ._kernels import spiral_row
from .errors import Status, error_for
from .segments import EPS, End, Segment, piece_range
from .shapes import DEFAULT_SHAPE, SHAPE_CODES, TRANSITION_SHAPES, shape_code


class BezierSpiral(Segment):
    """A cubic Bézier spiral: curvature grows monotonically from 0 to ``curvature``.

    Control points B0, B1 = B0 + a·T, B2 = B1 + b·T, B3 = B2 + c·rot(T, θ),
    with legs (a, b, c) set by ``shape`` (``spiral_cad.core.shapes``):
    ``"walton-meek"`` is Theorem 3.1 of Walton & Meek (1996), a = b =
    25 tan|θ| / (54 |κ| cos θ), c = 5 tan|θ| / (9 |κ|); ``"near-linear"``
    has curvature almost linear in arc length (a = b = c = (2/3)·sin|θ|/|κ|
    up to |θ| = 33.56°, defined up to 50°).

    Args:
        start: start point B0, where the curvature is 0.
        direction: start tangent (any non-zero length).
        theta: signed turn angle, 0 < |θ| < π/2 (positive turns left).
        curvature: signed end curvature, same sign as ``theta``.
        shape: ``"walton-meek"`` (default) or ``"near-linear"``.

    Raises:
        ValueError: non-finite input, zero direction, |θ| ∉ (0, π/2), zero
            curvature, signs that differ or an unknown shape.
        NoSolutionError: |θ| beyond the shape's range (near-linear: 50°), or
            a spiral that float64 cannot hold to 1e-9 where it is placed
            (e.g. curvature 5e-324, or a tiny spiral at 1e12).

    Pieces (``piece``) and reversals (``reversed``) are exact Bézier curves
    of the same shape; for them ``start_curvature`` need not be 0.
    """

    def __init__(self, start: Any, direction: Any, theta: float, curvature: float, shape: str = DEFAULT_SHAPE):
        bx, by = as_xy(start, "start")
        dx, dy = as_xy(direction, "direction")
        theta = as_float(theta, "theta")
        curvature = as_float(curvature, "curvature")
        code = shape_code(shape, TRANSITION_SHAPES)
        out = np.empty((1, 1, 4, 2))
        status, _, measure, _ = spiral_row(bx, by, dx, dy, theta, curvature, code, out, 0)
        if status != Status.OK:
            inputs = dict(start=(bx, by), direction=(dx, dy), theta=theta, curvature=curvature, shape=shape)
            raise error_for("BezierSpiral", status, measure, inputs)
        self._cp = out[0, 0]
        self._length = None
        self._shape = shape
        self._cp.setflags(write=False)

    @classmethod
    def from_control_points(cls, control_points: ArrayLike, shape: str | None = None) -> BezierSpiral:
        """Wrap control points that are known to form a spiral (or a piece of one).

        No check is made that the curvature is monotone or that the legs are
        those of ``shape``; use the solvers or the constructor to make spirals.

        Args:
            control_points: (4, 2) control points in travel order.
            shape: the shape the points were made with, if known (reported
                by ``shape``; None: not stated).

        Raises:
            ValueError: not a finite (4, 2) array, an end leg of zero
                length (no end tangent: a degenerate spiral), or an unknown shape.
        """
        if shape is not None and shape not in SHAPE_CODES:
            shape_code(shape, tuple(SHAPE_CODES))
        cp = np.array(control_points, dtype=float)
        if cp.shape != (4, 2):
            raise ValueError(f"control_points must have shape (4, 2); got {cp.shape}")
        if not np.isfinite(cp).all():
            raise ValueError(f"control_points must be finite; got {cp.tolist()}")
        for leg, (a, b) in (("first", (0, 1)), ("last", (2, 3))):
            if np.array_equal(cp[a], cp[b]) or not np.isfinite(cp[b] - cp[a]).all():
                raise ValueError(
                    f"control_points make a degenerate spiral: the {leg} leg from {cp[a].tolist()} to "
                    f"{cp[b].tolist()} has no direction"
                )
        return cls._wrap(cp, shape)

    @classmethod
    def _wrap(cls, cp: NDArray, shape: str | None) -> BezierSpiral:
        """Adopt a finite (4, 2) float64 array without copying or checks (solver output)."""
        spiral = object.__new__(cls)
        cp.setflags(write=False)
        spiral._cp = cp
        spiral._length = None
        spiral._shape = shape
        return spiral

    def __repr__(self) -> str:
        return f"BezierSpiral.from_control_points({self._cp.tolist()}, shape={self._shape!r})"

    @property
    def shape(self) -> str | None:
        """The shape the spiral was made with (``"walton-meek"``, ``"near-linear"``, ``"g2cbs"``; None if not stated)."""
        return self._shape

    @property
    def control_points(self) -> NDArray:
        """(4, 2) float64 control points in travel order (read-only)."""
        return self._cp

    def outline(self) -> list[tuple[float, float]]:
        return [tuple(p) for p in self._cp.tolist()]

    def _end_frames(self) -> tuple[End, End]:
        (x0, y0), (x1, y1), (x2, y2), (x3, y3) = self._cp.tolist()
        legs = ((x1 - x0, y1 - y0), (x2 - x1, y2 - y1), (x3 - x2, y3 - y2))
        scale = max(abs(v) for leg in legs for v in leg)  # keeps |leg|³ in range at any magnitude
        (ax, ay), (bx, by), (cx, cy) = ((u / scale, v / scale) for u, v in legs)
        la, lc = math.hypot(ax, ay), math.hypot(cx, cy)
        k0 = 2.0 / 3.0 * (ax * by - ay * bx) / la**3 / scale
        k1 = 2.0 / 3.0 * (bx * cy - by * cx) / lc**3 / scale
        return (x0, y0, ax / la, ay / la, k0), (x3, y3, cx / lc, cy / lc, k1)

    @property
    def theta(self) -> float:
        """Signed angle from the start tangent to the end tangent."""
        (x0, y0), (x1, y1), (x2, y2), (x3, y3) = self._cp.tolist()
        ax, ay, bx, by = x1 - x0, y1 - y0, x3 - x2, y3 - y2
        return math.atan2(ax * by - ay * bx, ax * bx + ay * by)

    @classmethod
    def measure_lengths(cls, spirals) -> None:
        """Measure the arc lengths of many spirals in one vectorised quadrature (each caches its own)."""
        todo = [s for s in spirals if isinstance(s, cls) and s._length is None]
        if todo:
            for spiral, length in zip(todo, bezier.arc_length(np.stack([s._cp for s in todo])).tolist()):
                spiral._length = length

    @property
    def length(self) -> float:
        """Arc length by composite Gauss–Legendre (≤ 1e-14 relative for |θ| ≤ 80°)."""
        if self._length is None:  # immutable curve: integrate once
            self._length = bezier.arc_length(self._cp)
        return self._length

    def parameter_at(self, s: ArrayLike) -> NDArray:
        """Parameters u with arc length ``s`` from the start (Newton, to 1e-14·length)."""
        s = np.asarray(s, dtype=float)
        total = self.length
        u = np.clip(s / total, 0.0, 1.0)
        for _ in range(30):
            step = (bezier.arc_length(self._cp, u) - s) / np.linalg.norm(bezier.derivative(self._cp, u), axis=-1)
            u = np.clip(u - step, 0.0, 1.0)
            if np.all(np.abs(step) <= 1e-14):
                break
        return u

    def point(self, u: ArrayLike) -> NDArray:
        return bezier.point(self._cp, u)

    def tangent(self, u: ArrayLike) -> NDArray:
        return bezier.tangent(self._cp, u)

    def curvature(self, u: ArrayLike) -> NDArray | float:
        return bezier.curvature(self._cp, u)[()]

    def rounding_floor(self, at_end: bool) -> tuple[float, float, float]:
        """Rounding floor of the end frame: κ comes from differences of rounded
        control points, (2/3)(a × b)/|a|³ with a the end leg and b the middle leg."""
        (x0, y0), (x1, y1), (x2, y2), (x3, y3) = self._cp.tolist()
        delta = 4.0 * EPS * max(abs(x0), abs(y0), abs(x1), abs(y1), abs(x2), abs(y2), abs(x3), abs(y3))
        middle = math.hypot(x2 - x1, y2 - y1)
        a, b = (math.hypot(x3 - x2, y3 - y2), middle) if at_end else (math.hypot(x1 - x0, y1 - y0), middle)
        kappa = abs(self.end_curvature if at_end else self.start_curvature)
        return delta, delta / a, 2.0 / 3.0 * delta * (a + b) / a**3 + 3.0 * kappa * delta / a

    def piece(self, t0: float, t1: float) -> BezierSpiral:
        """Exact sub-curve on [t0, t1] (de Casteljau) as a Bézier on [0, 1]."""
        t0, t1 = piece_range(t0, t1)
        return BezierSpiral.from_control_points(bezier.split(self._cp, t0, t1), self._shape)

    def reversed(self) -> BezierSpiral:
        return BezierSpiral._wrap(self._cp[::-1].copy(), self._shape)
