"""make_g2's pieces: the input's lines and arcs (merged with their G2 neighbours), how its joints are
classified, and how much of a piece a transition uses."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from ..core import _kernel_circles as KC
from ..core import _kernels as K
from ..core.segments import TAU, Arc, Line, Segment

#: The share of a line's length or an arc's sweep one joint may use when the other end has a joint too.
SHARED = 0.45


#: ... and when the other end is a free end of the path.
ALONE = 0.9


EPS = float(np.finfo(float).eps)


def _shown_point(point: Sequence[float]) -> str:
    return "(" + ", ".join(f"{v:.10g}" for v in point) + ")"


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

    def direction(self) -> tuple[float, float]:
        """A line's unit direction, as plain floats (``tangent`` of a line)."""
        dx, dy = float(self.b[0] - self.a[0]), float(self.b[1] - self.a[1])
        length = math.hypot(dx, dy)
        return dx / length, dy / length

    def tangent(self, at_end: bool) -> NDArray:
        if self.kind == "line":
            return np.array(self.direction())
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
        if segment.dim == 2:  # its end points as its frames hold them (copied from its row), without computing the frames
            return _Piece("line", index, index, a=segment._a.copy(), b=segment._b.copy())
        (x0, y0, *_), (x1, y1, *_) = segment.ends
        return _Piece("line", index, index, a=np.array([x0, y0]), b=np.array([x1, y1]))
    assert isinstance(segment, Arc)
    return _Piece("arc", index, index, c=segment.center[:2].copy(), r=segment.radius, a0=segment.start_angle, sweep=segment.sweep)


def _piece_ends(pieces: list[_Piece]) -> tuple[NDArray, NDArray]:
    """The start and end points of many pieces at once, (n, 2) each (``start()`` and ``end()`` of each)."""
    arc = np.array([p.kind == "arc" for p in pieces])[:, None]
    c = np.array([p.c for p in pieces]).reshape(-1, 2)
    r = np.array([p.r for p in pieces])
    a0 = np.array([p.a0 for p in pieces])
    a1 = a0 + np.copysign(1.0, r) * np.array([p.sweep for p in pieces])
    radius = np.abs(r)[:, None]
    start = np.where(arc, c + radius * np.stack([np.cos(a0), np.sin(a0)], axis=-1), np.array([p.a for p in pieces]).reshape(-1, 2))
    end = np.where(arc, c + radius * np.stack([np.cos(a1), np.sin(a1)], axis=-1), np.array([p.b for p in pieces]).reshape(-1, 2))
    return start, end


def _turn(a: _Piece, b: _Piece) -> float:
    ta, tb = a.tangent(True), b.tangent(False)
    return math.atan2(ta[0] * tb[1] - ta[1] * tb[0], float(np.dot(ta, tb)))


def _circle_offset(a: _Piece, b: _Piece) -> float:
    """How far the circle of arc ``b`` lies from the circle of arc ``a`` (centres apart plus radii apart):
    every point of ``b`` moves at most this far when it is taken onto ``a``'s circle."""
    return math.dist(a.c, b.c) + abs(abs(a.r) - abs(b.r))


def _same_circle(a: _Piece, b: _Piece, scale: float, bound: float) -> bool:
    """Whether arcs ``a`` and ``b`` turn the same way on one circle: to 1e-9 of the path's size, or to
    ``MERGE_SHARE`` of the bound (a hole cut as arcs whose centres the program rounded) and within
    ``MERGE_RELATIVE`` of the smaller radius (a loose bound never makes two different circles one)."""
    if (a.r > 0) != (b.r > 0):
        return False
    offset = _circle_offset(a, b)
    return offset <= 1e-9 * max(abs(a.r), scale) or offset <= min(MERGE_SHARE * bound, MERGE_RELATIVE * min(abs(a.r), abs(b.r)))


def _near_tangent(a: _Piece, b: _Piece, turn: float, bound: float) -> bool:
    """Whether a joint that turns by ``turn`` is made G2 as a tangent joint: below ``TANGENT_TOL``, or a
    small kink (as CAD and CAM files have, 1e-7 … 1e-3 rad) whose circles overlap by less than
    ``NEAR_SHARE`` of the bound (r·turn²/2 for the largest radius beside it), so that the shifts of the
    transition absorb it; the result's measured deviation includes it."""
    if abs(turn) <= TANGENT_TOL:
        return True
    radius = max(abs(p.r) for p in (a, b) if p.kind == "arc")
    return abs(turn) <= NEAR_MAX and 0.5 * radius * turn * turn <= NEAR_SHARE * bound


