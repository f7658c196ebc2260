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
* **a line between two arcs too short for a transition at each end**: left
  out, the arcs joined across it by a C (same sense) or S pair.
* **sharp corners next to an arc**: a tangent circle passing half the bound
  from the corner, then transitions as for every tangent joint.
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

import gc
import math
import time
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from ..core.chain import JOIN_TOLERANCE, Chain, g2_mismatch, join_tolerance
from ..core.errors import JointError, NoSolutionError
from ..core.inputs import as_float, as_real_array
from ..core.segments import TAU, Arc, Line, Segment
from ..core.shapes import SHAPE_CODES, TRANSITION_SHAPES, shape_code
from ..core.space import PlaneFrame
from ..core.spiral import BezierSpiral
from ..core.units import DEFAULT_UNITS, length_unit
from ._g2_kept import _KeptRefusal, is_kept, make_kept
from ._g2_measure import _deviation
from ._g2_pieces import (
    EPS,
    REVERSAL,
    TANGENT_TOL,
    _circle_offset,
    _classify,
    _flat_arcs,
    _merge,
    _merge_error,
    _Piece,
    _piece_ends,
    _piece_of,
    _Refusal,
    _sagitta,
    _shown_point,
    _Solved,
    _turn,
)
from ._g2_solve import _arc_corners, _bridge_short_lines, _c_unfit, _Group, _solve
from .rounding import _steepest_deflection

__all__ = ["TANGENT_TOL", "G2Joint", "G2Path", "make_g2", "smallest_max_deviation"]

#: The largest gap between segments that make_g2 closes, as a share of the bound.
GAP_SHARE = 0.5

JOINT_KINDS = ("line-arc", "arc-arc-compound", "arc-arc-reverse", "corner", "g2", "split")

#: The joints solved in ways the result does not name apart: a C pair between crossing circles of the same
#: sense is a compound joint (its ``moved`` says which).
PUBLIC_KINDS = {"arc-arc-c": "arc-arc-compound"}


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
    def split_joints(self) -> list[G2Joint]:
        """The joints where the path was split (a reversal, or a sharp corner where no tangent circle
        fits between its neighbours): the parts meet there with a kink (G0); ``moved`` says why."""
        return [j for j in self.joints if j.kind == "split"]

    def describe_splits(self) -> str:
        """The splits in words (empty when none): how many, and each joint, point and reason."""
        splits = self.split_joints
        if not splits:
            return ""
        named = "; ".join(f"joint {j.index} at {_shown_point(j.point)}: {j.moved.removeprefix('split here: ')}" for j in splits)
        return f"split into {len(self.chains)} G2 parts at {len(splits)} joint(s), G0 there ({named})"

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


def _path_segments(path: Any) -> tuple[list[Segment], PlaneFrame | None]:
    """Lines and arcs of the plane from ``path`` (a Chain, Line/Arc sequence or (n, 2|3) points), and the
    frame of a planar path in space (None in the plane)."""
    if isinstance(path, Chain):
        path = list(path)
    if isinstance(path, Sequence) and path and all(isinstance(s, Segment) for s in path):
        segments = list(path)
        if all(s.dim == 2 for s in segments):
            return segments, None
        for i, s in enumerate(segments):
            if is_kept(s):
                raise ValueError(f"make_g2 keeps spirals of a path in the plane (2-D); segment {i} is a {type(s).__name__} in space")
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
    # full matrices: a path of two points (a line) still gets a third direction, a normal to it
    _, singular, vt = np.linalg.svd(centred / size, full_matrices=True)
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
        raise _Refusal(max(where, 0), f"its transition does not join G2 ({detail})", True) from None
    if group.closed:
        problem = g2_mismatch(segments[-1], segments[0], chain.tolerance, units, len(segments) - 1)
        if problem:
            raise _Refusal(n - 1, f"the path does not close G2: {problem}", True)
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
    arc = Arc._of(piece.c.copy(), float(radius), float(piece.a0 + piece.sense * used[0]), float(sweep))
    arc._check()  # the checks of Arc(...), without converting what is already float
    return [arc]


