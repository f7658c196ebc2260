"""make_g2's solve: the shift of every arc within the bound, the transitions at every joint (one batch
per kind), tangent circles in corners next to arcs, and short lines between arcs bridged."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..core import _kernel_circles as KC
from ..core import _kernels as K
from ..core import batch
from ..core.errors import Status
from ..core.segments import TAU
from ..core.shapes import SHAPE_CODES
from ._g2_pieces import (
    ALONE,
    EPS,
    SHARED,
    TANGENT_TOL,
    _c_window,
    _Piece,
    _Refusal,
    _Solved,
    _turn,
    _used,
    _used_rows,
    _used_xy,
)
from .fillets import _intersect_xy
from .rounding import round_corners_batch

#: The shifts are aimed this much (relative) inside the bound.
BOUND_MARGIN = 1e-6


#: Largest relative shrink s/r of an arc (Walton–Meek; near-linear stops at its largest angle).
MAX_SHRINK = 0.5


#: A joint whose circles' shifts have shrunk below this share of their first try is refused.
SMALLEST_FACTOR = 1e-6


#: Sweeps (forward and back along the path) that pass the shifts' constraints through runs of C pairs.
SWEEPS = 6


#: A C pair is tried where, between the circles as they are, it needs at most this much of its arcs' share.
C_ROOM = 0.8


#: An arc that shifts only to follow its neighbours across C pairs shrinks by at most this share of its radius.
C_FOLLOW = 0.02


#: A kinked line → arc joint's spiral lands at least this far (radians) past where the arc's tangent is the
#: line's and past the arc's start (its circle then lies clear of the line by a margin float64 resolves).
LANDING_MARGIN = 1e-5


#: Passes of shrinking the shifts that overrun a line or an arc before a joint is refused.
PASSES = 60


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
        # A C pair between circles of the same sense: the larger circle shrinks by δ more than the smaller,
        # lo ≤ δ ≤ hi (they cross, at an angle float64 holds); it shifts when lo > 0, and the arcs joined by C
        # pairs all may shift when one of them does (for another joint).
        self.c_pairs: list[tuple[int, int, int, float, float]] = []  # (joint, small, big, lo, hi)
        self._compound: list[tuple[int, int, int, float, float]] | None = None
        for j in range(self.joint_count):
            if kinds[j] == "arc-arc-c":
                ends = (j, (j + 1) % n)
                window = _c_window(pieces[ends[0]], pieces[ends[1]])
                if window is None:
                    raise _Refusal(j, "its arcs lie on circles too nearly concentric for a C spiral pair", False, False)
                small, big, lo, hi = window
                self.c_pairs.append((j, ends[small], ends[big], lo, hi))
                if lo > 0.0:
                    self.needs_shift[ends[big]] = True
        following = [False] * n  # shifting only to follow a neighbour across C pairs (by a little: the pairs stay put)
        for members in _c_groups(kinds, self.joint_count, n):
            if any(self.needs_shift[k] for k in members):
                for k in members:
                    following[k] = not self.needs_shift[k]
                    self.needs_shift[k] = True
        code = SHAPE_CODES[shape]
        theta_max = KC.shape_max_theta(code)
        if code == K.NEAR_LINEAR:
            largest = 0.98 * theta_max
            q_max = 1.0 - 1.0 / K.shape_g1(code, math.sin(largest), math.cos(largest))
        else:
            q_max = MAX_SHRINK
        size = _coordinate_size(pieces)
        target = bound * (1.0 - BOUND_MARGIN) - 8.0 * EPS * size
        if not target > 0.0:
            raise _Refusal(
                0, f"it is below what float64 resolves at these coordinates (8 ulp of {size:.6g} is {8.0 * EPS * size:.3g})", True
            )
        self.target = target
        self.cap = [min(target - p.spent, (C_FOLLOW if follow else q_max) * abs(p.r)) if need else 0.0
                    for p, need, follow in zip(pieces, self.needs_shift, following)]  # fmt: skip
        self.floor = self._floors(code)
        self.factor = [1.0] * n
        self._corners: dict[int, _Solved] = {}
        #: Short lines left out between two arcs (by joint): (the line, the input joint after it).
        self.bridges: dict[int, tuple[_Piece, int]] = {}

    def shifts(self) -> list[float]:
        """Each arc's shrink: its cap times its factor, the smaller circle of a compound joint shrunk
        more than the larger one by a step inside the nested band (past the crossing of circles that
        cross), the circles of a C pair shrunk so that they still cross (``c_pairs``)."""
        s = [c * f for c, f in zip(self.cap, self.factor)]
        pairs = self._pairs()
        for _ in range(3):
            for _, small, big, cross, width in pairs:  # the larger circle shrinks less, by a step inside the band
                s[big] = min(s[big], s[small] - cross - min(0.5 * (s[small] - cross), 0.5 * width))
            for _, small, big, cross, width in pairs[::-1]:  # ... and not by more than the band allows
                s[small] = min(s[small], s[big] + cross + 0.9 * width)
        if self.c_pairs:  # the constraints passed along the path (runs of C pairs between compound joints), both ways
            chain = sorted([(j, "compound", small, big, cross, width) for j, small, big, cross, width in pairs]
                           + [(j, "c", small, big, lo, hi) for j, small, big, lo, hi in self.c_pairs])  # fmt: skip
            for _ in range(SWEEPS):
                before = list(s)
                for order in (chain, chain[::-1]):
                    for _, kind, small, big, x, y in order:
                        if kind == "c":  # still crossing, steeply enough: lo ≤ s[big] − s[small] ≤ hi
                            s[big] = min(s[big], s[small] + y)
                            s[small] = min(s[small], s[big] - x)
                        else:
                            s[big] = min(s[big], s[small] - x - min(0.5 * (s[small] - x), 0.5 * y))
                            s[small] = min(s[small], s[big] + x + 0.9 * y)
                if s == before:
                    break
        return [max(v, 0.0, f) for v, f in zip(s, self.floor)]

    def _floors(self, code: int) -> list[float]:
        """Each arc's least shrink: where a line meets it with a small kink (``line-arc``, a near-tangent joint),
        its circle crosses the line or is tangent to it before the arc starts, so the spiral needs the circle
        shrunk at least until it lands on the arc itself (Theorem 4.1: the centre lies r·g1(θ) off the line);
        shrinking the shifts to fit the room must not pass below that."""
        n = len(self.pieces)
        floor = [0.0] * n
        for j in range(self.joint_count):
            a, b = self.pieces[j], self.pieces[(j + 1) % n]
            if self.kinds[j] != "line-arc" or not abs(turn := _turn(a, b)) > TANGENT_TOL:
                continue
            k, line = (j + 1) % n if a.kind == "line" else j, a if a.kind == "line" else b
            arc = self.pieces[k]
            kink = turn * arc.sense  # > 0: the arc starts turned past the line's direction (reversing keeps the sign)
            ux, uy = line.direction()
            offset = abs(ux * (arc.c[1] - line.a[1]) - uy * (arc.c[0] - line.a[0]))  # the centre off the line
            theta = max(kink, 0.0) + LANDING_MARGIN
            floor[k] = max(floor[k], abs(arc.r) - offset / K.shape_g1(code, math.sin(theta), math.cos(theta)))
        return floor

    def _pairs(self) -> list[tuple[int, int, int, float, float]]:
        """(joint, small, big, how far the circles cross, band width) of every compound joint, smaller circles first."""
        if self._compound is None:
            n = len(self.pieces)
            pairs = []
            for j in range(self.joint_count):
                if self.kinds[j] == "arc-arc-compound":
                    a, b = j, (j + 1) % n
                    small, big = (a, b) if abs(self.pieces[a].r) < abs(self.pieces[b].r) else (b, a)
                    pa, pb = self.pieces[small], self.pieces[big]
                    cross = max(math.dist(pa.c, pb.c) - (abs(pb.r) - abs(pa.r)), 0.0)
                    pairs.append((j, small, big, cross, self._band_width(small, big)))
            pairs.sort(key=lambda pair: abs(self.pieces[pair[1]].r))
            self._compound = pairs
        return self._compound

    def _band_width(self, small: int, big: int) -> float:
        """How much more than the larger circle the smaller one may shrink: the nested band's width."""
        rs, rb = abs(self.pieces[small].r), abs(self.pieces[big].r)
        lower = KC.nested_band_lower(rs / rb, SHAPE_CODES[self.shape])
        return (rb - rs) * (1.0 / lower - 1.0)

    def solve_joints(self, s: list[float]) -> list[_Solved | None]:
        """Every joint's transition for the shifts ``s``: one batch solve per kind of joint."""
        out: list[_Solved | None] = [None] * self.joint_count
        by_kind: dict[str, list[int]] = {}
        for j in range(self.joint_count):
            by_kind.setdefault(self.kinds[j], []).append(j)
        if by_kind.get("line-arc"):
            self._lines_arcs(by_kind["line-arc"], s, out)
        for kind in ("arc-arc-reverse", "arc-arc-compound", "arc-arc-c", "bridge"):
            if by_kind.get(kind):
                self._arcs_arcs(by_kind[kind], s, kind, out)
        corners = by_kind.get("corner", [])  # a corner between lines does not depend on the shifts: solved once
        self._solve_corners([j for j in corners if j not in self._corners])
        for j in corners:
            out[j] = self._corners[j]
        return out

    def _lines_arcs(self, joints: list[int], s: list[float], out: list[_Solved | None]) -> None:
        """Line → arc and arc → line joints (Theorem 4.1 onto the shrunk circle), solved about each joint
        (where float64 holds a small transition far from the origin) and moved back."""
        n = len(self.pieces)
        before = [self.pieces[j] for j in joints]
        after = [self.pieces[(j + 1) % n] for j in joints]
        nexts = [(j + 1) % n for j in joints]
        # The line's end and direction of travel away from the arc, the arc's circle shrunk: a line → arc
        # joint as it is, an arc → line joint reversed.
        flip = np.array([a.kind != "line" for a in before])
        line_a = np.where(flip[:, None], np.array([b.b for b in after]), np.array([a.a for a in before]))
        points = np.where(flip[:, None], np.array([b.a for b in after]), np.array([a.b for a in before]))
        direction = points - line_a
        direction /= np.hypot(direction[:, 0], direction[:, 1])[:, None]
        centre = np.where(flip[:, None], np.array([a.c for a in before]), np.array([b.c for b in after]))
        radius_after = np.array([abs(b.r) for b in after]) - np.array([s[k] for k in nexts])
        radius_before = np.array([abs(a.r) for a in before]) - np.array([s[j] for j in joints])
        radius = np.where(flip, radius_before, radius_after)
        result = batch.line_to_circle(np.zeros_like(points), direction, centre - points, radius, shape=self.shape)
        spirals = result.spirals[0] + points[:, None]
        spirals[flip] = spirals[flip, ::-1]
        ok = result.ok.tolist()
        used_before = _used_rows(before, spirals[:, 0], True).tolist()
        used_after = _used_rows(after, spirals[:, 3], False).tolist()
        theta = result.theta.tolist()
        for m, j in enumerate(joints):
            if not ok[m]:
                out[j] = _Solved([], math.inf, math.inf, math.nan, int(result.status[m]), result.reason(m))
                continue
            out[j] = _Solved([spirals[m]], used_before[m], used_after[m], theta[m])

    def _arcs_arcs(self, joints: list[int], s: list[float], kind: str, out: list[_Solved | None]) -> None:
        """Reverse (S), compound (nested) or C joints between shrunk circles, solved about each joint."""
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
        ok = result.ok.tolist()
        used_before = _used_rows(before, moved[0][:, 0], True).tolist()
        used_after = _used_rows(after, moved[-1][:, 3], False).tolist()
        theta = result.theta.tolist()
        for m, j in enumerate(joints):
            if not ok[m]:
                out[j] = _Solved([], math.inf, math.inf, math.nan, int(result.status[m]), result.reason(m))
                continue
            out[j] = _Solved([sp[m] for sp in moved], used_before[m], used_after[m], theta[m])

    def _solve_corners(self, joints: list[int]) -> None:
        """Corners between lines rounded by spiral pairs within the target, all in one batch
        (``round_corners_batch``); a corner next to an arc has no pair (its tangent circle comes first)."""
        n = len(self.pieces)
        lines = []
        for j in joints:
            a, b = self.pieces[j], self.pieces[(j + 1) % n]
            if a.kind != "line" or b.kind != "line":
                self._corners[j] = _Solved([], math.inf, math.inf, math.nan, int(Status.OUTSIDE_SHAPE), "")
            else:
                lines.append(j)
        if not lines:
            return
        before = [self.pieces[j] for j in lines]
        after = [self.pieces[(j + 1) % n] for j in lines]
        corner = np.array([a.b for a in before])
        p0 = corner - np.array([self.allow[j][1] * a.tangent(True) for j, a in zip(lines, before)])
        p1 = corner + np.array([self.allow[(j + 1) % n][0] * b.tangent(False) for j, b in zip(lines, after)])
        result = round_corners_batch(p0, corner, p1, max_deviation=self.target, shape=self.shape)
        ok, theta = result.ok.tolist(), result.theta.tolist()
        for m, (j, a, b) in enumerate(zip(lines, before, after)):
            if not ok[m]:
                self._corners[j] = _Solved([], math.inf, math.inf, math.nan, int(result.status[m]), result.reason(m))
                continue
            pair = result.control_points[m]
            self._corners[j] = _Solved([pair[0].copy(), pair[1].copy()], _used(a, pair[0][0], True), _used(b, pair[1][3], False),
                                       theta[m])  # fmt: skip


