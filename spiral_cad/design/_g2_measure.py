"""make_g2's measure: the Hausdorff distance between the input and the result at every joint, for all
joints at once (exact distances to lines and arcs, Newton-polished nearest points on the spirals)."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from ..core.segments import TAU
from ._g2_pieces import (
    _Piece,
    _Solved,
)
from ._g2_solve import (
    _Group,
)

#: Samples per spiral (and per replaced stretch of the input) when the deviation is measured.
SAMPLES = 32


def _deviation(group: _Group, solved: list[_Solved | None], s: list[float], used: list[list[float]]) -> float:
    """The Hausdorff distance between the input and the result, measured: the shrink of each arc
    (every point of a concentric circle moves by it), and at each joint the spirals against the input
    pieces beside it, and the stretch of the input the joint replaced against the result (all joints
    at once, in blocks)."""
    n = len(group.pieces)
    # A tangent circle put into a corner is itself ``fillet`` off the input: its shifts and joints add it.
    worst = max((shift + p.fillet for shift, p in zip(s, group.pieces)), default=0.0)
    index = np.array([j for j, joint in enumerate(solved) if joint is not None], dtype=int)
    rows_all = _Rows.of(group.pieces)
    fillet = np.array([p.fillet for p in group.pieces])
    shift = np.array(s, dtype=float)
    used_lo, used_hi = np.array(used, dtype=float).reshape(-1, 2).T
    for block in range(0, len(index), BLOCK):
        joints = index[block : block + BLOCK]
        nexts = (joints + 1) % n
        added = np.maximum(fillet[joints], fillet[nexts])
        spirals = np.array([[cps[0], cps[-1]] for cps in (solved[j].spirals for j in joints.tolist())])
        rows_a, rows_b = rows_all.take(joints), rows_all.take(nexts)
        # A short line left out between two arcs is input the joint replaced (elsewhere: piece a again).
        bridged = np.array([j in group.bridges for j in joints.tolist()])
        rows_m = rows_a
        if bridged.any():
            rows_m = _Rows.of([group.bridges[j][0] if j in group.bridges else group.pieces[j] for j in joints.tolist()])
        u = np.linspace(0.0, 1.0, SAMPLES)
        curve = np.concatenate([_bezier_rows(spirals[:, 0], u), _bezier_rows(spirals[:, 1], u)], axis=1)  # a lone spiral twice
        there = np.minimum(rows_a.distance(curve), rows_b.distance(curve))
        if bridged.any():
            there = np.minimum(there, rows_m.distance(curve))
        worst = max(worst, float((there.max(axis=1) + added).max()))
        # A C pair beyond an arc's end (or before its start) extends that arc on its circle: the input there
        # is the other piece, against which the extension is measured; the stretch replaced is the rest.
        tail = np.maximum(used_hi[joints], 0.0)
        head = np.maximum(used_lo[nexts], 0.0)
        worst = max(worst, _extensions(rows_a, rows_b, joints, nexts, used_lo, used_hi, shift, added))
        replaced = np.concatenate(
            [rows_a.points(rows_a.size - tail, rows_a.size, SAMPLES), rows_b.points(np.zeros(len(joints)), head, SAMPLES)], axis=1
        )
        near = _distance_to_bezier_rows(replaced, spirals[:, 0])
        pairs = np.flatnonzero([len(solved[j].spirals) == 2 for j in joints.tolist()])
        if len(pairs):
            near[pairs] = np.minimum(near[pairs], _distance_to_bezier_rows(replaced[pairs], spirals[pairs, 1]))
        for rows, ks in ((rows_a, joints), (rows_b, nexts)):
            kept, present = rows.kept(used_lo[ks], used_hi[ks], shift[ks])
            if present.any():
                near = np.minimum(near, np.where(present[:, None], kept.where(present, rows).distance(replaced), np.inf))
        worst = max(worst, float((near.max(axis=1) + added).max()))
    return worst


def _extensions(rows_a: _Rows, rows_b: _Rows, joints: NDArray, nexts: NDArray, used_lo: NDArray, used_hi: NDArray,
                shift: NDArray, added: NDArray) -> float:  # fmt: skip
    """How far the result's arcs extended past a joint (a transition that leaves an arc after its end, or
    reaches one before its start: ``used`` < 0) lie from the input pieces beside the joint."""
    worst = 0.0
    for rows, ks, at_end in ((rows_a, joints, True), (rows_b, nexts, False)):
        over = -(used_hi[ks] if at_end else used_lo[ks])
        pick = np.flatnonzero(over > 0.0)
        if not len(pick):
            continue
        kept, _ = rows.take(pick).kept(used_lo[ks[pick]], used_hi[ks[pick]], shift[ks[pick]])
        left = kept.size
        lo, hi = (left - over[pick], left) if at_end else (np.zeros(len(pick)), over[pick])
        points = kept.points(lo, hi, SAMPLES)
        near = np.minimum(rows_a.take(pick).distance(points), rows_b.take(pick).distance(points))
        worst = max(worst, float((near.max(axis=1) + added[pick]).max()))
    return worst


#: Joints measured at once (bounds the memory of the point-to-sample distances).
BLOCK = 2048


#: Starting points of the nearest-point search on a spiral (its distance has one minimum per stretch
#: this short: a spiral turns less than 90°), and the Newton steps that polish them.
GUESSES = 17


NEWTON_STEPS = 5


#: A Newton step in u this small leaves the distance unchanged to float64 (second order: ~1e-24 relative).
SETTLED = 1e-12


class _Rows:
    """Pieces as arrays: lines (a → b) and arcs (centre, radius, start angle, sweep), one row each."""

    def __init__(self, arc: NDArray, a: NDArray, b: NDArray, c: NDArray, r: NDArray, sense: NDArray, a0: NDArray,
                 sweep: NDArray):  # fmt: skip
        self.arc, self.a, self.b, self.c, self.r, self.sense, self.a0, self.sweep = arc, a, b, c, r, sense, a0, sweep
        self.size = np.where(self.arc, self.sweep, np.hypot(*(self.b - self.a).T))

    @classmethod
    def of(cls, pieces: list[_Piece]) -> _Rows:
        """The rows of ``pieces``."""
        r = np.array([p.r for p in pieces])
        return cls(
            np.array([p.kind == "arc" for p in pieces]),
            np.array([p.a for p in pieces]).reshape(-1, 2),
            np.array([p.b for p in pieces]).reshape(-1, 2),
            np.array([p.c for p in pieces]).reshape(-1, 2),
            np.abs(r),
            np.copysign(1.0, r),
            np.array([p.a0 for p in pieces]),
            np.array([p.sweep for p in pieces]),
        )

    def take(self, rows: NDArray) -> _Rows:
        """The rows ``rows`` (indices) of these."""
        return _Rows(self.arc[rows], self.a[rows], self.b[rows], self.c[rows], self.r[rows], self.sense[rows], self.a0[rows],
                     self.sweep[rows])  # fmt: skip

    def where(self, mask: NDArray, other: _Rows) -> _Rows:
        """These rows where ``mask``, else ``other``'s."""
        pick = [np.where(mask[:, None] if x.ndim == 2 else mask, x, y) for x, y in
                ((self.arc, other.arc), (self.a, other.a), (self.b, other.b), (self.c, other.c), (self.r, other.r),
                 (self.sense, other.sense), (self.a0, other.a0), (self.sweep, other.sweep))]  # fmt: skip
        return _Rows(*pick)

    def kept(self, lo: NDArray, hi: NDArray, shrink: NDArray) -> tuple[_Rows, NDArray]:
        """What transitions using ``lo`` at the start and ``hi`` at the end leave of each row (an arc on its
        circle shrunk by ``shrink``), as ``_kept`` does for one piece, and whether anything is left."""
        with np.errstate(invalid="ignore", divide="ignore"):
            unit = (self.b - self.a) / np.where(self.arc, 1.0, self.size)[:, None]
        left = self.size - lo - hi
        a = self.a + lo[:, None] * unit
        b = self.a + (self.size - hi)[:, None] * unit
        a0 = self.a0 + self.sense * lo
        r = np.abs(self.sense * self.r - self.sense * shrink)
        line = ~self.arc
        rows = _Rows(self.arc, np.where(line[:, None], a, self.a), np.where(line[:, None], b, self.b), self.c,
                     np.where(self.arc, r, self.r), self.sense, np.where(self.arc, a0, self.a0),
                     np.where(self.arc, left, self.sweep))  # fmt: skip
        return rows, left > 0.0

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
        out = np.empty(points.shape[:2])
        line = np.flatnonzero(~self.arc)
        if len(line):
            out[line] = self._line_distance(line, points[line])
        arc = np.flatnonzero(self.arc)
        if len(arc):
            out[arc] = self._arc_distance(arc, points[arc])
        return out

    def _line_distance(self, rows: NDArray, points: NDArray) -> NDArray:
        a = self.a[rows]
        d = self.b[rows] - a
        dd = np.einsum("ij,ij->i", d, d)
        rel = points - a[:, None]
        with np.errstate(invalid="ignore", divide="ignore"):
            t = np.clip((rel @ d[:, :, None])[..., 0] / dd[:, None], 0.0, 1.0)
        off = rel - t[..., None] * d[:, None]
        return np.nan_to_num(np.hypot(off[..., 0], off[..., 1]), nan=np.inf)

    def _arc_distance(self, rows: NDArray, points: NDArray) -> NDArray:
        c, r, sense, a0, sweep = self.c[rows], self.r[rows], self.sense[rows], self.a0[rows], self.sweep[rows]
        rel = points - c[:, None]
        angle = np.arctan2(rel[..., 1], rel[..., 0])
        inside = (sense[:, None] * (angle - a0[:, None])) % TAU <= sweep[:, None]
        radial = np.abs(np.hypot(rel[..., 0], rel[..., 1]) - r[:, None])
        end_angle = a0 + sense * sweep
        start = r[:, None] * np.stack([np.cos(a0), np.sin(a0)], axis=-1)
        end = r[:, None] * np.stack([np.cos(end_angle), np.sin(end_angle)], axis=-1)
        to_start, to_end = rel - start[:, None], rel - end[:, None]
        ends = np.minimum(np.hypot(to_start[..., 0], to_start[..., 1]), np.hypot(to_end[..., 0], to_end[..., 1]))
        return np.where(inside, np.minimum(radial, ends), ends)