def make_g2(
    path: Any,
    max_deviation: float,
    *,
    closed: bool | None = None,
    shape: str = "near-linear",
    units: str = DEFAULT_UNITS,
    tolerance: float = JOIN_TOLERANCE,
    advise: bool = True,
) -> G2Path:
    """Make a path of lines and tangent arcs G2 within ``max_deviation``, keeping its arcs true arcs.

    Every tangent joint gets a transition (line → arc: one spiral onto the arc's
    circle shrunk about its centre by the shift the spiral needs; arc → arc:
    an S for a reverse curve, the nested-circle spiral for a compound one);
    sharp corners between lines get a spiral pair within the bound (as
    ``round_corners`` with ``max_deviation``); a corner next to an arc, or
    sharper than a spiral pair rounds, gets a tangent circle passing within
    the bound and a transition on each side. At a reversal (or where no such
    circle fits between its neighbours) the path is split and each part made
    G2 on its own. The shifts use the bound (gentlest transitions) as far as
    the arcs' sweeps and the lines' lengths allow (each joint may use up to
    45 % of a line or arc it shares with another joint). Arcs stay ``Arc``
    pieces: true circles, never chords.

    Args:
        path: a sequence of ``Line`` and ``Arc`` meeting end to start (2-D, or
            3-D in one plane), a ``Chain`` of them, or (n, 2|3) polyline points.
            Other segments (2-D ``BezierSpiral``, e.g. ``make_g2``'s own) are
            kept as they are when their joints are G2: ``make_g2`` of its own
            result changes nothing. Near-tangent joints (kinks whose circles
            overlap by at most a tenth of the bound) are made G2 as tangent
            ones; arcs of one circle (to a quarter of the bound) are merged. An arc too short
            for transitions that absorb a kinked joint beside it, lying within a quarter of the bound
            of its chord (a CAM program's short arc), is cut as its chord, its joints rounded as corners.
        max_deviation: the Hausdorff bound: every point of the result lies
            within it of the input and every input point within it of the result.
        closed: whether the path closes (its closing joint is then treated like
            every other); None: closed when its last point is its first.
        shape: ``"near-linear"`` (default: curvature almost linear in arc
            length) or ``"walton-meek"``.
        units: the length unit (default mm).
        tolerance: the chains' relative join tolerance.
        advise: whether a refusal searches for a bound that works (up to ``ADVICE_SECONDS``); False for a
            caller that only needs the joint refused and its reason (it splits there and goes on).

    Returns:
        A :class:`G2Path`: the chains, the measured deviation and what was done at every joint.

    Raises:
        NoSolutionError: a joint that cannot be made G2 within the bound; the
            message names the joint, the numbers and a bound that works (built
            and checked) when a larger one helps, in under a second.
        ValueError: malformed input (segments that do not meet, a bad bound, …).
    """
    bound = _bound(max_deviation)
    shape_code(shape, TRANSITION_SHAPES)
    units = length_unit(units)
    tolerance = join_tolerance(tolerance)
    started = time.perf_counter()
    segments, frame = _path_segments(path)
    with _collector_paused():
        result = _build(segments, bound, closed, shape, units, tolerance)
        if isinstance(result, _Refusal):
            # no search where one build of the whole path takes longer than the search may take
            cheap = time.perf_counter() - started <= ADVICE_SECONDS
            deadline = started + ADVICE_SECONDS if advise and cheap else -math.inf
            message = _refusal_message(result, segments, bound, closed, shape, units, tolerance, deadline)
    if isinstance(result, _Refusal):
        raise NoSolutionError(message) from None
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
        failed = _build(segments, 4.0 * size, closed, shape, units, tolerance)
        reason = _refusal_message(failed, segments, 4.0 * size, closed, shape, units, tolerance) if isinstance(failed, _Refusal) else ""
        raise NoSolutionError(f"no max_deviation up to the path's size makes it G2: {reason}")
    return works


