"""G0/G1/G2 continuity at every joint of the wires of a CAD shape or file.

OCCT's own tools do not answer this question: ``GeomLProp``/``BRepLProp``
``Continuity`` never reports G2, and ``LocalAnalysis_CurveContinuity`` fails
where the curvature is zero — exactly at a spiral's start. So the joint
quantities are measured here from first and second derivatives.

Measures and classification: ``spiral_cad.continuity.joints`` (shared with the
OpenDRIVE checker). Files are read and measured in a child process
(``spiral_cad.cad.readers``): only the measured numbers come back.

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

import contextlib
import dataclasses
import math
import os
import time
from collections.abc import Callable, Iterator
from functools import partial
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray
from OCP.BRep import BRep_Tool
from OCP.BRepAdaptor import BRepAdaptor_Curve
from OCP.BRepLProp import BRepLProp_CLProps
from OCP.BRepTools import BRepTools_WireExplorer
from OCP.Geom import Geom_BezierCurve, Geom_BSplineCurve
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
from scipy.spatial import cKDTree

from ..continuity.joints import (
    Continuity,
    ContinuityReport,
    Frame,
    JointReport,
    Timing,
    WireReport,
    check_tolerances,
    classify_pieces,
    closes_smoothly,
    curvature_rounding_floor,
    distance,
    flip,
    model_size,
    norms,
)
from ..core.chain import Chain
from ..core.segments import EPS
from ..core.units import length_unit
from .occ import as_occ_shape
from .readers import STEP_SUFFIXES, finish_reading, read_file, start_reading

__all__ = ["COMB_COLOUR", "Continuity", "ContinuityReport", "JointReport", "WireReport", "check_continuity", "curvature_comb"]

#: Loose edges whose ends lie closer than this fraction of the model size are
#: chained into one piece (and their gap is then judged against ``gap_tol``).
SNAP_FRACTION = 1e-2

#: Floats per measured edge: start and end frame (``FRAME`` each, travel sense), middle point.
FRAME = 11
ROW = 2 * FRAME + 3
#: What is measured of a shape: each wire as (edge count, closed), the number of
#: loose edges, and one row of ``ROW`` floats per edge (wires' edges in wire
#: order, then the loose ones) as float64 bytes: plain data for ``marshal``.
Measured = tuple[list[tuple[int, bool]], int, bytes]


# ---------------------------------------------------- edge end frames


def _frame(curve: BRepAdaptor_Curve, u: float, inward: float) -> Frame:
    """Frame at parameter ``u`` in the curve's parameter direction; ``inward`` (±1) points into the edge.

    The curvature vector is ``(r'' − (r''·t) t) / |r'|²`` with the unit
    tangent ``t``: the same as ``((r' × r'') × r') / |r'|⁴``, but no product
    of derivatives is formed, so no model within the float range overflows.
    """
    p, d1, d2 = gp_Pnt(), gp_Vec(), gp_Vec()
    curve.D2(u, p, d1, d2)
    ax, ay, az = d1.X(), d1.Y(), d1.Z()
    bx, by, bz = d2.X(), d2.Y(), d2.Z()
    speed = math.hypot(ax, ay, az)
    if not speed > 1e-12 * math.hypot(bx, by, bz):  # also r' = 0 and NaN
        return _singular_frame(curve, u, inward, p)
    tx, ty, tz = ax / speed, ay / speed, az / speed
    along = bx * tx + by * ty + bz * tz
    return (
        p.X(), p.Y(), p.Z(),
        tx, ty, tz,
        (bx - along * tx) / speed / speed, (by - along * ty) / speed / speed, (bz - along * tz) / speed / speed,
    )  # fmt: skip


def _singular_frame(curve: BRepAdaptor_Curve, u: float, inward: float, p: gp_Pnt) -> Frame:
    """Frame where r' = 0 (e.g. a Bézier with coincident end poles).

    The tangent comes from higher derivatives (CLProps), NaN if none defines
    it; the curvature vector, which is unbounded there in general, is taken
    just inside.
    """
    props = BRepLProp_CLProps(curve, u, 2, 0.0)
    if props.IsTangentDefined():
        t = gp_Dir()
        props.Tangent(t)
        tangent = (t.X(), t.Y(), t.Z())
    else:
        tangent = (math.nan, math.nan, math.nan)
    if inward:
        nudge = inward * 1e-9 * (curve.LastParameter() - curve.FirstParameter())
        k = _frame(curve, u + nudge, 0.0)[6:]
    else:  # already nudged once: the curvature is not defined here
        k = (math.nan, math.nan, math.nan)
    return (p.X(), p.Y(), p.Z(), *tangent, *k)


def _edge_rows(edges: list[TopoDS_Edge]) -> NDArray:
    """One row of 25 floats per edge of what OCCT evaluates; ``_edge_frames`` turns them into
    frames, floors and lengths in one vectorised pass.

    A row: point, first and second derivative at the curve's first and
    last parameter (18), the middle point (3), the degree of a polynomial
    curve (0 for other curves), its end knot spans (NaN where the edge is
    trimmed inside the curve) and 1 for a reversed edge.
    """
    p, d1, d2 = gp_Pnt(), gp_Vec(), gp_Vec()
    rows = []
    for edge in edges:
        curve = BRep_Tool.Curve_s(edge, 0.0, 0.0)  # a transformed copy if the edge is located
        u0, u1 = BRep_Tool.Range_s(edge)
        curve.D2(u0, p, d1, d2)
        start = p.Coord() + d1.Coord() + d2.Coord()
        curve.D2(u1, p, d1, d2)
        end = p.Coord() + d1.Coord() + d2.Coord()
        rows.append(start + end + curve.Value(0.5 * (u0 + u1)).Coord() + _polynomial(curve, u0, u1)
                    + (float(edge.Orientation() == TopAbs_REVERSED),))  # fmt: skip
    return np.array(rows, dtype=float).reshape(len(rows), 25)


def _polynomial(curve: Any, u0: float, u1: float) -> tuple[float, float, float]:
    """(degree, knot span at u0, knot span at u1) of a Bézier or non-rational B-spline curve whose
    ends the edge keeps (NaN spans where it does not); (0, NaN, NaN) for any other curve."""
    if isinstance(curve, Geom_BezierCurve) and not curve.IsRational():
        first, last, degree = curve.FirstParameter(), curve.LastParameter(), curve.Degree()
        h0 = h1 = last - first
    elif isinstance(curve, Geom_BSplineCurve) and not curve.IsRational():
        first, last, degree = curve.FirstParameter(), curve.LastParameter(), curve.Degree()
        h0 = h1 = last - first  # one span (a Bézier), else the spans at the ends:
        if curve.NbKnots() > 2:
            h0, h1 = curve.Knot(curve.FirstUKnotIndex() + 1) - first, last - curve.Knot(curve.LastUKnotIndex() - 1)
    else:
        return 0.0, math.nan, math.nan
    return float(degree), h0 if u0 == first else math.nan, h1 if u1 == last else math.nan


def _edge_frames(edges: list[TopoDS_Edge]) -> NDArray:
    """Rows of ``ROW`` floats: start and end frame of each edge in its travel sense — point, unit
    tangent, curvature vector ``(r'' − (r''·t) t) / |r'|²`` (no product of derivatives is formed,
    so no model within the float range overflows), curvature rounding floor, edge length — then
    its middle point."""
    raw = _edge_rows(edges)
    out = np.empty((len(raw), ROW))
    lengths = norms(raw[:, 18:21] - raw[:, 0:3]) + norms(raw[:, 9:12] - raw[:, 18:21])
    for end, (at, span) in enumerate(((0, 22), (9, 23))):
        p, d1, d2 = raw[:, at : at + 3], raw[:, at + 3 : at + 6], raw[:, at + 6 : at + 9]
        frame = out[:, end * FRAME : (end + 1) * FRAME]
        with np.errstate(all="ignore"):
            speed = norms(d1)[:, None]
            tangent = d1 / speed
            along = np.einsum("ij,ij->i", d2, tangent)[:, None]
            frame[:, 0:3], frame[:, 3:6] = p, tangent
            frame[:, 6:9] = (d2 - along * tangent) / speed / speed
            frame[:, 9] = _rounding_floor(p, d1, d2, raw[:, 21], raw[:, span], norms(frame[:, 6:9]), inward=1 - 2 * end)
        frame[:, 10] = lengths
        singular = ~(speed[:, 0] > 1e-12 * norms(d2))  # also r' = 0 and NaN
        for i in np.flatnonzero(singular):  # rare: the scalar path, from higher derivatives
            curve = BRepAdaptor_Curve(edges[i])
            u = curve.FirstParameter() if end == 0 else curve.LastParameter()
            frame[i, :9], frame[i, 9] = _frame(curve, u, 1.0 - 2.0 * end), math.nan
    out[:, 22:25] = raw[:, 18:21]
    reverse = raw[:, 24] == 1.0
    starts, ends = out[reverse, :FRAME].copy(), out[reverse, FRAME : 2 * FRAME].copy()
    out[reverse, :FRAME], out[reverse, FRAME : 2 * FRAME] = ends, starts
    out[reverse, 3:6] *= -1.0
    out[reverse, FRAME + 3 : FRAME + 6] *= -1.0
    return out


def _rounding_floor(p: NDArray, d1: NDArray, d2: NDArray, degree: NDArray, span: NDArray, curvature: NDArray,
                    inward: int) -> NDArray:  # fmt: skip
    """The curvature rounding floor at one end of each polynomial curve (0 for other curves, NaN
    where it is not known): its legs to the next two control points follow from the derivatives
    there (a = h r' / n, b = |a ± h² r'' / (n (n − 1))| with h the end knot span, n the degree),
    and its coordinates are at most |p| + a + b (``curvature_rounding_floor``)."""
    with np.errstate(all="ignore"):
        n = np.where(degree >= 2.0, degree, np.nan)
        first = d1 * (span / n)[:, None]
        second = first + inward * d2 * (span**2 / (n * (n - 1.0)))[:, None]
        a, b = norms(first), norms(second)
        delta = 4.0 * EPS * (np.abs(p).max(axis=1) + a + b)
        floor = curvature_rounding_floor(delta, a, b, curvature)
    return np.where(degree == 0.0, 0.0, floor)


# ----------------------------------------------------------- grouping


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
    if len(edges) < wire.NbChildren():
        stored = []
        it = TopoDS_Iterator(wire)
        while it.More():
            if it.Value().ShapeType() == TopAbs_EDGE:
                stored.append(TopoDS.Edge_s(it.Value()))
            it.Next()
        edges = stored if len(edges) < len(stored) else edges
    edges = [e for e in edges if not _is_degenerated(e)]
    if not edges:
        return edges, False
    v_first = TopExp.FirstVertex_s(edges[0], True)
    v_last = TopExp.LastVertex_s(edges[-1], True)
    return edges, (not v_first.IsNull()) and v_first.IsSame(v_last)


def _measure(shape: TopoDS_Shape) -> Measured:
    """Everything the checker needs of ``shape``, as plain data (see ``Measured``).

    For a file this runs in the reader's child process (``read_file``): only
    these numbers come back, so no curve of the file is evaluated here.
    """
    wires_found, edges = [], []
    wires = TopTools_IndexedMapOfShape()
    TopExp.MapShapes_s(shape, TopAbs_WIRE, wires)
    for i in range(1, wires.Extent() + 1):
        found, closed = _wire_edges(TopoDS.Wire_s(wires.FindKey(i)))
        if found:
            wires_found.append((len(found), closed))
            edges += found
    loose = TopTools_IndexedMapOfShape()
    explorer = TopExp_Explorer(shape, TopAbs_EDGE, TopAbs_WIRE)
    while explorer.More():
        loose.Add(explorer.Current())
        explorer.Next()
    loose_edges = [e for e in (TopoDS.Edge_s(loose.FindKey(i)) for i in range(1, loose.Extent() + 1)) if not _is_degenerated(e)]
    return wires_found, len(loose_edges), _edge_frames(edges + loose_edges).tobytes()


def _timed_measure(shape: TopoDS_Shape) -> tuple[Measured, float]:
    """``_measure`` and the seconds it took (in the reader's child: the rest of its time is the reader's)."""
    started = time.perf_counter()
    measured = _measure(shape)
    return measured, time.perf_counter() - started


def _chain_loose(ends: list[tuple[Frame, Frame]], snap: float, gap_tol: float, size: float) -> list[tuple[list[tuple[Frame, Frame]], bool]]:
    """Chain loose edges by nearest ends: each piece grows at both ends by the
    unused edge end nearest to it, while that is within ``snap``.

    The search runs on coordinates divided by the model ``size``, so its
    squared distances cannot overflow.
    """
    unit = size if size > 0.0 else 1.0
    points = np.array([f[:3] for pair in ends for f in pair]) / unit  # edge k: start 2k, end 2k + 1
    reach = snap / unit
    tree = cKDTree(points)
    used = np.zeros(len(ends), dtype=bool)

    def nearest(frame: Frame) -> int | None:
        """Index (2k or 2k + 1) of the nearest end of an unused edge within ``snap``."""
        count = 8
        while True:
            distances, found = tree.query(np.asarray(frame[:3]) / unit, k=min(count, len(points)), distance_upper_bound=reach)
            for d, i in zip(np.atleast_1d(distances), np.atleast_1d(found)):
                if math.isfinite(d) and not used[i // 2]:
                    return int(i)
            if count >= len(points) or not math.isfinite(np.atleast_1d(distances)[-1]):
                return None
            count *= 4

    pieces = []
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
        pieces.append((piece, closed))
    return pieces


# -------------------------------------------------------- measurement


def check_continuity(
    shape_or_path: Any,
    *,
    gap_tol: float = 1e-7,
    angle_tol: float = 1e-7,
    curvature_tol: float = 1e-6,
    snap: float | None = None,
    units: str | None = None,
    label: str | None = None,
) -> ContinuityReport:
    """Measure and classify every joint of every piece of a shape or STEP/IGES file.

    Wires are walked in connection order (``BRepTools_WireExplorer``), with
    the closing joint of closed wires. Edges that belong to no wire are
    chained by nearest ends within ``snap`` (see the module docstring), so a
    small gap is reported as a G0 failure rather than splitting the path.
    Degenerated edges (surface poles) are skipped.

    A file is read in a child process, whole or not at all, every curve
    accounted for (``spiral_cad.cad.readers``), in the unit it declares: the
    report states that unit, and the demo's ``NAME_continuity.txt`` and
    ``spiral-cad check`` print the same numbers for the same file.

    Args:
        shape_or_path: ``TopoDS_Shape``, build123d/CadQuery shape, ``Chain``,
            iterable of shapes, or a .step/.stp/.igs/.iges path.
        gap_tol: largest G0 gap, absolute model units.
        angle_tol: largest G1 tangent angle, radians.
        curvature_tol: largest G2 curvature jump relative to
            ``max(|K_a|, |K_b|, 1/size)``.
        snap: chaining distance for loose edges (model units); default
            ``SNAP_FRACTION · size``.
        units: for a file, the unit to read it in (None: the unit it
            declares); for a shape, the unit its numbers are in, for the
            report (None: a Chain's own unit, else "model units").
        label: name shown in the report (default: the file's name).

    Raises:
        ValueError: an unreadable or incompletely read file, or one the
            reader crashed on (``ReadError``, with the reason), a point that
            is not finite, or a negative/non-finite tolerance.
    """
    tolerances: dict[str, Any] = dict(gap_tol=gap_tol, angle_tol=angle_tol, curvature_tol=curvature_tol, snap=snap)
    _check_options(**tolerances)
    tolerances = {name: None if value is None else float(value) for name, value in tolerances.items()}  # 1 as 1.0
    if isinstance(shape_or_path, (str, os.PathLike)):
        with checking(shape_or_path, units=units, label=label, **tolerances) as report:
            return report()
    unit = length_unit(units) if units is not None else shape_or_path.units if isinstance(shape_or_path, Chain) else ""
    measured, measuring = _timed_measure(as_occ_shape(shape_or_path))
    return _timed_report(measured, unit, label or type(shape_or_path).__name__, tolerances, Timing(0.0, measuring, 0.0, ""))


@contextlib.contextmanager
def checking(path: str | os.PathLike, *, gap_tol: float = 1e-7, angle_tol: float = 1e-7, curvature_tol: float = 1e-6,
             snap: float | None = None, units: str | None = None,
             label: str | None = None) -> Iterator[Callable[[], ContinuityReport]]:  # fmt: skip
    """``check_continuity(path, ...)`` started: OCCT reads the file in its child process while
    the caller goes on; the function yielded waits for the report (leaving the block
    without asking for it stops the child). Arguments and errors as ``check_continuity``."""
    tolerances: dict[str, Any] = dict(gap_tol=gap_tol, angle_tol=angle_tol, curvature_tol=curvature_tol, snap=snap)
    _check_options(**tolerances)
    source = os.path.basename(os.fspath(path))
    reader = "the STEP reader (OCCT)" if Path(path).suffix.lower() in STEP_SUFFIXES else "the IGES reader (OCCT)"
    started = time.perf_counter()

    def report() -> ContinuityReport:
        unit, (measured, measuring) = finish_reading(child)
        timing = Timing(time.perf_counter() - started - measuring, measuring, 0.0, reader)
        return _timed_report(measured, unit, label or source, tolerances, timing)

    with start_reading(path, units, _timed_measure) as child:
        yield report


def _check_options(gap_tol: float, angle_tol: float, curvature_tol: float, snap: float | None) -> None:
    check_tolerances(gap_tol=gap_tol, angle_tol=angle_tol, curvature_tol=curvature_tol)
    if snap is not None:
        check_tolerances(snap=snap)


def _timed_report(measured: Measured, unit: str, source: str, tolerances: dict, timing: Timing) -> ContinuityReport:
    """The report of what was measured, with the time its classification took added to ``timing``."""
    classified = time.perf_counter()
    report = _report(measured, unit, source, **tolerances)
    return dataclasses.replace(report, timing=dataclasses.replace(timing, classifying=time.perf_counter() - classified))


def _report(measured: Measured, unit: str, source: str, gap_tol: float, angle_tol: float, curvature_tol: float,
            snap: float | None) -> ContinuityReport:  # fmt: skip
    """Chain the loose edges and classify every joint."""
    wires, loose, data = measured
    rows = np.frombuffer(data, dtype=float).reshape(-1, ROW)
    size = model_size(rows[:, [0, 1, 2, FRAME, FRAME + 1, FRAME + 2, 22, 23, 24]].reshape(-1, 3), source)
    link = SNAP_FRACTION * size if snap is None else snap
    frames = rows[:, : 2 * FRAME].reshape(-1, 2, FRAME)
    bounds = np.cumsum([0] + [count for count, _ in wires])
    # a wire whose ends are two vertices at one point is a loop when it goes on smoothly there
    pieces: list[tuple] = [("wire", frames[i:j], closed or closes_smoothly(frames[i:j], gap_tol, angle_tol))
                           for i, j, (_, closed) in zip(bounds, bounds[1:], wires)]  # fmt: skip
    if loose:
        loose_ends = [(tuple(start), tuple(end)) for start, end in frames[bounds[-1] :].tolist()]
        pieces += [("loose piece", ends, closed) for ends, closed in _chain_loose(loose_ends, link, gap_tol, size)]
    return classify_pieces(
        pieces, size, gap_tol=gap_tol, angle_tol=angle_tol, curvature_tol=curvature_tol, snap=link, source=source, units=unit
    )


# ------------------------------------------------------------------ comb


#: The colour a curvature comb is drawn in (the web page of ``check --html``, ``show_continuity``).
COMB_COLOUR = "#6baed6"


def curvature_comb(shape_or_path: Any, *, scale: float | None = None, per_edge: int = 24, units: str = "mm"):
    """The curvature comb of every edge as OCCT geometry: teeth and the envelope through their tips.

    A tooth runs from a point of the curve against its curvature vector
    (to the convex side), ``scale`` × |κ| long; by default the longest tooth
    is a fifth of the model size. Works for any wire or file the checker
    reads (a file is read in ``units``, default mm as build123d reads it), so
    a viewer (CQ-editor, FreeCAD) can show the comb beside the part.

    Returns:
        A ``TopoDS_Compound`` of line edges (teeth, then envelopes).

    Raises:
        ValueError: no edges, ``per_edge`` not an integer ≥ 2, a bad
            ``scale``, or an unreadable file.
    """
    if isinstance(per_edge, bool) or not isinstance(per_edge, int) or per_edge < 2:
        raise ValueError(f"per_edge must be an integer ≥ 2; got {per_edge!r:.40}")
    if scale is not None:
        check_tolerances(scale=scale)
    if isinstance(shape_or_path, (str, os.PathLike)):
        _, samples = read_file(shape_or_path, units, partial(_comb_samples, per_edge=per_edge))
    else:
        samples = _comb_samples(as_occ_shape(shape_or_path), per_edge)
    return _comb_compound(samples, scale)


def _comb_samples(shape: TopoDS_Shape, per_edge: int) -> list[list[Frame]]:
    """``per_edge`` frames along every non-degenerate edge (plain numbers: runs in the reader's child for files)."""
    samples = []
    explorer = TopExp_Explorer(shape, TopAbs_EDGE)
    while explorer.More():
        edge = TopoDS.Edge_s(explorer.Current())
        if not _is_degenerated(edge):
            curve = BRepAdaptor_Curve(edge)
            u0, u1 = curve.FirstParameter(), curve.LastParameter()
            samples.append([_frame(curve, u0 + (u1 - u0) * k / (per_edge - 1), 1.0 if k == 0 else -1.0) for k in range(per_edge)])
        explorer.Next()
    return samples


def _comb_compound(samples: list[list[Frame]], scale: float | None):
    """Teeth and envelopes of the sampled frames as a compound of line edges (non-finite samples are left out)."""
    from OCP.BRep import BRep_Builder
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeEdge
    from OCP.TopoDS import TopoDS_Compound

    if not samples:
        raise ValueError("the shape has no edges to comb")
    arrays = [np.array(frames, dtype=float).reshape(-1, 9) for frames in samples]
    arrays = [a[np.isfinite(a).all(axis=1)] for a in arrays]
    everything = np.vstack(arrays)
    if scale is None:
        size = model_size([tuple(p) for p in everything[:, :3].tolist()])
        peak = max((math.hypot(*k) for k in everything[:, 6:9].tolist()), default=0.0)
        scale = 0.2 * size / peak if peak > 0 else 0.0
    builder, compound = BRep_Builder(), TopoDS_Compound()
    builder.MakeCompound(compound)

    def line(a, b) -> None:
        if math.isfinite(math.hypot(*(b - a))) and math.hypot(*(b - a)) > 1e-12:
            builder.Add(compound, BRepBuilderAPI_MakeEdge(gp_Pnt(*a.tolist()), gp_Pnt(*b.tolist())).Edge())

    for frames in arrays:
        points, tips = frames[:, :3], frames[:, :3] - scale * frames[:, 6:9]
        for p, q in zip(points, tips):
            line(p, q)
        for p, q in zip(tips, tips[1:]):
            line(p, q)
    return compound
