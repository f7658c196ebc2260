"""The cubic Bézier spiral (Walton & Meek's Theorem 3.1, or another shape) as a path segment."""

from __future__ import annotations

import math
from typing import Any, cast

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import _kernel_spiral as KS
from . import bezier
from .errors import Status
from .inputs import as_float, as_xy
from .kinds import SPIRAL
from .messages import error_for
from .segments import EPS, PLANE_TOL, Segment, piece_range
from .shapes import DEFAULT_SHAPE, SHAPE_CODES, TRANSITION_SHAPES, shape_code
from .space import PlaneFrame


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
    of the same shape; for them ``start_curvature`` need not be 0. A spiral
    in space — ``placed`` in a ``PlaneFrame``, or ``from_control_points``
    with (4, 3) points in one plane — is the same planar cubic; its curvature
    is κ ≥ 0 and ``normal`` is the binormal it turns about.
    """

    def __init__(self, start: Any, direction: Any, theta: float, curvature: float, shape: str = DEFAULT_SHAPE) -> None:
        bx, by = as_xy(start, "start")
        dx, dy = as_xy(direction, "direction")
        theta = as_float(theta, "theta")
        curvature = as_float(curvature, "curvature")
        code = shape_code(shape, TRANSITION_SHAPES)
        out = np.empty((1, 1, 4, 2))
        status, _, measure, _ = KS.KERNELS.for_scalar_call().spiral_row(bx, by, dx, dy, theta, curvature, code, out, 0)
        if status != Status.OK:
            inputs = dict(start=(bx, by), direction=(dx, dy), theta=theta, curvature=curvature, shape=shape)
            raise error_for("BezierSpiral", status, measure, inputs)
        self._cp: NDArray[np.float64] = out[0, 0]
        self._dim: int = 2
        self._length: float | None = None
        self._shape: str | None = shape
        self._cp.setflags(write=False)

    @classmethod
    def from_control_points(cls, control_points: ArrayLike, shape: str | None = None) -> BezierSpiral:
        """Wrap control points that are known to form a spiral (or a piece of one).

        No check is made that the curvature is monotone or that the legs are
        those of ``shape``; use the solvers or the constructor to make spirals.

        Args:
            control_points: (4, 2) control points in travel order, or (4, 3) for
                a spiral in space (z = 0 everywhere: a plane spiral). A spiral
                in space is a planar cubic (``placed`` makes one from a plane spiral).
            shape: the shape the points were made with, if known (reported
                by ``shape``; None: not stated).

        Raises:
            ValueError: not a finite (4, 2) or (4, 3) array, an end leg of zero
                length (no end tangent: a degenerate spiral), control points in
                space off one plane (beyond 1e-9 of the legs plus rounding), or
                an unknown shape.
        """
        if shape is not None and shape not in SHAPE_CODES:
            shape_code(shape, tuple(SHAPE_CODES))
        cp = np.array(control_points, dtype=float)
        if cp.shape not in ((4, 2), (4, 3)):
            raise ValueError(f"control_points must have shape (4, 2) or (4, 3); got {cp.shape}")
        if not np.isfinite(cp).all():
            raise ValueError(f"control_points must be finite; got {cp.tolist()}")
        dim: int = cp.shape[1]  # as an int: mypy would narrow cp.shape to the first shape allowed above
        if dim == 3 and not cp[:, 2].any():
            cp = np.ascontiguousarray(cp[:, :2])
        for leg, (a, b) in (("first", (0, 1)), ("last", (2, 3))):
            if np.array_equal(cp[a], cp[b]) or not np.isfinite(cp[b] - cp[a]).all():
                raise ValueError(
                    f"control_points make a degenerate spiral: the {leg} leg from {cp[a].tolist()} to {cp[b].tolist()} has no direction"
                )
        if cp.shape[1] == 3:
            _check_planar(cp)
        return cls._wrap(cp, shape)

    @classmethod
    def _wrap(cls, cp: NDArray[np.float64], shape: str | None, length: float | None = None) -> BezierSpiral:
        """Adopt a finite (4, 2) or (4, 3) float64 array without copying or checks (solver output)."""
        spiral = object.__new__(cls)
        cp.setflags(write=False)
        spiral._cp = cp
        spiral._dim = cp.shape[1]
        spiral._length = length
        spiral._shape = shape
        return spiral

    def __repr__(self) -> str:
        return f"BezierSpiral.from_control_points({self._cp.tolist()}, shape={self._shape!r})"

    @property
    def shape(self) -> str | None:
        """The shape the spiral was made with (``"walton-meek"``, ``"near-linear"``, ``"g2cbs"``; None if not stated)."""
        return self._shape

    @property
    def control_points(self) -> NDArray[np.float64]:
        """(4, 2) float64 control points in travel order, (4, 3) in space (read-only)."""
        return self._cp

    def _row(self) -> tuple[int, NDArray[np.float64], tuple[float, float, float]]:
        geometry = np.zeros((4, 3))
        geometry[:, : self._dim] = self._cp
        return SPIRAL, geometry, (0.0, 0.0, 0.0)

    def outline(self) -> list[tuple[float, ...]]:
        return [tuple(p) for p in self._cp.tolist()]

    @property
    def theta(self) -> float:
        """Angle from the start tangent to the end tangent: signed in the plane, ≥ 0 in space."""
        return float(turn_angles(self._cp[None])[0])

    @property
    def normal(self) -> NDArray[np.float64]:
        """Unit normal (3,) of the spiral's plane: (0, 0, 1) in the plane (curvature signed about it);
        in space the binormal the spiral turns counterclockwise about.

        Raises:
            ValueError: a straight spiral in space (its legs span no plane).
        """
        if self._dim == 2:
            return np.array([0.0, 0.0, 1.0])
        n = _turn(self._cp)
        size = math.hypot(*n.tolist())
        if not size > 0.0:
            raise ValueError("a straight spiral in space has no plane")
        return n / size

    @property
    def length(self) -> float:
        """Arc length by composite Gauss–Legendre (≤ 1e-14 relative for |θ| ≤ 80°)."""
        if self._length is None:  # immutable curve: integrate once
            self._length = cast(float, bezier.arc_length(self._cp))  # one curve: a float
        return self._length

    def parameter_at(self, s: ArrayLike) -> NDArray[np.float64]:
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

    def point(self, u: ArrayLike) -> NDArray[np.float64]:
        return bezier.point(self._cp, u)

    def tangent(self, u: ArrayLike) -> NDArray[np.float64]:
        return bezier.tangent(self._cp, u)

    def curvature(self, u: ArrayLike) -> NDArray[np.float64] | float:
        if self._dim == 2:
            return bezier.curvature(self._cp, u)[()]
        kappa: NDArray[np.float64] | float = np.linalg.norm(self.curvature_vector(u), axis=-1)[()]
        return kappa

    def curvature_vector(self, u: ArrayLike) -> NDArray[np.float64]:
        """κN = ((Q' × Q'') × Q') / |Q'|⁴, on the control points scaled by a power of two (any magnitude)."""
        scale = math.ldexp(1.0, math.frexp(float(np.abs(np.diff(self._cp, axis=0)).max()))[1])
        cp = np.zeros((4, 3))
        cp[:, : self._dim] = self._cp / scale
        d1, d2 = (bezier.derivative(cp, u, order) for order in (1, 2))
        speed2 = np.einsum("...i,...i->...", d1, d1)
        k = np.cross(np.cross(d1, d2), d1) / (speed2 * speed2)[..., None] / scale
        vector: NDArray[np.float64] = k[..., : self._dim]
        return vector

    def piece(self, t0: float, t1: float) -> BezierSpiral:
        """Exact sub-curve on [t0, t1] (de Casteljau) as a Bézier on [0, 1]."""
        t0, t1 = piece_range(t0, t1)
        return BezierSpiral.from_control_points(bezier.split(self._cp, t0, t1), self._shape)

    def reversed(self) -> BezierSpiral:
        return BezierSpiral._wrap(self._cp[::-1].copy(), self._shape)

    def placed(self, frame: PlaneFrame) -> BezierSpiral:
        self._plane_only("placed")
        return BezierSpiral._wrap(frame.point(self._cp), self._shape)


def turn_angles(control_points: NDArray[np.float64]) -> NDArray[np.float64]:
    """The turn from start to end tangent of N cubics (N, 4, 2 or 3): signed in the plane, ≥ 0 in space."""
    a = control_points[:, 1] - control_points[:, 0]
    c = control_points[:, 3] - control_points[:, 2]
    size = np.maximum(np.abs(a).max(axis=1), np.abs(c).max(axis=1))
    far = ~((size > 1e-100) & (size < 1e100))
    if far.any():  # products of legs would leave float64: scale those rows by a power of two (exact)
        scale = np.ldexp(1.0, np.frexp(size[far])[1])[:, None]
        a[far], c[far] = a[far] / scale, c[far] / scale
    if a.shape[1] == 2:
        cross = a[:, 0] * c[:, 1] - a[:, 1] * c[:, 0]
        dot = a[:, 0] * c[:, 0] + a[:, 1] * c[:, 1]
    else:
        cross = np.linalg.norm(np.cross(a, c), axis=1)
        dot = np.einsum("ij,ij->i", a, c)
    # math.atan2, not np.arctan2: the same bits on every machine (numpy may use SIMD variants).
    return np.array([math.atan2(y, x) for y, x in zip(cross.tolist(), dot.tolist())])


def _turn(cp: NDArray[np.float64]) -> NDArray[np.float64]:
    """(a + b) × c of the legs a, b, c: along the binormal of a planar cubic that turns one way
    (a × b vanishes where a spiral starts straight, so it is not used alone)."""
    legs = np.diff(cp, axis=0)
    legs /= math.ldexp(1.0, math.frexp(float(np.abs(legs).max()))[1])  # exact: no |leg|² overflow
    return np.cross(legs[0] + legs[1], legs[2])


def _check_planar(cp: NDArray[np.float64]) -> None:
    """ValueError unless the (4, 3) control points lie in one plane (1e-9 of the legs plus rounding)."""
    n = _turn(cp)
    size = math.hypot(*n.tolist())
    if not size > 0.0:
        return  # collinear legs: a straight cubic lies in every plane through it
    legs = np.diff(cp, axis=0)
    off = float(np.abs(legs @ (n / size)).max())  # |leg · n̂|: no products of two legs
    allowed = PLANE_TOL * float(np.linalg.norm(legs, axis=1).max()) + 8.0 * EPS * float(np.abs(cp).max())
    if not off <= allowed:
        raise ValueError(
            f"control_points in space must lie in one plane (a spiral is planar): a leg leaves the plane of the others "
            f"by {off:.3g} (allowed {allowed:.3g})"
        )