@contextmanager
def _collector_paused() -> Iterator[None]:
    """Python's cycle collector paused while a path is made: its many small objects (a few per joint, none
    in cycles that outlive the call) would otherwise set off full collections that cost a fifth of the time."""
    was_enabled = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if was_enabled:
            gc.enable()


def _placed_joint(joint: G2Joint, frame: PlaneFrame) -> G2Joint:
    point = tuple(float(v) for v in frame.point(np.array(joint.point)).tolist())
    return G2Joint(joint.index, joint.kind, point, joint.moved, joint.shift, joint.theta)


class _Located(_Refusal):
    """A refusal located on the input: the input joint index and its point."""

    def __init__(self, index: int, point: tuple[float, ...], reason: str, larger_helps: bool):
        super().__init__(index, reason, larger_helps)
        self.point = point


def _refusal_message(refusal: _Refusal, segments: list[Segment], bound: float, closed: bool | None, shape: str, units: str,
                     tolerance: float, deadline: float = math.inf) -> str:  # fmt: skip
    where = f"joint {refusal.joint}"
    if isinstance(refusal, (_Located, _KeptRefusal)):
        where += f" (between segments {refusal.joint} and {(refusal.joint + 1) % len(segments)}) at {_shown_point(refusal.point)}"
    message = f"{where}: cannot be made G2 within max_deviation {bound:.6g} {units}: {refusal.reason}"
    if not refusal.larger_helps:
        return message + "; no larger max_deviation helps"
    if deadline == -math.inf:
        return message + "; a larger max_deviation may help"
    works = _advice(segments, refusal.joint, bound, closed, shape, units, tolerance, deadline)
    if works is None:
        return message + "; no max_deviation up to the path's size helps"
    if math.isnan(works):
        return message + f"; no larger max_deviation was found to work within {ADVICE_SECONDS:g} s of search"
    return message + f"; max_deviation {works:.3g} {units} works (built and checked)"


#: The time a refusal may take, its advice included (a bound that works, found on the joint's
#: neighbourhood and built on the whole path).
ADVICE_SECONDS = 0.6


def _advice(segments: list[Segment], joint: int, bound: float, closed: bool | None, shape: str, units: str,
            tolerance: float, deadline: float = math.inf) -> float | None:  # fmt: skip
    """A bound larger than ``bound`` with which the whole path is made G2, shown to 3 digits and built with
    that very number: searched on the few segments about the failing joint (cheap), then built whole; a
    joint that still fails is searched next. None: none up to the path's size; NaN: none found in time."""
    deadline = min(deadline, time.perf_counter() + ADVICE_SECONDS)
    n = len(segments)
    size = max(float(np.abs(np.array([p for s in segments for p in s.outline()])).max()), 1e-300)
    ends = np.array([segments[-1].end[:2], segments[0].start[:2]], dtype=float)
    wraps = closed is True or (closed is None and math.dist(*ends) <= 1e-9 * size)
    lo = bound
    for _ in range(8):
        picks = list(range(joint - 2, joint + 4)) if wraps else list(range(max(joint - 2, 0), min(joint + 4, n)))
        window = [segments[k % n] for k in picks] if n > len(picks) + 1 else segments
        works = _smallest_bound(window, lo, False if window is not segments else closed, shape, units, tolerance, deadline)
        if works is None or math.isnan(works):
            if window is segments:
                return works
            works = 4.0 * lo  # the window alone gives no advice: step on and let the whole path say
        if works > 4.0 * size:
            return None
        made = _build(segments, works, closed, shape, units, tolerance)
        if not isinstance(made, _Refusal):
            return works
        if not made.larger_helps or time.perf_counter() > deadline:
            return None if not made.larger_helps else math.nan
        joint, lo = made.joint, works
    return math.nan