def _nested_defect(a: _Piece, b: _Piece, shape: int) -> float:
    """How far two arcs of the same sense are from touching inside each other (centres apart minus radii
    apart), as a share of the band of the nested-circle spiral between them (0: touching; ≥ 1: no nested
    spiral after any shift; equal radii: infinite)."""
    rs, rb = sorted((abs(a.r), abs(b.r)))
    if not rb - rs > 1e-12 * rb:
        return math.inf
    width = (rb - rs) * (1.0 / KC.nested_band_lower(rs / rb, shape) - 1.0)
    return abs(math.dist(a.c, b.c) - (rb - rs)) / width


def _c_window(a: _Piece, b: _Piece) -> tuple[int, int, float, float] | None:
    """The C pair between the circles of two arcs of the same sense, as the shifts must leave it: (the smaller
    piece's side, 0 for ``a``, 1 for ``b``; the larger's; lo, hi) such that the larger circle shrinking by δ more
    than the smaller, lo ≤ δ ≤ hi, leaves them crossing at an angle whose C pair float64 holds G2 (its spirals
    turn about that angle: r·angle² ≥ ``C_HOLD`` of the coordinates, with a margin), not much further past
    touching than they are (the crossing, and the pair, stay near the joint); None when no shift does
    (circles nearly concentric)."""
    ra, rb = abs(a.r), abs(b.r)
    d = math.dist(a.c, b.c)
    size = max(float(np.abs(a.end()).max()), float(np.abs(a.c).max()), float(np.abs(b.c).max()), ra, rb)
    angle = C_MARGIN * math.sqrt(C_HOLD * size / min(ra, rb))
    if not angle < 0.5:
        return None
    # Circles of radii r0, r1 whose centres lie d apart cross at the angle α when (r0 − r1)² = d² − 4 r0 r1 sin²(α/2).
    m2 = d * d - 4.0 * ra * rb * math.sin(0.5 * angle) ** 2
    if not m2 > 0.0:
        return None
    m, dr = math.sqrt(m2), abs(ra - rb)
    small, big = (0, 1) if ra <= rb else (1, 0)
    # Between half and twice as far past touching as the circles are (or must be): their crossing, and the
    # pair, stay near the joint.
    lo = max(dr - m, -0.5 * (d - dr))
    base = max(lo, 0.0)
    return small, big, lo, base + (d - abs(dr - base))


def _c_pair(a: _Piece, b: _Piece, turn: float) -> bool:
    """Whether a kinked joint of two arcs of the same sense is joined by the broken-back C pair between their
    circles (Theorem 4.2; every kinked joint of two circles lies on circles that cross), both arcs kept or
    shrunk about their centres (``_c_window``). A spiral cut as arcs of slowly changing radius, each starting
    where the last ends, has such joints. Turning against the arcs, the pair lies at the joint; turning with
    them, at the circles' other crossing: the lens between must fit in the arcs."""
    if not abs(turn) > TANGENT_TOL or _c_window(a, b) is None:
        return False
    return turn * a.sense < 0.0 or _lens_fits(a, b)


def _lens_fits(a: _Piece, b: _Piece) -> bool:
    """Whether the lens between the two crossings of the circles of arcs ``a`` and ``b`` (the joint at one of
    them) spans at most the share of each arc a joint may use: a transition placed at the other crossing,
    or where the circles come nearest, fits."""
    d = math.dist(a.c, b.c)
    # each crossing's angle at a centre, from the line of centres (the smaller circle: from its far side)
    at = [math.acos(min(max((p.r * p.r + d * d - q.r * q.r) / (2.0 * abs(p.r) * d), -1.0), 1.0)) for p, q in ((a, b), (b, a))]
    return 2.0 * max(min(t, math.pi - t) for t in at) <= SHARED * min(a.sweep, b.sweep)


