"""Joint measures and their G0/G1/G2 classification, shared by every checker.

The STEP/IGES checker (``spiral_cad.continuity``, through OCCT) and the
OpenDRIVE checker (``spiral_cad.formats.opendrive``) both reduce a file to
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

Classification:

* ``G0``: gap ≤ ``gap_tol`` — an **absolute** length in model units, plus
  what float64 rounding can hide at that coordinate (16 ulp of its largest
  coordinate), so survey coordinates are not failed on their last bit.
* ``G1``: G0 and angle ≤ ``angle_tol`` (absolute, radians).
* ``G2``: G1 and curvature jump ≤ ``curvature_tol · scale`` — **relative**
  with ``scale = max(|K_a|, |K_b|, 1/size)``, ``size`` being the diagonal of
  the bounding box of the checked elements' start, middle and end points.
  The floor ``1/size`` keeps joints between straight and almost-straight
  pieces from failing on rounding noise.
* otherwise ``none`` (disconnected).
"""

from __future__ import annotations

import argparse
import math
from collections.abc import Sequence
from dataclasses import dataclass
from enum import IntEnum

import numpy as np

__all__ = ["Continuity", "ContinuityReport", "Frame", "JointReport", "WireReport", "classify_pieces", "print_report"]

#: A gap of this many ulp of the joint's largest coordinate is float64 rounding, not a gap.
ROUNDING_ULPS = 16


class Continuity(IntEnum):
    """Geometric continuity level of a joint; compares as none < G0 < G1 < G2."""

    NONE = 0
    G0 = 1
    G1 = 2
    G2 = 3

    def __str__(self) -> str:
        return "none" if self is Continuity.NONE else self.name

    @classmethod
    def parse(cls, value: str | int | Continuity) -> Continuity:
        """The level named ``"none"``, ``"G0"``, ``"G1"`` or ``"G2"`` (case-insensitive), or an int 0–3."""
        if isinstance(value, str):
            key = value.strip().upper()
            if key in ("NONE", "G0", "G1", "G2"):
                return cls[key]
            raise ValueError(f"continuity level must be one of none, G0, G1, G2; got {value!r}")
        try:
            return cls(value)
        except ValueError:
            raise ValueError(f"continuity level must be one of none, G0, G1, G2 (0–3); got {value!r}") from None


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
    """

    index: int
    gap: float
    angle: float
    curvature_jump: float
    level: Continuity
    curvature_before: float = 0.0
    curvature_after: float = 0.0
    relative_curvature_jump: float = 0.0


@dataclass(frozen=True)
class WireReport:
    """The joints of one wire (or one chain of loose edges) in travel order.

    Attributes:
        index: position in the report.
        edge_count: non-degenerate edges in the piece.
        closed: the last edge ends where the first starts (shared vertex or
            within ``gap_tol``); the closing joint is then reported last.
        joints: one report per joint.
        kind: ``"wire"``, ``"loose piece"`` (edges that belong to no wire,
            chained by nearest ends) or ``"road"`` (an OpenDRIVE planView).
    """

    index: int
    edge_count: int
    closed: bool
    joints: tuple[JointReport, ...]
    kind: str = "wire"

    @property
    def loose(self) -> bool:
        return self.kind == "loose piece"

    @property
    def min_level(self) -> Continuity:
        """Worst joint level (G2 when there is no joint)."""
        return min((j.level for j in self.joints), default=Continuity.G2)


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
    """

    wires: tuple[WireReport, ...]
    gap_tol: float
    angle_tol: float
    curvature_tol: float
    size: float
    snap: float = 0.0
    source: str = ""
    element: str = "edge"

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
        """What was found, e.g. ``"1 wire of 13 edges"`` or ``"1 wire of 5 edges and 2 loose pieces (3, 1 edges)"``."""
        parts = []
        for kind in dict.fromkeys(w.kind for w in self.wires):
            counts = [w.edge_count for w in self.wires if w.kind == kind]
            if len(counts) == 1:
                parts.append(f"1 {kind} of {_count(counts[0], self.element)}")
            else:
                parts.append(f"{len(counts)} {kind}s ({', '.join(map(str, counts))} {_plural(self.element)})")
        return " and ".join(parts) or f"no {_plural(self.element)}"

    def format_table(self) -> str:
        """Readable text: what was found, then a heading per piece and one line per joint."""
        snap = f"; loose ends snapped within {self.snap:.3g}" if self.snap else ""
        out = [
            f"{self.source or 'shape'}: {self.describe()}; worst joint {self.min_level}",
            f"  tolerances: gap {self.gap_tol:g} (model units), angle {self.angle_tol:g} rad, "
            f"curvature jump {self.curvature_tol:g} relative{snap}; model size {self.size:.6g}",
        ]
        head = f"  {'joint':>5} {'gap':>10} {'angle rad':>10} {'κ before':>11} {'κ after':>11} {'|Δκ|':>10} {'Δκ rel':>9} level"
        for w in self.wires:
            out.append(
                f"{w.kind} {w.index}: {_count(w.edge_count, self.element)}, {'closed' if w.closed else 'open'}, "
                f"{len(w.joints)} joint(s), worst {w.min_level}"
            )
            if w.joints:
                out.append(head)
            for j in w.joints:
                out.append(
                    f"  {j.index:5d} {j.gap:10.3e} {j.angle:10.3e} {j.curvature_before:11.5g} {j.curvature_after:11.5g} "
                    f"{j.curvature_jump:10.3e} {j.relative_curvature_jump:9.2e} {j.level}"
                )
        return "\n".join(out)


