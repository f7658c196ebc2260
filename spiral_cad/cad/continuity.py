"""G0/G1/G2 continuity at every joint of the wires of a CAD shape or file.

OCCT's own tools do not answer this question: ``GeomLProp``/``BRepLProp``
``Continuity`` never reports G2, and ``LocalAnalysis_CurveContinuity`` fails
where the curvature is zero — exactly at a spiral's start. So the joint
quantities are measured here from first and second derivatives.

Measures at the joint from edge *a* (its end) to edge *b* (its start), both
in travel order (a REVERSED edge runs from its curve's last parameter to its
first):

* **gap** — distance between the two points, in model units.
* **angle** — angle between the unit tangents, in radians.
* **curvature jump** — ``|K_a − K_b|`` with the curvature vector
  ``K = κ·N = ((r' × r'') × r') / |r'|⁴`` (1/model unit). ``K`` is defined
  where κ = 0 (it is the zero vector) and does not depend on the direction
  of travel, so it works for 3-D wires and reversed edges alike.

Classification (tolerances are keyword arguments of :func:`check_continuity`):

* ``G0``: gap ≤ ``gap_tol`` — an **absolute** length in model units (the
  unit the file was read in; STEP and IGES files are read in millimetres),
  plus what float64 rounding can hide at that coordinate (16 ulp of its
  largest coordinate), so survey coordinates are not failed on their last bit.
* ``G1``: G0 and angle ≤ ``angle_tol`` (absolute, radians).
* ``G2``: G1 and curvature jump ≤ ``curvature_tol · scale`` — **relative**
  with ``scale = max(|K_a|, |K_b|, 1/size)``, ``size`` being the diagonal of
  the bounding box of the checked edges' start, middle and end points. The
  floor ``1/size`` keeps joints between straight and almost-straight pieces
  from failing on rounding noise.
* otherwise ``none`` (disconnected).

Pieces: every wire is one piece, judged in wire order (with the closing
joint of a closed wire). Edges that belong to no wire are chained by nearest
ends: ends closer than the **snap distance** (``SNAP_FRACTION`` = 1 % of the
model size, or ``snap`` in model units) are joined, and a joint whose gap
then exceeds ``gap_tol`` is a G0 failure at that joint — so a small gap can
never split a path into two pieces that each look perfect. Ends further
apart start a new piece. A report that finds more pieces than expected
(one, unless told otherwise) does not pass.
"""

from __future__ import annotations

import argparse
import math
import os
import sys
from collections.abc import Sequence
from dataclasses import dataclass
from enum import IntEnum
from typing import Any

import numpy as np
from scipy.spatial import cKDTree
from OCP.BRep import BRep_Tool
from OCP.BRepAdaptor import BRepAdaptor_Curve
from OCP.BRepLProp import BRepLProp_CLProps
from OCP.BRepTools import BRepTools_WireExplorer
from OCP.gp import gp_Dir, gp_Pnt, gp_Vec
from OCP.TopAbs import TopAbs_EDGE, TopAbs_REVERSED, TopAbs_WIRE
from OCP.TopExp import TopExp, TopExp_Explorer
from OCP.TopoDS import (
    TopoDS,
    TopoDS_Edge,
    TopoDS_Iterator,
    TopoDS_Shape,
    TopoDS_Wire,
)
from OCP.TopTools import TopTools_IndexedMapOfShape

from .occ import as_occ_shape, read_shape

__all__ = ["Continuity", "ContinuityReport", "JointReport", "WireReport", "check_continuity"]

