"""Make a G1 path of lines and tangent arcs G2 within a stated deviation, keeping the arcs true arcs.

The world's CAD, CAM and civil data is lines and tangent circular arcs: tangent
(G1) at every joint, with a curvature jump at each. ``make_g2`` puts the
paper's transitions into those joints:

* **line → arc**: Theorem 4.1 needs the circle ``r·g1(θ)`` from the line, more
  than ``r``: the arc is kept a true arc of the same centre with its radius
  reduced by the shift ``s`` (the classical shifted circle of a transition
  curve). The line stays where it was; the spiral leaves it before the old
  tangent point and meets the smaller circle θ further round.
* **arc → arc, reverse (S)**: both circles shrink about their centres, so
  the circles that touched now lie apart and Theorem 4.3 joins them.
* **arc → arc, compound (same sense)**: the smaller circle shrinks by a
  little more than the larger one, so it lies just inside it, in the band
  where the nested-circle spiral (the fifth case) exists.
* **sharp corners between lines**: a spiral pair within the bound, as
  ``round_corners`` makes it (``round_corners_batch`` with ``max_deviation``).
* **reversals (cusps)** and corners too sharp for a spiral pair: the path is
  split there; every part is made G2 on its own.

A concentric shrink by ``s`` moves every point of an arc by exactly ``s``
and the spiral of a line → arc joint stays between the line and the old arc
(its farthest point from the input is its end, at ``s``), so the shifts are
aimed at the bound; the result's deviation is then measured (input ↔ result,
both ways) and returned. Each shift is as large as the bound, the arc's sweep
and the line's length allow: the gentlest transitions within the bound.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..core import _kernels as K
from ..core import batch
from ..core._inputs import as_float, as_real_array
from ..core.chain import JOIN_TOLERANCE, Chain, g2_mismatch, join_tolerance
from ..core.errors import JointError, NoSolutionError, Status
from ..core.segments import TAU, Arc, Line, Segment
from ..core.shapes import SHAPE_CODES, TRANSITION_SHAPES, shape_code
from ..core.space import PlaneFrame
from ..core.spiral import BezierSpiral
from ..core.units import DEFAULT_UNITS, length_unit
from .fillets import _intersect
from .rounding import _steepest_deflection, round_corners_batch

__all__ = ["G2Joint", "G2Path", "make_g2", "smallest_max_deviation"]

#: The shifts are aimed this much (relative) inside the bound.
BOUND_MARGIN = 1e-6
#: The share of a line's length or an arc's sweep one joint may use when the other end has a joint too.
SHARED = 0.45
#: ... and when the other end is a free end of the path.
ALONE = 0.9
#: Largest relative shrink s/r of an arc (Walton–Meek; near-linear stops at its largest angle).
MAX_SHRINK = 0.5
#: Passes of shrinking the shifts that overrun a line or an arc before a joint is refused.
PASSES = 60
#: Samples per spiral (and per replaced stretch of the input) when the deviation is measured.
SAMPLES = 32
EPS = float(np.finfo(float).eps)

JOINT_KINDS = ("line-arc", "arc-arc-compound", "arc-arc-reverse", "corner", "g2", "split")


@dataclass(frozen=True)
class G2Joint:
    """What ``make_g2`` did at one joint of the input.

    Attributes:
        index: the joint between input segments ``index`` and ``index + 1``
            (a closed path's closing joint is ``len(path) − 1``: last → first).
        kind: ``"line-arc"`` (either order), ``"arc-arc-compound"``,
            ``"arc-arc-reverse"``, ``"corner"``, ``"g2"`` (already G2: nothing
            done) or ``"split"`` (a reversal, or a corner too sharp for a spiral
            pair: the path is split there).
        point: where the joint is (input coordinates).
        moved: what was moved, in words (e.g. ``"arc 2 radius 10 → 9.99 (centre kept)"``).
        shift: by how much (the largest shift of the circles at this joint; for
            a corner, how far the path passes from the corner point).
        theta: the spiral angle of the transition (radians; NaN when none).
    """

    index: int
    kind: str
    point: tuple[float, ...]
    moved: str
    shift: float
    theta: float = math.nan


@dataclass(frozen=True)
class G2Path:
    """The result of ``make_g2``.

    Attributes:
        chains: the G2 chains, one per part (a path split at reversals has several).
        deviation: the measured Hausdorff distance between the input and the
            result (every point of each within it of the other), ≤ ``max_deviation``.
        joints: one ``G2Joint`` per joint of the input, in order.
        splits: the indices of the joints where the path was split.
        closed: whether the path was taken as closed (its closing joint G2 too).
        max_deviation: the bound asked for.
        shape: the spiral shape.
        units: the length unit.
    """

    chains: list[Chain]
    deviation: float
    joints: list[G2Joint]
    splits: list[int] = field(default_factory=list)
    closed: bool = False
    max_deviation: float = math.nan
    shape: str = "near-linear"
    units: str = DEFAULT_UNITS

    @property
    def chain(self) -> Chain:
        """The one chain of an unsplit path.

        Raises:
            ValueError: the path was split (the message names the joints and points).
        """
        if len(self.chains) == 1:
            return self.chains[0]
        where = ", ".join(f"joint {j.index} at {_shown_point(j.point)}" for j in self.joints if j.kind == "split")
        raise ValueError(f"the path was split into {len(self.chains)} parts at {where}; use .chains")


def _shown_point(point: Sequence[float]) -> str:
    return "(" + ", ".join(f"{v:.10g}" for v in point) + ")"


# ------------------------------------------------------------------ input


@dataclass
class _Piece:
    """A line (a → b) or an arc (centre c, signed radius r, start angle a0, sweep) of the input, merged
    with its G2 neighbours; ``first`` and ``last`` are the input segments it spans."""

    kind: str
    first: int
    last: int
    a: NDArray = field(default_factory=lambda: np.zeros(2))
    b: NDArray = field(default_factory=lambda: np.zeros(2))
    c: NDArray = field(default_factory=lambda: np.zeros(2))
    r: float = 0.0
    a0: float = 0.0
    sweep: float = 0.0
    #: A tangent circle put into a corner next to an arc: how far it passes from the corner (else 0).
    fillet: float = 0.0
    #: How much of the bound a tangent circle beside this piece has used (its shift must leave it).
    spent: float = 0.0

    @property
    def sense(self) -> float:
        return math.copysign(1.0, self.r)

    @property
    def a1(self) -> float:
        return self.a0 + self.sense * self.sweep

    def start(self) -> NDArray:
        if self.kind == "line":
            return self.a
        return self.c + abs(self.r) * np.array([math.cos(self.a0), math.sin(self.a0)])

    def end(self) -> NDArray:
        if self.kind == "line":
            return self.b
        return self.c + abs(self.r) * np.array([math.cos(self.a1), math.sin(self.a1)])

    def tangent(self, at_end: bool) -> NDArray:
        if self.kind == "line":
            d = self.b - self.a
            return d / math.hypot(*d)
        angle = self.a1 if at_end else self.a0
        return self.sense * np.array([-math.sin(angle), math.cos(angle)])

    def curvature(self) -> float:
        return 0.0 if self.kind == "line" else 1.0 / self.r

    @property
    def size(self) -> float:
        """Length of a line, sweep of an arc: what its joints share."""
        return math.hypot(*(self.b - self.a)) if self.kind == "line" else self.sweep


def _piece_of(segment: Segment, index: int) -> _Piece:
    if isinstance(segment, Line):
        (x0, y0, *_), (x1, y1, *_) = segment.ends
        return _Piece("line", index, index, a=np.array([x0, y0]), b=np.array([x1, y1]))
    assert isinstance(segment, Arc)
    return _Piece("arc", index, index, c=segment.center[:2].copy(), r=segment.radius, a0=segment.start_angle, sweep=segment.sweep)


def _path_segments(path: Any) -> tuple[list[Segment], PlaneFrame | None]:
    """Lines and arcs of the plane from ``path`` (a Chain, Line/Arc sequence or (n, 2|3) points), and the
    frame of a planar path in space (None in the plane)."""
    if isinstance(path, Chain):
        path = list(path)
    if isinstance(path, Sequence) and path and all(isinstance(s, Segment) for s in path):
        for i, s in enumerate(path):
            if not isinstance(s, (Line, Arc)):
                raise ValueError(f"make_g2 takes a path of lines and arcs; segment {i} is a {type(s).__name__}")
        segments = list(path)
        if all(s.dim == 2 for s in segments):
            return segments, None
        return _planar(segments)
    points = as_real_array(path, "path")
    if points.ndim != 2 or len(points) < 2 or points.shape[1] not in (2, 3):
        raise ValueError(f"path must be lines and arcs, or (n ≥ 2, 2|3) points; got shape {points.shape}")
    for i, (a, b) in enumerate(zip(points[:-1], points[1:])):
        if np.array_equal(a, b):
            raise ValueError(f"path points {i} and {i + 1} coincide at {_shown_point(a.tolist())}")
    lines: list[Segment] = [Line(a, b) for a, b in zip(points[:-1], points[1:])]
    if not np.isfinite(points).all():
        i = int(np.argmax(~np.isfinite(points).all(axis=1)))
        raise ValueError(f"path points must be finite; point {i} is {points[i].tolist()}")
    if points.shape[1] == 2 or not points[:, 2].any():
        return [Line(a[:2], b[:2]) for a, b in zip(points[:-1], points[1:])], None
    return _planar(lines)


def _planar(segments: list[Segment]) -> tuple[list[Segment], PlaneFrame]:
    """Segments in space that lie in one plane, in that plane's coordinates, and its frame."""
    points = np.array([p for s in segments for p in s.outline()], dtype=float)
    if points.shape[1] == 2:
        points = np.column_stack([points, np.zeros(len(points))])
    origin = points[0]
    centred = points - origin
    size = float(np.abs(centred).max()) or 1.0
    _, singular, vt = np.linalg.svd(centred / size, full_matrices=False)
    normal = vt[2]
    for s in segments:
        if isinstance(s, Arc) and s.dim == 3 and abs(abs(float(np.dot(s.normal, normal))) - 1.0) > 1e-9:
            normal = s.normal
    off = float(np.abs(centred @ normal).max())
    if off > 1e-9 * size:
        raise ValueError(f"make_g2 takes a path in one plane; this one leaves the best plane by {off:.3g}")
    x_dir = vt[0] - np.dot(vt[0], normal) * normal
    x_dir /= np.linalg.norm(x_dir)
    frame = PlaneFrame(origin, x_dir, normal)
    plane: list[Segment] = []
    for s in segments:
        if isinstance(s, Line):
            a, b = frame.local([s.start, s.end]) if s.dim == 3 else frame.local([(*s.start, 0.0), (*s.end, 0.0)])
            plane.append(Line(a, b))
        else:
            assert isinstance(s, Arc)
            start = frame.local([s.start if s.dim == 3 else (*s.start, 0.0)])[0]
            centre = frame.local([s.center if s.dim == 3 else (*s.center, 0.0)])[0]
            tangent = s.tangent(0.0)
            tangent3 = tangent if s.dim == 3 else np.append(tangent, 0.0)
            tx, ty = float(np.dot(tangent3, frame.x_dir)), float(np.dot(tangent3, frame.y_dir))
            u = np.subtract(start, centre)
            sense = 1.0 if float(u[0] * ty - u[1] * tx) > 0.0 else -1.0
            start_angle = math.atan2(start[1] - centre[1], start[0] - centre[0])
            plane.append(Arc(centre, sense * abs(s.radius), start_angle, s.sweep))
    return plane, frame


def _bound(value: Any) -> float:
    bound = as_float(value, "max_deviation")
    if not (bound > 0.0 and math.isfinite(bound)):
        raise ValueError(f"max_deviation must be positive and finite; got {bound!r}")
    return bound


# ------------------------------------------------------------------ joints


def _turn(a: _Piece, b: _Piece) -> float:
    ta, tb = a.tangent(True), b.tangent(False)
    return math.atan2(ta[0] * tb[1] - ta[1] * tb[0], float(np.dot(ta, tb)))


def _same_circle(a: _Piece, b: _Piece, scale: float) -> bool:
    return (a.r > 0) == (b.r > 0) and abs(a.r - b.r) <= 1e-9 * abs(a.r) and math.dist(a.c, b.c) <= 1e-9 * scale


def _classify(a: _Piece, b: _Piece, scale: float, steepest: float, bound: float) -> str:
    """The joint from piece ``a`` to ``b``: ``g2``, ``line-arc``, ``arc-arc-…``, ``corner`` or ``split``."""
    turn = _turn(a, b)
    if abs(turn) > steepest:
        return "split"
    if abs(turn) > TANGENT_TOL:
        return "corner"
    if a.kind == "line" and b.kind == "line":
        # Merged into one line only when the joint point lies within a thousandth of the bound of it.
        la, lb = a.size, b.size
        drop = la * lb / (la + lb) * abs(math.sin(turn))
        return "g2" if drop <= 1e-3 * bound else "corner"
    if a.kind == "arc" and b.kind == "arc":
        if _same_circle(a, b, scale):
            return "g2"
        return "arc-arc-compound" if (a.r > 0) == (b.r > 0) else "arc-arc-reverse"
    return "line-arc"


#: A joint whose tangent turns by less than this (radians) is tangent (G1).
TANGENT_TOL = 1e-7


def _merge(a: _Piece, b: _Piece) -> _Piece:
    if a.kind == "line":
        return _Piece("line", a.first, b.last, a=a.a, b=b.b)
    return _Piece("arc", a.first, b.last, c=a.c, r=a.r, a0=a.a0, sweep=min(a.sweep + b.sweep, TAU))


# ------------------------------------------------------------------ the solve


@dataclass
class _Solved:
    """One joint's transition: its spirals (control points in travel order), where they leave and
    reach the pieces (the share of each piece used) and its θ."""

    spirals: list[NDArray]
    used_before: float
    used_after: float
    theta: float
    status: int = 0
    reason: str = ""


def _angle_on(piece: _Piece, point: NDArray) -> float:
    return math.atan2(point[1] - piece.c[1], point[0] - piece.c[0])


def _wrap(angle: float) -> float:
    return (angle + math.pi) % TAU - math.pi


def _used(piece: _Piece, point: NDArray, at_end: bool) -> float:
    """How much of ``piece`` (length of a line, sweep of an arc) lies between ``point`` and its end (start)."""
    if piece.kind == "line":
        t = piece.tangent(True)
        return float(np.dot(piece.b - point, t)) if at_end else float(np.dot(point - piece.a, t))
    angle = _angle_on(piece, point)
    if at_end:
        return piece.sense * _wrap(piece.a1 - angle)
    return piece.sense * _wrap(angle - piece.a0)


class _Group:
    """One part of the path (between splits), its pieces and joints, and the solve."""

    def __init__(self, pieces: list[_Piece], kinds: list[str], closed: bool, bound: float, shape: str, scale: float):
        self.pieces, self.kinds, self.closed, self.bound, self.shape = pieces, kinds, closed, bound, shape
        self.scale = scale
        n = len(pieces)
        self.joint_count = n if closed else n - 1
        active = [[False, False] for _ in range(n)]
        for j in range(self.joint_count):
            active[j][1] = True
            active[(j + 1) % n][0] = True
        self.allow = [[(SHARED if all(act) else ALONE) * p.size if act[e] else 0.0 for e in range(2)] for p, act in zip(pieces, active)]
        self.needs_shift = [False] * n
        for j in range(self.joint_count):
            if kinds[j] in ("line-arc", "arc-arc-compound", "arc-arc-reverse", "bridge"):
                for k in (j, (j + 1) % n):
                    if pieces[k].kind == "arc":
                        self.needs_shift[k] = True
        code = SHAPE_CODES[shape]
        theta_max = K.shape_max_theta(code)
        if code == K.NEAR_LINEAR:
            largest = 0.98 * theta_max
            q_max = 1.0 - 1.0 / K.shape_g1(code, math.sin(largest), math.cos(largest))
        else:
            q_max = MAX_SHRINK
        size = max(float(np.abs(np.concatenate([p.start(), p.end(), p.c])).max()) for p in pieces)
        target = bound * (1.0 - BOUND_MARGIN) - 8.0 * EPS * size
        if not target > 0.0:
            raise _Refusal(
                0, f"it is below what float64 resolves at these coordinates (8 ulp of {size:.6g} is {8.0 * EPS * size:.3g})", True
            )
        self.target = target
        self.cap = [min(target - p.spent, q_max * abs(p.r)) if need else 0.0 for p, need in zip(pieces, self.needs_shift)]
        self.factor = [1.0] * n
        self._corners: dict[int, _Solved] = {}
        #: Short lines left out between two arcs (by joint): (the line, the input joint after it).
        self.bridges: dict[int, tuple[_Piece, int]] = {}

    def shifts(self) -> list[float]:
        """Each arc's shrink: its cap times its factor, the smaller circle of a compound joint shrunk
        more than the larger one by a step inside the nested band."""
        n = len(self.pieces)
        s = [c * f for c, f in zip(self.cap, self.factor)]
        pairs = []  # (small, big, band width) of every compound joint
        for j in range(self.joint_count):
            if self.kinds[j] == "arc-arc-compound":
                a, b = j, (j + 1) % n
                small, big = (a, b) if abs(self.pieces[a].r) < abs(self.pieces[b].r) else (b, a)
                pairs.append((small, big, self._band_width(small, big)))
        pairs.sort(key=lambda pair: abs(self.pieces[pair[0]].r))
        for _ in range(3):
            for small, big, width in pairs:  # the larger circle shrinks less, by a step inside the band
                s[big] = min(s[big], s[small] - min(0.5 * s[small], 0.5 * width))
            for small, big, width in pairs[::-1]:  # ... and not by more than the band allows
                s[small] = min(s[small], s[big] + 0.9 * width)
        return s

    def _band_width(self, small: int, big: int) -> float:
        """How much more than the larger circle the smaller one may shrink: the nested band's width."""
        rs, rb = abs(self.pieces[small].r), abs(self.pieces[big].r)
        lower = K.nested_band_lower(rs / rb, SHAPE_CODES[self.shape])
        return (rb - rs) * (1.0 / lower - 1.0)

    def solve_joints(self, s: list[float]) -> list[_Solved | None]:
        """Every joint's transition for the shifts ``s``: one batch solve per kind of joint."""
        n = len(self.pieces)
        out: list[_Solved | None] = [None] * self.joint_count
        by_kind: dict[str, list[int]] = {}
        for j in range(self.joint_count):
            by_kind.setdefault(self.kinds[j], []).append(j)
        if by_kind.get("line-arc"):
            self._lines_arcs(by_kind["line-arc"], s, out)
        for kind in ("arc-arc-reverse", "arc-arc-compound", "bridge"):
            if by_kind.get(kind):
                self._arcs_arcs(by_kind[kind], s, kind, out)
        for j in by_kind.get("corner", []):  # a corner between lines does not depend on the shifts
            if j not in self._corners:
                self._corners[j] = self._corner(j, self.pieces[j], self.pieces[(j + 1) % n])
            out[j] = self._corners[j]
        return out

    def _lines_arcs(self, joints: list[int], s: list[float], out: list[_Solved | None]) -> None:
        """Line → arc and arc → line joints (Theorem 4.1 onto the shrunk circle), solved about each joint
        (where float64 holds a small transition far from the origin) and moved back."""
        n = len(self.pieces)
        origin, direction, centre, radius, reverse = [], [], [], [], []
        for j in joints:
            a, b = self.pieces[j], self.pieces[(j + 1) % n]
            if a.kind == "line":
                origin.append(a.b)
                direction.append(a.tangent(True))
                centre.append(b.c)
                radius.append(abs(b.r) - s[(j + 1) % n])
                reverse.append(False)
            else:
                origin.append(b.a)
                direction.append(-b.tangent(False))
                centre.append(a.c)
                radius.append(abs(a.r) - s[j])
                reverse.append(True)
        points = np.array(origin)
        result = batch.line_to_circle(
            np.zeros_like(points), np.array(direction), np.array(centre) - points, np.array(radius), shape=self.shape
        )
        spirals = result.spirals[0] + points[:, None]
        ok = result.ok
        for m, j in enumerate(joints):
            a, b = self.pieces[j], self.pieces[(j + 1) % n]
            if not ok[m]:
                out[j] = _Solved([], math.inf, math.inf, math.nan, int(result.status[m]), result.reason(m))
                continue
            cp = spirals[m][::-1].copy() if reverse[m] else spirals[m]
            out[j] = _Solved([cp], _used(a, cp[0], True), _used(b, cp[3], False), float(result.theta[m]))

    def _arcs_arcs(self, joints: list[int], s: list[float], kind: str, out: list[_Solved | None]) -> None:
        """Reverse (S) or compound (nested) joints between shrunk circles, solved about each joint."""
        n = len(self.pieces)
        before = [self.pieces[j] for j in joints]
        after = [self.pieces[(j + 1) % n] for j in joints]
        origin = np.array([a.end() for a in before])
        c0 = np.array([a.c for a in before]) - origin
        c1 = np.array([b.c for b in after]) - origin
        r0 = np.array([a.r - a.sense * s[j] for a, j in zip(before, joints)])
        r1 = np.array([b.r - b.sense * s[(j + 1) % n] for b, j in zip(after, joints)])
        solver = batch.circle_in_circle if kind == "arc-arc-compound" else batch.circle_to_circle
        result = solver(c0, r0, c1, r1, shape=self.shape)
        moved = [sp + origin[:, None] for sp in result.spirals]
        ok = result.ok
        for m, j in enumerate(joints):
            if not ok[m]:
                out[j] = _Solved([], math.inf, math.inf, math.nan, int(result.status[m]), result.reason(m))
                continue
            spirals = [sp[m] for sp in moved]
            out[j] = _Solved(spirals, _used(before[m], spirals[0][0], True), _used(after[m], spirals[-1][3], False), float(result.theta[m]))

    def _corner(self, j: int, a: _Piece, b: _Piece) -> _Solved:
        n = len(self.pieces)
        if a.kind != "line" or b.kind != "line":
            return _Solved([], math.inf, math.inf, math.nan, int(Status.OUTSIDE_SHAPE), "")
        corner = a.b
        p0 = corner - self.allow[j][1] * a.tangent(True)
        p1 = corner + self.allow[(j + 1) % n][0] * b.tangent(False)
        result = round_corners_batch(p0, corner, p1, max_deviation=self.target, shape=self.shape)
        if not result.ok[0]:
            return _Solved([], math.inf, math.inf, math.nan, int(result.status[0]), result.reason(0))
        pair = result.control_points[0]
        return _Solved([pair[0].copy(), pair[1].copy()], _used(a, pair[0][0], True), _used(b, pair[1][3], False),
                       float(result.theta[0]))  # fmt: skip


def _distance_to_piece(points: NDArray, piece: _Piece) -> NDArray:
    """Exact distance of ``points`` (m, 2) to a line segment or an arc of the input."""
    if piece.kind == "line":
        d = piece.b - piece.a
        t = np.clip(((points - piece.a) @ d) / float(d @ d), 0.0, 1.0)
        return np.hypot(*(points - piece.a - t[:, None] * d).T)
    rel = points - piece.c
    angle = np.arctan2(rel[:, 1], rel[:, 0])
    inside = (piece.sense * (angle - piece.a0)) % TAU <= piece.sweep
    radial = np.abs(np.hypot(rel[:, 0], rel[:, 1]) - abs(piece.r))
    ends = np.minimum(np.hypot(*(points - piece.start()).T), np.hypot(*(points - piece.end()).T))
    return np.where(inside, np.minimum(radial, ends), ends)


def _distance_to_bezier(points: NDArray, cp: NDArray) -> NDArray:
    """Distance of ``points`` (m, 2) to the cubic Bézier ``cp``: the nearest of dense samples, polished
    by Newton steps on (B(u) − p)·B'(u) = 0 (clamped to [0, 1])."""
    u = np.linspace(0.0, 1.0, 4 * SAMPLES + 1)
    samples = _bezier_at(cp, u)
    best = u[np.argmin(np.einsum("mkj,mkj->mk", points[:, None] - samples[None], points[:, None] - samples[None]), axis=1)]
    d1 = 3.0 * np.diff(cp, axis=0)
    d2 = 2.0 * np.diff(d1, axis=0)
    for _ in range(8):
        off = _bezier_at(cp, best) - points
        v = 1.0 - best[:, None]
        w = best[:, None]
        first = v * v * d1[0] + 2 * v * w * d1[1] + w * w * d1[2]
        second = v * d2[0] + w * d2[1]
        f = np.einsum("ij,ij->i", off, first)
        df = np.einsum("ij,ij->i", first, first) + np.einsum("ij,ij->i", off, second)
        with np.errstate(invalid="ignore", divide="ignore"):
            step = np.where(df > 0.0, f / df, 0.0)
        best = np.clip(best - np.nan_to_num(step), 0.0, 1.0)
    return np.hypot(*(_bezier_at(cp, best) - points).T)


def _bezier_at(cp: NDArray, u: NDArray) -> NDArray:
    u = np.asarray(u)[:, None]
    v = 1.0 - u
    return v**3 * cp[0] + 3 * v * v * u * cp[1] + 3 * v * u * u * cp[2] + u**3 * cp[3]


def _bezier(cp: NDArray, count: int) -> NDArray:
    return _bezier_at(cp, np.linspace(0.0, 1.0, count))


def _kept(piece: _Piece, used: list[float], shrink: float) -> _Piece | None:
    """What the transitions leave of ``piece`` (an arc on its shrunk circle), as a piece; None if nothing."""
    if piece.kind == "line":
        t = piece.tangent(True)
        length = piece.size - used[0] - used[1]
        if not length > 0.0:
            return None
        return _Piece("line", piece.first, piece.last, a=piece.a + used[0] * t, b=piece.a + (piece.size - used[1]) * t)
    sweep = piece.sweep - used[0] - used[1]
    if not sweep > 0.0:
        return None
    return _Piece(
        "arc", piece.first, piece.last, c=piece.c, r=piece.r - piece.sense * shrink, a0=piece.a0 + piece.sense * used[0], sweep=sweep
    )


def _piece_points(piece: _Piece, start_used: float, end_used: float, count: int, shrink: float = 0.0,
                  region: str = "all") -> NDArray:  # fmt: skip
    """Points of ``piece``: ``region`` "head" (its first ``start_used``), "tail" (its last ``end_used``),
    or "all" (between them); an arc on its circle shrunk by ``shrink``."""
    size = piece.size
    if region == "head":
        lo, hi = 0.0, min(start_used, size)
    elif region == "tail":
        lo, hi = max(size - end_used, 0.0), size
    else:
        lo, hi = start_used, size - end_used
    u = np.linspace(lo, hi, count)
    if piece.kind == "line":
        t = piece.tangent(True)
        return piece.a + u[:, None] * t
    angle = piece.a0 + piece.sense * u
    radius = abs(piece.r) - shrink
    return piece.c + radius * np.column_stack([np.cos(angle), np.sin(angle)])


class _Refusal(Exception):
    """A joint that cannot be made G2 within the bound (its index in the group and the reason)."""

    def __init__(self, joint: int, reason: str, larger_helps: bool):
        super().__init__(reason)
        self.joint, self.reason, self.larger_helps = joint, reason, larger_helps


def _solve(group: _Group) -> tuple[list[_Solved | None], list[float]]:
    """The shifts and transitions of a group: shifts that overrun a piece shrink until every joint fits."""
    n = len(group.pieces)
    for _ in range(PASSES):
        s = group.shifts()
        solved = group.solve_joints(s)
        over: dict[int, float] = {}
        failed: list[int] = []
        for j, joint in enumerate(solved):
            if joint is None:
                continue
            if joint.status:
                failed.append(j)
                continue
            # An overrun shrinks the shifts of this joint's circles (a smaller shift: a shorter transition).
            worst = 1.0
            for k, used, end in ((j, joint.used_before, 1), ((j + 1) % n, joint.used_after, 0)):
                room = group.allow[k][end]
                if not (used <= room):
                    worst = min(worst, (room / used) ** 2 * 0.8 if used > 0.0 and room > 0.0 else 0.25)
            if worst < 1.0:
                for k in _joint_circles(group, j):
                    over[k] = min(over.get(k, 1.0), worst)
        if not over and not failed:
            return solved, s
        for j in failed:
            kind = group.kinds[j]
            if kind == "corner":
                joint = solved[j]
                assert joint is not None
                raise _Refusal(j, joint.reason, joint.status == Status.UNVERIFIED)
            for k in _joint_circles(group, j):
                over[k] = min(over.get(k, 1.0), 0.5)
        for k, factor in over.items():
            group.factor[k] *= factor
    s = group.shifts()
    solved = group.solve_joints(s)
    for j, joint in enumerate(solved):
        if joint is not None and joint.status:
            raise _Refusal(j, joint.reason or describe_status(joint.status), True)
    raise _Refusal(0, "the transitions could not be fitted into the lines and arcs", True)


def _joint_circles(group: _Group, j: int) -> list[int]:
    """The pieces of joint ``j`` whose circles shift."""
    n = len(group.pieces)
    return [k for k in (j, (j + 1) % n) if group.needs_shift[k]]


def describe_status(status: int) -> str:
    return f"no transition ({Status(status).name})"


def _assemble(group: _Group, solved: list[_Solved | None], s: list[float], units: str, tolerance: float) -> tuple[Chain, float]:
    """The chain of a solved group and its measured deviation from the input."""
    n = len(group.pieces)
    used = [[0.0, 0.0] for _ in range(n)]
    for j, joint in enumerate(solved):
        if joint is not None:
            used[j][1] = joint.used_before
            used[(j + 1) % n][0] = joint.used_after
    segments: list[Segment] = []
    owners: list[int] = []  # the joint each segment belongs to (a piece: the joint after it)
    for k, piece in enumerate(group.pieces):
        kept = _trimmed(piece, used[k], s[k], solved, k, n, group.closed)
        segments += kept
        owners += [min(k, len(solved) - 1)] * len(kept)
        joint = solved[k] if k < len(solved) else None
        if joint is not None:
            segments += [BezierSpiral._wrap(cp, group.shape) for cp in joint.spirals]
            owners += [k] * len(joint.spirals)
    try:
        chain = Chain(segments, tolerance, units)
    except JointError as error:
        where = owners[error.joint + 1] if isinstance(segments[error.joint + 1], BezierSpiral) else owners[error.joint]
        detail = str(error).split("): ", 1)[-1]
        raise _Refusal(max(where, 0), f"float64 cannot hold its transition G2 at these coordinates and sizes ({detail})", True) from None
    if group.closed:
        problem = g2_mismatch(segments[-1], segments[0], chain.tolerance, units, len(segments) - 1)
        if problem:
            raise _Refusal(n - 1, f"float64 cannot close the path G2: {problem}", True)
    return chain, _deviation(group, solved, s, used)


def _trimmed(piece: _Piece, used: list[float], shrink: float, solved: list[_Solved | None], k: int, n: int,
             closed: bool) -> list[Segment]:  # fmt: skip
    """The part of ``piece`` the transitions leave, from the end of the one before to the start of the one after."""
    before = solved[(k - 1) % n] if (closed or k > 0) and ((k - 1) % n) < len(solved) else None
    after = solved[k] if k < len(solved) else None
    if piece.kind == "line":
        start = before.spirals[-1][3] if before is not None else piece.a
        end = after.spirals[0][0] if after is not None else piece.b
        if np.array_equal(start, end):
            return []
        return [Line(start, end)]
    sweep = piece.sweep - used[0] - used[1]
    if not sweep > 0.0:
        return []
    radius = piece.r - piece.sense * shrink
    return [Arc(piece.c, radius, piece.a0 + piece.sense * used[0], sweep)]


def _deviation(group: _Group, solved: list[_Solved | None], s: list[float], used: list[list[float]]) -> float:
    """The Hausdorff distance between the input and the result, measured: the shrink of each arc
    (every point of a concentric circle moves by it), and at each joint the spirals against the input
    pieces beside it, and the stretch of the input the joint replaced against the result (all joints
    at once, in blocks)."""
    n = len(group.pieces)
    # A tangent circle put into a corner is itself ``fillet`` off the input: its shifts and joints add it.
    worst = max((shift + p.fillet for shift, p in zip(s, group.pieces)), default=0.0)
    index = [j for j, joint in enumerate(solved) if joint is not None]
    for block in range(0, len(index), BLOCK):
        joints = index[block : block + BLOCK]
        before = [group.pieces[j] for j in joints]
        after = [group.pieces[(j + 1) % n] for j in joints]
        added = np.array([max(a.fillet, b.fillet) for a, b in zip(before, after)])
        spirals = np.array([[cps[0], cps[-1]] for cps in (solved[j].spirals for j in joints)])  # type: ignore[union-attr]
        rows_a, rows_b = _Rows(before), _Rows(after)
        # A short line left out between two arcs is input the joint replaced (elsewhere: piece a again).
        middle = [group.bridges[j][0] if j in group.bridges else a for j, a in zip(joints, before)]
        rows_m = _Rows(middle)
        u = np.linspace(0.0, 1.0, SAMPLES)
        curve = np.concatenate([_bezier_rows(spirals[:, 0], u), _bezier_rows(spirals[:, 1], u)], axis=1)  # a lone spiral twice
        there = np.minimum(np.minimum(rows_a.distance(curve), rows_b.distance(curve)), rows_m.distance(curve))
        worst = max(worst, float((there.max(axis=1) + added).max()))
        tail = np.array([used[j][1] for j in joints])
        head = np.array([used[(j + 1) % n][0] for j in joints])
        replaced = np.concatenate(
            [rows_a.points(rows_a.size - tail, rows_a.size, SAMPLES), rows_b.points(np.zeros(len(joints)), head, SAMPLES)], axis=1
        )
        near = _distance_to_bezier_rows(replaced, spirals[:, 0])
        pairs = np.flatnonzero([len(solved[j].spirals) == 2 for j in joints])  # type: ignore[union-attr]
        if len(pairs):
            near[pairs] = np.minimum(near[pairs], _distance_to_bezier_rows(replaced[pairs], spirals[pairs, 1]))
        for pieces, ks in ((before, joints), (after, [(j + 1) % n for j in joints])):
            kept = [_kept(piece, used[k], s[k]) for piece, k in zip(pieces, ks)]
            present = np.array([k is not None for k in kept])
            if present.any():
                rows = _Rows([k if k is not None else pieces[i] for i, k in enumerate(kept)])
                near = np.minimum(near, np.where(present[:, None], rows.distance(replaced), np.inf))
        worst = max(worst, float((near.max(axis=1) + added).max()))
    return worst


#: Joints measured at once (bounds the memory of the point-to-sample distances).
BLOCK = 256
#: Starting points of the nearest-point search on a spiral (its distance has one minimum per stretch
#: this short: a spiral turns less than 90°), and the Newton steps that polish them.
GUESSES = 17
NEWTON_STEPS = 5


class _Rows:
    """Pieces as arrays: lines (a → b) and arcs (centre, radius, start angle, sweep), one row each."""

    def __init__(self, pieces: list[_Piece]):
        self.arc = np.array([p.kind == "arc" for p in pieces])
        self.a = np.array([p.a for p in pieces])
        self.b = np.array([p.b for p in pieces])
        self.c = np.array([p.c for p in pieces])
        self.r = np.array([abs(p.r) for p in pieces])
        self.sense = np.array([p.sense for p in pieces])
        self.a0 = np.array([p.a0 for p in pieces])
        self.sweep = np.array([p.sweep for p in pieces])
        self.size = np.where(self.arc, self.sweep, np.hypot(*(self.b - self.a).T))

    def points(self, lo: NDArray, hi: NDArray, count: int) -> NDArray:
        """(J, count, 2) points from ``lo`` to ``hi`` (length along a line, angle along an arc)."""
        t = lo[:, None] + np.linspace(0.0, 1.0, count)[None] * (hi - lo)[:, None]
        with np.errstate(invalid="ignore", divide="ignore"):
            unit = (self.b - self.a) / np.where(self.arc, 1.0, self.size)[:, None]
        line = self.a[:, None] + t[..., None] * unit[:, None]
        angle = self.a0[:, None] + self.sense[:, None] * t
        arc = self.c[:, None] + self.r[:, None, None] * np.stack([np.cos(angle), np.sin(angle)], axis=-1)
        return np.where(self.arc[:, None, None], arc, line)

    def distance(self, points: NDArray) -> NDArray:
        """(J, M) exact distance of ``points`` (J, M, 2) to each row's line segment or arc."""
        d = self.b - self.a
        dd = np.einsum("ij,ij->i", d, d)
        with np.errstate(invalid="ignore", divide="ignore"):
            t = np.clip(np.einsum("jmk,jk->jm", points - self.a[:, None], d) / dd[:, None], 0.0, 1.0)
        line = np.linalg.norm(points - self.a[:, None] - t[..., None] * d[:, None], axis=-1)
        rel = points - self.c[:, None]
        angle = np.arctan2(rel[..., 1], rel[..., 0])
        inside = (self.sense[:, None] * (angle - self.a0[:, None])) % TAU <= self.sweep[:, None]
        radial = np.abs(np.hypot(rel[..., 0], rel[..., 1]) - self.r[:, None])
        end_angle = self.a0 + self.sense * self.sweep
        start = self.c + self.r[:, None] * np.stack([np.cos(self.a0), np.sin(self.a0)], axis=-1)
        end = self.c + self.r[:, None] * np.stack([np.cos(end_angle), np.sin(end_angle)], axis=-1)
        ends = np.minimum(np.linalg.norm(points - start[:, None], axis=-1), np.linalg.norm(points - end[:, None], axis=-1))
        arc = np.where(inside, np.minimum(radial, ends), ends)
        return np.where(self.arc[:, None], arc, np.nan_to_num(line, nan=np.inf))


def _bezier_rows(cp: NDArray, u: NDArray) -> NDArray:
    """(J, len(u), 2) points of J cubic Béziers (J, 4, 2)."""
    u = u[None, :, None] if u.ndim == 1 else u[..., None]
    v = 1.0 - u
    return v**3 * cp[:, None, 0] + 3 * v * v * u * cp[:, None, 1] + 3 * v * u * u * cp[:, None, 2] + u**3 * cp[:, None, 3]


def _distance_to_bezier_rows(points: NDArray, cp: NDArray) -> NDArray:
    """(J, M) distance of ``points`` (J, M, 2) to the cubic Béziers ``cp`` (J, 4, 2): the nearest of dense
    samples, polished by Newton steps on (B(u) − p)·B'(u) = 0 (clamped to [0, 1])."""
    grid = np.linspace(0.0, 1.0, GUESSES)
    samples = _bezier_rows(cp, grid)  # (J, K, 2)
    squared = (np.einsum("jmk,jmk->jm", points, points)[..., None] - 2.0 * np.einsum("jmk,jsk->jms", points, samples)
               + np.einsum("jsk,jsk->js", samples, samples)[:, None])  # fmt: skip
    best = grid[np.argmin(squared, axis=2)]  # (J, M)
    d1 = 3.0 * np.diff(cp, axis=1)  # (J, 3, 2)
    d2 = 2.0 * np.diff(d1, axis=1)  # (J, 2, 2)
    for _ in range(NEWTON_STEPS):
        off = _bezier_rows(cp, best) - points
        v, w = (1.0 - best)[..., None], best[..., None]
        first = v * v * d1[:, None, 0] + 2 * v * w * d1[:, None, 1] + w * w * d1[:, None, 2]
        second = v * d2[:, None, 0] + w * d2[:, None, 1]
        f = np.einsum("jmk,jmk->jm", off, first)
        df = np.einsum("jmk,jmk->jm", first, first) + np.einsum("jmk,jmk->jm", off, second)
        with np.errstate(invalid="ignore", divide="ignore"):
            step = np.where(df > 0.0, f / df, 0.0)
        best = np.clip(best - np.nan_to_num(step), 0.0, 1.0)
    return np.linalg.norm(_bezier_rows(cp, best) - points, axis=-1)


# ------------------------------------------------------------------ the front


def make_g2(
    path: Any,
    max_deviation: float,
    *,
    closed: bool | None = None,
    shape: str = "near-linear",
    units: str = DEFAULT_UNITS,
    tolerance: float = JOIN_TOLERANCE,
) -> G2Path:
    """Make a path of lines and tangent arcs G2 within ``max_deviation``, keeping its arcs true arcs.

    Every tangent joint gets a transition (line → arc: one spiral onto the arc's
    circle shrunk about its centre by the shift the spiral needs; arc → arc:
    an S for a reverse curve, the nested-circle spiral for a compound one);
    sharp corners between lines get a spiral pair within the bound (as
    ``round_corners`` with ``max_deviation``); at a reversal, or a corner
    sharper than a spiral pair rounds, the path is split and each part made
    G2 on its own. The shifts use the bound (gentlest transitions) as far as
    the arcs' sweeps and the lines' lengths allow (each joint may use up to
    45 % of a line or arc it shares with another joint). Arcs stay ``Arc``
    pieces: true circles, never chords.

    Args:
        path: a sequence of ``Line`` and ``Arc`` meeting end to start (2-D, or
            3-D in one plane), a ``Chain`` of them, or (n, 2|3) polyline points.
        max_deviation: the Hausdorff bound: every point of the result lies
            within it of the input and every input point within it of the result.
        closed: whether the path closes (its closing joint is then treated like
            every other); None: closed when its last point is its first.
        shape: ``"near-linear"`` (default: curvature almost linear in arc
            length) or ``"walton-meek"``.
        units: the length unit (default mm).
        tolerance: the chains' relative join tolerance.

    Returns:
        A :class:`G2Path`: the chains, the measured deviation and what was done at every joint.

    Raises:
        NoSolutionError: a joint that cannot be made G2 within the bound; the
            message names the joint, the numbers and the smallest bound that
            works (built and checked) when a larger one helps.
        ValueError: malformed input (segments that do not meet, a bad bound, …).
    """
    bound = _bound(max_deviation)
    shape_code(shape, TRANSITION_SHAPES)
    units = length_unit(units)
    tolerance = join_tolerance(tolerance)
    segments, frame = _path_segments(path)
    result = _make(segments, bound, closed, shape, units, tolerance)
    if isinstance(result, _Refusal):
        raise NoSolutionError(_refusal_message(result, segments, bound, closed, shape, units, tolerance)) from None
    if frame is not None:
        result = G2Path([c.placed(frame) for c in result.chains], result.deviation,
                        [_placed_joint(j, frame) for j in result.joints], result.splits, result.closed, bound, shape, units)  # fmt: skip
    return result


def smallest_max_deviation(
    path: Any, *, closed: bool | None = None, shape: str = "near-linear", units: str = DEFAULT_UNITS, tolerance: float = JOIN_TOLERANCE
) -> float:
    """The smallest ``max_deviation`` with which ``make_g2`` makes ``path`` G2 (what ``spiral-cad check``
    tells of a G1 file).

    Tangent joints need only a positive shift, so this is where float64 stops
    holding the transitions at the path's coordinates and sizes. Found by
    building: doubling from the coordinates' rounding, then bisecting, and
    shown to 3 digits rounded up, that very number built again.

    Args:
        path, closed, shape, units, tolerance: as for ``make_g2``.

    Raises:
        NoSolutionError: no bound up to the path's size works (the first joint
            that fails is named).
        ValueError: malformed input.
    """
    shape_code(shape, TRANSITION_SHAPES)
    units = length_unit(units)
    tolerance = join_tolerance(tolerance)
    segments, _ = _path_segments(path)
    size = max(float(np.abs(np.array([p for s in segments for p in s.outline()])).max()), 1e-300)
    floor = 8.0 * EPS * size
    works = _smallest_bound(segments, floor, closed, shape, units, tolerance)
    if works is None:
        failed = _make(segments, 4.0 * size, closed, shape, units, tolerance)
        reason = _refusal_message(failed, segments, 4.0 * size, closed, shape, units, tolerance) if isinstance(failed, _Refusal) else ""
        raise NoSolutionError(f"no max_deviation up to the path's size makes it G2: {reason}")
    return works


def _placed_joint(joint: G2Joint, frame: PlaneFrame) -> G2Joint:
    point = tuple(float(v) for v in frame.point(np.array(joint.point)).tolist())
    return G2Joint(joint.index, joint.kind, point, joint.moved, joint.shift, joint.theta)


class _Located(_Refusal):
    """A refusal located on the input: the input joint index and its point."""

    def __init__(self, index: int, point: tuple[float, ...], reason: str, larger_helps: bool):
        super().__init__(index, reason, larger_helps)
        self.point = point


def _refusal_message(refusal: _Refusal, segments: list[Segment], bound: float, closed: bool | None, shape: str, units: str,
                     tolerance: float) -> str:  # fmt: skip
    where = f"joint {refusal.joint}"
    if isinstance(refusal, _Located):
        where += f" (between segments {refusal.joint} and {(refusal.joint + 1) % len(segments)}) at {_shown_point(refusal.point)}"
    message = f"{where}: cannot be made G2 within max_deviation {bound:.6g} {units}: {refusal.reason}"
    if not refusal.larger_helps:
        return message + "; no larger max_deviation helps"
    works = _smallest_bound(segments, bound, closed, shape, units, tolerance)
    if works is None:
        return message + "; no max_deviation up to the path's size helps"
    return message + f"; max_deviation {works:.3g} {units} works (built and checked)"


def _smallest_bound(segments: list[Segment], bound: float, closed: bool | None, shape: str, units: str, tolerance: float) -> float | None:
    """The smallest bound (to a few per cent) with which the path is made G2, found by building it."""
    size = max(float(np.abs(np.array([p for s in segments for p in s.outline()])).max()), 1e-300)
    lo, hi = bound, bound
    while True:
        hi *= 4.0
        if hi > 4.0 * size:
            return None
        made = _make(segments, hi, closed, shape, units, tolerance)
        if not isinstance(made, _Refusal):
            break
        if not made.larger_helps:
            return None
        lo = hi
    for _ in range(6):
        mid = math.sqrt(lo * hi)
        if isinstance(_make(segments, mid, closed, shape, units, tolerance), _Refusal):
            lo = mid
        else:
            hi = mid
    # The advice is shown to 3 digits: rounded up, and that very number built again.
    for _ in range(8):
        digits = 10.0 ** (math.floor(math.log10(hi)) - 2)
        shown = float(f"{math.ceil(hi / digits) * digits:.3g}")
        if not isinstance(_make(segments, shown, closed, shape, units, tolerance), _Refusal):
            return shown
        hi = 1.25 * shown
    return None


def _make(segments: list[Segment], bound: float, closed: bool | None, shape: str, units: str, tolerance: float) -> G2Path | _Refusal:
    """``make_g2`` of plane segments, or the refusal of its first joint that fails."""
    pieces = [_piece_of(s, i) for i, s in enumerate(segments)]
    points = np.array([p for s in segments for p in s.outline()])
    scale = float(np.abs(points).max()) or 1.0
    extent = float(np.hypot(*(points.max(axis=0) - points.min(axis=0)))) or scale
    gap_tol = max(1e-9 * extent, 64.0 * EPS * scale, 1e-3 * bound)
    for i, (a, b) in enumerate(zip(pieces[:-1], pieces[1:])):
        gap = math.dist(a.end(), b.start())
        if gap > gap_tol:
            raise ValueError(
                f"segments {i} and {i + 1} do not meet: segment {i} ends at {_shown_point(a.end().tolist())}, "
                f"segment {i + 1} starts at {_shown_point(b.start().tolist())} ({gap:.3g} apart)"
            )
    meets = math.dist(pieces[-1].end(), pieces[0].start()) <= gap_tol
    if closed is None:
        closed = meets and (len(pieces) > 1 or (pieces[0].kind == "arc" and pieces[0].sweep >= TAU - 1e-12))
    elif closed and not meets:
        raise ValueError(
            f"closed=True but the path ends at {_shown_point(pieces[-1].end().tolist())}, not at its start "
            f"{_shown_point(pieces[0].start().tolist())}"
        )
    corner_shape = shape
    steepest = _steepest_deflection(corner_shape)
    count = len(pieces)
    joint_count = count if closed else count - 1
    kinds = [_classify(pieces[i], pieces[(i + 1) % count], extent, steepest, bound) for i in range(joint_count)]
    joints: dict[int, G2Joint] = {}
    for i, kind in enumerate(kinds):
        if kind in ("g2", "split"):
            joints[i] = G2Joint(i, kind, tuple(pieces[i].end().tolist()), "nothing" if kind == "g2" else "split here", 0.0)
    # Merge G2 neighbours; a closed path starts after a joint that is not G2 (if it has one).
    order = list(range(count))
    if closed:
        cut = next((i for i, k in enumerate(kinds) if k != "g2"), None)
        if cut is None:  # every joint G2: a full circle or a closed line loop of one direction
            chain = Chain(segments, tolerance, units)
            return G2Path([chain], 0.0, [joints[i] for i in sorted(joints)], [], True, bound, shape, units)
        order = order[cut + 1 :] + order[: cut + 1]
    groups: list[tuple[list[_Piece], list[str], list[int], bool]] = []
    current: list[_Piece] = []
    current_kinds: list[str] = []
    current_joints: list[int] = []
    open_path = not closed or "split" in kinds
    if closed and "split" in kinds:  # start the open walk at a split
        cut = kinds.index("split")
        order = list(range(cut + 1, count)) + list(range(cut + 1))
    for k in order:
        piece = pieces[k]
        if current:
            joint = (k - 1) % count
            kind = kinds[joint]
            if kind == "g2":
                current[-1] = _merge(current[-1], piece)
                continue
            if kind == "split":
                groups.append((current, current_kinds, current_joints, False))
                current, current_kinds, current_joints = [], [], []
            else:
                current_kinds.append(kind)
                current_joints.append(joint)
        current.append(_Piece(piece.kind, piece.first, piece.last, piece.a, piece.b, piece.c, piece.r, piece.a0, piece.sweep))
    if current:
        if closed and not open_path:
            last = order[-1]
            current_kinds.append(kinds[last])
            current_joints.append(last)
        groups.append((current, current_kinds, current_joints, closed and not open_path))
    chains: list[Chain] = []
    deviation = 0.0
    for group_pieces, group_kinds, group_joints, group_closed in groups:
        try:
            group_pieces, group_kinds, group_joints = _arc_corners(group_pieces, group_kinds, group_joints, group_closed, bound)
            group_pieces, group_kinds, group_joints, bridges = _bridge_short_lines(group_pieces, group_kinds, group_joints,
                                                                                   group_closed, bound)  # fmt: skip
            group = _Group(group_pieces, group_kinds, group_closed, bound, shape, extent)
            group.bridges = bridges
            solved, s = _solve(group)
            chain, measured = _assemble(group, solved, s, units, tolerance)
        except _Refusal as refusal:
            index = group_joints[refusal.joint] if group_joints else 0
            return _Located(index, tuple(pieces[index].end().tolist()), refusal.reason, refusal.larger_helps)
        except ValueError as error:
            index = group_joints[0] if group_joints else 0
            return _Located(index, tuple(pieces[index].end().tolist()), f"float64 cannot hold the result: {error}", True)
        if measured > bound:
            index = group_joints[0] if group_joints else 0
            return _Located(index, tuple(pieces[index].end().tolist()),
                            f"the result lies {measured:.6g} from the input, beyond the bound", True)  # fmt: skip
        chains.append(chain)
        deviation = max(deviation, measured)
        for j, (kind, solved_joint) in enumerate(zip(group_kinds, solved)):
            index = group_joints[j]
            a, b = group_pieces[j], group_pieces[(j + 1) % len(group_pieces)]
            if kind == "bridge":
                line, after = group.bridges[j]
                moved = (f"line {line.first} ({line.size:.6g} long, too short for a transition at each end) joined across by "
                         f"a {'C' if (a.r > 0) == (b.r > 0) else 'S'} spiral pair; {_moved('line-arc', a, b, s[j], s[(j + 1) % len(group_pieces)], solved_joint)}")  # fmt: skip
                for where in (index, after):
                    joints[where] = G2Joint(where, "line-arc", tuple(pieces[where].end().tolist()), moved,
                                            max(s[j], s[(j + 1) % len(group_pieces)]), solved_joint.theta if solved_joint else math.nan)  # fmt: skip
                continue
            if a.fillet or b.fillet:
                circle, shift = (a, s[j]) if a.fillet else (b, s[(j + 1) % len(group_pieces)])
                moved = (f"corner rounded by a tangent circle of radius {abs(circle.r):.6g} passing {circle.fillet:.6g} from it, "
                         f"shrunk by {shift:.6g} for its transitions")  # fmt: skip
                joints[index] = G2Joint(index, "corner", tuple(pieces[index].end().tolist()), moved, circle.fillet + shift,
                                        solved_joint.theta if solved_joint is not None else math.nan)  # fmt: skip
                continue
            joints[index] = G2Joint(index, kind, tuple(pieces[index].end().tolist()), _moved(kind, a, b, s[j], s[(j + 1) % len(group_pieces)], solved_joint),
                                    _joint_shift(kind, s[j], s[(j + 1) % len(group_pieces)], group, solved_joint, a),
                                    solved_joint.theta if solved_joint is not None else math.nan)  # fmt: skip
    records = [joints[i] for i in sorted(joints)]
    splits = [j.index for j in records if j.kind == "split"]
    return G2Path(chains, deviation, records, splits, bool(closed) and not splits, bound, shape, units)


def _arc_corners(pieces: list[_Piece], kinds: list[str], joints: list[int], closed: bool,
                 bound: float) -> tuple[list[_Piece], list[str], list[int]]:  # fmt: skip
    """Each sharp corner next to an arc given a tangent circle (a circular fillet) passing half the bound
    from the corner point, so that the path is tangent there and its transitions do the rest."""
    n = len(pieces)
    corners = [j for j, kind in enumerate(kinds) if kind == "corner" and "arc" in (pieces[j].kind, pieces[(j + 1) % n].kind)]
    if not corners:
        return pieces, kinds, joints
    pieces = [_Piece(p.kind, p.first, p.last, p.a.copy(), p.b.copy(), p.c.copy(), p.r, p.a0, p.sweep) for p in pieces]
    sizes = [p.size for p in pieces]
    both = [closed or 0 < k < n - 1 for k in range(n)]
    circles: dict[int, _Piece] = {}
    for j in corners:
        a, b = pieces[j], pieces[(j + 1) % n]
        room_a = (SHARED if both[j] else ALONE) * sizes[j]
        room_b = (SHARED if both[(j + 1) % n] else ALONE) * sizes[(j + 1) % n]
        made = _tangent_circle(a, b, 0.5 * bound, room_a, room_b)
        if made is None:
            raise _Refusal(j, "no tangent circle fits into this corner between its neighbours", False)
        circle, end_a, start_b = made
        _trim_end(a, end_a)
        _trim_start(b, start_b)
        a.spent = max(a.spent, circle.fillet)
        b.spent = max(b.spent, circle.fillet)
        circle.spent = circle.fillet
        circles[j] = circle
    out_pieces: list[_Piece] = []
    out_kinds: list[str] = []
    out_joints: list[int] = []
    for k in range(n):
        out_pieces.append(pieces[k])
        if k >= len(kinds):
            continue
        if k in circles:
            circle, after = circles[k], pieces[(k + 1) % n]
            out_pieces.append(circle)
            out_kinds += [_tangent_kind(pieces[k], circle), _tangent_kind(circle, after)]
            out_joints += [joints[k], joints[k]]
        else:
            out_kinds.append(kinds[k])
            out_joints.append(joints[k])
    return out_pieces, out_kinds, out_joints


#: A line between two arcs is left out (the arcs joined by a C or S pair across it) when the shift
#: its length allows a transition at each end is below this share of the bound.
SHORT_LINE_SHIFT = 1e-4


def _bridge_short_lines(pieces: list[_Piece], kinds: list[str], joints: list[int], closed: bool,
                        bound: float) -> tuple[list[_Piece], list[str], list[int], dict[int, tuple[_Piece, int]]]:  # fmt: skip
    """Lines between two tangent arcs too short for a transition at each end (the shift they allow,
    about (0.45·ℓ)²/(6r), below ``SHORT_LINE_SHIFT`` of the bound) left out: the two arcs are joined
    across the line by the paper's pair between circles (a C for the same sense, an S for opposite)."""
    n = len(pieces)
    joint_count = len(kinds)
    short = set()
    for k, piece in enumerate(pieces):
        before, after = (k - 1) % n, k
        if piece.kind != "line" or not (closed or 0 < k < n - 1) or after >= joint_count or before >= joint_count:
            continue
        if kinds[before] != "line-arc" or kinds[after] != "line-arc" or before in short or (k + 1) % n in short:
            continue
        radius = min(abs(pieces[before].r), abs(pieces[(k + 1) % n].r))
        if (SHARED * piece.size) ** 2 / (6.0 * radius) < SHORT_LINE_SHIFT * bound:
            short.add(k)
    if not short or len(short) == n:
        return pieces, kinds, joints, {}
    out_pieces: list[_Piece] = []
    out_kinds: list[str] = []
    out_joints: list[int] = []
    bridges: dict[int, tuple[_Piece, int]] = {}
    order = list(range(n))
    if closed and 0 in short:  # start after a kept piece so that no bridge wraps round the start
        first = next(k for k in range(n) if k not in short)
        order = order[first:] + order[:first]
    for k in order:
        if k in short:
            bridges[len(out_kinds) - 1] = (pieces[k], joints[k])
            out_kinds[-1] = "bridge"
            continue
        out_pieces.append(pieces[k])
        if k < joint_count:
            out_kinds.append(kinds[k])
            out_joints.append(joints[k])
    return out_pieces, out_kinds, out_joints, bridges


def _tangent_kind(a: _Piece, b: _Piece) -> str:
    if a.kind == "line" or b.kind == "line":
        return "line-arc"
    return "arc-arc-compound" if (a.r > 0) == (b.r > 0) else "arc-arc-reverse"


def _tangent_circle(a: _Piece, b: _Piece, depth: float, room_a: float, room_b: float) -> tuple[_Piece, NDArray, NDArray] | None:
    """The largest circle tangent to ``a`` and ``b`` inside their corner that passes at most ``depth`` from the
    corner point and touches each within its room; (circle piece, touch on a, touch on b), None if none fits."""
    corner = a.end()
    turn = _turn(a, b)
    sense = math.copysign(1.0, turn)

    def attempt(rho: float) -> tuple[_Piece, NDArray, NDArray] | None:
        loci: list[tuple[str, NDArray, Any]] = []
        for piece in (a, b):
            if piece.kind == "line":
                t = piece.tangent(True)
                normal = np.array([-t[1], t[0]]) * sense
                loci.append(("line", piece.a + rho * normal, t))
            else:
                distance = abs(piece.r) - rho if (piece.r > 0) == (sense > 0) else abs(piece.r) + rho
                if not distance > 0.0:
                    return None
                loci.append(("circle", piece.c, distance))
        centre = _intersect(loci[0], loci[1], corner)
        if centre is None:
            return None
        touches = []
        for piece in (a, b):
            if piece.kind == "line":
                t = piece.tangent(True)
                touches.append(piece.a + float(np.dot(centre - piece.a, t)) * t)
            else:
                away = centre - piece.c
                touches.append(piece.c + abs(piece.r) * away / math.hypot(*away))
        used_a, used_b = _used(a, touches[0], True), _used(b, touches[1], False)
        if not (0.0 < used_a <= room_a and 0.0 < used_b <= room_b):
            return None
        if not math.dist(centre, corner) - rho <= depth:
            return None
        start = math.atan2(touches[0][1] - centre[1], touches[0][0] - centre[0])
        end = math.atan2(touches[1][1] - centre[1], touches[1][0] - centre[0])
        sweep = (sense * (end - start)) % TAU
        if not 0.0 < sweep < math.pi:
            return None
        circle = _Piece("arc", -1, -1, c=centre, r=sense * rho, a0=start, sweep=sweep, fillet=math.dist(centre, corner) - rho)
        return circle, touches[0], touches[1]

    half = abs(turn) / 2.0
    rho = depth / max(1.0 / math.cos(half) - 1.0, 1e-300)
    best = None
    for _ in range(200):
        best = attempt(rho)
        if best is not None:
            break
        rho *= 0.5
    if best is None:
        return None
    lo, hi = rho, 2.0 * rho
    for _ in range(40):
        mid = 0.5 * (lo + hi)
        found = attempt(mid)
        if found is not None:
            lo, best = mid, found
        else:
            hi = mid
    return best


def _trim_end(piece: _Piece, point: NDArray) -> None:
    if piece.kind == "line":
        piece.b = point.copy()
    else:
        piece.sweep -= _used(piece, point, True)


def _trim_start(piece: _Piece, point: NDArray) -> None:
    if piece.kind == "line":
        piece.a = point.copy()
    else:
        used = _used(piece, point, False)
        piece.a0 += piece.sense * used
        piece.sweep -= used


def _moved(kind: str, a: _Piece, b: _Piece, sa: float, sb: float, solved: _Solved | None) -> str:
    def arc(piece: _Piece, shift: float) -> str:
        return f"arc {piece.first} radius {abs(piece.r):.10g} → {abs(piece.r) - shift:.10g} (centre kept)"

    if kind == "corner":
        return "corner rounded by a spiral pair"
    parts = [arc(p, s) for p, s in ((a, sa), (b, sb)) if p.kind == "arc"]
    return "; ".join(parts)


def _joint_shift(kind: str, sa: float, sb: float, group: _Group, solved: _Solved | None, a: _Piece) -> float:
    if kind == "corner" and solved is not None:
        pair = solved.spirals
        return float(math.dist(pair[0][3], a.b))
    return max(sa, sb)
