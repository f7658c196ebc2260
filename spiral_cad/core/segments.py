"""Path segments with one evaluation interface: Line, Arc and the base class.

Every segment is parametrised by u ∈ [0, 1] in travel order; curvature is
signed (positive turns left).
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from dataclasses import dataclass
from functools import cached_property
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ._inputs import as_float, as_xy

TAU = 2.0 * math.pi
EPS = float(np.finfo(float).eps)


#: One end of a segment as plain floats: x, y, unit tangent (travel sense) and signed curvature.
End = tuple[float, float, float, float, float]


class Segment(ABC):
    """Common interface of ``Line``, ``Arc`` and ``BezierSpiral``."""

    @abstractmethod
    def _end_frames(self) -> tuple[End, End]:
        """Start and end frames, computed with plain floats (chains check thousands of joints)."""

    @cached_property
    def ends(self) -> tuple[End, End]:
        """(start, end) frames: point, unit tangent in travel sense and signed curvature, as floats."""
        return self._end_frames()

    @abstractmethod
    def point(self, u: ArrayLike) -> NDArray:
        """Points at parameters ``u`` (shape ``u.shape + (2,)``)."""

    @abstractmethod
    def tangent(self, u: ArrayLike) -> NDArray:
        """Unit tangents in travel direction at ``u``."""

    @abstractmethod
    def curvature(self, u: ArrayLike) -> NDArray | float:
        """Signed curvature at ``u``."""

    @property
    @abstractmethod
    def length(self) -> float:
        """Arc length."""

    @abstractmethod
    def reversed(self) -> Segment:
        """The same curve travelled the other way (curvature changes sign)."""

    @abstractmethod
    def piece(self, t0: float, t1: float) -> Segment:
        """The part between parameters ``t0`` < ``t1`` as a segment on [0, 1]."""

    def parameter_at(self, s: ArrayLike) -> NDArray:
        """Parameters u where the arc length from the start equals ``s``."""
        return _u(s) / self.length

    def outline(self) -> list[tuple[float, float]]:
        """A few points whose box is about the segment's box (start, end and middle; a
        spiral gives its control points, whose hull holds it)."""
        mid = self.point(0.5)
        return [self.ends[0][:2], self.ends[1][:2], (float(mid[0]), float(mid[1]))]

    def rounding_floor(self, at_end: bool) -> tuple[float, float, float]:
        """(gap, tangent angle, curvature) that float64 rounding of the stored
        coordinates can hide at the start or end (exact types: only the gap)."""
        x, y = self.ends[1 if at_end else 0][:2]
        return 4.0 * EPS * max(abs(x), abs(y)), 0.0, 0.0

    @property
    def start(self) -> NDArray:
        return np.array(self.ends[0][:2])

    @property
    def end(self) -> NDArray:
        return np.array(self.ends[1][:2])

    @property
    def start_tangent(self) -> NDArray:
        return np.array(self.ends[0][2:4])

    @property
    def end_tangent(self) -> NDArray:
        return np.array(self.ends[1][2:4])

    @property
    def start_curvature(self) -> float:
        return self.ends[0][4]

    @property
    def end_curvature(self) -> float:
        return self.ends[1][4]


def _u(u: ArrayLike) -> NDArray:
    return np.asarray(u, dtype=float)


def piece_range(t0: Any, t1: Any) -> tuple[float, float]:
    """``(t0, t1)`` as floats with 0 ≤ t0 < t1 ≤ 1, else ValueError naming both."""
    t0 = as_float(t0, "t0")
    t1 = as_float(t1, "t1")
    if not 0.0 <= t0 < t1 <= 1.0:
        raise ValueError(f"piece needs 0 ≤ t0 < t1 ≤ 1; got t0 = {t0}, t1 = {t1}")
    return t0, t1


class Line(Segment):
    """Straight segment from ``start`` to ``end`` (distinct points)."""


    def __init__(self, start: Any, end: Any):
        self._a = np.array(as_xy(start, "start"))
        self._b = np.array(as_xy(end, "end"))
        if np.array_equal(self._a, self._b):
            raise ValueError(f"Line needs distinct end points; both are {tuple(self._a.tolist())}")
        if not math.isfinite(self.length):
            raise ValueError(
                f"Line end points {tuple(self._a.tolist())} and {tuple(self._b.tolist())} are too far apart for float64"
            )

    def __repr__(self) -> str:
        return f"Line({tuple(self._a.tolist())}, {tuple(self._b.tolist())})"

    def outline(self) -> list[tuple[float, float]]:
        return [self.ends[0][:2], self.ends[1][:2]]

    def _end_frames(self) -> tuple[End, End]:
        (ax, ay), (bx, by) = self._a.tolist(), self._b.tolist()
        length = self.length
        tx, ty = (bx - ax) / length, (by - ay) / length
        return (ax, ay, tx, ty, 0.0), (bx, by, tx, ty, 0.0)

    @property
    def length(self) -> float:
        return float(np.hypot(*(self._b - self._a)))

    def point(self, u: ArrayLike) -> NDArray:
        return self._a + _u(u)[..., None] * (self._b - self._a)

    def tangent(self, u: ArrayLike) -> NDArray:
        d = (self._b - self._a) / self.length
        return np.broadcast_to(d, _u(u).shape + (2,)).copy()

    def curvature(self, u: ArrayLike) -> NDArray | float:
        return np.zeros_like(_u(u))[()]

    def reversed(self) -> Line:
        return Line(self._b, self._a)

    def rounding_floor(self, at_end: bool) -> tuple[float, float, float]:
        delta = 4.0 * EPS * max(abs(v) for v in (*self.ends[0][:2], *self.ends[1][:2]))
        return delta, delta / self.length, 0.0

    def piece(self, t0: float, t1: float) -> Line:
        t0, t1 = piece_range(t0, t1)
        return Line(self.point(t0), self.point(t1))


@dataclass(frozen=True)
class Ray:
    """A directed line: a point on it and its travel direction."""

    point: tuple[float, float]
    direction: tuple[float, float]

    def reversed(self) -> Ray:
        return Ray(self.point, (-self.direction[0], -self.direction[1]))


@dataclass(frozen=True)
class Circle:
    """A circle with a travel sense: ``radius`` > 0 counterclockwise, < 0 clockwise."""

    center: tuple[float, float]
    radius: float

    def reversed(self) -> Circle:
        return Circle(self.center, -self.radius)


class Arc(Segment):
    """Circular arc travelled ``sweep`` radians from polar angle ``start_angle``.

    Args:
        center: centre point.
        radius: signed radius; positive travels counterclockwise.
        start_angle: polar angle of the start point about ``center`` (radians).
        sweep: angle travelled, in (0, 2π] (radians); the sense comes from ``radius``.

    Raises:
        ValueError: non-finite values, zero radius, a sweep outside (0, 2π],
            or a radius too small to resolve at the centre's coordinates.
    """


    def __init__(self, center: Any, radius: float, start_angle: float, sweep: float):
        self._c = np.array(as_xy(center, "center"))
        self._r = as_float(radius, "radius")
        if self._r == 0.0:
            raise ValueError("Arc radius must be non-zero (its sign is the travel sense); got 0.0")
        self._a0 = as_float(start_angle, "start_angle")
        self._sweep = as_float(sweep, "sweep")
        if not 0.0 < self._sweep <= TAU:
            raise ValueError(f"Arc sweep must lie in (0, 2π] (the sense comes from the radius); got {self._sweep}")
        if not abs(self._r) > 4.0 * EPS * float(np.abs(self._c).max()) or not self.length > 0.0:
            raise ValueError(
                f"Arc radius {self._r} with sweep {self._sweep} is below float64's resolution at centre "
                f"{tuple(self._c.tolist())}: its points would coincide"
            )

    @classmethod
    def between(cls, center: Any, radius: float, start: Any, end: Any) -> Arc:
        """Arc on circle (center, radius) from the polar angle of ``start`` to that of ``end``.

        The sweep is taken in the travel sense of ``radius`` and lies in (0, 2π):
        ``start`` and ``end`` must lie at different polar angles.
        """
        cx, cy = as_xy(center, "center")
        sx, sy = as_xy(start, "start")
        ex, ey = as_xy(end, "end")
        radius = as_float(radius, "radius")
        a0 = math.atan2(sy - cy, sx - cx)
        a1 = math.atan2(ey - cy, ex - cx)
        sweep = math.copysign(1.0, radius) * (a1 - a0) % TAU
        return cls((cx, cy), radius, a0, sweep)

    def __repr__(self) -> str:
        return f"Arc(center={tuple(self._c.tolist())}, radius={self._r}, start_angle={self._a0}, sweep={self._sweep})"

    @property
    def center(self) -> NDArray:
        return self._c.copy()

    @property
    def radius(self) -> float:
        return self._r

    @property
    def start_angle(self) -> float:
        return self._a0

    @property
    def sweep(self) -> float:
        return self._sweep

    @property
    def circle(self) -> Circle:
        return Circle((float(self._c[0]), float(self._c[1])), self._r)

    @property
    def length(self) -> float:
        return abs(self._r) * self._sweep

    def _end_frames(self) -> tuple[End, End]:
        (cx, cy), r = self._c.tolist(), abs(self._r)
        sense = math.copysign(1.0, self._r)
        frames = []
        for angle in (self._a0, self._a0 + sense * self._sweep):
            c, s = math.cos(angle), math.sin(angle)
            frames.append((cx + r * c, cy + r * s, -sense * s, sense * c, 1.0 / self._r))
        return frames[0], frames[1]

    def _angle(self, u: ArrayLike) -> NDArray:
        return self._a0 + math.copysign(self._sweep, self._r) * _u(u)

    def point(self, u: ArrayLike) -> NDArray:
        a = self._angle(u)
        return self._c + abs(self._r) * np.stack([np.cos(a), np.sin(a)], axis=-1)

    def tangent(self, u: ArrayLike) -> NDArray:
        a = self._angle(u)
        s = math.copysign(1.0, self._r)
        return s * np.stack([-np.sin(a), np.cos(a)], axis=-1)

    def curvature(self, u: ArrayLike) -> NDArray | float:
        return np.full_like(_u(u), 1.0 / self._r)[()]

    def reversed(self) -> Arc:
        return Arc(self._c, -self._r, float(self._angle(1.0)), self._sweep)

    def piece(self, t0: float, t1: float) -> Arc:
        t0, t1 = piece_range(t0, t1)
        return Arc(self._c, self._r, float(self._angle(t0)), self._sweep * (t1 - t0))


@dataclass(frozen=True)
class Join:
    """Mismatch at the joint between segments ``index`` and ``index + 1``."""

    index: int
    gap: float
    angle: float
    curvature_jump: float


def measure_join(a: Segment, b: Segment, index: int = 0) -> Join:
    """Position gap, tangent angle (rad) and curvature jump from ``a``'s end to ``b``'s start."""
    ax, ay, tax, tay, ka = a.ends[1]
    bx, by, tbx, tby, kb = b.ends[0]
    angle = abs(math.atan2(tax * tby - tay * tbx, tax * tbx + tay * tby))
    return Join(index, math.hypot(bx - ax, by - ay), angle, abs(kb - ka))
