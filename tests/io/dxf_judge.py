"""The judge of a rewritten drawing: ezdxf's own reading of the file, sharing no code with our reader or writer.

The model space's curves (``LINE``, ``ARC``, ``CIRCLE``, ``SPLINE``, polylines through ezdxf's virtual
entities) are matched end to end; at every point where exactly two ends meet, the joint's tangent angle
and curvature jump are computed from ezdxf's geometry (a ``SPLINE``'s from ezdxf's ``BSpline``
derivatives). Paths are the connected groups of curves; open ends are ends that meet no other.
"""

from __future__ import annotations

import math
from collections import Counter
from dataclasses import dataclass, field

import numpy as np

#: The G2 criteria of issue 40: tangent angle, and curvature jump relative to the largest end curvature of the two pieces.
ANGLE = 1e-6
JUMP = 1e-5
PATHS = ("LINE", "ARC", "CIRCLE", "SPLINE", "LWPOLYLINE", "POLYLINE", "ELLIPSE")


@dataclass
class _Curve:
    start: np.ndarray
    end: np.ndarray
    frames: tuple  # (tangent, curvature) at start, at end, along the entity's own direction
    closed: bool = False


def _frame(d1, d2) -> tuple[np.ndarray, float]:
    d1, d2 = np.asarray(d1, dtype=float)[:2], np.asarray(d2, dtype=float)[:2]
    speed = float(np.hypot(*d1))
    return d1 / speed, float(d1[0] * d2[1] - d1[1] * d2[0]) / speed**3


def _curve(entity) -> _Curve | None:
    kind = entity.dxftype()
    if kind == "LINE":
        a, b = np.array(entity.dxf.start, dtype=float)[:2], np.array(entity.dxf.end, dtype=float)[:2]
        if not np.hypot(*(b - a)) > 0.0:
            return None  # a point drawn as a line: no curve
        t = (b - a) / np.hypot(*(b - a))
        return _Curve(a, b, ((t, 0.0), (t, 0.0)))
    if kind in ("ARC", "CIRCLE"):
        assert tuple(entity.dxf.extrusion) == (0.0, 0.0, 1.0), "the judge reads plane drawings"
        c, r = np.array(entity.dxf.center, dtype=float)[:2], float(entity.dxf.radius)
        if not r > 0.0:
            return None  # a point drawn as a circle: no curve
        a0 = math.radians(entity.dxf.start_angle) if kind == "ARC" else 0.0
        a1 = math.radians(entity.dxf.end_angle) if kind == "ARC" else 2 * math.pi
        ends = [c + r * np.array([math.cos(a), math.sin(a)]) for a in (a0, a1)]
        frames = tuple((np.array([-math.sin(a), math.cos(a)]), 1.0 / r) for a in (a0, a1))
        return _Curve(ends[0], ends[1], frames, closed=kind == "CIRCLE")
    if kind == "SPLINE":
        bs = entity.construction_tool()
        t0, t1 = 0.0, bs.max_t
        p0, d10, d20 = bs.derivative(t0, n=2)
        p1, d11, d21 = bs.derivative(t1, n=2)
        return _Curve(np.array(p0, dtype=float)[:2], np.array(p1, dtype=float)[:2], (_frame(d10, d20), _frame(d11, d21)))
    return None


def curves(msp) -> tuple[list[_Curve], Counter]:
    """The model space's curves (polylines through their virtual entities), and the count of the others by (type, layer)."""
    found, others = [], Counter()
    for entity in msp:
        kind = entity.dxftype()
        if kind in ("LWPOLYLINE", "POLYLINE"):
            found += [c for e in entity.virtual_entities() if (c := _curve(e)) is not None]
        elif kind in PATHS and kind != "ELLIPSE":
            curve = _curve(entity)
            if curve is not None:
                found.append(curve)
        else:
            others[(kind, entity.dxf.layer)] += 1
    return found, others


@dataclass
class Verdict:
    """The judge's figures of one drawing."""

    paths: int = 0
    joints: int = 0
    g2: int = 0
    open_ends: int = 0
    worst_share: float = 1.0  # the smallest share of G2 joints over the paths with joints
    others: Counter = field(default_factory=Counter)

    @property
    def share(self) -> float:
        return self.g2 / self.joints if self.joints else 1.0


def judge(msp) -> Verdict:
    """Joints, G2 joints, paths and open ends of a model space, by ezdxf's geometry alone."""
    found, others = curves(msp)
    ends = [(k, side) for k, c in enumerate(found) if not c.closed for side in (0, 1)]
    points = np.array([found[k].start if side == 0 else found[k].end for k, side in ends]).reshape(-1, 2)
    size = float(np.linalg.norm(points.max(axis=0) - points.min(axis=0))) if len(points) else 1.0
    tol = 1e-6 * (size or 1.0)
    parent = list(range(len(found)))

    def root(i: int) -> int:
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    verdict = Verdict(others=others)
    joint_of: list[tuple[int, bool]] = []  # (curve, G2) per joint
    close = np.hypot(*(points[:, None, :] - points[None, :, :]).transpose(2, 0, 1)) <= tol
    np.fill_diagonal(close, False)
    for i in range(len(ends)):
        near = np.flatnonzero(close[i]).tolist()
        if not near:
            verdict.open_ends += 1
            continue
        if len(near) != 1 or near[0] < i:
            continue  # a branch point, or this pair seen already
        (a, sa), (b, sb) = ends[i], ends[near[0]]
        parent[root(a)] = root(b)
        ta, ka = found[a].frames[sa]
        tb, kb = found[b].frames[sb]
        # travel along a into the joint, then along b out of it
        ta, ka = (ta, ka) if sa == 1 else (-ta, -ka)
        tb, kb = (tb, kb) if sb == 0 else (-tb, -kb)
        angle = abs(math.atan2(ta[0] * tb[1] - ta[1] * tb[0], float(ta @ tb)))
        scale = max(abs(k) for _, k in (*found[a].frames, *found[b].frames))  # the two pieces' curvature
        jump = abs(ka - kb) <= JUMP * scale
        joint_of.append((a, angle <= ANGLE and jump))
    groups: dict[int, list[bool]] = {}
    for k in range(len(found)):
        groups.setdefault(root(k), [])
    for a, ok in joint_of:
        groups[root(a)].append(ok)
    verdict.paths = len(groups)
    verdict.joints = len(joint_of)
    verdict.g2 = sum(ok for _, ok in joint_of)
    shares = [sum(js) / len(js) for js in groups.values() if js]
    verdict.worst_share = min(shares, default=1.0)
    return verdict
