"""Circle chains: a G2 path that runs round a sequence of circles.

Consecutive circles are joined by the transition their radii call for
(signed radii give the travel sense): a broken-back C for equal signs, an S
for opposite signs, or the single nested-circle spiral when one circle lies
inside the other; ``Chain.join`` adds the arcs between contacts.

Overlap criterion (Walton & Meek §5: a spiral may reach a circle past the
point where the next spiral leaves it). On each intermediate circle k the
arc from the incoming contact A to the outgoing contact B is compared with
the arc a G1 "belt" of common tangent lines would use: A0 is where the
tangent line from circle k−1 touches circle k, B0 where the tangent line to
circle k+1 leaves it (for nested circles, the point of circle k nearest the
other circle stands in for the tangent point). A spiral contact is displaced
from its tangent point by less than a half turn, so the intended sweep is

    σ = σ_belt(A0 → B0) − α(A0 → A) − α(B → B0),

with σ_belt ∈ [0, 2π) (taken as 0 when A0 and B0 coincide to rounding) and
the displacements α wrapped to (−π, π]. σ < 0 means the arc would have to run
backwards: the circles are reported and no chain is built.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from typing import Any, cast

import numpy as np
from numpy.typing import NDArray

from ..core import batch
from ..core.chain import Chain
from ..core.errors import JointError, NoSolutionError
from ..core.inputs import as_float, as_xy, shown
from ..core.segments import TAU, Circle
from ..core.shapes import DEFAULT_SHAPE, TRANSITION_SHAPES, shape_code
from ..core.spiral import BezierSpiral
from ..core.transitions import Transition
from ..core.units import DEFAULT_UNITS

#: Belt sweeps within this of 2π count as 0 (coincident tangent points).
_FULL_TURN_TOL = 1e-9


@dataclass(frozen=True)
class CircleChain:
    """A path round circles: the chain, the transitions and each intermediate arc's sweep.

    Attributes:
        chain: the G2 chain from the first transition's start to the last one's end.
        circles: the input circles (signed radii).
        transitions: transition i joins circle i to circle i + 1.
        sweeps: sweep (radians, ≥ 0) of the arc on each intermediate circle
            1 … n − 2, in travel sense.
    """

    chain: Chain
    circles: list[Circle]
    transitions: list[Transition]
    sweeps: list[float]

    @property
    def shape(self) -> str:
        """The spiral shape of the transitions."""
        return self.transitions[0].shape


def _as_circle(value: Any, index: int) -> Circle:
    center: Any  # a point of any form until as_xy checks it
    if isinstance(value, Circle):
        center, radius = value.center, value.radius
    else:
        if isinstance(value, (str, bytes, dict)) or not isinstance(value, Iterable):
            raise ValueError(f"circle {index} must be a Circle, (center, radius) or (x, y, radius); got {shown(value):.80}")
        items = list(value)
        if len(items) == 3:
            center, radius = items[:2], items[2]
        elif len(items) == 2:
            center, radius = items
        else:
            raise ValueError(f"circle {index} must be a Circle, (center, radius) or (x, y, radius); got {shown(value):.80}")
    center = as_xy(center, f"circle {index} center")
    radius = as_float(radius, f"circle {index} radius")
    if radius == 0.0:
        raise ValueError(f"circle {index}: radius must be non-zero (its sign is the travel sense); got 0.0")
    return Circle(center, radius)


def _nested(a: Circle, b: Circle) -> bool:
    """Same travel sense and one circle inside the other."""
    distance = math.dist(a.center, b.center)
    return (a.radius > 0.0) == (b.radius > 0.0) and distance < abs(abs(a.radius) - abs(b.radius))


def belt_contacts(a: Circle, b: Circle) -> tuple[NDArray, NDArray] | None:
    """Where the directed common tangent line from circle ``a`` to circle ``b`` touches them.

    The line is travelled in each circle's sense (centre on the left for a
    positive radius): with unit direction t and n = rot90(t), the contacts
    are C − r·n, so n·(Cb − Ca) = rb − ra. None if no such line exists.
    """
    ca, cb = np.array(a.center), np.array(b.center)
    offset = cb - ca
    distance = float(np.hypot(*offset))
    ratio = (b.radius - a.radius) / distance if distance > 0.0 else math.inf
    if not abs(ratio) <= 1.0:
        return None
    angle = math.atan2(offset[1], offset[0]) + math.acos(ratio)
    n = np.array([math.cos(angle), math.sin(angle)])
    return ca - a.radius * n, cb - b.radius * n


def _reference(circle: Circle, other: Circle, contact: NDArray | None) -> NDArray:
    """The belt tangent point on ``circle`` (or, nested, its point nearest ``other``)."""
    if contact is not None:
        return contact
    c, o = np.array(circle.center), np.array(other.center)
    away = (o - c) if abs(circle.radius) > abs(other.radius) else (c - o)
    return c + abs(circle.radius) * (away / np.hypot(*away))  # unit vector first: r·away may overflow


def _sense_angle(circle: Circle, a: NDArray, b: NDArray) -> float:
    """Angle from ``a`` to ``b`` about the centre, in the circle's travel sense, in (−π, π]."""
    c = circle.center
    turn = math.atan2(b[1] - c[1], b[0] - c[0]) - math.atan2(a[1] - c[1], a[0] - c[0])
    turn = math.copysign(1.0, circle.radius) * turn
    return math.pi - (math.pi - turn) % TAU


