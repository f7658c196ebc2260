"""Chains: G2-checked sequences of lines, arcs and Bézier spirals, in the plane or in space.

A chain keeps its segments as arrays (``spiral_cad.core.rows``) and checks
every joint in one compiled pass (``_chain_kernels.joint_measures``);
``Line``/``Arc``/``BezierSpiral`` objects are made only when a segment is
asked for.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Iterator, Sequence
from typing import TYPE_CHECKING, Any, cast

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import _chain_kernels as CK
from .errors import JointError
from .inputs import as_float, as_point, as_real_array
from .kinds import ARC, LINE, SPIRAL
from .rows import SegmentRows
from .segments import _XY_BASIS, Arc, Join, Line, Segment, curvature_scales, joint_table, lifted
from .space import PlaneFrame
from .spiral import BezierSpiral
from .transitions import Transition
from .units import DEFAULT_UNITS, length_unit

if TYPE_CHECKING:
    from typing import TypeAlias

    #: End frames (n, 2, 9), rounding floors (n, 2, 3) and lengths (n,) of rows (``SegmentRows.measure``).
    Measured: TypeAlias = tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]

#: Default join tolerance: gap / chain size, tangent angle (rad) and
#: curvature jump × chain size must each stay below it.
JOIN_TOLERANCE = 1e-9
#: Largest join tolerance a chain accepts: looser joins are not G2.
MAX_JOIN_TOLERANCE = 1e-3
#: Largest allowance for float64 rounding at a joint (relative, like the
#: tolerance): a rounding floor above it means the segment is too small for
#: its coordinates, and the joint is judged as if exact.
ROUNDING_CAP = 1e-6

_KIND_NAMES = ("Line", "Arc", "BezierSpiral")


def _problem(index: int, measures: NDArray[np.float64], tolerance: float, units: str) -> str:
    """The message of a joint that fails (``measures``: its row of ``joint_table``)."""
    gap, angle, jump, short, kappa = measures[:5].tolist()
    return (
        f"joint {index} (between segments {index} and {index + 1}): gap {gap:.3g}, tangent angle "
        f"{angle:.3g} rad, curvature jump {jump:.3g} (tolerance {tolerance:g}: gap relative to the "
        f"shorter segment, {short:.6g} {units}; curvature jump relative to {kappa:.6g} 1/{units})"
    )


def g2_mismatch(a: Segment, b: Segment, tolerance: float, units: str = "", index: int = 0) -> str | None:
    """Why the joint from ``a`` to ``b`` is not G2 (see ``Chain``), or None when it is."""
    if a.dim != b.dim:
        a, b = (s if s.dim == 3 else s.placed(PlaneFrame()) for s in (a, b))
    (frames_a, floors_a), (frames_b, floors_b) = a._ends, b._ends
    own = curvature_scales(np.stack([frames_a, frames_b])).max()
    out, first = joint_table(frames_a[1:], floors_a[1:], np.array([a.length]), frames_b[:1], floors_b[:1],
                             np.array([b.length]), own, tolerance, ROUNDING_CAP)  # fmt: skip
    return None if first < 0 else _problem(index, out[0], tolerance, units)


def rounding_floor(segment: Segment, at_end: bool) -> tuple[float, float, float]:
    """``segment.rounding_floor(at_end)``: (gap, angle, curvature) — a length, a pure number and an
    inverse length — evaluated on a copy scaled by a power of two (exact in float64), so a segment
    of any magnitude gets its floor; one that float64 cannot hold gives an unbounded floor (the cap applies)."""
    return segment.rounding_floor(at_end)


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
    """An ordered, G2-continuous path of ``Line``, ``Arc`` and ``BezierSpiral``, in the plane or in space.

    Consecutive segments must share end point, unit tangent and curvature
    vector. ``size`` is the diagonal of the box around the segments'
    outlines (``Segment.outline``). Each joint is judged on its own scale, as the G2
    checker judges files: with L_short and L_long the lengths of its two segments,

    * gap ≤ tol · L_short,
    * tangent angle ≤ tol (radians),
    * |Δκ| ≤ tol · max(|κ_before|, |κ_after|, κ_own, 1/L_long),

    κ_own being the largest |κ| either segment reaches at its ends (a spiral's
    peak): a spiral leaving a long line is judged on its own curvature, not on
    the line's length, so float64 residue of its start curvature (~1e-12 of its
    peak) never fails a joint that the spiral's construction holds.
    where tol is ``tolerance`` (default 1e-9). Each bound is widened by what
    float64 rounding of the stored coordinates can hide at that joint
    (``Segment.rounding_floor``), so survey coordinates (~1e6) and tiny
    spirals are judged by their geometry, not by their last bits; that
    allowance is capped at ``ROUNDING_CAP`` (1e-6) on the same scales, so a
    segment too small for its coordinates can never hide a kink.

    In space (``dim`` 3: any segment with 3-D points; plane segments then lie
    in the XY plane) the curvature jump is that of κB = T × κN, the
    curvature vector turned a quarter turn about the tangent: in the plane it
    is exactly |Δκ| (κ signed), in space it equals |Δ(κN)| up to κ × the
    tangent angle, so a joint where the osculating plane turns at non-zero
    curvature is refused.

    The segments are stored as arrays (``spiral_cad.core.rows``) and every
    joint is checked in one compiled pass; segment objects are made when
    indexed or iterated.

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
        items = _segment_tuple(segments)
        rows = SegmentRows.of_segments(items)
        keep = rows.dim == 2 or all(s._dim == 3 for s in items)  # plane segments of a space chain are made again in 3-D
        self._setup(rows, rows.measure(), list(items) if keep else None, join_tolerance(tolerance), length_unit(units))

    @classmethod
    def _of_rows(
        cls,
        rows: SegmentRows,
        tolerance: float,
        units: str,
        measured: Measured | None = None,
        objects: list[Segment | None] | None = None,
        owners: NDArray[np.int64] | None = None,
    ) -> Chain:
        """A checked chain of ``rows`` (tolerance and units already checked). With ``owners`` (the
        ``Chain.join`` part of every row) a failing joint raises a ``JointError`` naming its part."""
        chain = object.__new__(cls)
        try:
            chain._setup(rows, rows.measure() if measured is None else measured, objects, tolerance, units)
        except JointError as error:
            if owners is None:
                raise
            before, after = int(owners[error.joint]), int(owners[error.joint + 1])
            part = after if after != before else before
            raise JointError(f"{error} (at parts[{part}])", error.joint, part) from None
        return chain

    def _setup(self, rows: SegmentRows, measured: Measured, objects: list[Segment | None] | None, tolerance: float, units: str) -> None:
        self._rows = rows
        self._frames, floors, self._lengths = measured
        self._objects: list[Segment | None] = objects if objects is not None else [None] * len(rows)
        self._segments: tuple[Segment, ...] | None = None
        self.tolerance = tolerance
        self.units = units
        self._stations = np.concatenate([[0.0], np.cumsum(self._lengths)])
        if not math.isfinite(self._stations[-1]):
            raise ValueError(f"Chain length overflows float64 ({len(self)} segments)")
        self.size = _size(rows, self._frames) or 1.0
        if not math.isfinite(self.size):
            raise ValueError("Chain extent overflows float64")
        f, lengths = self._frames, self._lengths
        own = curvature_scales(f)
        self._joints, first = joint_table(f[:-1, 1], floors[:-1, 1], lengths[:-1], f[1:, 0], floors[1:, 0], lengths[1:],
                                          np.maximum(own[:-1], own[1:]), tolerance, ROUNDING_CAP)  # fmt: skip
        if first >= 0:
            raise JointError(f"Chain is not G2 at {_problem(first, self._joints[first], tolerance, units)}", first)

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
        chain is the line from ``start`` to ``end``). Parts and points may
        be in space (3-D): an ``Arc`` in space is continued on its own circle.

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
            raise ValueError(f"parts must be a list of transitions and segments; got {type(parts).__name__} (wrap one part in a list)")
        for i, part in enumerate(parts):
            if not isinstance(part, (Transition, Segment)):
                raise ValueError(f"parts[{i}] must be a Transition or a segment; got {type(part).__name__} {part!r:.80}")
        tolerance = join_tolerance(tolerance)
        first = None if start is None else as_point(start, "start")
        last = None if end is None else as_point(end, "end")
        owned = [p.spirals if isinstance(p, Transition) else [p] for p in parts]
        objects = [s for own in owned for s in own]
        rows = SegmentRows.of_segments(objects)
        counts = np.array([len(own) for own in owned])
        circles = PartCircles.of_parts(parts)
        return join_rows(rows, counts, circles, first, last, tolerance, length_unit(units), objects)

    # ------------------------------------------------------------- access

    @property
    def dim(self) -> int:
        """2 for a plane chain, 3 for a chain in space."""
        return self._rows.dim

    def _object(self, index: int) -> Segment:
        segment = self._objects[index]
        if segment is None:
            segment = self._objects[index] = self._rows.segment(index)
        return segment

    @property
    def segments(self) -> tuple[Segment, ...]:
        if self._segments is None:
            self._segments = tuple(self._object(i) for i in range(len(self)))
        return self._segments

    def __len__(self) -> int:
        return len(self._rows)

    def __iter__(self) -> Iterator[Segment]:
        return iter(self.segments)

    def __getitem__(self, index: int) -> Segment:
        if isinstance(index, slice):
            return self.segments[index]
        return self._object(index)

    def __repr__(self) -> str:
        kinds = " → ".join(_KIND_NAMES[k] for k in self._rows.kind.tolist())
        return f"Chain({len(self)} segments, length {self.length:.6g} {self.units}: {kinds})"

    @property
    def length(self) -> float:
        return float(self._stations[-1])

    @property
    def lengths(self) -> NDArray[np.float64]:
        """Arc length of each segment (n,)."""
        return self._lengths.copy()

    @property
    def rows(self) -> SegmentRows:
        """The segments as arrays (``spiral_cad.core.rows.SegmentRows``; read-only views)."""
        rows = self._rows
        views = SegmentRows(rows.kind.view(), rows.geometry.view(), rows.params.view(), rows.shapes.view(), rows.dim, self._lengths.view())
        for view in (views.kind, views.geometry, views.params, views.shapes, views.lengths):
            view.flags.writeable = False
        return views

    @property
    def stations(self) -> NDArray[np.float64]:
        """Arc length at the start of each segment, plus the total (len + 1)."""
        return self._stations.copy()

    @property
    def start(self) -> NDArray[np.float64]:
        point: NDArray[np.float64] = self._frames[0, 0, : self.dim].copy()
        return point

    @property
    def end(self) -> NDArray[np.float64]:
        point: NDArray[np.float64] = self._frames[-1, 1, : self.dim].copy()
        return point

    @property
    def segment_ends(self) -> NDArray[np.float64]:
        """The start and end point of every segment, (n, 2, dim) (a copy)."""
        points: NDArray[np.float64] = self._frames[:, :, : self.dim].copy()
        return points

    def joins(self) -> list[Join]:
        """Mismatches at every internal joint, in order (``Join``)."""
        return [Join(i, gap, angle, jump) for i, (gap, angle, jump) in enumerate(self._joints[:, :3].tolist())]

    def reversed(self) -> Chain:
        return Chain._of_rows(self._rows.reversed(), self.tolerance, self.units)

    def placed(self, frame: PlaneFrame) -> Chain:
        """This plane chain in space: (x, y) ↦ ``frame.point((x, y))`` (``spiral_cad.core.space.PlaneFrame``).

        Raises:
            ValueError: the chain is already in space, or ``frame`` is not a ``PlaneFrame``.
        """
        if not isinstance(frame, PlaneFrame):
            raise ValueError(f"frame must be a PlaneFrame; got {type(frame).__name__}")
        if self.dim != 2:
            raise ValueError("placed takes a plane chain; this chain is already in space")
        return Chain._of_rows(self._rows.placed(frame.origin, frame.x_dir, frame.y_dir), self.tolerance, self.units)

    # --------------------------------------------------- station queries

    def _locate(self, s: ArrayLike) -> tuple[NDArray[np.intp], NDArray[np.float64]]:
        s = as_real_array(s, "stations")
        if not np.all((s >= -1e-12 * self.length) & (s <= self.length * (1 + 1e-12))):
            bad = s[~((s >= -1e-12 * self.length) & (s <= self.length * (1 + 1e-12)))].ravel()[0]
            raise ValueError(f"stations must lie in [0, {self.length}]; got {bad}")
        index = np.clip(np.searchsorted(self._stations, s, side="right") - 1, 0, len(self) - 1)
        return index, s - self._stations[index]

    def _at(self, s: ArrayLike, method: str, width: tuple[int, ...]) -> NDArray[np.float64]:
        index, local = self._locate(s)
        flat_index, flat_local = index.ravel(), local.ravel()
        out = np.empty(flat_index.shape + width)
        # Group the samples by segment in one sort (linear in the samples, not
        # samples × segments).
        order = np.argsort(flat_index, kind="stable")
        bounds = np.flatnonzero(np.diff(flat_index[order])) + 1
        for group in np.split(order, bounds):
            if len(group):
                seg = self._object(int(flat_index[group[0]]))
                out[group] = getattr(seg, method)(seg.parameter_at(flat_local[group]))
        return out.reshape(index.shape + width)

    def point_at(self, s: ArrayLike) -> NDArray[np.float64]:
        """Points at stations ``s`` (arc length from the start), shape ``s.shape + (dim,)``."""
        return self._at(s, "point", (self.dim,))

    def tangent_at(self, s: ArrayLike) -> NDArray[np.float64]:
        """Unit tangents at stations ``s``."""
        return self._at(s, "tangent", (self.dim,))

    def curvature_at(self, s: ArrayLike) -> NDArray[np.float64]:
        """Curvature at stations ``s``: signed in the plane, κ ≥ 0 in space."""
        return self._at(s, "curvature", ())

    def curvature_vector_at(self, s: ArrayLike) -> NDArray[np.float64]:
        """Curvature vectors κN at stations ``s``, shape ``s.shape + (dim,)``."""
        return self._at(s, "curvature_vector", (self.dim,))

    def sample(self, per_segment: int = 32) -> NDArray[np.float64]:
        """Points along the chain, ``per_segment`` per segment plus the end (for plots)."""
        u = np.linspace(0.0, 1.0, per_segment, endpoint=False)
        pts = [seg.point(u) for seg in self.segments]
        return np.vstack(pts + [self.end[None]])

    def to_nurbs(self) -> Any:
        """The whole chain as one exact rational cubic B-spline (``spiral_cad.core.nurbs.Nurbs``).

        Raises:
            ValueError: a chain in space (``Nurbs`` is planar).
        """
        if self.dim != 2:
            raise ValueError(
                "to_nurbs takes a plane chain; this chain is in space (use spiral_cad.build123d.chain_edges/chain_to_wire for exact 3-D edges)"
            )
        from .nurbs import chain_to_nurbs

        return chain_to_nurbs(self.segments)