def _smallest_bound(segments: list[Segment], bound: float, closed: bool | None, shape: str, units: str, tolerance: float,
                    deadline: float = math.inf) -> float | None:  # fmt: skip
    """The smallest bound above ``bound`` (to a few per cent) with which the path is made G2, found by building
    it, shown to 3 digits rounded up and that very number built; None: none up to the path's size; NaN:
    ``deadline`` (``time.perf_counter()``) passed."""
    size = max(float(np.abs(np.array([p for s in segments for p in s.outline()])).max()), 1e-300)
    lo, hi = bound, bound
    while True:
        hi *= 4.0
        if hi > 4.0 * size:
            return None
        if time.perf_counter() > deadline:
            return math.nan
        made = _build(segments, hi, closed, shape, units, tolerance, retry=False)
        if not isinstance(made, _Refusal):
            break
        if not made.larger_helps:
            return None
        lo = hi
    for _ in range(6):
        if time.perf_counter() > deadline:
            break
        mid = math.sqrt(lo * hi)
        if isinstance(_build(segments, mid, closed, shape, units, tolerance, retry=False), _Refusal):
            lo = mid
        else:
            hi = mid
    # The advice is shown to 3 digits: rounded up, and that very number built again.
    for _ in range(8):
        if time.perf_counter() > deadline:
            return math.nan
        digits = 10.0 ** (math.floor(math.log10(hi)) - 2)
        shown = float(f"{math.ceil(hi / digits) * digits:.3g}")
        if not isinstance(_build(segments, shown, closed, shape, units, tolerance), _Refusal):
            return shown
        hi = 1.25 * shown
    return None


def _build(segments: list[Segment], bound: float, closed: bool | None, shape: str, units: str, tolerance: float,
           retry: bool = True) -> G2Path | _Refusal:  # fmt: skip
    """``make_g2`` of plane segments (spirals and other segments kept as they are), or the refusal of its
    first joint that fails."""
    if any(is_kept(s) for s in segments):
        made: G2Path | _Refusal = make_kept(segments, bound, closed, shape, units, tolerance, _make, G2Path, G2Joint, retry)
        return made
    return _make(segments, bound, closed, shape, units, tolerance, retry)


@dataclass(frozen=True)
class _Attempt:
    """How ``_make`` makes a path; each way it is made again after a refusal changes one of these.

    Attributes:
        round_sharp: a corner sharper than a spiral pair rounds (not a reversal) gets a tangent circle within
            the bound and a transition on each side; where that fails, the path is made again split there.
        no_c: joints between crossing circles whose C pair was refused, made as compound joints or corners.
        retried: how many times ``no_c`` has grown.
        loose: arcs of one circle to a share of the bound are merged (they move their neighbours' ends);
            where that fails, only arcs of one circle to float64's resolution (a bound that works keeps working
            when it grows).
        chorded: short arcs beside a kinked joint refused, made their chords (each moves the path by its
            sagitta), their joints corners.
        near: small kinks are absorbed by the shifts of the arcs beside them; where that fails, rounded as the
            corners they are.
    """

    round_sharp: bool = True
    no_c: frozenset[int] = frozenset()
    retried: int = 0
    loose: bool = True
    chorded: frozenset[int] = frozenset()
    near: bool = True


