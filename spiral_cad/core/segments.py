"""Path segments with one evaluation interface: Line, Arc and the base class.

Every segment is parametrised by u ∈ [0, 1] in travel order. A segment lies
in the plane (``dim`` 2: points (x, y), curvature signed, positive turns
left) or in space (``dim`` 3: points (x, y, z), curvature κ ≥ 0 with its
direction given by ``curvature_vector``, κN). Points given with z = 0 are
plane points, as everywhere in the API; a plane segment is lifted into
space by ``placed`` (``spiral_cad.core.space.PlaneFrame``), and a chain
holding both kinds takes its plane segments in the XY plane.

Space arcs and spirals are planar: an arc turns about its ``normal``, a
spiral is a planar cubic (its ``normal`` is the binormal it turns about).
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from dataclasses import dataclass
from functools import cached_property
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import _chain_kernels as CK
from .inputs import as_float, as_point, as_xy
from .kinds import ARC, LINE
from .space import PlaneFrame

TAU = 2.0 * math.pi
EPS = float(np.finfo(float).eps)
#: Largest |n · e| (cosine) between a space arc's normal and its start direction.
PLANE_TOL = 1e-9


#: One end of a plane segment as plain floats: x, y, unit tangent (travel sense) and signed curvature.
End = tuple[float, float, float, float, float]


def lifted(point: tuple[float, ...], dim: int) -> tuple[float, ...]:
    """A plane point with z = 0 appended when ``dim`` is 3."""
    return point + (0.0,) * (dim - len(point))


def row_frames(
    kind: NDArray[np.int8], geometry: NDArray[np.float64], params: NDArray[np.float64], dim: int
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """End frames (n, 2, 9), rounding floors (n, 2, 3) and lengths (n,; NaN for spirals) of segment rows.

    The layout of rows and frames is described in ``spiral_cad.core._chain_kernels``.
    """
    n = len(kind)
    frames = np.empty((n, 2, 9))
    floors = np.empty((n, 2, 3))
    lengths = np.full(n, np.nan)
    CK.segment_ends(kind, geometry, params, dim == 2, frames, floors, lengths)
    return frames, floors, lengths


class Segment(ABC):
    """Common interface of ``Line``, ``Arc`` and ``BezierSpiral`` (plane or space)."""

    _dim = 2

    @property
    def dim(self) -> int:
        """2 for a plane segment, 3 for a segment in space."""
        return self._dim

    @abstractmethod
    def _row(self) -> tuple[int, NDArray[np.float64], tuple[float, float, float]]:
        """(kind, geometry (4, 3), params): the segment as a row of a chain's arrays (``_chain_kernels``)."""

    @cached_property
    def _ends(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """End frames (2, 9) and rounding floors (2, 3), from the same kernel chains use."""
        kind, geometry, params = self._row()
        frames, floors, _ = row_frames(np.array([kind], dtype=np.int8), geometry[None], np.array([params]), self._dim)
        return frames[0], floors[0]

    @property
    def ends(self) -> tuple[End, End]:
        """(start, end) frames of a plane segment: point, unit tangent in travel sense and signed curvature, as floats.

        Raises:
            ValueError: a segment in space (use ``start``, ``start_tangent``, ``start_curvature_vector``, …).
        """
        if self._dim != 2:
            raise ValueError("ends holds plane frames; a segment in space has start, start_tangent, start_curvature_vector, …")
        (x0, y0, _, tx0, ty0, _, _, _, k0), (x1, y1, _, tx1, ty1, _, _, _, k1) = self._ends[0].tolist()
        return (x0, y0, tx0, ty0, k0), (x1, y1, tx1, ty1, k1)

    @abstractmethod
    def point(self, u: ArrayLike) -> NDArray[np.float64]:
        """Points at parameters ``u`` (shape ``u.shape + (dim,)``)."""

    @abstractmethod
    def tangent(self, u: ArrayLike) -> NDArray[np.float64]:
        """Unit tangents in travel direction at ``u``."""

    @abstractmethod
    def curvature(self, u: ArrayLike) -> NDArray[np.float64] | float:
        """Curvature at ``u``: signed in the plane (positive turns left), κ ≥ 0 in space."""

    @abstractmethod
    def curvature_vector(self, u: ArrayLike) -> NDArray[np.float64]:
        """The curvature vector κN at ``u`` (shape ``u.shape + (dim,)``): towards the centre of curvature, |κN| = |κ|."""

    @property
    @abstractmethod
    def length(self) -> float:
        """Arc length."""

    @abstractmethod
    def reversed(self) -> Segment:
        """The same curve travelled the other way (a plane curvature changes sign)."""

    @abstractmethod
    def piece(self, t0: float, t1: float) -> Segment:
        """The part between parameters ``t0`` < ``t1`` as a segment on [0, 1]."""

    @abstractmethod
    def placed(self, frame: PlaneFrame) -> Segment:
        """This plane segment in space: (x, y) ↦ ``frame.point((x, y))`` (the same parameters, so the same lengths).

        Raises:
            ValueError: the segment is already in space.
        """

    def _plane_only(self, what: str) -> None:
        if self._dim != 2:
            raise ValueError(f"{what} takes a plane segment; this {type(self).__name__} is already in space")

    def parameter_at(self, s: ArrayLike) -> NDArray[np.float64]:
        """Parameters u where the arc length from the start equals ``s``."""
        return _u(s) / self.length

    def outline(self) -> list[tuple[float, ...]]:
        """A few points whose box is about the segment's box (start, end and middle; a
        spiral gives its control points, whose hull holds it)."""
        frames = self._ends[0]
        return [tuple(frames[0, : self._dim].tolist()), tuple(frames[1, : self._dim].tolist()), tuple(self.point(0.5).tolist())]

    def rounding_floor(self, at_end: bool) -> tuple[float, float, float]:
        """(gap, tangent angle, curvature) that float64 rounding of the stored coordinates can hide at
        the start or end (a relative floor evaluated on a copy scaled by a power of two, so at any magnitude)."""
        gap, angle, curvature = self._ends[1][1 if at_end else 0].tolist()
        return gap, angle, curvature

    @property
    def start(self) -> NDArray[np.float64]:
        return self._ends[0][0, : self._dim].copy()

    @property
    def end(self) -> NDArray[np.float64]:
        return self._ends[0][1, : self._dim].copy()

    @property
    def start_tangent(self) -> NDArray[np.float64]:
        return self._ends[0][0, 3 : 3 + self._dim].copy()

    @property
    def end_tangent(self) -> NDArray[np.float64]:
        return self._ends[0][1, 3 : 3 + self._dim].copy()

    def _end_curvature(self, end: int) -> float:
        frame = self._ends[0][end]
        return float(frame[8]) if self._dim == 2 else float(CK.norm3(frame[6], frame[7], frame[8]))

    @property
    def start_curvature(self) -> float:
        """Curvature at the start: signed in the plane, κ ≥ 0 in space."""
        return self._end_curvature(0)

    @property
    def end_curvature(self) -> float:
        """Curvature at the end: signed in the plane, κ ≥ 0 in space."""
        return self._end_curvature(1)

    def _end_curvature_vector(self, end: int) -> NDArray[np.float64]:
        frame = self._ends[0][end]
        return np.cross(frame[6:9], frame[3:6])[: self._dim]  # κN = ω × T (ω = κB)

    @property
    def start_curvature_vector(self) -> NDArray[np.float64]:
        """κN at the start (``dim`` components)."""
        return self._end_curvature_vector(0)

    @property
    def end_curvature_vector(self) -> NDArray[np.float64]:
        """κN at the end (``dim`` components)."""
        return self._end_curvature_vector(1)


def _u(u: ArrayLike) -> NDArray[np.float64]:
    return np.asarray(u, dtype=float)


def norm(v: NDArray[np.float64]) -> float:
    """|v| of a 2- or 3-vector as the kernels compute it (``_chain_kernels.norm3``)."""
    return float(CK.norm3(*(v.tolist() + [0.0] * (3 - len(v)))))


def piece_range(t0: Any, t1: Any) -> tuple[float, float]:
    """``(t0, t1)`` as floats with 0 ≤ t0 < t1 ≤ 1, else ValueError naming both."""
    t0 = as_float(t0, "t0")
    t1 = as_float(t1, "t1")
    if not 0.0 <= t0 < t1 <= 1.0:
        raise ValueError(f"piece needs 0 ≤ t0 < t1 ≤ 1; got t0 = {t0}, t1 = {t1}")
    return t0, t1


class Line(Segment):
    """Straight segment from ``start`` to ``end`` (distinct points, 2-D or 3-D).

    Raises:
        ValueError: equal or non-finite points, or points too far apart for float64.
    """

    def __init__(self, start: Any, end: Any):
        a, b = as_point(start, "start"), as_point(end, "end")
        dim = max(len(a), len(b))
        a, b = lifted(a, dim), lifted(b, dim)
        self._set(np.array(a), np.array(b))
        if a == b:
            raise ValueError(f"Line needs distinct end points; both are {tuple(self._a.tolist())}")
        if max(map(abs, a + b)) > 1e300 and not math.isfinite(self.length):  # below, the length is finite
            raise ValueError(f"Line end points {tuple(self._a.tolist())} and {tuple(self._b.tolist())} are too far apart for float64")

    def _set(self, a: NDArray[np.float64], b: NDArray[np.float64]) -> None:
        self._a, self._b, self._dim = a, b, len(a)

    @classmethod
    def _of(cls, a: NDArray[np.float64], b: NDArray[np.float64]) -> Line:
        """Adopt two checked end points (2 or 3 coordinates) without copying or checks."""
        line = object.__new__(cls)
        line._set(a, b)
        return line

    def __repr__(self) -> str:
        return f"Line({tuple(self._a.tolist())}, {tuple(self._b.tolist())})"

    def _row(self) -> tuple[int, NDArray[np.float64], tuple[float, float, float]]:
        geometry = np.zeros((4, 3))
        geometry[0, : self._dim], geometry[1, : self._dim] = self._a, self._b
        return LINE, geometry, (0.0, 0.0, 0.0)

    def outline(self) -> list[tuple[float, ...]]:
        return [tuple(self._a.tolist()), tuple(self._b.tolist())]

    @property
    def length(self) -> float:
        return norm(self._b - self._a)

    def point(self, u: ArrayLike) -> NDArray[np.float64]:
        return self._a + _u(u)[..., None] * (self._b - self._a)

    def tangent(self, u: ArrayLike) -> NDArray[np.float64]:
        d = (self._b - self._a) / self.length
        return np.broadcast_to(d, _u(u).shape + (self._dim,)).copy()

    def curvature(self, u: ArrayLike) -> NDArray[np.float64] | float:
        return np.zeros_like(_u(u))[()]

    def curvature_vector(self, u: ArrayLike) -> NDArray[np.float64]:
        return np.zeros(_u(u).shape + (self._dim,))

    def reversed(self) -> Line:
        return Line._of(self._b.copy(), self._a.copy())

    def piece(self, t0: float, t1: float) -> Line:
        t0, t1 = piece_range(t0, t1)
        return Line._of(self.point(t0), self.point(t1))

    def placed(self, frame: PlaneFrame) -> Line:
        self._plane_only("placed")
        return Line._of(frame.point(self._a), frame.point(self._b))


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


#: The plane basis of plane arcs (the x and y axes).
_XY_BASIS = np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
#: The normal of a plane arc (``Arc.normal`` of the XY plane): e1 × e2 of ``_XY_BASIS``.
_XY_NORMAL = np.cross(_XY_BASIS[0], _XY_BASIS[1])
_XY_BASIS.flags.writeable = False


class Arc(Segment):
    """Circular arc travelled ``sweep`` radians from polar angle ``start_angle``.

    Args:
        center: centre point (x, y).
        radius: signed radius; positive travels counterclockwise.
        start_angle: polar angle of the start point about ``center`` (radians).
        sweep: angle travelled, in (0, 2π] (radians); the sense comes from ``radius``.

    Arcs in space are made by ``Arc.in_space`` (centre, normal, start point
    and signed sweep) or by ``placed``; their polar angles are taken in the
    plane basis (e1, e2) with e1 × e2 = ``normal``, and a positive radius
    turns counterclockwise about ``normal``.

    Raises:
        ValueError: non-finite values, zero radius, a sweep outside (0, 2π],
            or a radius too small to resolve at the centre's coordinates.
    """

    def __init__(self, center: Any, radius: float, start_angle: float, sweep: float):
        self._set(np.array(as_xy(center, "center")), as_float(radius, "radius"), as_float(start_angle, "start_angle"),
                  as_float(sweep, "sweep"), None)  # fmt: skip
        self._check()

    def _set(self, center: NDArray[np.float64], radius: float, start_angle: float, sweep: float, basis: NDArray[np.float64] | None) -> None:
        self._c, self._r, self._a0, self._sweep, self._basis = center, radius, start_angle, sweep, basis
        self._dim = len(center)

    def _check(self) -> None:
        if self._r == 0.0:
            raise ValueError("Arc radius must be non-zero (its sign is the travel sense); got 0.0")
        if not 0.0 < self._sweep <= TAU:
            raise ValueError(f"Arc sweep must lie in (0, 2π] (the sense comes from the radius); got {self._sweep}")
        if not abs(self._r) > 4.0 * EPS * float(np.abs(self._c).max()) or not self.length > 0.0:
            raise ValueError(
                f"Arc radius {self._r} with sweep {self._sweep} is below float64's resolution at centre "
                f"{tuple(self._c.tolist())}: its points would coincide"
            )

    @classmethod
    def _of(
        cls, center: NDArray[np.float64], radius: float, start_angle: float, sweep: float, basis: NDArray[np.float64] | None = None
    ) -> Arc:
        """Adopt checked values without copying or checks (``basis`` (2, 3) for an arc in space)."""
        arc = object.__new__(cls)
        arc._set(center, radius, start_angle, sweep, basis)
        return arc

    @classmethod
    def in_space(cls, center: Any, normal: Any, start: Any, sweep: float) -> Arc:
        """The arc in space about ``center`` from the point ``start``, turning ``sweep`` radians about ``normal``.

        Args:
            center: centre (x, y, z).
            normal: the axis of the arc's plane (any non-zero length); a positive
                sweep turns counterclockwise seen from its tip (right-hand rule).
            start: the start point; the radius is its distance from ``center``.
            sweep: signed angle travelled, 0 < |sweep| ≤ 2π.

        Raises:
            ValueError: non-finite values, a zero normal, a start at the centre or
                off the plane through ``center`` normal to ``normal`` (|cos| > 1e-9),
                a sweep outside [-2π, 0) ∪ (0, 2π], or a radius too small for the coordinates.
        """
        c = np.array(lifted(as_point(center, "center"), 3))
        n = np.array(lifted(as_point(normal, "normal"), 3))
        d = np.array(lifted(as_point(start, "start"), 3)) - c
        sweep = as_float(sweep, "sweep")
        radius, size = norm(d), norm(n)
        if not size > 0.0:
            raise ValueError(f"Arc normal must be a non-zero vector; got {tuple(n.tolist())}")
        if not radius > 0.0 or not math.isfinite(radius):
            raise ValueError(
                f"Arc start {tuple((d + c).tolist())} must lie at a finite non-zero distance from the centre {tuple(c.tolist())}"
            )
        e1, n = d / radius, n / size
        off = float(np.dot(n, e1))
        if abs(off) > PLANE_TOL:
            raise ValueError(
                f"Arc start {tuple((d + c).tolist())} is off the plane through the centre normal to {tuple((n * size).tolist())}: "
                f"the angle between start direction and normal is {math.degrees(math.acos(max(-1.0, min(1.0, off)))):.9g}°, not 90°"
            )
        axis = n - off * e1
        axis /= norm(axis)
        arc = cls._of(c, math.copysign(radius, sweep), 0.0, abs(sweep), np.array([e1, np.cross(axis, e1)]))
        arc._check()
        return arc

    @classmethod
    def between(cls, center: Any, radius: float, start: Any, end: Any) -> Arc:
        """Plane arc on circle (center, radius) from the polar angle of ``start`` to that of ``end``.

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
        if self._basis is None:
            return f"Arc(center={tuple(self._c.tolist())}, radius={self._r}, start_angle={self._a0}, sweep={self._sweep})"
        return (
            f"Arc.in_space(center={tuple(self._c.tolist())}, normal={tuple(self.normal.tolist())}, "
            f"start={tuple(self.start.tolist())}, sweep={math.copysign(self._sweep, self._r)})"
        )

    def _row(self) -> tuple[int, NDArray[np.float64], tuple[float, float, float]]:
        geometry = np.zeros((4, 3))
        geometry[0, : self._dim] = self._c
        geometry[1:3] = _XY_BASIS if self._basis is None else self._basis
        return ARC, geometry, (self._r, self._a0, self._sweep)

    @property
    def center(self) -> NDArray[np.float64]:
        return self._c.copy()

    @property
    def radius(self) -> float:
        """Signed radius: positive travels counterclockwise (about ``normal`` in space)."""
        return self._r

    @property
    def start_angle(self) -> float:
        """Polar angle of the start (in space: in the basis e1, e2 of ``basis``)."""
        return self._a0

    @property
    def sweep(self) -> float:
        """Angle travelled, in (0, 2π]."""
        return self._sweep

    @property
    def normal(self) -> NDArray[np.float64]:
        """Unit normal (3,) of the arc's plane: (0, 0, 1) in the plane; positive radius turns counterclockwise about it."""
        if self._basis is None:
            return _XY_NORMAL.copy()
        e1, e2 = self._basis
        return np.cross(e1, e2)

    @property
    def basis(self) -> NDArray[np.float64]:
        """(2, 3) orthonormal vectors e1, e2 of the arc's plane in which polar angles are measured."""
        return (_XY_BASIS if self._basis is None else self._basis).copy()

    @property
    def circle(self) -> Circle:
        """The plane circle the arc runs on (travel-sense radius).

        Raises:
            ValueError: an arc in space (its circle is ``center``, ``radius``, ``normal``).
        """
        if self._dim != 2:
            raise ValueError("circle is the plane circle of a plane arc; an Arc in space has center, radius and normal")
        return Circle((float(self._c[0]), float(self._c[1])), self._r)

    @property
    def length(self) -> float:
        return abs(self._r) * self._sweep

    def _angle(self, u: ArrayLike) -> NDArray[np.float64]:
        return self._a0 + math.copysign(self._sweep, self._r) * _u(u)

    def _in_plane(self, x: NDArray[np.float64], y: NDArray[np.float64]) -> NDArray[np.float64]:
        """Plane-basis coordinates as points of the segment's space."""
        if self._basis is None:
            return np.stack([x, y], axis=-1)
        points: NDArray[np.float64] = x[..., None] * self._basis[0] + y[..., None] * self._basis[1]
        return points

    def point(self, u: ArrayLike) -> NDArray[np.float64]:
        a = self._angle(u)
        return self._c + abs(self._r) * self._in_plane(np.cos(a), np.sin(a))

    def tangent(self, u: ArrayLike) -> NDArray[np.float64]:
        a = self._angle(u)
        s = math.copysign(1.0, self._r)
        return s * self._in_plane(-np.sin(a), np.cos(a))

    def curvature(self, u: ArrayLike) -> NDArray[np.float64] | float:
        return np.full_like(_u(u), 1.0 / (self._r if self._dim == 2 else abs(self._r)))[()]

    def curvature_vector(self, u: ArrayLike) -> NDArray[np.float64]:
        a = self._angle(u)
        return self._in_plane(np.cos(a), np.sin(a)) / -abs(self._r)

    def reversed(self) -> Arc:
        return Arc._of(self._c.copy(), -self._r, float(self._angle(1.0)), self._sweep, self._basis)

    def piece(self, t0: float, t1: float) -> Arc:
        t0, t1 = piece_range(t0, t1)
        return Arc._of(self._c.copy(), self._r, float(self._angle(t0)), self._sweep * (t1 - t0), self._basis)

    def placed(self, frame: PlaneFrame) -> Arc:
        self._plane_only("placed")
        return Arc._of(frame.point(self._c), self._r, self._a0, self._sweep, frame.basis)


@dataclass(frozen=True)
class Join:
    """Mismatch at the joint between segments ``index`` and ``index + 1``.

    ``curvature_jump`` is |Δ(κB)|, the jump of the curvature vector turned a
    quarter turn about the tangent: in the plane exactly |Δκ|; in space the
    jump of κN up to κ × the tangent angle.
    """

    index: int
    gap: float
    angle: float
    curvature_jump: float


def curvature_scales(frames: NDArray[np.float64]) -> NDArray[np.float64]:
    """Each segment's own curvature scale from its end frames (n, 2, 9): the larger |κ| of its two ends
    (0 for a line, 1/r for an arc, the peak of a monotone-curvature spiral)."""
    scales: NDArray[np.float64] = np.sqrt(np.max(np.einsum("nej,nej->ne", frames[:, :, 6:9], frames[:, :, 6:9]), axis=1))
    return scales


def joint_table(
    end: NDArray[np.float64], end_floor: NDArray[np.float64], end_length: NDArray[np.float64],
    start: NDArray[np.float64], start_floor: NDArray[np.float64], start_length: NDArray[np.float64],
    own: NDArray[np.float64] | float, tolerance: float, cap: float,
) -> tuple[NDArray[np.float64], int]:  # fmt: skip
    """Measure and judge m joints in one pass (``_chain_kernels.joint_measures``): (m, 6) rows of gap,
    angle, curvature jump, shorter length, curvature scale and failure flag, and the first failing joint (-1: none).
    ``own`` (m,): the larger ``curvature_scales`` of each joint's two segments."""
    out = np.empty((len(end), 6))
    scales = np.ascontiguousarray(np.broadcast_to(np.asarray(own, dtype=float), (len(end),)))
    first = CK.joint_measures(end, end_floor, end_length, start, start_floor, start_length, scales, tolerance, cap, out)
    return out, int(first)


def measure_join(a: Segment, b: Segment, index: int = 0) -> Join:
    """Position gap, tangent angle (rad) and curvature jump from ``a``'s end to ``b``'s start."""
    if a.dim != b.dim:
        a, b = (s if s.dim == 3 else s.placed(PlaneFrame()) for s in (a, b))
    (frames_a, floors_a), (frames_b, floors_b) = a._ends, b._ends
    one = np.ones(1)
    out, _ = joint_table(frames_a[1:], floors_a[1:], one, frames_b[:1], floors_b[:1], one, 0.0, 1.0, 0.0)
    gap, angle, jump = out[0, :3].tolist()
    return Join(index, gap, angle, jump)
