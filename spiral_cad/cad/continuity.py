"""G0/G1/G2 continuity at every joint of the wires of a CAD shape or file.

OCCT's own tools do not answer this question: ``GeomLProp``/``BRepLProp``
``Continuity`` never reports G2, and ``LocalAnalysis_CurveContinuity`` fails
where the curvature is zero — exactly at a spiral's start. So the joint
quantities are measured here from first and second derivatives.

Measures and classification: ``spiral_cad.formats.joints`` (shared with the
OpenDRIVE checker).

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
from dataclasses import dataclass
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

from ..formats.joints import (
    Continuity,
    ContinuityReport,
    Frame,
    JointReport,
    WireReport,
    check_tolerances,
    classify_pieces,
    diagonal,
    distance,
    flip,
    print_report,
)
from .occ import as_occ_shape, read_shape

__all__ = ["Continuity", "ContinuityReport", "JointReport", "WireReport", "check_continuity", "curvature_comb"]

#: Loose edges whose ends lie closer than this fraction of the model size are
#: chained into one piece (and their gap is then judged against ``gap_tol``).
SNAP_FRACTION = 1e-2



# --------------------------------------------------------------- input


# ---------------------------------------------------- edge end frames

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
        return flip(last), flip(first), middle
    return first, last, middle


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
                    piece.append((start, end) if at_start else (flip(end), flip(start)))
                else:  # joined before the piece: its end meets our start
                    piece.insert(0, (start, end) if not at_start else (flip(end), flip(start)))
        closed = len(piece) > 1 and distance(piece[-1][1], piece[0][0]) <= gap_tol
        groups.append(_Group(piece, closed, True))
    return groups


# -------------------------------------------------------- measurement


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
    check_tolerances(gap_tol=gap_tol, angle_tol=angle_tol, curvature_tol=curvature_tol)
    if isinstance(shape_or_path, (str, os.PathLike)):
        source = os.path.basename(os.fspath(shape_or_path))
        shape = read_shape(shape_or_path, units)
    else:
        source = type(shape_or_path).__name__
        shape = as_occ_shape(shape_or_path)
    groups, loose_ends, points = _collect(shape)
    link = SNAP_FRACTION * diagonal(points) if snap is None else snap
    check_tolerances(snap=link)
    if loose_ends:
        groups += _chain_loose(loose_ends, link, gap_tol)
    pieces = [("loose piece" if g.loose else "wire", g.ends, g.closed) for g in groups]
    return classify_pieces(
        pieces, points, gap_tol=gap_tol, angle_tol=angle_tol, curvature_tol=curvature_tol, snap=link, source=label or source
    )


# ------------------------------------------------------------------ CLI


def main_check(args: argparse.Namespace) -> int:
    """Run ``spiral-cad check``: the joint table; exit 0 ok, 1 below ``--require`` or the wrong
    number of pieces, 2 unreadable (``error: …`` with the reader's reason)."""
    try:
        report = check_continuity(
            args.file, gap_tol=args.gap_tol, angle_tol=args.angle_tol, curvature_tol=args.curvature_tol, snap=args.snap
        )
        if args.comb:
            from ..export import export_step

            export_step(curvature_comb(args.file), args.comb, name=f"{os.path.basename(args.file)} curvature comb")
    except ValueError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    if not report.wires:
        print(f"error: {os.path.basename(args.file)!r} contains no edges to check", file=sys.stderr)
        return 2
    return print_report(report, args)


# ------------------------------------------------------------------ comb


def curvature_comb(shape_or_path: Any, *, scale: float | None = None, per_edge: int = 24, units: str = "mm"):
    """The curvature comb of every edge as OCCT geometry: teeth and the envelope through their tips.

    A tooth runs from a point of the curve against its curvature vector
    (to the convex side), ``scale`` × |κ| long; by default the longest tooth
    is a fifth of the model size. Works for any wire or file the checker
    reads, so a viewer (CQ-editor, FreeCAD) can show the comb beside the part.

    Returns:
        A ``TopoDS_Compound`` of line edges (teeth, then envelopes).
    """
    from OCP.BRep import BRep_Builder
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeEdge
    from OCP.TopoDS import TopoDS_Compound

    shape = read_shape(shape_or_path, units) if isinstance(shape_or_path, (str, os.PathLike)) else as_occ_shape(shape_or_path)
    samples = []
    explorer = TopExp_Explorer(shape, TopAbs_EDGE)
    while explorer.More():
        edge = TopoDS.Edge_s(explorer.Current())
        if not _is_degenerated(edge):
            curve = BRepAdaptor_Curve(edge)
            u0, u1 = curve.FirstParameter(), curve.LastParameter()
            frames = [_frame(curve, u0 + (u1 - u0) * k / (per_edge - 1), 1.0 if k == 0 else -1.0) for k in range(per_edge)]
            samples.append(np.array(frames))
        explorer.Next()
    if not samples:
        raise ValueError("the shape has no edges to comb")
    everything = np.vstack(samples)
    if scale is None:
        size = diagonal([tuple(p) for p in everything[:, :3]])
        peak = float(np.linalg.norm(everything[:, 6:9], axis=1).max())
        scale = 0.2 * size / peak if peak > 0 else 0.0
    builder, compound = BRep_Builder(), TopoDS_Compound()
    builder.MakeCompound(compound)

    def line(a, b) -> None:
        if np.linalg.norm(b - a) > 1e-12:
            builder.Add(compound, BRepBuilderAPI_MakeEdge(gp_Pnt(*a), gp_Pnt(*b)).Edge())

    for frames in samples:
        points, tips = frames[:, :3], frames[:, :3] - scale * frames[:, 6:9]
        for p, q in zip(points, tips):
            line(p, q)
        for p, q in zip(tips, tips[1:]):
            line(p, q)
    return compound
