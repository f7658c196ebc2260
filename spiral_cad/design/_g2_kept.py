"""make_g2 of a path that holds segments other than lines and arcs (its own spirals, a G2 sketch's
Bézier edges): those are kept as they are, their joints must be G2 already, and the runs of lines and
arcs between them are made G2 on their own, so that make_g2 of its own result changes nothing."""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np

from ..core.chain import Chain, g2_mismatch
from ..core.segments import Arc, Line, Segment
from ._g2_pieces import _Refusal, _shown_point

#: make_g2's result and refusal types, handed in by ``g2`` (which imports this module).
Make = Callable[[list[Segment], float, "bool | None", str, str, float, bool], Any]


class _KeptRefusal(_Refusal):
    """A refusal of a path with kept segments, located on the input (index and point)."""

    def __init__(self, index: int, point: tuple[float, ...], reason: str, larger_helps: bool):
        super().__init__(index, reason, larger_helps)
        self.point = point


def is_kept(segment: Segment) -> bool:
    """Whether make_g2 keeps ``segment`` as it is (anything but a line or an arc)."""
    return not isinstance(segment, (Line, Arc))


def make_kept(segments: list[Segment], bound: float, closed: bool | None, shape: str, units: str, tolerance: float,
              make: Make, result_type: Any, joint_type: Any, retry: bool = True) -> Any:  # fmt: skip
    """``make`` (make_g2 of lines and arcs) of each run of lines and arcs between the kept segments, the
    kept ones as they are; a G2Path (``result_type``) or a refusal located on the input.

    Raises:
        ValueError: a kept segment that does not join its neighbours G2 (named, with the mismatch).
    """
    n = len(segments)
    size = max(float(np.abs(np.array([p for s in segments for p in s.outline()])).max()), 1e-300)
    meets = math.dist(segments[-1].end[:2], segments[0].start[:2]) <= max(1e-9 * size, 0.5 * bound)
    if closed is None:
        closed = meets and n > 1
    joint_count = n if closed else n - 1
    for j in range(joint_count):
        a, b = segments[j], segments[(j + 1) % n]
        if is_kept(a) or is_kept(b):
            problem = g2_mismatch(a, b, tolerance, units, j)
            if problem:
                raise ValueError(
                    f"make_g2 keeps segments other than lines and arcs as they are, so their joints must be G2 already; "
                    f"joint {j} ({type(a).__name__} → {type(b).__name__}) at {_shown_point(a.end[:2].tolist())} is not: {problem}"
                )
    # A closed path starts at a kept segment: every run of lines and arcs is then open, between kept segments.
    first = next(k for k, s in enumerate(segments) if is_kept(s)) if closed else 0
    order = list(range(first, n)) + list(range(first)) if closed else list(range(n))
    parts: list[list[Segment]] = [[]]
    zero_at: int | None = None  # where the output of input segment 0 starts (a closed path is turned back to it)
    joints: dict[int, Any] = {}
    splits: list[int] = []
    deviation = 0.0
    k = 0
    while k < len(order):
        index = order[k]
        if index == 0 and len(parts) == 1:
            zero_at = len(parts[0])
        if is_kept(segments[index]):
            parts[-1].append(segments[index])
            k += 1
            continue
        run = []
        while k < len(order) and not is_kept(segments[order[k]]):
            run.append(order[k])
            k += 1
        made = make([segments[i] for i in run], bound, False, shape, units, tolerance, retry)
        if isinstance(made, _Refusal):
            at = run[min(made.joint, len(run) - 1)]
            point = getattr(made, "point", tuple(segments[at].end[:2].tolist()))
            return _KeptRefusal(at, point, made.reason, made.larger_helps)
        for c, chain in enumerate(made.chains):
            if c:
                parts.append([])
            parts[-1] += list(chain)
        for joint in made.joints:
            where = run[joint.index]
            joints[where] = joint_type(where, joint.kind, joint.point, joint.moved, joint.shift, joint.theta)
        splits += [run[s] for s in made.splits]
        deviation = max(deviation, made.deviation)
        after_kept = closed or k - len(run) > 0
        before_kept = closed or k < len(order)
        for end, at_end, check in ((run[0], False, after_kept), (run[-1], True, before_kept)):  # an arc beside a kept segment
            if not check:  # keeps its end
                continue
            made_end = made.chains[-1][-1].end if at_end else made.chains[0][0].start
            moved = math.dist(made_end[:2], (segments[end].end if at_end else segments[end].start)[:2])
            if moved > tolerance * max(segments[end].length, 1e-300):
                return _KeptRefusal(end, tuple(segments[end].start[:2].tolist()),
                                    f"arc {end} lies between a kept segment and a joint whose transition shrinks it "
                                    f"(its end would move {moved:.3g})", False)  # fmt: skip
    for j in range(joint_count):
        if j not in joints:
            point = tuple(float(v) for v in segments[j].end[:2])
            joints[j] = joint_type(j, "g2", point, "nothing", 0.0)
    if closed and not splits and zero_at:
        parts[0] = parts[0][zero_at:] + parts[0][:zero_at]
    try:
        chains = [Chain(part, tolerance, units) for part in parts if part]
    except ValueError as error:
        return _KeptRefusal(0, tuple(segments[0].start[:2].tolist()), f"the kept segments and the made runs do not join G2: {error}", False)
    whole = bool(closed) and not splits
    if whole:
        problem = g2_mismatch(chains[-1][-1], chains[0][0], tolerance, units, n - 1)
        if problem:
            return _KeptRefusal(n - 1, tuple(segments[-1].end[:2].tolist()), f"the path does not close G2: {problem}", False)
    return result_type(chains, deviation, [joints[j] for j in sorted(joints)], sorted(splits), whole, bound, shape, units)