def _make(segments: list[Segment], bound: float, closed: bool | None, shape: str, units: str, tolerance: float,
          retry: bool = True, attempt: _Attempt = _Attempt()) -> G2Path | _Refusal:  # fmt: skip
    """``make_g2`` of plane lines and arcs, or the refusal of its first joint that fails (``retry``: a part
    refused within the bound tried again within smaller shares of it; the advice's search goes without),
    made as ``attempt`` says, and again in the next way where that is refused."""
    round_sharp, no_c, loose, chorded, near = attempt.round_sharp, attempt.no_c, attempt.loose, attempt.chorded, attempt.near
    pieces = [_piece_of(s, i) for i, s in enumerate(segments)]
    chord_off = 0.0
    for i in chorded:
        chord_off = max(chord_off, _sagitta(pieces[i]))
        pieces[i] = _Piece("line", i, i, a=pieces[i].start(), b=pieces[i].end())
    points = np.array([p for s in segments for p in s.outline()])
    scale = float(np.abs(points).max()) or 1.0
    extent = float(np.hypot(*(points.max(axis=0) - points.min(axis=0)))) or scale
    gap_tol = max(1e-9 * extent, 64.0 * EPS * scale, GAP_SHARE * bound)
    starts, ends = _piece_ends(pieces)
    between = ends - np.roll(starts, -1, axis=0)  # each piece's end to the next one's start (the last: to the first)
    distances = np.hypot(between[:, 0], between[:, 1])
    for i in np.flatnonzero(distances[:-1] > gap_tol)[:1].tolist():
        a, b, gap = pieces[i], pieces[i + 1], float(distances[i])
        if gap > gap_tol:
            raise ValueError(
                f"segments {i} and {i + 1} do not meet: segment {i} ends at {_shown_point(a.end().tolist())}, "
                f"segment {i + 1} starts at {_shown_point(b.start().tolist())} ({gap:.3g} apart; make_g2 closes gaps "
                f"up to {GAP_SHARE:g} of max_deviation, {gap_tol:.3g})"
            )
    meets = bool(distances[-1] <= gap_tol)
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
    kinds = [_classify(pieces[i], pieces[(i + 1) % count], extent, steepest, bound, SHAPE_CODES[shape], i not in no_c, loose, near)
             for i in range(joint_count)]  # fmt: skip
    unfit = _c_unfit(pieces, kinds, shape)
    if unfit:  # C pairs that do not fit beside the joint: those joints made compound or corners
        no_c = no_c | frozenset(unfit)
        for i in unfit:
            kinds[i] = _classify(pieces[i], pieces[(i + 1) % count], extent, steepest, bound, SHAPE_CODES[shape], False, loose, near)
    sharp = [i for i, kind in enumerate(kinds) if kind == "split" and abs(_turn(pieces[i], pieces[(i + 1) % count])) < REVERSAL]
    if round_sharp:
        for i in sharp:
            kinds[i] = "corner"
    # A small gap (arcs of a CNC program end off their circles by the program's rounding) is closed: a
    # transition or tangent circle spans it by construction; two lines at a corner meet half-way. The
    # shifts leave room for it and the deviation adds it.
    gaps = distances[:joint_count].tolist()
    for i, gap in enumerate(gaps):
        a, b = pieces[i], pieces[(i + 1) % count]
        if gap > 0.0 and kinds[i] == "corner" and a.kind == "line" and b.kind == "line":
            a.b = b.a = 0.5 * (a.b + b.a)
    spanned = max(gaps, default=0.0) if max(gaps, default=0.0) > 64.0 * EPS * scale else 0.0
    shown = [tuple(point) for point in _piece_ends(pieces)[1].tolist()]  # each joint's point (corners met half-way)
    joints: dict[int, G2Joint] = {}
    for i, kind in enumerate(kinds):
        if kind in ("g2", "split"):
            moved = "nothing" if kind == "g2" else _split_reason(pieces[i], pieces[(i + 1) % count], steepest)
            joints[i] = G2Joint(i, kind, shown[i], moved, 0.0)
    # Merge G2 neighbours; a closed path starts after a joint that is not G2 (if it has one).
    order = list(range(count))
    if closed:
        cut = next((i for i, k in enumerate(kinds) if k != "g2"), None)
        if cut is None:  # every joint G2: a full circle (of arcs of one circle) or a closed line loop
            whole = pieces[0]
            for piece in pieces[1:]:
                whole = _merge(whole, piece)
            if whole.kind != "arc" or whole.sweep < TAU - 1e-9:
                return _Located(0, shown[0], "every joint is G2 but the pieces do not close into one circle", False)
            off = max(_circle_offset(whole, p) for p in pieces) + spanned
            if off > bound:
                return _Located(0, shown[0], f"its arcs lie {off:.3g} off one circle, beyond the bound", True)
            circle = Arc._of(whole.c.copy(), float(whole.r), float(whole.a0), TAU)
            return G2Path([Chain([circle], tolerance, units)], off, [joints[i] for i in sorted(joints)], [], True, bound, shape, units)
        order = order[cut + 1 :] + order[: cut + 1]
    groups: list[tuple[list[_Piece], list[str], list[int], bool]] = []
    current: list[_Piece] = []
    current_kinds: list[str] = []
    current_joints: list[int] = []
    merged_off = 0.0  # how far merging G2 neighbours (arcs of one circle, lines in line) moves the input
    arcs_merged = False  # whether arcs of nearly one circle were merged
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
                merged_off = max(merged_off, _merge_error(current[-1], piece))
                arcs_merged = arcs_merged or (piece.kind == "arc" and _merge_error(current[-1], piece) > 0.0)
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
    spanned += merged_off + chord_off
    room = bound - spanned
    if not room > 0.0:
        return _Located(0, shown[0], f"its gaps and the arcs of one circle merged move it {spanned:.3g}, the whole bound", True)
    chains: list[Chain] = []
    deviation = 0.0
    for group_pieces, group_kinds, group_joints, group_closed in groups:
        made = _solve_group(group_pieces, group_kinds, group_joints, group_closed, room, shape, extent, units, tolerance, spanned,
                            bound, shown, steepest, RETRY_SHARES if retry else ())  # fmt: skip
        if isinstance(made, _Located):
            tried = replace(attempt, no_c=no_c)
            if made.joint < joint_count and kinds[made.joint] == "arc-arc-c" and attempt.retried < C_RETRIES:
                return _make(segments, bound, closed, shape, units, tolerance, retry,
                             replace(tried, no_c=no_c | {made.joint}, retried=attempt.retried + 1))  # fmt: skip
            flat = _flat_arcs(pieces, kinds, room) & {made.joint, (made.joint + 1) % count} - chorded
            kinked = near and any(kind != "corner" and abs(_turn(pieces[i], pieces[(i + 1) % count])) > TANGENT_TOL
                                  for i, kind in enumerate(kinds) if kind not in ("g2", "split"))  # fmt: skip
            for again in (
                replace(tried, loose=False) if loose and arcs_merged else None,  # arcs of nearly one circle: joined by transitions
                replace(tried, chorded=chorded | flat) if flat else None,  # short arcs beside the kinked joint refused: chords
                replace(tried, near=False) if kinked else None,  # small kinks rounded as corners
            ):
                remade = _make(segments, bound, closed, shape, units, tolerance, retry, again) if again else None
                if remade is not None and not isinstance(remade, _Refusal):
                    return remade
            if round_sharp and sharp:  # the tangent circles did not fit: split at those corners instead
                return _make(segments, bound, closed, shape, units, tolerance, retry, replace(tried, round_sharp=False))
            return made
        chain, measured, group, solved, s, group_pieces, group_kinds, group_joints = made
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
                    joints[where] = G2Joint(where, "line-arc", shown[where], moved,
                                            max(s[j], s[(j + 1) % len(group_pieces)]), solved_joint.theta if solved_joint else math.nan)  # fmt: skip
                continue
            if a.fillet or b.fillet:
                circle, shift = (a, s[j]) if a.fillet else (b, s[(j + 1) % len(group_pieces)])
                moved = (f"corner rounded by a tangent circle of radius {abs(circle.r):.6g} passing {circle.fillet:.6g} from it, "
                         f"shrunk by {shift:.6g} for its transitions")  # fmt: skip
                joints[index] = G2Joint(index, "corner", shown[index], moved, circle.fillet + shift,
                                        solved_joint.theta if solved_joint is not None else math.nan)  # fmt: skip
                continue
            joints[index] = G2Joint(index, PUBLIC_KINDS.get(kind, kind), shown[index],
                                    _moved(kind, a, b, s[j], s[(j + 1) % len(group_pieces)], solved_joint),
                                    _joint_shift(kind, s[j], s[(j + 1) % len(group_pieces)], group, solved_joint, a),
                                    solved_joint.theta if solved_joint is not None else math.nan)  # fmt: skip
    records = [joints[i] for i in sorted(joints)]
    splits = [j.index for j in records if j.kind == "split"]
    return G2Path(chains, deviation, records, splits, bool(closed) and not splits, bound, shape, units)


