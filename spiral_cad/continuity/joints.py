"""Joint measures and their G0/G1/G2 classification, shared by every checker.

The STEP/IGES checker (``spiral_cad.cad.continuity``, through OCCT) and the
OpenDRIVE checker (``spiral_cad.io.opendrive``) both reduce a file to
pieces (wires, chains of loose edges, roads) of elements in travel order,
each element given by its two end frames; this module measures and
classifies the joints between them.

Measures at the joint from element *a* (its end) to element *b* (its start):

* **gap** — distance between the two points, in model units.
* **angle** — angle between the unit tangents, in radians.
* **curvature jump** — ``|K_a − K_b|`` with the curvature vector
  ``K = κ·N = ((r' × r'') × r') / |r'|⁴`` (1/model unit). ``K`` is defined
  where κ = 0 (it is the zero vector) and does not depend on the direction
  of travel, so it works for 3-D wires and reversed edges alike.
* **plane change** — the angle between the osculating planes (normal
  T × K) on either side of the joint, in [0, π/2], so a user sees where a
  path in space twists (0 everywhere in the plane). It does not grade the
  joint: a G2 joint may change plane where κ = 0, and only there. Where an
  end is straight (|K| ≤ ``curvature_tol``/size: a line, a spiral's start)
  it has no osculating plane; the edge's other end lends its plane, and a
  straight edge carries the last plane before it, so a twist between two
  curved stretches is reported once, at the joint where the next one
  begins. NaN where no plane is known before the joint (a path that starts
  straight).

Classification:

* ``G0``: gap ≤ ``gap_tol`` — an **absolute** length in model units, plus
  what float64 rounding can hide at that coordinate (16 ulp of its largest
  coordinate), so survey coordinates are not failed on their last bit.
* ``G1``: G0 and angle ≤ ``angle_tol`` (absolute, radians).
* ``G2``: G1 and curvature jump ≤ ``curvature_tol · scale`` — **relative**
  with ``scale = max(|K_a|, |K_b|, 1/size)``, ``size`` being the diagonal of
  the bounding box of the checked elements' start, middle and end points.
  The floor ``1/size`` keeps joints between straight and almost-straight
  pieces from failing on rounding noise. A CAD edge's frames also carry
  what float64 rounding of its curve's stored coordinates can hide in its
  end curvature (``curvature_rounding_floor``: a polynomial curve's
  curvature comes from differences of nearby control points, so at survey
  coordinates, ~3e6 m, a spiral's zero start curvature reads ~1e-13): the
  bound widens by the two ends' floors, capped at ``ROUNDING_CAP`` (1e-6)
  of the joint's own scale max(|K_a|, |K_b|, 1/longer edge) — as a
  ``Chain`` judges its joints — so a real kink is caught at any coordinate.
* otherwise ``none`` (disconnected).
* ``unmeasurable``: the measure that decides is not a finite number (NaN or
  infinite: a tangent or curvature the element does not define, or an
  overflow). Every comparison is written ``not (x <= tol)``, which is true
  for NaN, so a NaN can never pass; this level is below ``none`` and fails
  every requirement.

All lengths are in the model's unit, which the report states. The measures
are computed without squaring coordinates (``math.hypot``), so a model
anywhere within the float range is measured; a model whose points are not
finite, or span more than the float range, is refused (``model_size``).
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Sequence
from dataclasses import dataclass
from enum import IntEnum

import numpy as np
from numpy.typing import NDArray

from ..core.chain import ROUNDING_CAP

__all__ = ["Continuity", "ContinuityReport", "Frame", "JointReport", "Timing", "WireReport", "classify_pieces"]

#: A gap of this many ulp of the joint's largest coordinate is float64 rounding, not a gap.
ROUNDING_ULPS = 16


class Continuity(IntEnum):
    """Geometric continuity level of a joint; compares as unmeasurable < none < G0 < G1 < G2."""

    UNMEASURABLE = -1
    NONE = 0
    G0 = 1
    G1 = 2
    G2 = 3

    def __str__(self) -> str:
        return self.name.lower() if self < Continuity.G0 else self.name

    @classmethod
    def parse(cls, value: str | int | Continuity) -> Continuity:
        """A required level: ``"none"``, ``"G0"``, ``"G1"`` or ``"G2"`` (case-insensitive), or an int 0–3.

        ``unmeasurable`` is a result, never a requirement (it would pass a NaN).
        """
        if isinstance(value, str):
            key = value.strip().upper()
            if key in ("NONE", "G0", "G1", "G2"):
                return cls[key]
            raise ValueError(f"continuity level must be one of none, G0, G1, G2; got {value!r:.40}")
        if isinstance(value, int) and not isinstance(value, bool) and 0 <= value <= 3:
            return cls(value)
        raise ValueError(f"continuity level must be one of none, G0, G1, G2 (0–3); got {value!r:.40}")


@dataclass(frozen=True)
class JointReport:
    """Measurements at the joint from edge ``index`` to edge ``index + 1`` (mod the edge count).

    Attributes:
        index: joint number; the closing joint of a closed wire is the last.
        gap: distance between the two end points (model units).
        angle: angle between the unit tangents (radians).
        curvature_jump: ``|K_a − K_b|`` of the curvature vectors (1/model unit).
        level: the continuity the tolerances grant.
        curvature_before: curvature magnitude at the end of edge ``index``.
        curvature_after: curvature magnitude at the start of the next edge.
        relative_curvature_jump: ``curvature_jump / max(|K_a|, |K_b|, 1/size)``,
            the value compared with ``curvature_tol``.
        plane_change: angle between the osculating planes before and after
            the joint (radians, [0, π/2]; see the module docstring), NaN when
            no plane is known before it.
        point: where the joint is: the end of edge ``index`` (NaN where not known).
    """

    index: int
    gap: float
    angle: float
    curvature_jump: float
    level: Continuity
    curvature_before: float = 0.0
    curvature_after: float = 0.0
    relative_curvature_jump: float = 0.0
    plane_change: float = math.nan
    point: tuple[float, float, float] = (math.nan, math.nan, math.nan)


@dataclass(frozen=True)
class WireReport:
    """The joints of one wire (or one chain of loose edges) in travel order.

    Attributes:
        index: position in the report.
        edge_count: non-degenerate edges in the piece.
        closed: the last edge ends where the first starts (a shared vertex,
            or within ``gap_tol`` going on smoothly) and does not come back
            along it (see ``reverses``); the closing joint is then reported last.
        joints: one report per joint.
        kind: ``"wire"``, ``"loose piece"`` (edges that belong to no wire,
            chained by nearest ends) or ``"road"`` (an OpenDRIVE planView).
        name: what the file calls it, if anything (an OpenDRIVE road's id).
        reverses: its last edge ends where the first starts but arrives going back the way the
            first leaves (a path that returns along its start, as a program often does): it is
            judged as an open path, two ends and no closing joint (``closed`` is then False).
    """

    index: int
    edge_count: int
    closed: bool
    joints: tuple[JointReport, ...]
    kind: str = "wire"
    name: str = ""
    reverses: bool = False

    @property
    def loose(self) -> bool:
        return self.kind == "loose piece"

    @property
    def min_level(self) -> Continuity:
        """Worst joint level (G2 when there is no joint)."""
        return min((j.level for j in self.joints), default=Continuity.G2)


@dataclass(frozen=True)
class Timing:
    """Where a check spent its time, in seconds.

    Attributes:
        reading: the file's reader, with its checks that the file was read whole and the child
            process round trip; 0 for a shape.
        measuring: evaluating every edge's end frames.
        classifying: chaining loose edges and classifying every joint.
        reader: who read the file (``"the STEP reader (OCCT)"``); empty for a shape.
    """

    reading: float
    measuring: float
    classifying: float
    reader: str = ""

    def describe(self, joints: int) -> str:
        """One line: the total, each part, the joints per second of ours, and which part limits the check."""
        ours = self.measuring + self.classifying
        total = self.reading + ours
        rate = f"{joints / ours:,.0f} joints/s" if ours > 0.0 else "no time measured"
        parts = f"measuring {self.measuring:.3g} s and classifying {self.classifying:.3g} s ({rate})"
        if not self.reader:
            return f"time {total:.3g} s: {parts}"
        share = self.reading / total if total > 0.0 else 0.0
        verdict = f"{self.reader} limits this check" if share >= 0.5 else "measuring and classifying limit this check"
        return f"time {total:.3g} s: {self.reader} {self.reading:.3g} s ({share:.0%}), {parts}; {verdict}"


#: How many pieces' sizes a one-line description lists (a program may have 100 000 runs).
_LISTED_COUNTS = 12


@dataclass(frozen=True)
class ContinuityReport:
    """Joint continuity of every piece (wire or chain of loose edges) of a shape.

    Attributes:
        wires: one report per piece.
        gap_tol, angle_tol, curvature_tol: the tolerances used.
        size: the model size behind the relative curvature floor.
        snap: the distance within which loose ends were chained.
        source: file name or shape description, for the table heading.
        element: what a piece is made of (``"edge"``, or ``"geometry"`` for OpenDRIVE).
        units: the unit of every length (a file's own unit; ``""``: not
            known, shown as "model units").
        timing: where the check spent its time (STEP/IGES files and shapes;
            ``timing_line()``), or None.
        notes: what the reader of a drawing, program or LandXML file tells about what was judged
            (moves or entities left out, how a spiral was rebuilt); not part of the table.
    """

    wires: tuple[WireReport, ...]
    gap_tol: float
    angle_tol: float
    curvature_tol: float
    size: float
    snap: float = 0.0
    source: str = ""
    element: str = "edge"
    units: str = ""
    timing: Timing | None = None
    notes: tuple[str, ...] = ()

    @property
    def joints(self) -> list[JointReport]:
        """All joints of all pieces."""
        return [j for w in self.wires for j in w.joints]

    @property
    def pieces(self) -> int:
        """How many separate pieces the shape holds (wires plus chains of loose edges)."""
        return len(self.wires)

    @property
    def min_level(self) -> Continuity:
        """Worst joint level over all pieces (G2 when there is no joint)."""
        return min((w.min_level for w in self.wires), default=Continuity.G2)

    def passes(self, required: str | int | Continuity, pieces: int = 1) -> bool:
        """True when every joint reaches ``required`` (e.g. ``"G2"``) and the
        shape holds exactly ``pieces`` separate pieces (default one path)."""
        return self.pieces == pieces and self.min_level >= Continuity.parse(required)

    def describe(self) -> str:
        """What was found, e.g. ``"1 wire of 13 edges"`` or ``"1 wire of 5 edges and 2 loose pieces (3, 1 edges)"``
        (past 12 pieces, the rest's total: ``"40 wires (1, 1, …, 1, … edges; 28 edges in the other 28)"``)."""
        parts = []
        for kind in dict.fromkeys(w.kind for w in self.wires):
            counts = [w.edge_count for w in self.wires if w.kind == kind]
            if len(counts) == 1:
                parts.append(f"1 {kind} of {_count(counts[0], self.element)}")
            else:
                listed = ", ".join(map(str, counts[:_LISTED_COUNTS]))
                rest = counts[_LISTED_COUNTS:]
                more = f"; {_count(sum(rest), self.element)} in the other {len(rest)}" if rest else ""
                parts.append(f"{len(counts)} {kind}s ({listed}{', …' if rest else ''} {_plural(self.element)}{more})")
        return " and ".join(parts) or f"no {_plural(self.element)}"

    def largest_plane_change(self) -> tuple[float, int, int] | None:
        """(angle in radians, piece, joint) where the path changes plane most, or None without a measured plane change."""
        found = [(j.plane_change, w.index, j.index) for w in self.wires for j in w.joints if j.plane_change == j.plane_change]
        return max(found, default=None)

    def timing_line(self) -> str:
        """Where the check spent its time (``spiral-cad check --timing``): the reader's share, and
        whether the reader or our measuring and classifying limit it; empty without ``timing``."""
        return self.timing.describe(len(self.joints)) if self.timing is not None else ""

    def format_table(self) -> str:
        """Readable text: what was found, then a heading per piece and one line per joint.

        Lengths carry the report's unit (``gap 1e-07 m``, ``model size 2316.7 m``)
        and curvatures its inverse, so the same file always prints the same numbers.
        """
        unit = f" {self.units}" if self.units else " (model units)"
        snap = f"; loose ends snapped within {self.snap:.3g}{unit}" if self.snap else ""
        out = [
            f"{self.source or 'shape'}: {self.describe()}; worst joint {self.min_level}",
            f"  tolerances: gap {self.gap_tol:g}{unit}, angle {self.angle_tol:g} rad, "
            f"curvature jump {self.curvature_tol:g} relative{snap}; model size {self.size:.6g}{unit}",
        ]
        twist = self.largest_plane_change()
        if twist is not None and twist[0] > 0.0:
            out.append(f"  largest plane change {math.degrees(twist[0]):.4g}° at joint {twist[2]} of {self.wires[twist[1]].kind} "
                       f"{twist[1]} (the angle between the osculating planes before and after a joint)")  # fmt: skip
        head = (f"  {'joint':>5} {'gap':>10} {'angle rad':>10} {'κ before':>11} {'κ after':>11} {'|Δκ|':>10} {'Δκ rel':>9} "
                f"{'plane°':>7} level")  # fmt: skip
        for w in self.wires:
            out.append(
                f"{w.kind} {w.index}{f' (id {w.name})' if w.name else ''}: {_count(w.edge_count, self.element)}, "
                f"{'closed' if w.closed else 'open (its ends meet, reversing: no closing joint)' if w.reverses else 'open'}, "
                f"{len(w.joints)} joint(s), worst {w.min_level}"
            )
            if w.joints:
                out.append(head)
            for j in w.joints:
                plane = f"{math.degrees(j.plane_change):7.3f}" if j.plane_change == j.plane_change else f"{'–':>7}"
                out.append(
                    f"  {j.index:5d} {j.gap:10.3e} {j.angle:10.3e} {j.curvature_before:11.5g} {j.curvature_after:11.5g} "
                    f"{j.curvature_jump:10.3e} {j.relative_curvature_jump:9.2e} {plane} {j.level}"
                )
        return "\n".join(out)


def _plural(noun: str) -> str:
    return noun[:-1] + "ies" if noun.endswith("y") else noun + "s"


def _count(count: int, noun: str) -> str:
    return f"{count} {noun if count == 1 else _plural(noun)}"


#: An end frame as plain floats: point, unit tangent (travel sense) and curvature
#: vector; a CAD edge's frame adds what float64 rounding of its curve's stored
#: coordinates can hide in that curvature (1/model unit, ``curvature_rounding_floor``)
#: and the edge's length (model units).
Frame = tuple[float, ...]


def flip(f: Frame) -> Frame:
    """The frame seen travelling the other way: the tangent flips, the curvature vector does not."""
    return (f[0], f[1], f[2], -f[3], -f[4], -f[5], *f[6:])


def distance(a: Frame, b: Frame) -> float:
    """Distance between the points of two frames (no overflow short of the float range)."""
    return math.hypot(a[0] - b[0], a[1] - b[1], a[2] - b[2])


def curvature_rounding_floor(delta: NDArray, leg: NDArray, next_leg: NDArray, curvature: NDArray) -> NDArray:
    """What rounding the coordinates of a polynomial curve's first three control points by
    ``delta`` can change in its end curvature (the same bound as a chain's spirals,
    ``BezierSpiral.rounding_floor``): κ = (2/3) |a × b| / |a|³ with ``leg`` |a| the end leg
    and ``next_leg`` |b| the next one."""
    with np.errstate(all="ignore"):
        return 2.0 / 3.0 * delta * (leg + next_leg) / leg**3 + 3.0 * curvature * delta / leg


def norms(v: NDArray) -> NDArray:
    """Lengths of the rows of an (n, 3) array, without squaring (no overflow short of the float range)."""
    return np.hypot(np.hypot(v[:, 0], v[:, 1]), v[:, 2])


def classify_joints(a: NDArray, b: NDArray, gap_tol: float, angle_tol: float, curvature_tol: float,
                    floor: float) -> tuple[NDArray, ...]:  # fmt: skip
    """Measure and classify the joints from end frames ``a`` to start frames ``b`` (rows of 9
    floats, or 11 with each edge's curvature rounding floor and length).

    Returns the arrays (gap, angle, curvature jump, level, |K_a|, |K_b|, relative jump). Each
    measure is compared as ``not (x <= tol)``: a NaN never passes, and a deciding measure that is
    not finite makes the joint ``unmeasurable``. Where the frames carry rounding floors the
    curvature bound widens by their sum, capped at ``ROUNDING_CAP`` relative to the joint's own
    scale max(|K_a|, |K_b|, 1/longer edge), as ``Chain`` judges its joints.
    """
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    with np.errstate(all="ignore"):
        gap = norms(a[:, :3] - b[:, :3])
        gap_bound = gap_tol + ROUNDING_ULPS * np.spacing(np.abs(a[:, :3]).max(axis=1))
        angle = np.arctan2(norms(np.cross(a[:, 3:6], b[:, 3:6])), np.einsum("ij,ij->i", a[:, 3:6], b[:, 3:6]))
        ka, kb = norms(a[:, 6:9]), norms(b[:, 6:9])
        jump = norms(a[:, 6:9] - b[:, 6:9])
        scale = np.maximum(np.maximum(ka, kb), floor)
        relative = np.where(np.isfinite(ka + kb + jump), jump / scale, np.nan)
        curvature_bound = np.full(len(a), curvature_tol)
        if a.shape[1] > 9 and b.shape[1] > 9:
            cap = ROUNDING_CAP * np.maximum(np.maximum(ka, kb), 1.0 / np.maximum(a[:, 10], b[:, 10]))
            allowance = np.minimum(a[:, 9] + b[:, 9], cap) / scale
            curvature_bound += np.where(np.isfinite(allowance) & (allowance > 0.0), allowance, 0.0)
    level = np.full(len(a), int(Continuity.G2))
    decided = np.zeros(len(a), dtype=bool)
    for value, bound, failed in ((gap, gap_bound, Continuity.NONE), (angle, angle_tol, Continuity.G0),
                                 (relative, curvature_bound, Continuity.G1)):  # fmt: skip
        fails = ~decided & ~(value <= bound)
        level[fails] = np.where(np.isfinite(value[fails]), int(failed), int(Continuity.UNMEASURABLE))
        decided |= fails
    return gap, angle, jump, level, ka, kb, relative


def plane_changes(frames: NDArray, closed: bool, straight: float) -> NDArray:
    """The plane change at each joint of one piece (radians; see the module docstring).

    ``frames`` is (edges, 2, ≥ 9): every edge's start and end frame in travel
    order; an end whose |K| ≤ ``straight`` has no osculating plane. Returns
    one angle per joint (the closing joint last when ``closed``).
    """
    with np.errstate(all="ignore"):
        tangent, k = frames[:, :, 3:6], frames[:, :, 6:9]
        normal = np.cross(tangent, k)
        length = np.sqrt(np.einsum("...i,...i->...", normal, normal))
        curved = (np.sqrt(np.einsum("...i,...i->...", k, k)) > straight) & (length > 0.0)
        normal = np.where(curved[..., None], normal / length[..., None], np.nan)
        # an edge lends the plane of its other end to a straight end
        lent = np.where(curved[..., None], normal, normal[:, ::-1])
        sequence = lent.reshape(-1, 3)  # start, end, start, end, … in travel order
        twice = np.concatenate([sequence, sequence]) if closed else sequence
        known = np.flatnonzero(~np.isnan(twice[:, 0]))
        last = np.full(len(twice), -1)
        last[known] = known
        last = np.maximum.accumulate(last)  # the last plane at or before each position
        carried = np.where((last >= 0)[:, None], twice[np.maximum(last, 0)], np.nan)
        if closed:
            carried = carried[len(sequence) :]
        edges = len(frames)
        joints = edges if closed else edges - 1
        before = carried[1 : 2 * joints : 2]  # the end of edge i, or what it carries
        after = lent[(np.arange(joints) + 1) % edges, 0]  # the start of edge i + 1, from its own plane
        after = np.where(np.isnan(after), before, after)  # a straight edge changes no plane
        cross = np.cross(before, after)
        return np.arctan2(np.sqrt(np.einsum("ij,ij->i", cross, cross)), np.abs(np.einsum("ij,ij->i", before, after)))


def classify_joint(index: int, a: Frame, b: Frame, gap_tol: float, angle_tol: float, curvature_tol: float, floor: float) -> JointReport:
    """Measure and classify the joint from end frame ``a`` to start frame ``b`` (``classify_joints``)."""
    joints = classify_joints(np.array([a]), np.array([b]), gap_tol, angle_tol, curvature_tol, floor)
    return _joint_reports([index], joints, points=np.array([a[:3]], dtype=float))[0]


def _joint_reports(indices: Sequence[int], measures: tuple[NDArray, ...], planes: NDArray | None = None,
                   points: NDArray | None = None) -> list[JointReport]:  # fmt: skip
    gap, angle, jump, level, ka, kb, relative = (m.tolist() for m in measures)
    plane = [math.nan] * len(gap) if planes is None else planes.tolist()
    where = [(math.nan,) * 3] * len(gap) if points is None else [tuple(p) for p in points.tolist()]
    levels = [Continuity(v) for v in range(-1, 4)]
    return [
        JointReport(i, g, an, j, levels[lv + 1], x, y, r, pc, p)
        for i, g, an, j, lv, x, y, r, pc, p in zip(indices, gap, angle, jump, level, ka, kb, relative, plane, where)
    ]


def model_size(points: Sequence[tuple[float, float, float]] | NDArray, source: str = "") -> float:
    """The diagonal of the bounding box of ``points`` (a sequence or (n, 3) array; 0 for none).

    Raises:
        ValueError: a coordinate that is not a finite number, or a box wider
            than the float range — naming the coordinate.
    """
    if len(points) == 0:
        return 0.0
    where = f"{source}: " if source else ""
    with np.errstate(all="ignore"):
        xyz = np.asarray(points, dtype=float).reshape(-1, 3)
        bad = ~np.isfinite(xyz)
        if bad.any():
            row = xyz[np.argmax(bad.any(axis=1))]
            raise ValueError(f"{where}a point of the model is not finite: ({', '.join(repr(float(v)) for v in row)})")
        low, high = xyz.min(axis=0), xyz.max(axis=0)
        size = math.hypot(*(float(h) - float(lo) for lo, h in zip(low, high)))
        axis = int(np.argmax(high - low > 1e307))
    if not math.isfinite(size):
        raise ValueError(
            f"{where}the model spans {'xyz'[axis]} = {float(low[axis])!r} to {float(high[axis])!r}, "
            "wider than a float can measure (±1.8e308)"
        )
    return size


def classify_pieces(
    pieces: Sequence[tuple],
    size: float,
    *,
    gap_tol: float,
    angle_tol: float,
    curvature_tol: float,
    snap: float = 0.0,
    source: str = "",
    element: str = "edge",
    units: str = "",
) -> ContinuityReport:
    """Classify every joint of ``pieces`` — (kind, element end frames in travel order, closed[, name]) —
    in a model of ``size`` (``model_size`` of the elements' start, middle and end points)."""
    floor = 1.0 / size if size > 0.0 else 0.0
    wires = []
    for w, (kind, ends, closed, *name) in enumerate(pieces):
        reverses = bool(closed) and len(ends) > 1 and _reversal(ends[-1][1], ends[0][0], gap_tol, angle_tol)
        closed = closed and not reverses
        pairs = len(ends) if closed else len(ends) - 1
        joints: tuple[JointReport, ...] = ()
        if pairs > 0:
            frames = np.asarray(ends, dtype=float)  # (edges, 2: start and end, frame)
            after = np.roll(frames[:, 0], -1, axis=0)[:pairs]
            measures = classify_joints(frames[:pairs, 1], after, gap_tol, angle_tol, curvature_tol, floor)
            planes = plane_changes(frames, closed, curvature_tol * floor)
            joints = tuple(_joint_reports(range(pairs), measures, planes, points=frames[:pairs, 1, :3]))
        wires.append(WireReport(w, len(ends), closed, joints, kind, name[0] if name else "", reverses=reverses))
    return ContinuityReport(tuple(wires), gap_tol, angle_tol, curvature_tol, size, snap, source, element, units)


def _closing_angle(a: Frame, b: Frame) -> float:
    """The angle between the unit tangents of frames ``a`` and ``b`` (radians, [0, π]; atan2 keeps it exact near π)."""
    ta, tb = np.asarray(a[3:6], dtype=float), np.asarray(b[3:6], dtype=float)
    with np.errstate(all="ignore"):
        return math.atan2(float(np.linalg.norm(np.cross(ta, tb))), float(ta @ tb))


def _reversal(a: Frame, b: Frame, gap_tol: float, angle_tol: float) -> bool:
    """The end frame ``a`` meets the start frame ``b`` (within ``gap_tol``) heading the opposite way (within
    ``angle_tol`` of π): a path that comes back along its start, not a loop through its closing point."""
    return distance(a, b) <= gap_tol and math.pi - _closing_angle(a, b) <= angle_tol


def closes_smoothly(ends: Sequence[tuple[Frame, Frame]] | NDArray, gap_tol: float, angle_tol: float) -> bool:
    """The last element ends where the first starts (within ``gap_tol``) going on the same way (within
    ``angle_tol``): a path whose end points are not one vertex but which is a loop all the same."""
    if not len(ends):
        return False
    a, b = ends[-1][1], ends[0][0]
    return distance(a, b) <= gap_tol and _closing_angle(a, b) <= angle_tol


def check_tolerances(**tolerances: float) -> None:
    """Each tolerance must be a finite number ≥ 0, else ValueError naming it."""
    for name, value in tolerances.items():
        if not (isinstance(value, numbers.Real) and not isinstance(value, (bool, np.bool_)) and math.isfinite(value) and value >= 0.0):
            raise ValueError(f"{name} must be finite and ≥ 0; got {value!r}")