def _classify(a: _Piece, b: _Piece, scale: float, steepest: float, bound: float, shape: int = K.NEAR_LINEAR,
              c_pair: bool = True, loose: bool = True, near: bool = True) -> str:  # fmt: skip
    """The joint from piece ``a`` to ``b``: ``g2``, ``line-arc``, ``arc-arc-…`` (``arc-arc-c``: a C pair between
    crossing circles of the same sense, unless not ``c_pair``), ``corner`` or ``split``; arcs of one circle to a
    share of the bound are ``g2`` (merged) when ``loose``, else only to float64's resolution; a small kink is
    made G2 as a tangent joint when ``near`` (``_near_tangent``), else rounded as the corner it is."""
    turn = _turn(a, b)
    if abs(turn) > steepest:
        return "split"
    if a.kind == "line" and b.kind == "line":
        if abs(turn) > TANGENT_TOL:
            return "corner"
        # Merged into one line only when the joint point lies within a thousandth of the bound of it.
        la, lb = a.size, b.size
        drop = la * lb / (la + lb) * abs(math.sin(turn))
        return "g2" if drop <= 1e-3 * bound else "corner"
    if a.kind == "arc" and b.kind == "arc" and abs(turn) <= NEAR_MAX and _same_circle(a, b, scale, bound if loose else 0.0):
        return "g2"
    if (a.kind == "arc" and b.kind == "arc" and (a.r > 0) == (b.r > 0) and turn * a.sense < 0.0 and abs(turn) <= NEAR_MAX and c_pair
            and _c_pair(a, b, turn)):  # fmt: skip
        return "arc-arc-c"  # a small kink against both arcs: the C pair lies at the joint, whatever the bound
    if not (_near_tangent(a, b, turn, bound) if near else abs(turn) <= TANGENT_TOL):
        return "corner"
    if a.kind == "arc" and b.kind == "arc":
        if (a.r > 0) != (b.r > 0):
            return "arc-arc-reverse"
        if c_pair and _c_pair(a, b, turn):
            return "arc-arc-c"
        # A kinked compound joint: its circles cross; the nested spiral needs them to touch (to a share of its band).
        share = NESTED_AGAINST if turn * a.sense < 0.0 else NESTED_SHARE
        return "arc-arc-compound" if abs(turn) <= TANGENT_TOL or _nested_defect(a, b, shape) <= share else "corner"
    return "line-arc"


#: A joint whose tangent turns by less than this (radians) is tangent (G1).
TANGENT_TOL = 1e-7


#: A joint whose tangent turns by this much or more (radians) is a reversal: the path is split there.
REVERSAL = math.pi - 1e-6


#: A kink up to this (radians) may be made G2 as a tangent joint (see ``_near_tangent``).
NEAR_MAX = 0.02


#: ... when the circles beside it overlap by at most this share of the bound.
NEAR_SHARE = 0.1


#: An arc whose chord lies within this share of the bound of it may be made a line where a joint beside it has a
#: kink that its sweep leaves no room to absorb (a CAM program's short arc): its joints become corners.
CHORD_SHARE = 0.25


def _sagitta(piece: _Piece) -> float:
    """How far an arc lies from its chord (the farthest point of the arc from the segment between its ends)."""
    return abs(piece.r) * (1.0 - math.cos(0.5 * piece.sweep))


def _flat_arcs(pieces: list[_Piece], kinds: list[str], bound: float) -> frozenset[int]:
    """The arcs beside a joint with a kink (not tangent, not a split) that lie within ``CHORD_SHARE`` of
    ``bound`` of their chords."""
    n = len(pieces)
    flat: set[int] = set()
    for j, kind in enumerate(kinds):
        a, b = pieces[j], pieces[(j + 1) % n]
        if kind not in ("g2", "split") and abs(_turn(a, b)) > TANGENT_TOL:
            flat.update(k for k in (j, (j + 1) % n) if pieces[k].kind == "arc" and _sagitta(pieces[k]) <= CHORD_SHARE * bound)
    return frozenset(flat)


#: A kinked compound joint is made G2 as tangent when its circles touch to this share of the nested band.
NESTED_SHARE = 0.25


#: ... or to this share when the kink turns against the arcs (the nested spiral then lies at the joint): the
#: smaller circle shrinks past the crossing into the band.
NESTED_AGAINST = 64.0


#: The C pair of a kinked joint between circles of the same sense needs r·angle² of at least this share of its
#: coordinates (the angle at which the circles cross; smaller pairs are beyond float64's G2).
C_HOLD = 5e-10


#: ... and the shifts make it cross at this many times the least such angle.
C_MARGIN = 1.0