#: Loose edges whose ends lie closer than this fraction of the model size are
#: chained into one piece (and their gap is then judged against ``gap_tol``).
SNAP_FRACTION = 1e-2
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
        loose: True for a chain assembled from edges that belong to no wire.
    """

    index: int
    edge_count: int
    closed: bool
    joints: tuple[JointReport, ...]
    loose: bool = False

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
    """

    wires: tuple[WireReport, ...]
    gap_tol: float
    angle_tol: float
    curvature_tol: float
    size: float
    snap: float = 0.0
    source: str = ""

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
        for loose, noun in ((False, "wire"), (True, "loose piece")):
            counts = [w.edge_count for w in self.wires if w.loose == loose]
            if len(counts) == 1:
                parts.append(f"1 {noun} of {_edges(counts[0])}")
            elif counts:
                parts.append(f"{len(counts)} {noun}s ({', '.join(map(str, counts))} edges)")
        return " and ".join(parts) or "no edges"

    def format_table(self) -> str:
        """Readable text: what was found, then a heading per piece and one line per joint."""
        out = [
            f"{self.source or 'shape'}: {self.describe()}; worst joint {self.min_level}",
            f"  tolerances: gap {self.gap_tol:g} (model units), angle {self.angle_tol:g} rad, "
            f"curvature jump {self.curvature_tol:g} relative; loose ends snapped within {self.snap:.3g}; "
            f"model size {self.size:.6g}",
        ]
        head = f"  {'joint':>5} {'gap':>10} {'angle rad':>10} {'κ before':>11} {'κ after':>11} {'|Δκ|':>10} {'Δκ rel':>9} level"
        for w in self.wires:
            kind = "loose piece" if w.loose else "wire"
            out.append(
                f"{kind} {w.index}: {_edges(w.edge_count)}, {'closed' if w.closed else 'open'}, "
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


def _edges(count: int) -> str:
    return f"{count} edge" + ("" if count == 1 else "s")


# --------------------------------------------------------------- input


# ---------------------------------------------------- edge end frames

# An end frame is a 9-tuple of floats: point, unit tangent (travel sense)
# and curvature vector. Plain floats: cheaper than numpy for 3-vectors.
Frame = tuple[float, float, float, float, float, float, float, float, float]


def _frame(curve: BRepAdaptor_Curve, u: float, inward: float) -> Frame:
    """Frame at parameter ``u`` in the curve's parameter direction; ``inward`` (±1) points into the edge."""
    p, d1, d2 = gp_Pnt(), gp_Vec(), gp_Vec()
    curve.D2(u, p, d1, d2)
    ax, ay, az = d1.X(), d1.Y(), d1.Z()
    bx, by, bz = d2.X(), d2.Y(), d2.Z()
    n2 = ax * ax + ay * ay + az * az
    if n2 <= 1e-24 * (bx * bx + by * by + bz * bz) or n2 == 0.0:
        return _singular_frame(curve, u, inward, p)
    cx, cy, cz = ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx
    q = 1.0 / (n2 * n2)
    s = 1.0 / math.sqrt(n2)
    return (
        p.X(), p.Y(), p.Z(),
        ax * s, ay * s, az * s,
        (cy * az - cz * ay) * q, (cz * ax - cx * az) * q, (cx * ay - cy * ax) * q,
    )  # fmt: skip


def _singular_frame(curve: BRepAdaptor_Curve, u: float, inward: float, p: gp_Pnt) -> Frame:
    """Frame where r' = 0 (e.g. a Bézier with coincident end poles).

    The tangent comes from higher derivatives (CLProps); the curvature
    vector, which is unbounded there in general, is taken just inside.
    """
    props = BRepLProp_CLProps(curve, u, 2, 0.0)
    t = gp_Dir(1.0, 0.0, 0.0)
    if props.IsTangentDefined():
        props.Tangent(t)
    if inward:
        nudge = inward * 1e-9 * (curve.LastParameter() - curve.FirstParameter())
        k = _frame(curve, u + nudge, 0.0)[6:]
    else:  # already nudged once: give up on the curvature
        k = (0.0, 0.0, 0.0)
    return (p.X(), p.Y(), p.Z(), t.X(), t.Y(), t.Z(), *k)


def _edge_ends(edge: TopoDS_Edge) -> tuple[Frame, Frame, tuple[float, float, float]]:
    """(start frame, end frame, middle point) of ``edge`` in its travel sense."""
    curve = BRepAdaptor_Curve(edge)
    u0, u1 = curve.FirstParameter(), curve.LastParameter()
    first = _frame(curve, u0, 1.0)
    last = _frame(curve, u1, -1.0)
    mid = curve.Value(0.5 * (u0 + u1))
    middle = (mid.X(), mid.Y(), mid.Z())
    if edge.Orientation() == TopAbs_REVERSED:
        return _flip(last), _flip(first), middle
    return first, last, middle


def _flip(f: Frame) -> Frame:
    """The frame seen travelling the other way: the tangent flips, the curvature vector does not."""
    return (f[0], f[1], f[2], -f[3], -f[4], -f[5], f[6], f[7], f[8])


# ----------------------------------------------------------- grouping


@dataclass
class _Group:
    ends: list[tuple[Frame, Frame]]
    closed: bool
    loose: bool


def _is_degenerated(edge: TopoDS_Edge) -> bool:
    return BRep_Tool.Degenerated_s(edge) or not BRep_Tool.IsGeometric_s(edge)


def _wire_edges(wire: TopoDS_Wire) -> tuple[list[TopoDS_Edge], bool]:
    """Edges of ``wire`` in connection order with composed orientation, and whether it is closed by a vertex.

    ``BRepTools_WireExplorer`` follows shared vertices; a wire whose edges do
    not connect stops it early, and then the stored edge order is used.
    """
    edges = []
    explorer = BRepTools_WireExplorer(wire)
    while explorer.More():
        edges.append(explorer.Current())
        explorer.Next()
    stored = []
    it = TopoDS_Iterator(wire)
    while it.More():
        if it.Value().ShapeType() == TopAbs_EDGE:
            stored.append(TopoDS.Edge_s(it.Value()))
        it.Next()
    if len(edges) < len(stored):
        edges = stored
    edges = [e for e in edges if not _is_degenerated(e)]
    if not edges:
        return edges, False
    v_first = TopExp.FirstVertex_s(edges[0], True)
    v_last = TopExp.LastVertex_s(edges[-1], True)
    return edges, (not v_first.IsNull()) and v_first.IsSame(v_last)


def _collect(shape: TopoDS_Shape) -> tuple[list[_Group], list[tuple[Frame, Frame]], list[tuple[float, float, float]]]:
    """Wire groups (evaluated), evaluated loose edges and all sample points."""
    points: list[tuple[float, float, float]] = []

    def evaluate(edge: TopoDS_Edge) -> tuple[Frame, Frame]:
        start, end, middle = _edge_ends(edge)
        points.extend((start[:3], end[:3], middle))
        return start, end

    groups = []
    wires = TopTools_IndexedMapOfShape()
    TopExp.MapShapes_s(shape, TopAbs_WIRE, wires)
    for i in range(1, wires.Extent() + 1):
        edges, closed = _wire_edges(TopoDS.Wire_s(wires.FindKey(i)))
        if edges:
            groups.append(_Group([evaluate(e) for e in edges], closed, False))
    loose = TopTools_IndexedMapOfShape()
    explorer = TopExp_Explorer(shape, TopAbs_EDGE, TopAbs_WIRE)
    while explorer.More():
        loose.Add(explorer.Current())
        explorer.Next()
    loose_ends = []
    for i in range(1, loose.Extent() + 1):
        edge = TopoDS.Edge_s(loose.FindKey(i))
        if not _is_degenerated(edge):
            loose_ends.append(evaluate(edge))
    return groups, loose_ends, points


def _chain_loose(ends: list[tuple[Frame, Frame]], snap: float, gap_tol: float) -> list[_Group]:
    """Chain loose edges by nearest ends: each piece grows at both ends by the
    unused edge end nearest to it, while that is within ``snap``."""
    points = np.array([f[:3] for pair in ends for f in pair])  # edge k: start 2k, end 2k + 1
    tree = cKDTree(points)
    used = np.zeros(len(ends), dtype=bool)

    def nearest(frame: Frame) -> int | None:
        """Index (2k or 2k + 1) of the nearest end of an unused edge within ``snap``."""
        count = 8
        while True:
            distances, found = tree.query(frame[:3], k=min(count, len(points)), distance_upper_bound=snap)
            for d, i in zip(np.atleast_1d(distances), np.atleast_1d(found)):
                if math.isfinite(d) and not used[i // 2]:
                    return int(i)
            if count >= len(points) or not math.isfinite(np.atleast_1d(distances)[-1]):
                return None
            count *= 4

    groups: list[_Group] = []
    for first in range(len(ends)):
        if used[first]:
            continue
        used[first] = True
        piece = [ends[first]]
        for forward in (True, False):
            while True:
                found = nearest(piece[-1][1] if forward else piece[0][0])
                if found is None:
                    break
                k, at_start = found // 2, found % 2 == 0
                used[k] = True
                start, end = ends[k]
                if forward:  # joined at its start: as it is; at its end: run backwards
                    piece.append((start, end) if at_start else (_flip(end), _flip(start)))
                else:  # joined before the piece: its end meets our start
                    piece.insert(0, (start, end) if not at_start else (_flip(end), _flip(start)))
        closed = len(piece) > 1 and _distance(piece[-1][1], piece[0][0]) <= gap_tol
        groups.append(_Group(piece, closed, True))
    return groups


def _distance(a: Frame, b: Frame) -> float:
    return math.sqrt((a[0] - b[0]) ** 2 + (a[1] - b[1]) ** 2 + (a[2] - b[2]) ** 2)


# -------------------------------------------------------- measurement


def _joint(index: int, a: Frame, b: Frame, gap_tol: float, angle_tol: float, curvature_tol: float, floor: float) -> JointReport:
    """Measure and classify the joint from end frame ``a`` to start frame ``b``."""
    gap = math.sqrt((a[0] - b[0]) ** 2 + (a[1] - b[1]) ** 2 + (a[2] - b[2]) ** 2)
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


def check_continuity(
    shape_or_path: Any,
    *,
    gap_tol: float = 1e-7,
    angle_tol: float = 1e-7,
    curvature_tol: float = 1e-6,
    snap: float | None = None,
    units: str = "mm",
    label: str | None = None,
) -> ContinuityReport:
    """Measure and classify every joint of every piece of a shape or STEP/IGES file.

    Wires are walked in connection order (``BRepTools_WireExplorer``), with
    the closing joint of closed wires. Edges that belong to no wire are
    chained by nearest ends within ``snap`` (see the module docstring), so a
    small gap is reported as a G0 failure rather than splitting the path.
    Degenerated edges (surface poles) are skipped. A file is read whole or
    not at all (``spiral_cad.occ.read_shape``).

    Args:
        shape_or_path: ``TopoDS_Shape``, build123d/CadQuery shape, iterable of
            shapes, or a .step/.stp/.igs/.iges path.
        gap_tol: largest G0 gap, absolute model units.
        angle_tol: largest G1 tangent angle, radians.
        curvature_tol: largest G2 curvature jump relative to
            ``max(|K_a|, |K_b|, 1/size)``.
        snap: chaining distance for loose edges (model units); default
            ``SNAP_FRACTION · size``.
        units: the unit a file is read in (the model units of the report).
        label: name shown in the report (default: the file's name).

    Raises:
        ValueError: an unreadable or incompletely read file (``ReadError``,
            with the reader's reason), or a negative/non-finite tolerance.
    """
    for name, value in (("gap_tol", gap_tol), ("angle_tol", angle_tol), ("curvature_tol", curvature_tol)):
        if not (isinstance(value, (int, float)) and math.isfinite(value) and value >= 0.0):
            raise ValueError(f"{name} must be finite and ≥ 0; got {value!r}")
    if isinstance(shape_or_path, (str, os.PathLike)):
        source = os.path.basename(os.fspath(shape_or_path))
        shape = read_shape(shape_or_path, units)
    else:
        source = type(shape_or_path).__name__
        shape = as_occ_shape(shape_or_path)
    groups, loose_ends, points = _collect(shape)
    size = _diagonal(points)
    floor = 1.0 / size if size > 0.0 else 0.0
    link = SNAP_FRACTION * size if snap is None else snap
    if not (isinstance(link, (int, float)) and math.isfinite(link) and link >= 0.0):
        raise ValueError(f"snap must be finite and ≥ 0; got {snap!r}")
    if loose_ends:
        groups += _chain_loose(loose_ends, link, gap_tol)
    wires = []
    for w, g in enumerate(groups):
        ends = g.ends
        pairs = len(ends) if g.closed else len(ends) - 1
        joints = tuple(
            _joint(i, ends[i][1], ends[(i + 1) % len(ends)][0], gap_tol, angle_tol, curvature_tol, floor)
            for i in range(pairs)
        )
        wires.append(WireReport(w, len(ends), g.closed, joints, g.loose))
    return ContinuityReport(tuple(wires), gap_tol, angle_tol, curvature_tol, size, link, label or source)


def _diagonal(points: Sequence[tuple[float, float, float]]) -> float:
    if not points:
        return 0.0
    xyz = np.array(points)
    return float(np.linalg.norm(xyz.max(axis=0) - xyz.min(axis=0)))


# ------------------------------------------------------------------ CLI


def main_check(args: argparse.Namespace) -> int:
    """Run ``spiral-cad check``: the joint table; exit 0 ok, 1 below ``--require`` or the wrong
    number of pieces, 2 unreadable (``error: …`` with the reader's reason)."""
    try:
        report = check_continuity(
            args.file, gap_tol=args.gap_tol, angle_tol=args.angle_tol, curvature_tol=args.curvature_tol, snap=args.snap
        )
    except ValueError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    if not report.wires:
        print(f"error: {os.path.basename(args.file)!r} contains no edges to check", file=sys.stderr)
        return 2
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