def _size(rows: SegmentRows, frames: NDArray[np.float64]) -> float:
    """The diagonal of the box around every segment's outline (``Segment.outline``), in one pass."""
    kind, g, p = rows.kind, rows.geometry, rows.params
    arc = kind == ARC
    r, a0, sweep = p[arc].T
    middle = a0 + np.copysign(sweep, r) * 0.5
    e = g[arc]
    mid = e[:, 0] + np.abs(r)[:, None] * (np.cos(middle)[:, None] * e[:, 1] + np.sin(middle)[:, None] * e[:, 2])
    groups = [g[kind == SPIRAL], g[kind == LINE, :2], frames[arc, :, :3], mid]
    extent = []
    for j in range(rows.dim):  # one coordinate at a time: contiguous reductions
        column = np.concatenate([x[..., j].ravel() for x in groups])
        extent.append(float(column.max() - column.min()))
    return math.hypot(*extent)


# ---------------------------------------------------------------- joining


class PartCircles:
    """The circle each ``Chain.join`` part ends on (where the connector after it is an arc).

    Attributes:
        present: (P,) bool.
        center: (P, 3) centres; radius: (P,) signed (travel sense); basis: (P, 2, 3) the plane basis.
    """

    def __init__(self, count: int):
        self.present = np.zeros(count, dtype=bool)
        self.center = np.zeros((count, 3))
        self.radius = np.zeros(count)
        self.basis = np.zeros((count, 2, 3))
        self.basis[:, 0, 0] = self.basis[:, 1, 1] = 1.0

    @classmethod
    def of_parts(cls, parts: Sequence[Transition | Segment]) -> PartCircles:
        """A transition's ``end_circle``; an ``Arc``'s own circle (in its plane); none after other segments."""
        circles = cls(len(parts))
        found: list[tuple[int, tuple[float, ...], float, NDArray[np.float64]]] = []
        for k, part in enumerate(parts):
            circle = part.end_circle if isinstance(part, Transition) else None
            if circle is not None:
                found.append((k, circle.center + (0.0,), circle.radius, _XY_BASIS))
            elif isinstance(part, Arc):
                found.append((k, tuple(lifted(tuple(part._c.tolist()), 3)), part._r, part.basis))
        if found:
            slots, centers, radii, bases = zip(*found)
            index = list(slots)
            circles.present[index] = True
            circles.center[index], circles.radius[index], circles.basis[index] = centers, radii, bases
        return circles


