"""Chains: G2-checked sequences of lines, arcs and Bézier spirals."""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ._inputs import as_float, as_real_array, as_xy
from .errors import JointError
from .segments import Arc, Join, Line, Segment, measure_join
from .spiral import BezierSpiral
from .transitions import Transition
from .units import DEFAULT_UNITS, length_unit

#: Default join tolerance: gap / chain size, tangent angle (rad) and
#: curvature jump × chain size must each stay below it.
JOIN_TOLERANCE = 1e-9
#: Largest join tolerance a chain accepts: looser joins are not G2.
MAX_JOIN_TOLERANCE = 1e-3
#: Largest allowance for float64 rounding at a joint (relative, like the
#: tolerance): a rounding floor above it means the segment is too small for
#: its coordinates, and the joint is judged as if exact.
ROUNDING_CAP = 1e-6


def g2_mismatch(a: Segment, b: Segment, tolerance: float, units: str = "", index: int = 0) -> str | None:
    """Why the joint from ``a`` to ``b`` is not G2 (see ``Chain``), or None when it is."""
    j = measure_join(a, b, index)
    la, lb = a.length, b.length
    short, long = min(la, lb), max(la, lb)
    kappa = max(abs(a.end_curvature), abs(b.start_curvature), 1.0 / long)
    scale = np.array([short, 1.0, kappa])
    floor = np.minimum(np.add(rounding_floor(a, True), rounding_floor(b, False)), ROUNDING_CAP * scale)
    if j.gap > tolerance * short + floor[0] or j.angle > tolerance + floor[1] or j.curvature_jump > tolerance * kappa + floor[2]:
        return (
            f"joint {index} (between segments {index} and {index + 1}): gap {j.gap:.3g}, tangent angle "
            f"{j.angle:.3g} rad, curvature jump {j.curvature_jump:.3g} (tolerance {tolerance:g}: gap relative to the "
            f"shorter segment, {short:.6g} {units}; curvature jump relative to {kappa:.6g} 1/{units})"
        )
    return None


def rounding_floor(segment: Segment, at_end: bool) -> tuple[float, float, float]:
    """``segment.rounding_floor(at_end)``, also where its own arithmetic leaves float64.

    A floor is (gap, angle, curvature): a length, a pure number and an inverse
    length. Where a segment's formula overflows or underflows (a spiral's
    |leg|³ beyond 1e308 or below 1e-308), it is evaluated on a copy scaled
    by a power of two (exact in float64) and scaled back; a copy that float64
    cannot hold either means an unbounded floor (the cap then applies).
    """
    try:
        return segment.rounding_floor(at_end)
    except ArithmeticError:
        pass
    rebuild = getattr(type(segment), "from_control_points", None)  # spirals: the only floors that can raise
    if rebuild is None:
        return math.inf, math.inf, math.inf
    exponent = math.frexp(segment.length)[1]
    try:
        gap, angle, curvature = rebuild(np.ldexp(segment.control_points, -exponent)).rounding_floor(at_end)
    except (ArithmeticError, ValueError):
        return math.inf, math.inf, math.inf
    return math.ldexp(gap, exponent), angle, math.ldexp(curvature, -exponent)


def join_tolerance(value: Any) -> float:
    """A chain's join tolerance: finite and in (0, MAX_JOIN_TOLERANCE], else ValueError."""
    tolerance = as_float(value, "tolerance")
    if not 0.0 < tolerance <= MAX_JOIN_TOLERANCE:
        raise ValueError(f"tolerance must lie in (0, {MAX_JOIN_TOLERANCE:g}]; got {tolerance!r}")
    return tolerance


def _segment_tuple(segments: Any) -> tuple[Segment, ...]:
    if isinstance(segments, (Segment, Transition, str, bytes)) or not isinstance(segments, Iterable):
        raise ValueError(f"segments must be a list of Line, Arc and BezierSpiral; got {type(segments).__name__}")
    items = tuple(segments)
    if not items:
        raise ValueError("Chain needs at least one segment")
    for i, seg in enumerate(items):
        if not isinstance(seg, Segment):
            raise ValueError(f"Chain segment {i} must be a Line, Arc or BezierSpiral; got {type(seg).__name__} {seg!r:.80}")
    return items


