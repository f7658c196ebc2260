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
  unit the file was read in; STEP and IGES files are read in millimetres).
* ``G1``: G0 and angle ≤ ``angle_tol`` (absolute, radians).
* ``G2``: G1 and curvature jump ≤ ``curvature_tol · scale`` — **relative**
  with ``scale = max(|K_a|, |K_b|, 1/size)``, ``size`` being the diagonal of
  the bounding box of the checked edges' start, middle and end points. The
  floor ``1/size`` keeps joints between straight and almost-straight pieces
  from failing on rounding noise.
* otherwise ``none`` (disconnected).
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
from OCP.BRep import BRep_Tool
from OCP.BRepAdaptor import BRepAdaptor_Curve
from OCP.BRepLProp import BRepLProp_CLProps
from OCP.BRepTools import BRepTools_WireExplorer
from OCP.gp import gp_Dir, gp_Pnt, gp_Vec, gp_XYZ
from OCP.ShapeAnalysis import ShapeAnalysis_WireOrder
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

from .occ import as_occ_shape

__all__ = ["Continuity", "ContinuityReport", "JointReport", "WireReport", "check_continuity"]

#: Loose edges whose ends lie closer than this fraction of the model size are
#: chained into one group (and their gap is then judged against ``gap_tol``).
LINK_FRACTION = 1e-3



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
        edge_count: non-degenerate edges in the group.
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
    """Joint continuity of every wire of a shape.

    Attributes:
        wires: one report per wire / loose-edge chain.
        gap_tol, angle_tol, curvature_tol: the tolerances used.
        size: the model size behind the relative curvature floor.
        source: file name or shape description, for the table heading.
    """

    wires: tuple[WireReport, ...]
    gap_tol: float
    angle_tol: float
    curvature_tol: float
    size: float
    source: str = ""

    @property
    def joints(self) -> list[JointReport]:
        """All joints of all wires."""
        return [j for w in self.wires for j in w.joints]

    @property
    def min_level(self) -> Continuity:
        """Worst joint level over all wires (G2 when there is no joint)."""
        return min((w.min_level for w in self.wires), default=Continuity.G2)

    def passes(self, required: str | int | Continuity) -> bool:
        """True when every joint reaches ``required`` (e.g. ``"G2"``)."""
        return self.min_level >= Continuity.parse(required)

    def format_table(self) -> str:
        """Readable text: a heading per wire and one line per joint."""
        out = [
            f"{self.source or 'shape'}: {len(self.wires)} wire(s), worst joint {self.min_level}  "
            f"(gap_tol {self.gap_tol:g} abs, angle_tol {self.angle_tol:g} rad, "
            f"curvature_tol {self.curvature_tol:g} rel, size {self.size:.6g})"
        ]
        head = f"  {'joint':>5} {'gap':>10} {'angle rad':>10} {'κ before':>11} {'κ after':>11} {'|Δκ|':>10} {'Δκ rel':>9} level"
        for w in self.wires:
            kind = "loose-edge chain" if w.loose else "wire"
            out.append(
                f"{kind} {w.index}: {w.edge_count} edge(s), {'closed' if w.closed else 'open'}, "
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


def _chain_loose(ends: list[tuple[Frame, Frame]], link_tol: float, gap_tol: float) -> list[_Group]:
    """Order loose edges into chains (ShapeAnalysis_WireOrder), splitting where ends are > ``link_tol`` apart."""
    order = ShapeAnalysis_WireOrder(True, link_tol)
    for start, end in ends:
        order.Add(gp_XYZ(*start[:3]), gp_XYZ(*end[:3]))
    order.Perform()
    if not order.IsDone():
        sequence = list(range(1, len(ends) + 1))
    else:
        sequence = [order.Ordered(k) for k in range(1, len(ends) + 1)]
    oriented = [ends[n - 1] if n > 0 else (_flip(ends[-n - 1][1]), _flip(ends[-n - 1][0])) for n in sequence]
    groups: list[_Group] = []
    current: list[tuple[Frame, Frame]] = []
    for item in oriented:
        if current and _distance(current[-1][1], item[0]) > link_tol:
            groups.append(_Group(current, False, True))
            current = []
        current.append(item)
    if current:
        groups.append(_Group(current, False, True))
    for g in groups:
        g.closed = _distance(g.ends[-1][1], g.ends[0][0]) <= gap_tol
    return groups


def _distance(a: Frame, b: Frame) -> float:
    return math.sqrt((a[0] - b[0]) ** 2 + (a[1] - b[1]) ** 2 + (a[2] - b[2]) ** 2)


# -------------------------------------------------------- measurement


def _joint(index: int, a: Frame, b: Frame, gap_tol: float, angle_tol: float, curvature_tol: float, floor: float) -> JointReport:
    """Measure and classify the joint from end frame ``a`` to start frame ``b``."""
    gap = math.sqrt((a[0] - b[0]) ** 2 + (a[1] - b[1]) ** 2 + (a[2] - b[2]) ** 2)
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
    link_tol: float | None = None,
) -> ContinuityReport:
    """Measure and classify every joint of every wire of a shape or STEP/IGES file.

    Wires are walked in connection order (``BRepTools_WireExplorer``), with
    the closing joint of closed wires. Edges that belong to no wire are
    ordered into chains (``ShapeAnalysis_WireOrder``): consecutive loose
    edges whose ends are within ``link_tol`` form one chain, so a small gap
    is reported (and fails G0) while separate curves stay separate.
    Degenerated edges (surface poles) are skipped. See the module docstring
    for the measures and the meaning of the tolerances.

    Args:
        shape_or_path: ``TopoDS_Shape``, build123d/CadQuery shape, iterable of
            shapes, or a .step/.stp/.igs/.iges path.
        gap_tol: largest G0 gap, absolute model units.
        angle_tol: largest G1 tangent angle, radians.
        curvature_tol: largest G2 curvature jump relative to
            ``max(|K_a|, |K_b|, 1/size)``.
        link_tol: chaining distance for loose edges (model units); default
            ``LINK_FRACTION · size``.

    Raises:
        ValueError: unreadable input or a negative/non-finite tolerance.
    """
    for name, value in (("gap_tol", gap_tol), ("angle_tol", angle_tol), ("curvature_tol", curvature_tol)):
        if not (math.isfinite(value) and value >= 0.0):
            raise ValueError(f"{name} must be finite and ≥ 0; got {value}")
    source = str(shape_or_path) if isinstance(shape_or_path, (str, os.PathLike)) else type(shape_or_path).__name__
    shape = as_occ_shape(shape_or_path)
    groups, loose_ends, points = _collect(shape)
    size = _diagonal(points)
    floor = 1.0 / size if size > 0.0 else 0.0
    if loose_ends:
        link = LINK_FRACTION * size if link_tol is None else float(link_tol)
        if not (math.isfinite(link) and link >= 0.0):
            raise ValueError(f"link_tol must be finite and ≥ 0; got {link_tol}")
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
    return ContinuityReport(tuple(wires), gap_tol, angle_tol, curvature_tol, size, source)


def _diagonal(points: Sequence[tuple[float, float, float]]) -> float:
    if not points:
        return 0.0
    xyz = np.array(points)
    return float(np.linalg.norm(xyz.max(axis=0) - xyz.min(axis=0)))


# ------------------------------------------------------------------ CLI


def main_check(args: argparse.Namespace) -> int:
    """Run ``spiral-cad check``: print the joint table; exit code 0 ok, 1 below ``--require``, 2 unreadable."""
    try:
        report = check_continuity(
            args.file, gap_tol=args.gap_tol, angle_tol=args.angle_tol, curvature_tol=args.curvature_tol
        )
    except ValueError as exc:
        print(f"spiral-cad check: {exc}", file=sys.stderr)
        return 2
    if not report.wires:
        print(f"spiral-cad check: {args.file!r} contains no edges to check", file=sys.stderr)
        return 2
    print(report.format_table())
    if args.require and not report.passes(args.require):
        print(f"FAIL: worst joint is {report.min_level}, below the required {args.require}")
        return 1
    if args.require:
        print(f"OK: every joint is at least {args.require}")
    return 0
