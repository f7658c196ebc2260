"""The five G2 transitions of Walton & Meek (1996), one problem at a time.

Each solver returns a :class:`Transition` whose ``spirals`` read in travel
order, made with the spiral ``shape`` asked for (``spiral_cad.core.shapes``:
``"walton-meek"`` by default, or ``"near-linear"``). The work is done by the
row kernels that ``spiral_cad.core.batch`` runs over arrays, so scalar and batch
results agree bit for bit.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
from numpy.typing import NDArray

from . import _kernel_circles as KC
from . import _kernel_line_circle as KLC
from . import _kernel_line_line as KLL
from .inputs import as_float, as_xy
from .messages import error_for
from .segments import Arc, Circle, Join, Line, Ray, Segment, measure_join
from .shapes import CORNER_SHAPES, DEFAULT_SHAPE, shape_code
from .spiral import BezierSpiral


@dataclass(frozen=True)
class Transition:
    """A solved transition.

    Attributes:
        kind: ``"line-circle"``, ``"circle-line"``, ``"C"``, ``"S"``,
            ``"line-line"`` or ``"circle-circle-nested"``.
        spirals: the Bézier spirals in travel order.
        theta: the theorem's spiral angle θ ∈ (0, π/2) (each spiral's own
            signed turn is ``spiral.theta``).
        start_circle: the circle the path leaves (travel-sense radius), if any.
        end_circle: the circle the path reaches, if any.
        start_line, end_line: the given lines the path leaves / reaches, if any.
        parameter: nested case only: the parameter t ∈ (0, 1) of the full
            spiral where it meets the larger circle.
        shape: the spiral shape (``"walton-meek"``, ``"near-linear"``, ``"g2cbs"``).
    """

    kind: str
    spirals: list[BezierSpiral]
    theta: float
    start_circle: Circle | None = None
    end_circle: Circle | None = None
    parameter: float | None = None
    start_line: Ray | None = None
    end_line: Ray | None = None
    shape: str = DEFAULT_SHAPE

    @classmethod
    def _solved(cls, kind: str, spirals: list[BezierSpiral], theta: float, shape: str, start_circle: Circle | None = None,
                end_circle: Circle | None = None, parameter: float | None = None, start_line: Ray | None = None,
                end_line: Ray | None = None) -> Transition:  # fmt: skip
        """A solver's result, its fields set directly: the frozen dataclass's ``__init__``
        sets each through ``object.__setattr__`` (a fifth of a scalar solve)."""
        transition = object.__new__(cls)
        object.__setattr__(transition, "__dict__", {
            "kind": kind, "spirals": spirals, "theta": theta, "start_circle": start_circle, "end_circle": end_circle,
            "parameter": parameter, "start_line": start_line, "end_line": end_line, "shape": shape,
        })  # fmt: skip
        return transition

    @property
    def start(self) -> NDArray[np.float64]:
        """Contact point where the transition leaves the first line/circle."""
        return self.spirals[0].start

    @property
    def start_tangent(self) -> NDArray[np.float64]:
        return self.spirals[0].start_tangent

    @property
    def end(self) -> NDArray[np.float64]:
        """Contact point where the transition reaches the last line/circle."""
        return self.spirals[-1].end

    @property
    def end_tangent(self) -> NDArray[np.float64]:
        return self.spirals[-1].end_tangent

    @property
    def joint(self) -> NDArray[np.float64] | None:
        """Where two spirals meet (two-spiral cases), else None."""
        return self.spirals[0].end if len(self.spirals) == 2 else None

    @property
    def length(self) -> float:
        return sum(s.length for s in self.spirals)

    def reversed(self) -> Transition:
        """The same curve travelled the other way (e.g. circle → line)."""
        kinds = {"line-circle": "circle-line", "circle-line": "line-circle"}
        return replace(
            self,
            kind=kinds.get(self.kind, self.kind),
            spirals=[s.reversed() for s in reversed(self.spirals)],
            start_circle=self.end_circle and self.end_circle.reversed(),
            end_circle=self.start_circle and self.start_circle.reversed(),
            start_line=self.end_line and self.end_line.reversed(),
            end_line=self.start_line and self.start_line.reversed(),
        )

    def joins(self) -> list[Join]:
        """Mismatches (gap, tangent angle, curvature jump) at every contact, in travel order.

        The first and last entries compare the spirals with the given lines or
        circles, the others the joints between spirals.
        """
        size = self.length
        first = _contact_piece(self.start_circle, self.start_line, self.start, True, size)
        last = _contact_piece(self.end_circle, self.end_line, self.end, False, size)
        chain: list[Segment] = [first, *self.spirals, last]
        return [measure_join(a, b, i) for i, (a, b) in enumerate(zip(chain, chain[1:]))]


def _contact_piece(circle: Circle | None, line: Ray | None, point: NDArray[np.float64], before: bool, size: float) -> Segment:
    """A short piece of the given circle/line ending (``before``) or starting at the foot of ``point``.

    A line piece is ``size`` long (the transition's length), so it stays
    resolvable at any coordinate magnitude the solvers accept.
    """
    if circle is not None:
        cx, cy = circle.center
        angle = math.atan2(point[1] - cy, point[0] - cx)
        step = 1e-3 * math.copysign(1.0, circle.radius)
        return Arc(circle.center, circle.radius, angle - step if before else angle, 1e-3)
    assert line is not None  # every contact is a circle or a line
    (px, py), direction = line.point, np.asarray(line.direction) / math.hypot(*line.direction)
    foot = np.array([px, py]) + np.dot(point - (px, py), direction) * direction
    leg = size * direction
    return Line(foot - leg, foot) if before else Line(foot, foot + leg)


def _spirals(out: NDArray[np.float64], shape: str) -> list[BezierSpiral]:
    """The solved row ``out`` (1, k, 4, 2), k = 1 or 2, as spirals (read-only views)."""
    first = BezierSpiral._wrap(out[0, 0], shape)
    return [first] if out.shape[1] == 1 else [first, BezierSpiral._wrap(out[0, 1], shape)]


def line_to_circle(point: Any, direction: Any, center: Any, radius: float, shape: str = DEFAULT_SHAPE) -> Transition:
    """Theorem 4.1: spiral from a directed line onto a circle.

    Travel runs along ``direction`` and turns toward the side of the line the
    circle lies on. Use ``.reversed()`` for circle → line.

    Args:
        point: any point of the line.
        direction: travel direction of the line (non-zero).
        center: circle centre, off the line.
        radius: circle radius, > 0.
        shape: ``"walton-meek"`` (any shift q = (d − r)/r > 0) or
            ``"near-linear"`` (q < 0.1152: θ ≤ 50°; the equal-leg closed form
            for q < 1/27).

    Raises:
        NoSolutionError: the circle touches or crosses the line (r ≥ d), or
            lies beyond the shape's reach.
        ValueError: malformed input.
    """
    px, py = as_xy(point, "point")
    dx, dy = as_xy(direction, "direction")
    cx, cy = as_xy(center, "center")
    r = as_float(radius, "radius")
    out = np.empty((1, 1, 4, 2))
    status, theta, measure, side = KLC.KERNELS.for_scalar_call().line_to_circle_row(px, py, dx, dy, cx, cy, r, shape_code(shape), out, 0)
    if status:
        inputs = dict(point=(px, py), direction=(dx, dy), center=(cx, cy), radius=r, shape=shape)
        raise error_for("line_to_circle", status, measure, inputs)
    circle, line = Circle((cx, cy), side * r), Ray((px, py), (dx, dy))
    return Transition._solved("line-circle", _spirals(out, shape), theta, shape, end_circle=circle, start_line=line)


def _two_circles(
    case: str, center0: Any, radius0: Any, center1: Any, radius1: Any, shape: str
) -> tuple[tuple[float, float], float, tuple[float, float], float, NDArray[np.float64], float, float]:
    """Coerce the two circles' arguments (in argument order), solve ``case``'s row and
    raise its error if it fails: (c0, r0, c1, r1, out, θ, extra)."""
    c0 = as_xy(center0, "center0")
    r0 = as_float(radius0, "radius0")
    c1 = as_xy(center1, "center1")
    r1 = as_float(radius1, "radius1")
    rows = KC.KERNELS.for_scalar_call()
    row, spirals = (rows.circle_to_circle_row, 2) if case == "circle_to_circle" else (rows.circle_in_circle_row, 1)
    out = np.empty((1, spirals, 4, 2))
    status, theta, measure, extra = row(c0[0], c0[1], r0, c1[0], c1[1], r1, shape_code(shape), out, 0)
    if status:
        inputs = dict(center0=c0, radius0=r0, center1=c1, radius1=r1, shape=shape)
        raise error_for(case, status, measure, inputs)
    return c0, r0, c1, r1, out, theta, extra


def circle_to_circle(center0: Any, radius0: float, center1: Any, radius1: float, shape: str = DEFAULT_SHAPE) -> Transition:
    """Theorems 4.2 and 4.3: two spirals from circle 0 to circle 1.

    The sign of each radius is the travel sense on that circle (positive:
    counterclockwise). Same signs give a broken-back C (zero curvature at the
    joint), opposite signs an S (an inflection at the joint).

    Args:
        center0, radius0: the circle left (signed radius: travel sense).
        center1, radius1: the circle reached.
        shape: ``"walton-meek"`` or ``"near-linear"`` (S: D < 1.4108·(r0 + r1);
            C: D < √((r0 + r1)²·0.8642² + (r1 − r0)²·1.1152²), its 50° limit).

    Raises:
        NoSolutionError: C with one circle enclosing the other, S with
            circles that touch or overlap, or circles beyond the shape's reach.
        ValueError: malformed input (zero radius, coincident centres, …).
    """
    c0, r0, c1, r1, out, theta, _ = _two_circles("circle_to_circle", center0, radius0, center1, radius1, shape)
    kind = "S" if (r0 > 0) != (r1 > 0) else "C"
    return Transition._solved(kind, _spirals(out, shape), theta, shape, Circle(c0, r0), Circle(c1, r1))


def line_to_line(p0: Any, corner: Any, p1: Any, curvature: float | None = None, shape: str = DEFAULT_SHAPE) -> Transition:
    """Theorem 4.4: two spirals from the line p0→corner to the line corner→p1.

    Args:
        p0: a point on the incoming line (before the corner).
        corner: the lines' intersection.
        p1: a point on the outgoing line (after the corner).
        curvature: joint curvature magnitude (> 0). ``None`` applies
            Corollary 4.5: the largest pair, starting exactly at the nearer of
            p0 and p1.
        shape: ``"walton-meek"``, ``"near-linear"`` (deflections up to 100°)
            or ``"g2cbs"``; the pair starts K(θ)/κ from the corner, K the
            shape's corner factor.

    Raises:
        NoSolutionError: collinear or folded-back legs, a deflection beyond
            the shape's range, or a curvature so small that the spirals would
            start beyond p0 or p1.
        ValueError: malformed input.
    """
    a = as_xy(p0, "p0")
    p = as_xy(corner, "corner")
    b = as_xy(p1, "p1")
    k = math.nan if curvature is None else as_float(curvature, "curvature")
    out = np.empty((1, 2, 4, 2))
    code = shape_code(shape, CORNER_SHAPES)
    status, theta, measure, _ = KLL.KERNELS.for_scalar_call().line_to_line_row(a[0], a[1], p[0], p[1], b[0], b[1], k, code, out, 0)
    if status:
        inputs = dict(p0=a, corner=p, p1=b, curvature=curvature, shape=shape)
        raise error_for("line_to_line", status, measure, inputs)
    start, end = Ray(p, (p[0] - a[0], p[1] - a[1])), Ray(p, (b[0] - p[0], b[1] - p[1]))
    return Transition._solved("line-line", _spirals(out, shape), theta, shape, start_line=start, end_line=end)


def circle_in_circle(center0: Any, radius0: float, center1: Any, radius1: float, shape: str = DEFAULT_SHAPE) -> Transition:
    """The fifth case: one spiral between nested circles, either way.

    Radii are signed by travel sense and must share the sign. The larger
    circle is met at an interior parameter t of the full spiral, so the
    returned spiral is the exact piece [t, 1] (reversed when travelling out
    of the smaller circle). Solutions exist only in a thin band just inside
    internal tangency, whose lower end depends on the shape (see
    ``NoSolutionError`` messages).

    Raises:
        NoSolutionError: centre distance outside the band, or equal radii.
        ValueError: malformed input or radii of different signs.
    """
    c0, r0, c1, r1, out, theta, t = _two_circles("circle_in_circle", center0, radius0, center1, radius1, shape)
    circles = Circle(c0, r0), Circle(c1, r1)
    return Transition._solved("circle-circle-nested", _spirals(out, shape), theta, shape, *circles, parameter=t)