class Chain:
    """An ordered, G2-continuous path of ``Line``, ``Arc`` and ``BezierSpiral``.

    Consecutive segments must share end point, unit tangent and signed
    curvature. ``size`` is the diagonal of the box around the segments'
    outlines (``Segment.outline``). Each joint is judged on its own scale, as the G2 checker
    judges files: with L_short and L_long the lengths of its two segments,

    * gap ≤ tol · L_short,
    * tangent angle ≤ tol (radians),
    * |Δκ| ≤ tol · max(|κ_before|, |κ_after|, 1/L_long),

    where tol is ``tolerance`` (default 1e-9). Each bound is widened by what
    float64 rounding of the stored coordinates can hide at that joint
    (``Segment.rounding_floor``), so survey coordinates (~1e6) and tiny
    spirals are judged by their geometry, not by their last bits; that
    allowance is capped at ``ROUNDING_CAP`` (1e-6) on the same scales, so a
    segment too small for its coordinates can never hide a kink.

    Args:
        segments: the segments in travel order (at least one).
        tolerance: relative join tolerance, in (0, 1e-3].
        units: the length unit of the coordinates (``spiral_cad.core.units``:
            mm, cm, m, km, in, ft; default mm as in build123d/CadQuery). It
            travels with the chain into every file written from it.

    Raises:
        ValueError: a joint exceeds the tolerance (a ``JointError`` naming the
            joint index and the three mismatches), no segments were given, or
            the tolerance is not in (0, 1e-3].
    """

    def __init__(self, segments: Iterable[Segment], tolerance: float = JOIN_TOLERANCE, units: str = DEFAULT_UNITS):
        self._segments: tuple[Segment, ...] = _segment_tuple(segments)
        BezierSpiral.measure_lengths(self._segments)
        self.tolerance = join_tolerance(tolerance)
        self.units = length_unit(units)
        lengths = np.array([s.length for s in self._segments])
        self._stations = np.concatenate([[0.0], np.cumsum(lengths)])
        if not math.isfinite(self._stations[-1]):
            raise ValueError(f"Chain length overflows float64 ({len(self)} segments)")
        pts = np.array([p for s in self._segments for p in s.outline()])
        self.size = float(math.hypot(*(pts.max(axis=0) - pts.min(axis=0)))) or 1.0
        if not math.isfinite(self.size):
            raise ValueError("Chain extent overflows float64")
        for index, (a, b) in enumerate(zip(self._segments, self._segments[1:])):
            problem = g2_mismatch(a, b, self.tolerance, self.units, index)
            if problem:
                raise JointError(f"Chain is not G2 at {problem}", index)

    @classmethod
    def join(
        cls,
        parts: Sequence[Transition | Segment],
        start: Any = None,
        end: Any = None,
        tolerance: float = JOIN_TOLERANCE,
        units: str = DEFAULT_UNITS,
    ) -> Chain:
        """Chain transitions and segments, filling each gap with the right connector.

        Between two parts, a gap is bridged by an arc of the circle the first
        part ends on (its ``end_circle``, travelled in its sense for the sweep
        up to the next contact) or, when it ends on a line, by a line.
        ``start``/``end`` add a leading/trailing line to those points
        (none where a part already starts or ends there; with no parts the
        chain is the line from ``start`` to ``end``).

        Example:
            ``Chain.join([line_to_circle(...), circle_to_line(...)], start=a, end=b)``
            gives line → spiral → arc → spiral → line.

        Raises:
            ValueError: malformed parts, a ``start`` ahead of the first part's
                start or an ``end`` behind the last part's end (the line would
                fold back), or a joint that is not G2 (a ``JointError`` whose
                ``part`` is the index of the part the joint belongs to).
        """
        if isinstance(parts, (Segment, Transition, str, bytes)) or not isinstance(parts, Sequence):
            raise ValueError(
                f"parts must be a list of transitions and segments; got {type(parts).__name__} (wrap one part in a list)"
            )
        for i, part in enumerate(parts):
            if not isinstance(part, (Transition, Segment)):
                raise ValueError(f"parts[{i}] must be a Transition or a segment; got {type(part).__name__} {part!r:.80}")
        tolerance = join_tolerance(tolerance)
        BezierSpiral.measure_lengths(s for p in parts for s in (p.spirals if isinstance(p, Transition) else [p]))
        if not parts:
            if start is None or end is None:
                raise ValueError("Chain.join needs parts, or both start and end for a straight chain")
            return cls([Line(as_xy(start, "start"), as_xy(end, "end"))], tolerance, units)
        segments: list[Segment] = []
        owners: list[int] = []  # the part each segment comes from or follows
        if start is not None:
            first = np.array(as_xy(start, "start"))
            bridge = _bridge(first, parts[0].start, parts[0].length, tolerance)
            if bridge and float(np.dot(parts[0].start - first, parts[0].start_tangent)) < 0.0:
                raise ValueError(
                    f"start {tuple(first.tolist())} lies ahead of where parts[0] begins, "
                    f"{tuple(parts[0].start.tolist())}: the line from it would run backwards"
                )
            segments.extend(bridge)
        owners += [0] * len(segments)
        for k, (previous, part) in enumerate(zip([None, *parts], parts)):
            if previous is not None:
                bridge = _connector(previous, part, tolerance)
                segments.extend(bridge)
                owners += [k - 1] * len(bridge)
            own = part.spirals if isinstance(part, Transition) else [part]
            segments.extend(own)
            owners += [k] * len(own)
        if end is not None:
            last = np.array(as_xy(end, "end"))
            bridge = _bridge(parts[-1].end, last, parts[-1].length, tolerance)
            if bridge and float(np.dot(last - parts[-1].end, parts[-1].end_tangent)) < 0.0:
                raise ValueError(
                    f"end {tuple(last.tolist())} lies behind where parts[{len(parts) - 1}] ends, "
                    f"{tuple(parts[-1].end.tolist())}: the line to it would run backwards"
                )
            segments.extend(bridge)
        owners += [len(parts) - 1] * (len(segments) - len(owners))
        try:
            return cls(segments, tolerance, units)
        except JointError as error:
            part = owners[error.joint + 1] if owners[error.joint + 1] != owners[error.joint] else owners[error.joint]
            raise JointError(f"{error} (at parts[{part}])", error.joint, part) from None

    # ------------------------------------------------------------- access

    @property
    def segments(self) -> tuple[Segment, ...]:
        return self._segments

    def __len__(self) -> int:
        return len(self._segments)

    def __iter__(self):
        return iter(self._segments)

    def __getitem__(self, index: int) -> Segment:
        return self._segments[index]

    def __repr__(self) -> str:
        kinds = " → ".join(type(s).__name__ for s in self._segments)
        return f"Chain({len(self)} segments, length {self.length:.6g} {self.units}: {kinds})"

    @property
    def length(self) -> float:
        return float(self._stations[-1])

    @property
    def stations(self) -> NDArray:
        """Arc length at the start of each segment, plus the total (len + 1)."""
        return self._stations.copy()

    @property
    def start(self) -> NDArray:
        return self._segments[0].start

    @property
    def end(self) -> NDArray:
        return self._segments[-1].end

    def joins(self) -> list[Join]:
        """Mismatches at every internal joint, in order."""
        return [measure_join(a, b, i) for i, (a, b) in enumerate(zip(self._segments, self._segments[1:]))]

    def reversed(self) -> Chain:
        return Chain([s.reversed() for s in reversed(self._segments)], self.tolerance, self.units)

    # --------------------------------------------------- station queries

    def _locate(self, s: ArrayLike) -> tuple[NDArray, NDArray]:
        s = as_real_array(s, "stations")
        if not np.all((s >= -1e-12 * self.length) & (s <= self.length * (1 + 1e-12))):
            bad = s[~((s >= -1e-12 * self.length) & (s <= self.length * (1 + 1e-12)))].ravel()[0]
            raise ValueError(f"stations must lie in [0, {self.length}]; got {bad}")
        index = np.clip(np.searchsorted(self._stations, s, side="right") - 1, 0, len(self) - 1)
        return index, s - self._stations[index]

    def _at(self, s: ArrayLike, method: str, width: tuple[int, ...]) -> NDArray:
        index, local = self._locate(s)
        flat_index, flat_local = index.ravel(), local.ravel()
        out = np.empty(flat_index.shape + width)
        # Group the samples by segment in one sort (linear in the samples, not
        # samples × segments).
        order = np.argsort(flat_index, kind="stable")
        bounds = np.flatnonzero(np.diff(flat_index[order])) + 1
        for group in np.split(order, bounds):
            if len(group):
                seg = self._segments[flat_index[group[0]]]
                out[group] = getattr(seg, method)(seg.parameter_at(flat_local[group]))
        return out.reshape(index.shape + width)

    def point_at(self, s: ArrayLike) -> NDArray:
        """Points at stations ``s`` (arc length from the start)."""
        return self._at(s, "point", (2,))

    def tangent_at(self, s: ArrayLike) -> NDArray:
        """Unit tangents at stations ``s``."""
        return self._at(s, "tangent", (2,))

    def curvature_at(self, s: ArrayLike) -> NDArray:
        """Signed curvature at stations ``s``."""
        return self._at(s, "curvature", ())

    def sample(self, per_segment: int = 32) -> NDArray:
        """Points along the chain, ``per_segment`` per segment plus the end (for plots)."""
        u = np.linspace(0.0, 1.0, per_segment, endpoint=False)
        pts = [seg.point(u) for seg in self._segments]
        return np.vstack(pts + [self.end[None]])

    # ------------------------------------------- CAD (imported when used)

    def to_edges(self, plane: Any = None) -> list:
        """The exact build123d edges (LINE, CIRCLE, BEZIER) in travel order.

        Args:
            plane: a build123d ``Plane`` holding the chain's 2-D coordinates
                (None: ``Plane.XY``).
        """
        from build123d import Edge

        from ..cad.occ import segment_edges

        return [Edge(e) for e in segment_edges(self._segments, _ax3(plane))]

    def to_wire(self, plane: Any = None) -> Any:
        """The chain as one build123d ``Wire`` on ``plane`` (None: ``Plane.XY``)."""
        from build123d import Wire

        from ..cad.occ import chain_wire

        return Wire(chain_wire(self._segments, _ax3(plane)))

    def to_nurbs(self) -> Any:
        """The whole chain as one exact rational cubic B-spline (``spiral_cad.nurbs.Nurbs``)."""
        from .nurbs import chain_to_nurbs

        return chain_to_nurbs(self._segments)