def _coordinate_size(pieces: list[_Piece]) -> float:
    """The largest coordinate of the pieces' ends and centres (what float64 resolves them against)."""
    arc = np.array([p.kind == "arc" for p in pieces])
    c = np.array([p.c for p in pieces]).reshape(-1, 2)
    r = np.abs(np.array([p.r for p in pieces]))[:, None]
    a0 = np.array([p.a0 for p in pieces])
    a1 = a0 + np.array([p.sense * p.sweep for p in pieces])
    start = np.where(arc[:, None], c + r * np.stack([np.cos(a0), np.sin(a0)], axis=-1), np.array([p.a for p in pieces]).reshape(-1, 2))
    end = np.where(arc[:, None], c + r * np.stack([np.cos(a1), np.sin(a1)], axis=-1), np.array([p.b for p in pieces]).reshape(-1, 2))
    return float(max(np.abs(start).max(), np.abs(end).max(), np.abs(c).max()))


def _solve(group: _Group) -> tuple[list[_Solved | None], list[float]]:
    """The shifts and transitions of a group: shifts that overrun a piece shrink until every joint fits."""
    n = len(group.pieces)
    tightest = (1.0, 0)  # the joint whose transitions overran their room most in the last pass, and by how much
    for _ in range(PASSES):
        s = group.shifts()
        solved = group.solve_joints(s)
        over: dict[int, float] = {}
        failed: list[int] = []
        tightest = (1.0, 0)
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
                tightest = min(tightest, (worst, j))
                if group.kinds[j] == "arc-arc-c":  # a C pair's use hardly depends on the shifts: nothing to shrink
                    raise _Refusal(j, "its C spiral pair between the crossing circles needs more of the arcs than they have", False,
                                   False)  # fmt: skip
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
        if failed and all(group.factor[k] < SMALLEST_FACTOR for j in failed for k in _joint_circles(group, j)):
            break  # shifts this small find no transition either: the failing joint is refused now
    s = group.shifts()
    solved = group.solve_joints(s)
    for j, joint in enumerate(solved):
        if joint is not None and joint.status:
            raise _Refusal(j, joint.reason or describe_status(joint.status), True)
    raise _Refusal(tightest[1], "its transitions could not be fitted into the lines and arcs beside it", True)