#: The most joints between crossing circles whose C pair is refused and made again otherwise (each a new solve).
C_RETRIES = 8


#: A group refused within the room is tried again within this share of it, ... (a result within a smaller
#: bound is within the larger one: a bound that works stays working when it grows).
RETRY_SHARES = (0.25, 1.0 / 16.0, 1.0 / 64.0)


def _solve_group(pieces: list[_Piece], kinds: list[str], joints: list[int], closed: bool, room: float, shape: str, extent: float,
                 units: str, tolerance: float, spanned: float, bound: float, shown: list[tuple[float, ...]], steepest: float,
                 shares: tuple[float, ...] = RETRY_SHARES) -> Any:  # fmt: skip
    """One group (a part between splits) made G2 within ``room``, or else within a share of it; the first
    refusal (located on the input) when none works."""
    first: _Located | None = None
    for share in (1.0, *shares):
        group_joints = joints
        try:
            group_pieces, group_kinds, group_joints = _arc_corners(pieces, kinds, joints, closed, share * room, steepest)
            group_pieces, group_kinds, group_joints, bridges = _bridge_short_lines(group_pieces, group_kinds, group_joints,
                                                                                   closed, share * room)  # fmt: skip
            group = _Group(group_pieces, group_kinds, closed, share * room, shape, extent)
            group.bridges = bridges
            solved, s = _solve(group)
            chain, measured = _assemble(group, solved, s, units, tolerance)
            measured += spanned
            if measured > bound:
                index = group_joints[0] if group_joints else 0
                raise _Located(index, shown[index], f"the result lies {measured:.6g} from the input, beyond the bound", True)
        except _Located as refusal:
            first = first or refusal
            continue
        except _Refusal as refusal:
            index = group_joints[refusal.joint] if group_joints and refusal.joint < len(group_joints) else joints[0] if joints else 0
            first = first or _Located(index, shown[index], refusal.reason, refusal.larger_helps)
            if not refusal.smaller_helps:
                break
            continue
        except ValueError as error:
            index = joints[0] if joints else 0
            first = first or _Located(index, shown[index], f"the transitions do not join G2: {error}", True)
            continue
        return chain, measured, group, solved, s, group_pieces, group_kinds, group_joints
    assert first is not None
    return first