def _ax3(plane: Any) -> Any:
    """A build123d ``Plane`` (or None) as the OCP ``gp_Ax3`` the edge makers take."""
    if plane is None:
        return None
    to_gp_ax3 = getattr(plane, "to_gp_ax3", None)
    if to_gp_ax3 is None:
        raise ValueError(f"plane must be a build123d Plane or None; got {plane!r}")
    return to_gp_ax3()


def _connector(previous: Transition | Segment, part: Transition | Segment, tolerance: float) -> list[Segment]:
    """The line or arc that bridges ``previous``'s end to ``part``'s start (none if they meet)."""
    a, b = previous.end, part.start
    scale = max(previous.length, part.length)
    circle = previous.end_circle if isinstance(previous, Transition) else None
    if circle is None and isinstance(previous, Arc):
        circle = previous.circle
    if circle is None:
        return _bridge(a, b, scale, tolerance)
    return [] if _meet(a, b, scale, tolerance) else [Arc.between(circle.center, circle.radius, a, b)]


def _meet(a: NDArray, b: NDArray, scale: float, tolerance: float) -> bool:
    return bool(np.hypot(*(b - a)) <= tolerance * scale)


def _bridge(a: NDArray, b: NDArray, scale: float, tolerance: float) -> list[Segment]:
    """A line from ``a`` to ``b``, or nothing when they meet."""
    return [] if _meet(a, b, scale, tolerance) else [Line(a, b)]