def _c_unfit(pieces: list[_Piece], kinds: list[str], shape: str) -> list[int]:
    """The C joints (``arc-arc-c``) whose pair, between the circles as they are (the larger shrunk by the least
    δ of ``_c_window``), is not found or needs more than ``C_ROOM`` of the share (``SHARED``) of an arc beside it
    (the shifts move it a little): made otherwise."""
    n = len(pieces)
    joints = [j for j, kind in enumerate(kinds) if kind == "arc-arc-c"]
    if not joints:
        return []
    before = [pieces[j] for j in joints]
    after = [pieces[(j + 1) % n] for j in joints]
    shrink = np.zeros((len(joints), 2))
    for m, (a, b) in enumerate(zip(before, after)):
        window = _c_window(a, b)
        if window is not None:
            shrink[m, window[1]] = max(window[2], 0.0)
    origin = np.array([a.end() for a in before])
    r0 = np.array([a.r - a.sense * shrink[m, 0] for m, a in enumerate(before)])
    r1 = np.array([b.r - b.sense * shrink[m, 1] for m, b in enumerate(after)])
    result = batch.circle_to_circle(np.array([a.c for a in before]) - origin, r0, np.array([b.c for b in after]) - origin, r1,
                                    shape=shape)  # fmt: skip
    moved = [sp + origin[:, None] for sp in result.spirals]
    with np.errstate(invalid="ignore"):
        used_before = _used_rows(before, moved[0][:, 0], True)
        used_after = _used_rows(after, moved[-1][:, 3], False)
    room_before = np.array([C_ROOM * SHARED * a.sweep for a in before])
    room_after = np.array([C_ROOM * SHARED * b.sweep for b in after])
    fits = result.ok & (used_before <= room_before) & (used_after <= room_after)
    return [j for j, ok in zip(joints, fits.tolist()) if not ok]


