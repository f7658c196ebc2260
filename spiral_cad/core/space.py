"""Planes in space: where plane geometry goes when a path leaves the plane.

Every spiral is planar (Walton & Meek §5), and so is every corner of a
polyline: the two legs span a plane. Plane geometry is solved in plane
coordinates (x, y) — the transitions and batch solvers as they are — and
then placed: a ``PlaneFrame`` maps (x, y) to origin + x·x_dir + y·y_dir.
``place`` does the same for arrays of points in arrays of frames (the
spirals of a million corners, each in its own plane) in one pass.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ._inputs import as_float, as_real_array

#: Legs whose |sin(turn)| is at most this span no plane.
COLLINEAR_TOL = 1e-12


def place(points: ArrayLike, origin: ArrayLike, x_dir: ArrayLike, y_dir: ArrayLike) -> NDArray:
    """Plane points (..., 2) in space: origin + x·x_dir + y·y_dir, shape (..., 3).

    ``origin``, ``x_dir`` and ``y_dir`` are (..., 3) and broadcast against the
    points' leading shape, so N frames place (N, k, 2) points as
    ``place(points, origin[:, None], x_dir[:, None], y_dir[:, None])``.
    """
    p = np.asarray(points, dtype=float)
    x, y = p[..., 0, None], p[..., 1, None]
    return origin + x * np.asarray(x_dir, dtype=float) + y * np.asarray(y_dir, dtype=float)


def _vector3(value: Any, name: str) -> NDArray:
    v = as_real_array(value, name)
    if v.shape not in ((2,), (3,)):
        raise ValueError(f"{name} must have 2 or 3 coordinates; got shape {v.shape}")
    out = np.zeros(3)
    out[: len(v)] = [as_float(c, f"{name}[{i}]") for i, c in enumerate(v.tolist())]
    return out


def _unit(v: NDArray, name: str) -> NDArray:
    length = math.hypot(*v.tolist())
    if not length > 0.0 or not math.isfinite(length):
        raise ValueError(f"{name} must be a non-zero finite vector; got {tuple(v.tolist())}")
    return v / length


@dataclass(frozen=True, init=False)
class PlaneFrame:
    """An orthonormal frame of a plane in space, like build123d's ``Plane(origin, x_dir, z_dir)``.

    Plane coordinates (x, y) lie at origin + x·x_dir + y·y_dir; ``normal`` =
    x_dir × y_dir, so a counterclockwise (positive) plane turn is
    counterclockwise about ``normal``.

    Args:
        origin: where (0, 0) lies (2 or 3 coordinates; default the origin).
        x_dir: the direction of the x axis (made perpendicular to ``normal``).
        normal: the plane's normal (default +z: the XY plane).

    Raises:
        ValueError: non-finite values, a zero ``normal``, or an ``x_dir`` along ``normal``.
    """

    origin: tuple[float, float, float]
    x_dir: tuple[float, float, float]
    y_dir: tuple[float, float, float]
    normal: tuple[float, float, float]

    def __init__(self, origin: Any = (0.0, 0.0, 0.0), x_dir: Any = (1.0, 0.0, 0.0), normal: Any = (0.0, 0.0, 1.0)):
        o = _vector3(origin, "origin")
        n = _unit(_vector3(normal, "normal"), "normal")
        x = _vector3(x_dir, "x_dir")
        x = _unit(x - float(np.dot(x, n)) * n, "x_dir off the normal")
        y = np.cross(n, x)
        for name, value in (("origin", o), ("x_dir", x), ("y_dir", y), ("normal", np.cross(x, y))):
            object.__setattr__(self, name, tuple(value.tolist()))

    @classmethod
    def of_corner(cls, before: Any, corner: Any, after: Any) -> PlaneFrame:
        """The plane of the corner before → corner → after: origin at ``corner``, x_dir along the
        incoming leg, normal along d_in × d_out, so the corner turns left (counterclockwise) in it.

        Raises:
            ValueError: a zero leg, or legs that are collinear (|sin| ≤ 1e-12) and span no plane.
        """
        a, p, b = (_vector3(v, name) for v, name in ((before, "before"), (corner, "corner"), (after, "after")))
        d_in = _unit(p - a, "the incoming leg")
        d_out = _unit(b - p, "the outgoing leg")
        turn = np.cross(d_in, d_out)
        if not math.hypot(*turn.tolist()) > COLLINEAR_TOL:
            raise ValueError(f"the corner at {tuple(p.tolist())} has collinear legs: they span no plane")
        return cls(p, d_in, turn)

    @property
    def basis(self) -> NDArray:
        """(2, 3): x_dir and y_dir."""
        return np.array([self.x_dir, self.y_dir])

    def point(self, xy: ArrayLike) -> NDArray:
        """Plane points (..., 2) in space (..., 3)."""
        return place(xy, self.origin, self.x_dir, self.y_dir)

    def vector(self, xy: ArrayLike) -> NDArray:
        """Plane vectors (..., 2) in space (..., 3) (directions: no origin)."""
        return place(xy, (0.0, 0.0, 0.0), self.x_dir, self.y_dir)

    def local(self, xyz: ArrayLike) -> NDArray:
        """Plane coordinates (..., 2) of points (..., 3): their projection onto the plane."""
        d = np.asarray(xyz, dtype=float) - self.origin
        return np.stack([d @ self.x_dir, d @ self.y_dir], axis=-1)