def _plural(noun: str) -> str:
    return noun[:-1] + "ies" if noun.endswith("y") else noun + "s"


def _count(count: int, noun: str) -> str:
    return f"{count} {noun if count == 1 else _plural(noun)}"


#: An end frame as 9 plain floats (cheaper than numpy for 3-vectors): point,
#: unit tangent (travel sense) and curvature vector.
Frame = tuple[float, float, float, float, float, float, float, float, float]



def flip(f: Frame) -> Frame:
    """The frame seen travelling the other way: the tangent flips, the curvature vector does not."""
    return (f[0], f[1], f[2], -f[3], -f[4], -f[5], f[6], f[7], f[8])


def distance(a: Frame, b: Frame) -> float:
    return math.sqrt((a[0] - b[0]) ** 2 + (a[1] - b[1]) ** 2 + (a[2] - b[2]) ** 2)


def classify_joint(index: int, a: Frame, b: Frame, gap_tol: float, angle_tol: float, curvature_tol: float, floor: float) -> JointReport:
    """Measure and classify the joint from end frame ``a`` to start frame ``b``."""
    gap = distance(a, b)
    gap_tol += ROUNDING_ULPS * math.ulp(max(abs(v) for v in a[:3]))
    cx, cy, cz = a[4] * b[5] - a[5] * b[4], a[5] * b[3] - a[3] * b[5], a[3] * b[4] - a[4] * b[3]
    angle = math.atan2(math.sqrt(cx * cx + cy * cy + cz * cz), a[3] * b[3] + a[4] * b[4] + a[5] * b[5])
    ka = math.sqrt(a[6] * a[6] + a[7] * a[7] + a[8] * a[8])
    kb = math.sqrt(b[6] * b[6] + b[7] * b[7] + b[8] * b[8])
    jump = math.sqrt((a[6] - b[6]) ** 2 + (a[7] - b[7]) ** 2 + (a[8] - b[8]) ** 2)
    relative = jump / max(ka, kb, floor)
    if gap > gap_tol:
        level = Continuity.NONE
    elif angle > angle_tol:
        level = Continuity.G0
    elif relative > curvature_tol:
        level = Continuity.G1
    else:
        level = Continuity.G2
    return JointReport(index, gap, angle, jump, level, ka, kb, relative)


def diagonal(points: Sequence[tuple[float, float, float]]) -> float:
    if not points:
        return 0.0
    xyz = np.array(points)
    return float(np.linalg.norm(xyz.max(axis=0) - xyz.min(axis=0)))


def classify_pieces(
    pieces: Sequence[tuple[str, Sequence[tuple[Frame, Frame]], bool]],
    points: Sequence[tuple[float, float, float]],
    *,
    gap_tol: float,
    angle_tol: float,
    curvature_tol: float,
    snap: float = 0.0,
    source: str = "",
    element: str = "edge",
) -> ContinuityReport:
    """Classify every joint of ``pieces`` — (kind, element end frames in travel order, closed) —
    with ``size`` taken from ``points`` (the elements' start, middle and end points)."""
    size = diagonal(points)
    floor = 1.0 / size if size > 0.0 else 0.0
    wires = []
    for w, (kind, ends, closed) in enumerate(pieces):
        pairs = len(ends) if closed else len(ends) - 1
        joints = tuple(
            classify_joint(i, ends[i][1], ends[(i + 1) % len(ends)][0], gap_tol, angle_tol, curvature_tol, floor)
            for i in range(pairs)
        )
        wires.append(WireReport(w, len(ends), closed, joints, kind))
    return ContinuityReport(tuple(wires), gap_tol, angle_tol, curvature_tol, size, snap, source, element)


def check_tolerances(**tolerances: float) -> None:
    """Each tolerance must be a finite number ≥ 0, else ValueError naming it."""
    for name, value in tolerances.items():
        if not (isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value) and value >= 0.0):
            raise ValueError(f"{name} must be finite and ≥ 0; got {value!r}")


def print_report(report: ContinuityReport, args: argparse.Namespace) -> int:
    """Print ``report`` for ``spiral-cad check``; exit status 0 ok, 1 below ``--require`` or not ``--pieces`` pieces."""
    print(report.format_table())
    if not args.require:
        return 0
    expected = 1 if args.pieces is None else args.pieces
    if report.pieces != expected:
        hint = "" if args.pieces is not None else " (pass --pieces N if the file holds N separate paths)"
        print(f"FAIL: {report.describe()}: {report.pieces} separate pieces, expected {expected}{hint}")
        return 1
    if not report.passes(args.require, expected):
        print(f"FAIL: worst joint is {report.min_level}, below the required {args.require}")
        return 1
    print(f"OK: {report.describe()}, every joint at least {args.require}")
    return 0