def _c_groups(kinds: list[str], joint_count: int, n: int) -> list[list[int]]:
    """The runs of pieces joined by C pairs (``arc-arc-c`` joints), each as its piece indices."""
    groups: list[list[int]] = []
    for j in range(joint_count):
        if kinds[j] != "arc-arc-c":
            continue
        k = (j + 1) % n
        if groups and groups[-1][-1] == j:
            groups[-1].append(k)
        else:
            groups.append([j, k])
    if len(groups) > 1 and groups[-1][-1] == groups[0][0]:  # a closed path: the last run goes on into the first
        groups[0] = groups.pop()[:-1] + groups[0]
    return [sorted(set(members)) for members in groups]


def _joint_circles(group: _Group, j: int) -> list[int]:
    """The pieces of joint ``j`` whose circles shift."""
    n = len(group.pieces)
    return [k for k in (j, (j + 1) % n) if group.needs_shift[k]]


def describe_status(status: int) -> str:
    return f"no transition ({Status(status).name})"


def _arc_corners(pieces: list[_Piece], kinds: list[str], joints: list[int], closed: bool,
                 bound: float, steepest: float = math.pi) -> tuple[list[_Piece], list[str], list[int]]:  # fmt: skip
    """Each sharp corner next to an arc, or turning more than a spiral pair rounds (``steepest``), given a
    tangent circle (a circular fillet) passing half the bound from the corner point, so that the path is
    tangent there and its transitions do the rest."""
    n = len(pieces)
    corners = [
        j
        for j, kind in enumerate(kinds)
        if kind == "corner"
        and ("arc" in (pieces[j].kind, pieces[(j + 1) % n].kind) or abs(_turn(pieces[j], pieces[(j + 1) % n])) > steepest)
    ]
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
    cx, cy = (float(v) for v in a.end())
    turn = _turn(a, b)
    sense = math.copysign(1.0, turn)
    # what does not change with the radius, in plain floats (each attempt is a few hundred float operations)
    fixed = []
    for piece in (a, b):
        if piece.kind == "line":
            tx, ty = piece.direction()
            fixed.append((True, float(piece.a[0]), float(piece.a[1]), tx, ty, -ty * sense, tx * sense, 0.0))
        else:
            fixed.append((False, float(piece.c[0]), float(piece.c[1]), 0.0, 0.0, 0.0, 0.0, abs(piece.r)))

    def attempt(rho: float) -> tuple[float, tuple[float, float], list[tuple[float, float]], float, float, float] | None:
        """The circle of radius ``rho`` (radius, centre, touches, start angle, sweep, distance from the corner), or None."""
        loci: list[tuple[str, tuple[float, float], Any]] = []
        for piece, (line, px, py, tx, ty, nx, ny, radius) in zip((a, b), fixed):
            if line:
                loci.append(("line", (px + rho * nx, py + rho * ny), (tx, ty)))
            else:
                distance = radius - rho if (piece.r > 0) == (sense > 0) else radius + rho
                if not distance > 0.0:
                    return None
                loci.append(("circle", (px, py), distance))
        centre = _intersect_xy(loci[0], loci[1], (cx, cy))
        if centre is None:
            return None
        ox, oy = centre
        touches = []
        for line, px, py, tx, ty, _, _, radius in fixed:
            if line:
                along = (ox - px) * tx + (oy - py) * ty
                touches.append((px + along * tx, py + along * ty))
            else:
                awayx, awayy = ox - px, oy - py
                length = math.hypot(awayx, awayy)
                touches.append((px + radius * awayx / length, py + radius * awayy / length))
        used_a, used_b = _used_xy(a, *touches[0], True, fixed[0][3:5]), _used_xy(b, *touches[1], False, fixed[1][3:5])
        if not (0.0 < used_a <= room_a and 0.0 < used_b <= room_b):
            return None
        fillet = math.dist(centre, (cx, cy)) - rho
        if not fillet <= depth:
            return None
        start = math.atan2(touches[0][1] - oy, touches[0][0] - ox)
        end = math.atan2(touches[1][1] - oy, touches[1][0] - ox)
        sweep = (sense * (end - start)) % TAU
        if not 0.0 < sweep < math.pi:
            return None
        return rho, centre, touches, start, sweep, fillet

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
    rho, centre, touches, start, sweep, fillet = best
    circle = _Piece("arc", -1, -1, c=np.array(centre), r=sense * rho, a0=start, sweep=sweep, fillet=fillet)
    return circle, np.array(touches[0]), np.array(touches[1])


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