def join_rows(
    rows: SegmentRows,
    counts: NDArray[np.int64],
    circles: PartCircles,
    start: tuple[float, ...] | None,
    end: tuple[float, ...] | None,
    tolerance: float,
    units: str,
    objects: Sequence[Segment] | None = None,
) -> Chain:
    """``Chain.join`` on arrays: parts of ``counts`` consecutive ``rows`` each, ending on ``circles``.

    The connectors (lines and arcs, ``_chain_kernels.connectors``) are made
    for every gap at once and the chain is checked in one pass; ``objects``
    (the segment objects of ``rows``, if any) are kept as the chain's segments.
    The design tools build their chains this way, e.g. a rounded polyline
    (in the plane, or in space after ``space.place``)::

        rows = SegmentRows.spirals(pairs.reshape(-1, 4, d), shape)   # (N, 2, 4, d) corner pairs
        join_rows(rows, np.full(N, 2), PartCircles(N), start, end, tolerance, units)

    Args:
        rows: every part's segments in travel order.
        counts: (P,) how many rows each part has (P ≥ 1; none: the line ``start`` → ``end``).
        circles: the circle each part ends on (``PartCircles``).
        start, end: points (2 or 3 coordinates) for a leading / trailing line, or None.
        tolerance, units: checked values (``join_tolerance``, ``length_unit``).

    Raises:
        ValueError: as ``Chain.join``.
    """
    if not len(counts):
        if start is None or end is None:
            raise ValueError("Chain.join needs parts, or both start and end for a straight chain")
        return Chain([Line(start, end)], tolerance, units)
    dim = max(rows.dim, len(start or ()), len(end or ()))
    rows = SegmentRows(rows.kind, rows.geometry, rows.params, rows.shapes, dim, rows.lengths)
    frames, floors, lengths = rows.measure()
    for segment, length in zip(objects or (), lengths.tolist()):
        if isinstance(segment, BezierSpiral) and segment._length is None:
            segment._length = length  # the objects share the chain's measure
    count, head, tail = len(counts), start is not None, end is not None
    last_row = np.cumsum(counts) - 1
    first_row = last_row - counts + 1
    part_length = np.add.reduceat(lengths, first_row)
    begins, ends = frames[first_row, 0], frames[last_row, 1]
    # The gaps in travel order: [start →] part 0 → part 1 … → part P-1 [→ end].
    gaps = head + count - 1 + tail
    inner = slice(int(head), int(head) + count - 1)
    a, b, scale, owner = np.zeros((gaps, 3)), np.zeros((gaps, 3)), np.zeros(gaps), np.zeros(gaps, dtype=np.int64)
    a[inner], b[inner], owner[inner] = ends[:-1, :3], begins[1:, :3], np.arange(count - 1)
    scale[inner] = np.maximum(part_length[:-1], part_length[1:])
    if start is not None:  # head
        a[0], b[0], scale[0] = lifted(start, 3), begins[0, :3], part_length[0]
    if end is not None:  # tail
        a[-1], b[-1], scale[-1], owner[-1] = ends[-1, :3], lifted(end, 3), part_length[-1], count - 1
    present, center, radius, basis = np.zeros(gaps, dtype=bool), np.zeros((gaps, 3)), np.zeros(gaps), np.zeros((gaps, 2, 3))
    present[inner], center[inner], radius[inner], basis[inner] = (
        x[:-1] for x in (circles.present, circles.center, circles.radius, circles.basis)
    )
    bridge = SegmentRows.empty(gaps, dim)
    kind = np.empty(gaps, dtype=np.int8)
    CK.connectors(a, b, scale, present, center, radius, basis, dim == 2, tolerance, kind, bridge.geometry, bridge.params)
    bridge.kind[:] = np.maximum(kind, 0)
    bridge_frames, bridge_floors, bridge_lengths = bridge.measure()
    _check_connectors(bridge, kind, bridge_lengths, a, b, dim, head, tail, begins, ends, count)
    # Interleave by sort keys: part k's rows at 2k + 1, the gap in front of part k at 2k, the end gap at 2P.
    part_of_row = np.repeat(np.arange(count), counts)
    gap_before = np.arange(count) - 1 + head  # -1: part 0 without a start line
    fronted = np.flatnonzero(gap_before >= 0)
    gap_slots = np.concatenate([gap_before[fronted], [gaps - 1] if tail else []]).astype(np.int64)
    keys = np.concatenate([2 * part_of_row + 1, 2 * fronted, [2 * count] if tail else []])
    pool = np.concatenate([np.arange(len(rows)), len(rows) + gap_slots])
    owners = np.concatenate([part_of_row, owner[gap_slots]])
    made = np.concatenate([np.ones(len(rows), dtype=bool), kind[gap_slots] >= 0])
    order = np.argsort(keys, kind="stable")
    order = order[made[order]]
    index = pool[order].astype(np.int64)
    every = SegmentRows.concatenate([rows, bridge])
    measured = cast(
        "Measured", tuple(np.concatenate(x)[index] for x in ((frames, bridge_frames), (floors, bridge_floors), (lengths, bridge_lengths)))
    )
    chain_objects = None
    if objects is not None and all(s.dim == dim for s in objects):
        pool_objects: list[Segment | None] = [*objects, *([None] * gaps)]
        chain_objects = [pool_objects[i] for i in index.tolist()]
    return Chain._of_rows(every.take(index), tolerance, units, measured, chain_objects, owners[order])