def circle_chain(circles: Sequence[Any], units: str = DEFAULT_UNITS, shape: str = DEFAULT_SHAPE) -> CircleChain:
    """A G2 path round ``circles`` in order, with spiral transitions between them.

    Args:
        circles: at least two circles, each a ``Circle``, ``(center, radius)``
            or ``(x, y, radius)``; the radius sign is the travel sense
            (positive counterclockwise).
        units: length unit of centres and radii (default mm).
        shape: spiral shape of every transition: ``"walton-meek"`` (default,
            the paper's geometry) or ``"near-linear"`` (curvature closer to
            linear in arc length; C and S pairs reach less far apart circles).

    Each consecutive pair gets ``circle_in_circle`` when nested (same sense,
    one inside the other) and ``circle_to_circle`` otherwise (C for equal
    senses, S for opposite). See the module docstring for the overlap test.

    Raises:
        NoSolutionError: no transition between circles i and i + 1 (the
            message names both), or the transitions overlap on circle k
            (the message names it and its neighbours to move or resize).
        ValueError: malformed input.
    """
    if isinstance(circles, (str, bytes, dict)) or not isinstance(circles, Iterable):
        raise ValueError(f"circles must be a list of circles; got {type(circles).__name__}")
    items = [_as_circle(c, i) for i, c in enumerate(circles)]
    shape_code(shape, TRANSITION_SHAPES)
    if len(items) < 2:
        raise ValueError(f"circle_chain needs at least 2 circles; got {len(items)}")
    transitions = _transitions(items, shape)
    sweeps = []
    for k in range(1, len(items) - 1):
        sweeps.append(_arc_sweep(items, transitions, k))
    try:
        chain = Chain.join(transitions, units=units)
    except JointError as error:
        assert error.part is not None  # Chain.join names the part
        k = error.part
        raise NoSolutionError(f"circles {k} and {k + 1}: float64 cannot hold the path G2 at these coordinates: {error}") from None
    return CircleChain(chain, items, transitions, sweeps)


def _transitions(items: list[Circle], shape: str) -> list[Transition]:
    """The transition between each pair of consecutive circles: one batch call per case (nested
    pairs, and C/S pairs); the first pair that has none raises, named."""
    centers = np.array([c.center for c in items])
    radii = np.array([c.radius for c in items])
    nested = np.array([_nested(a, b) for a, b in zip(items, items[1:])], dtype=bool)
    solved = {}
    for case, solve, rows in (
        ("nested", batch.circle_in_circle, np.flatnonzero(nested)),
        ("pair", batch.circle_to_circle, np.flatnonzero(~nested)),
    ):
        if len(rows):
            solved[case] = (rows, solve(centers[rows], radii[rows], centers[rows + 1], radii[rows + 1], shape=shape))
    failed = [(int(rows[k]), result) for rows, result in solved.values() for k in np.flatnonzero(~result.ok)]
    if failed:
        i, result = min(failed, key=lambda f: f[0])
        k = int(np.flatnonzero(solved["nested" if nested[i] else "pair"][0] == i)[0])
        error = result.error(k)
        if isinstance(error, NoSolutionError):
            raise NoSolutionError(f"circles {i} and {i + 1}: {error}")
        raise error
    transitions: list[Transition | None] = [None] * len(nested)
    for case, (rows, result) in solved.items():
        pairs = zip(rows.tolist(), zip(*(s.tolist() for s in result.spirals)), result.theta.tolist())
        for k, (i, spirals, theta) in enumerate(pairs):
            a, b = items[i], items[i + 1]
            if case == "nested":
                assert result.parameter is not None  # the nested case carries t
                kind, parameter = "circle-circle-nested", float(result.parameter[k])
            else:
                kind, parameter = ("S" if (a.radius > 0) != (b.radius > 0) else "C"), None
            curves = [BezierSpiral._wrap(np.array(cp), shape) for cp in spirals]
            transitions[i] = Transition(kind, curves, theta, a, b, parameter=parameter, shape=shape)
    return cast("list[Transition]", transitions)  # every pair solved (a failure raised above)


def _arc_sweep(items: list[Circle], transitions: list[Transition], k: int) -> float:
    """Intended sweep on circle k (module docstring); raises when it is negative."""
    circle, before, after = items[k], items[k - 1], items[k + 1]
    inbound = belt_contacts(before, circle)
    outbound = belt_contacts(circle, after)
    a0 = _reference(circle, before, None if inbound is None else inbound[1])
    b0 = _reference(circle, after, None if outbound is None else outbound[0])
    a, b = transitions[k - 1].end, transitions[k].start
    belt = _sense_angle(circle, a0, b0) % TAU
    if belt > TAU - _FULL_TURN_TOL:
        belt = 0.0
    sweep = belt - _sense_angle(circle, a0, a) - _sense_angle(circle, b, b0)
    if sweep < -1e-12:
        overlap = -sweep
        raise NoSolutionError(
            f"circle {k}: the transition from circle {k - 1} reaches it {math.degrees(overlap):.4g}° "
            f"({overlap * abs(circle.radius):.6g} along the circle) past where the transition to circle "
            f"{k + 1} leaves it, so the arc between them would run backwards. Move circle {k - 1} or "
            f"circle {k + 1} further round circle {k}, or resize circle {k}"
        )
    return max(sweep, 0.0)