def _bernstein(u: NDArray, degree: int) -> NDArray:
    """The Bernstein basis of ``degree`` at ``u`` (any shape), on a new last axis."""
    v = 1.0 - u
    if degree == 3:
        return np.stack([v * v * v, 3.0 * v * v * u, 3.0 * v * u * u, u * u * u], axis=-1)
    if degree == 2:
        return np.stack([v * v, 2.0 * v * u, u * u], axis=-1)
    return np.stack([v, u], axis=-1)


def _bezier_rows(cp: NDArray, u: NDArray) -> NDArray:
    """(J, len(u), 2) points of J cubic Béziers (J, 4, 2) at the same ``u``, or (J, M, 2) at ``u`` (J, M)."""
    return _bernstein(u, 3) @ cp


def _distance_to_bezier_rows(points: NDArray, cp: NDArray) -> NDArray:
    """(J, M) distance of ``points`` (J, M, 2) to the cubic Béziers ``cp`` (J, 4, 2): the nearest of dense
    samples, polished by Newton steps on (B(u) − p)·B'(u) = 0 (clamped to [0, 1]), at most ``NEWTON_STEPS``:
    fewer once no u moves by more than ``SETTLED`` (near a nearest point the distance changes only to second
    order in u, and any u gives a distance no smaller than the nearest one)."""
    # About each spiral's start: far from the origin, |s|² − 2 p·s would lose the small distances.
    points = points - cp[:, None, 0]
    cp = cp - cp[:, None, 0]
    grid = np.linspace(0.0, 1.0, GUESSES)
    samples = _bezier_rows(cp, grid)  # (J, K, 2)
    squared = np.einsum("jsk,jsk->js", samples, samples)[:, None] - 2.0 * (points @ samples.transpose(0, 2, 1))
    best = grid[np.argmin(squared, axis=2)]  # (J, M); |p|² is the same for every sample
    d1 = 3.0 * np.diff(cp, axis=1)  # (J, 3, 2)
    d2 = 2.0 * np.diff(d1, axis=1)  # (J, 2, 2)
    for _ in range(NEWTON_STEPS):
        off = _bezier_rows(cp, best) - points
        first = _bernstein(best, 2) @ d1
        second = _bernstein(best, 1) @ d2
        f = np.einsum("jmk,jmk->jm", off, first)
        df = np.einsum("jmk,jmk->jm", first, first) + np.einsum("jmk,jmk->jm", off, second)
        with np.errstate(invalid="ignore", divide="ignore"):
            step = np.nan_to_num(np.where(df > 0.0, f / df, 0.0))
        moved = np.clip(best - step, 0.0, 1.0)
        settled = not np.abs(moved - best).max(initial=0.0) > SETTLED
        best = moved
        if settled:
            break
    off = _bezier_rows(cp, best) - points
    return np.hypot(off[..., 0], off[..., 1])