#: Arcs of one circle (to this share of the bound) are merged into one arc.
MERGE_SHARE = 0.25


#: ... and to this share of their smaller radius (a program rounds centres to ~1e-4 of a hole's radius).
MERGE_RELATIVE = 1e-2


def _merge_error(a: _Piece, b: _Piece) -> float:
    """How far ``_merge(a, b)`` moves the points of ``a`` and ``b``: b's circle off a's, or the joint point off
    the line from a's start to b's end."""
    if a.kind != "line":
        return _circle_offset(a, b)
    d = b.b - a.a
    length = math.hypot(*d)
    return abs(float(d[0] * (a.b - a.a)[1] - d[1] * (a.b - a.a)[0])) / length if length > 0.0 else 0.0


def _merge(a: _Piece, b: _Piece) -> _Piece:
    """``a`` and its G2 neighbour ``b`` as one piece: a line from a's start to b's end, or an arc on a's
    circle from a's start to b's end (b's points move by at most ``_circle_offset(a, b)``)."""
    if a.kind == "line":
        return _Piece("line", a.first, b.last, a=a.a, b=b.b, spent=max(a.spent, b.spent))
    start, end = b.start(), b.end()
    gap = a.sense * _wrap(math.atan2(start[1] - a.c[1], start[0] - a.c[0]) - a.a1)
    drift = a.sense * _wrap(math.atan2(end[1] - a.c[1], end[0] - a.c[0]) - (a.a1 + a.sense * (gap + b.sweep)))
    sweep = a.sweep + gap + b.sweep + drift
    return _Piece("arc", a.first, b.last, c=a.c, r=a.r, a0=a.a0, sweep=min(max(sweep, 0.0), TAU), spent=max(a.spent, b.spent))


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


def _wrap(angle: float) -> float:
    return (angle + math.pi) % TAU - math.pi


def _used(piece: _Piece, point: NDArray, at_end: bool) -> float:
    """How much of ``piece`` (length of a line, sweep of an arc) lies between ``point`` and its end (start)."""
    return _used_xy(piece, float(point[0]), float(point[1]), at_end)


def _used_xy(piece: _Piece, x: float, y: float, at_end: bool, direction: tuple[float, float] | None = None) -> float:
    """``_used`` of the point (x, y), in plain floats (``direction``: a line's, when known)."""
    if piece.kind == "line":
        tx, ty = piece.direction() if direction is None else direction
        if at_end:
            return float(piece.b[0] - x) * tx + float(piece.b[1] - y) * ty
        return float(x - piece.a[0]) * tx + float(y - piece.a[1]) * ty
    angle = math.atan2(y - float(piece.c[1]), x - float(piece.c[0]))
    if at_end:
        return piece.sense * _wrap(piece.a1 - angle)
    return piece.sense * _wrap(angle - piece.a0)


def _used_rows(pieces: list[_Piece], points: NDArray, at_end: bool) -> NDArray:
    """``_used`` of many pieces at once: each piece's share between its point (rows of ``points``) and
    its end (start)."""
    line = np.array([p.kind == "line" for p in pieces])
    a = np.array([p.a for p in pieces])
    b = np.array([p.b for p in pieces])
    c = np.array([p.c for p in pieces])
    sense = np.copysign(1.0, np.array([p.r for p in pieces]))
    a0 = np.array([p.a0 for p in pieces])
    a1 = a0 + sense * np.array([p.sweep for p in pieces])
    d = b - a
    with np.errstate(invalid="ignore", divide="ignore"):
        t = d / np.hypot(d[:, 0], d[:, 1])[:, None]
    along = np.einsum("ij,ij->i", b - points, t) if at_end else np.einsum("ij,ij->i", points - a, t)
    angle = np.arctan2(points[:, 1] - c[:, 1], points[:, 0] - c[:, 0])
    turned = a1 - angle if at_end else angle - a0
    around = sense * ((turned + math.pi) % TAU - math.pi)
    return np.where(line, along, around)


class _Refusal(Exception):
    """A joint that cannot be made G2 within the bound (its index in the group and the reason)."""

    def __init__(self, joint: int, reason: str, larger_helps: bool, smaller_helps: bool = True):
        super().__init__(reason)
        self.joint, self.reason, self.larger_helps = joint, reason, larger_helps
        #: Whether a smaller share of the bound may work (not when the transitions are too small to hold G2).
        self.smaller_helps = smaller_helps