def _split_reason(a: _Piece, b: _Piece, steepest: float) -> str:
    """Why the path is split at the joint from ``a`` to ``b``, in words."""
    turn = abs(_turn(a, b))
    if turn >= REVERSAL:
        return f"split here: a reversal (the path turns back on itself, {math.degrees(turn):.6g}°)"
    return (f"split here: a corner of {math.degrees(turn):.4g}°, sharper than the {math.degrees(steepest):.4g}° "
            "a spiral pair rounds")  # fmt: skip


def _moved(kind: str, a: _Piece, b: _Piece, sa: float, sb: float, solved: _Solved | None) -> str:
    def arc(piece: _Piece, shift: float) -> str:
        return f"arc {piece.first} radius {abs(piece.r):.10g} → {abs(piece.r) - shift:.10g} (centre kept)"

    if kind == "corner":
        return "corner rounded by a spiral pair"
    parts = [arc(p, s) for p, s in ((a, sa), (b, sb)) if p.kind == "arc"]
    if kind == "arc-arc-c":
        parts.insert(0, "a C spiral pair between the crossing circles")
    return "; ".join(parts)


def _joint_shift(kind: str, sa: float, sb: float, group: _Group, solved: _Solved | None, a: _Piece) -> float:
    if kind == "corner" and solved is not None:
        pair = solved.spirals
        return float(math.dist(pair[0][3], a.b))
    return max(sa, sb)