def _check_connectors(
    bridge: SegmentRows,
    kind: NDArray[np.int8],
    lengths: NDArray[np.float64],
    a: NDArray[np.float64],
    b: NDArray[np.float64],
    dim: int,
    head: bool,
    tail: bool,
    begins: NDArray[np.float64],
    ends: NDArray[np.float64],
    count: int,
) -> None:
    """Raise, in travel order, what ``Line``/``Arc.between`` and the fold checks would raise for the connectors."""
    r, sweep = bridge.params[:, 0], bridge.params[:, 2]
    resolution = 4.0 * np.finfo(float).eps * np.abs(bridge.geometry[:, 0]).max(axis=1)
    with np.errstate(invalid="ignore"):
        bad = ~(np.isfinite(lengths) & (lengths > 0.0))
        bad |= (kind == ARC) & ~((sweep > 0.0) & (sweep <= 2.0 * math.pi) & (np.abs(r) > resolution))
    made = kind >= 0
    suspects = np.flatnonzero(made & bad).tolist()
    if head and made[0]:
        suspects.append(0)
    if tail and made[-1]:
        suspects.append(len(kind) - 1)
    for i in sorted(set(suspects)):
        if bad[i]:  # make the object, to raise its own error
            if kind[i] == LINE:
                Line(tuple(a[i, :dim].tolist()), tuple(b[i, :dim].tolist()))
            elif dim == 2:
                Arc.between(bridge.geometry[i, 0, :2], bridge.params[i, 0], a[i, :2], b[i, :2])
            else:
                radius, start_angle, sweep_i = bridge.params[i].tolist()
                Arc._of(bridge.geometry[i, 0], radius, start_angle, sweep_i, bridge.geometry[i, 1:3])._check()
        if head and i == 0:
            _fold(a[0], begins[0], dim, "start", count)
        if tail and i == len(kind) - 1:
            _fold(b[i], ends[-1], dim, "end", count)


def _fold(point: NDArray[np.float64], frame: NDArray[np.float64], dim: int, which: str, count: int) -> None:
    """A start line must not run against the first part's start tangent (an end line: its end tangent)."""
    if which == "start":
        if float(np.dot(frame[:3] - point, frame[3:6])) < 0.0:
            raise ValueError(
                f"start {tuple(point[:dim].tolist())} lies ahead of where parts[0] begins, "
                f"{tuple(frame[:dim].tolist())}: the line from it would run backwards"
            )
    elif float(np.dot(point - frame[:3], frame[3:6])) < 0.0:
        raise ValueError(
            f"end {tuple(point[:dim].tolist())} lies behind where parts[{count - 1}] ends, "
            f"{tuple(frame[:dim].tolist())}: the line to it would run backwards"
        )
