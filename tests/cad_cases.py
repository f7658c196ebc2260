"""Chains for every transition kind, shared by the CAD adapter and export tests."""

from __future__ import annotations

import math

import numpy as np

from spiral_cad import Arc, Chain, Circle, Line, circle_in_circle, circle_to_circle, line_to_circle, line_to_line


def arc_on(circle: Circle, point, sweep: float, before: bool = False) -> Arc:
    """Arc of ``circle`` (in its travel sense) ending at (``before``) or starting at ``point``."""
    angle = math.atan2(point[1] - circle.center[1], point[0] - circle.center[0])
    if before:
        angle -= math.copysign(sweep, circle.radius)
    return Arc(circle.center, circle.radius, angle, sweep)


def around(transition, sweep: float = 0.6) -> Chain:
    """The transition with a piece of its given lines/circles before and after."""
    t = transition
    if t.start_circle is not None:
        first = arc_on(t.start_circle, t.start, sweep, before=True)
    else:
        d = t.start_tangent
        first = Line(t.start - 3.0 * d, t.start)
    if t.end_circle is not None:
        last = arc_on(t.end_circle, t.end, sweep)
    else:
        d = t.end_tangent
        last = Line(t.end, t.end + 3.0 * d)
    return Chain([first, *t.spirals, last])


def transition_chains() -> dict[str, Chain]:
    """One chain per transition kind plus a mixed chain with full-size arcs."""
    nested_distance = (3.0 - 1.2) * 0.9935
    mixed = Chain.join(
        [
            line_to_circle((0, 0), (1, 0), (40, 25), 15.0),
            circle_to_circle((40, 25), 15.0, (85, 30), -12.0),
            circle_to_circle((85, 30), -12.0, (120, 10), -9.0),
        ],
        start=(-80, 0),
    )
    return {
        "line-circle": around(line_to_circle((0, 0), (1, 0), (6, 4), 2.5)),
        "circle-line": around(line_to_circle((0, 0), (1, 1), (2, 7), 3.0).reversed()),
        "C": around(circle_to_circle((0, 0), 2.0, (7, 1), 1.5)),
        "S": around(circle_to_circle((0, 0), 2.0, (8, -1), -1.5)),
        "line-line": around(line_to_line((-10, 0), (0, 0), (6, 8))),
        "nested": around(circle_in_circle((0, 0), 3.0, (nested_distance, 0.0), 1.2), sweep=2.0),
        "mixed": mixed,
    }


def curvature_vector(d1: np.ndarray, d2: np.ndarray) -> np.ndarray:
    """Curvature vector κN from first and second derivatives (independent of the parametrisation)."""
    speed2 = float(d1 @ d1)
    return (d2 - (d2 @ d1) / speed2 * d1) / speed2
