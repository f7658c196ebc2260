"""A STEP or IGES file rewritten G2 in place: one file in, the same file out (``rewrite_step_g2``, ``rewrite_iges_g2``).

The file is first read whole by our reader (``spiral_cad.cad.readers``: every curve accounted for, in
the unit it declares), then read again through OCCT's XDE (``STEPCAFControl_Reader`` /
``IGESCAFControl_Reader``) into an XCAF document in that same unit, so that the products, their names,
colours and layers come along. Every wire of every shape in the document — a wire that is no face's
boundary, or loose edges chained end to end into wires (ends within half the bound, a gap ``make_g2``
closes; a wider gap that ``spiral-cad check`` would chain is named and counted below G2) — is measured
(``check_continuity``: G2 when every joint is); a wire that is not G2 is made G2 within the bound by
``spiral_cad.design.make_g2`` (``g2_wire``: lines and arcs kept true lines and arcs, spirals between
them, its own cubic Bézier spirals kept). The made wire takes the place of the old one in its shape
(``XCAFDoc_ShapeTool.SetShape`` on the shape's label), and the document is written back in the same
format and unit by ``STEPCAFControl_Writer`` / ``IGESCAFControl_Writer``, whole or not at all, its reals
with 17 significant digits (``occ.print_model``) and an IGES file's BRep solids in BRep mode.

Solids, shells and faces are kept as they are: a part's faces are not this verb's job (``g2_face`` and
``g2_fillet`` make faces G2). A wire that is G2 already, one that is not planar or holds curves other
than lines, arcs and cubic Bézier spans (a free-form B-spline whose joints are not G2), and one
``make_g2`` refuses within the bound are kept as they are, and the report says why.

Both the reading and the rewriting run in child processes (``spiral_cad.cad.sandbox``): OCCT's readers
can crash on a damaged file, and the caller lives on. The bound is in the file's own unit.

How OCCT writes wires: a STEP wire becomes a ``GEOMETRIC_CURVE_SET`` of trimmed curves (lines, circles,
B-splines), an IGES wire a composite curve; readers get the edges back and chain them.
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import numpy as np
from OCP.BRep import BRep_Builder, BRep_Tool
from OCP.BRepAdaptor import BRepAdaptor_Curve
from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeEdge, BRepBuilderAPI_MakeWire
from OCP.BRepTools import BRepTools_ReShape, BRepTools_WireExplorer
from OCP.GC import GC_MakeArcOfCircle
from OCP.gce import gce_MakeCirc, gce_MakeLin
from OCP.GeomAbs import GeomAbs_CurveType
from OCP.ShapeAnalysis import ShapeAnalysis_FreeBounds
from OCP.TopAbs import TopAbs_COMPOUND, TopAbs_EDGE, TopAbs_FACE, TopAbs_REVERSED, TopAbs_SHELL, TopAbs_SOLID, TopAbs_WIRE
from OCP.TopExp import TopExp, TopExp_Explorer
from OCP.TopoDS import TopoDS, TopoDS_Compound, TopoDS_Edge, TopoDS_Iterator, TopoDS_Shape, TopoDS_Wire
from OCP.TopTools import TopTools_HSequenceOfShape
from scipy.spatial import cKDTree

from ..continuity.joints import Continuity
from ..core.units import MM_PER_UNIT
from ..design.g2 import GAP_SHARE
from ..io.document_report import DocumentReport, PathReport
from ..io.staging import temporary_beside
from .continuity import SNAP_FRACTION, check_continuity
from .g2wire import g2_wire
from .readers import IGES_SUFFIXES, STEP_SUFFIXES, read_file
from .sandbox import run_isolated

__all__ = ["rewrite_iges_g2", "rewrite_step_g2"]

#: OCCT's names for ``write.step.unit`` and ``write.iges.unit``.
_UNIT_NAME = {"mm": "MM", "cm": "CM", "m": "M", "km": "KM", "in": "INCH", "ft": "FT"}
#: Loose edges whose ends lie this close (relative to the model size, at least 1e-7) are chained into one wire.
CHAIN_TOLERANCE = 1e-9
#: A B-spline edge within this share of its length of a line or a circle is read as that line or arc.
ANALYTIC_TOLERANCE = 1e-9


def rewrite_step_g2(source: str | os.PathLike, target: str | os.PathLike, max_deviation: float, *,
                    shape: str | None = None) -> DocumentReport:  # fmt: skip
    """Rewrite a STEP file with every wire that is not G2 made G2 within ``max_deviation`` (see the module docstring).

    Args:
        source: the STEP file (.step/.stp).
        target: the STEP file to write (not ``source``).
        max_deviation: the largest distance between a wire and its G2 wire, in the file's length unit.
        shape: the spiral shape (``"near-linear"``, the default, or ``"walton-meek"``).

    Returns:
        The report: per wire its measured deviation and joints changed, or why it was kept.

    Raises:
        ValueError: a file the reader refuses (``ReadError``, with the reason), or a bad bound.
        OSError: the file could not be written.
    """
    return _rewrite(Path(source), Path(target), max_deviation, shape, "STEP")


def rewrite_iges_g2(source: str | os.PathLike, target: str | os.PathLike, max_deviation: float, *,
                    shape: str | None = None) -> DocumentReport:  # fmt: skip
    """Rewrite an IGES file with every wire that is not G2 made G2 within ``max_deviation``; as :func:`rewrite_step_g2`.

    Raises:
        ValueError, OSError: as :func:`rewrite_step_g2`.
    """
    return _rewrite(Path(source), Path(target), max_deviation, shape, "IGES")


def _rewrite(source: Path, target: Path, max_deviation: float, shape: str | None, kind: str) -> DocumentReport:
    if not (isinstance(max_deviation, (int, float)) and math.isfinite(max_deviation) and max_deviation > 0.0):
        raise ValueError(f"max_deviation must be a positive length; got {max_deviation!r}")
    suffixes = STEP_SUFFIXES if kind == "STEP" else IGES_SUFFIXES
    for path in (source, target):
        if path.suffix.lower() not in suffixes:
            raise ValueError(f"{path.name}: a {kind} file ends in {' or '.join(suffixes)}")
    unit, _ = read_file(source, None, _nothing)  # whole, every curve accounted for, or a ReadError naming why
    paths, notes = run_isolated(_rewrite_document, str(source), str(target), kind, unit, float(max_deviation),
                                shape or "near-linear", what=f"the {kind} rewriter", subject=source.name)  # fmt: skip
    reports = tuple(PathReport(*row) for row in paths)
    what = "STEP file" if kind == "STEP" else "IGES file"
    return DocumentReport(source.name, target.name, what, unit, float(max_deviation), reports, tuple(notes))


def _nothing(shape: TopoDS_Shape) -> int:
    return 0


# ------------------------------------------------------------ in the child


def _rewrite_document(source: str, target: str, kind: str, unit: str, bound: float, spiral: str) -> tuple[list, list[str]]:
    """The child's work: read the file into an XCAF document, make its wires G2, write it; the report as plain data.
    Loose edges whose ends lie within ``GAP_SHARE`` of the bound (the gaps make_g2 closes) are chained."""
    # an IGES file of BRep solids (186, shells 514) is written in BRep mode, so its solids stay solids
    settings: dict[str, int | str] = {
        "write.iges.unit": _UNIT_NAME[unit],
        "write.iges.brep.mode": int(kind == "IGES" and _iges_brep(source)),
    }
    if kind == "STEP":  # names of solids and other sub-shapes kept too, and written in the file's unit
        settings = {"read.stepcaf.subshapes.name": 1, "write.stepcaf.subshapes.name": 1, "write.step.unit": _UNIT_NAME[unit]}
    with _settings(kind, settings):
        doc = _read_document(source, kind, unit)
        paths, notes, gained = _rewrite_wires(doc, bound, spiral, unit, GAP_SHARE * bound)
        notes.append("names, colours and layers kept through OCCT's XDE"
                     + (" (a PRODUCT's id is written as its name); wires written as curve sets (readers chain their edges)"
                        if kind == "STEP" else "; wires written as composite curves"))  # fmt: skip
        _write_document(doc, Path(target), kind, lambda written: _check_written(source, written, kind, unit, gained))
    return paths, notes


def _iges_brep(source: str) -> bool:
    """Whether an IGES file holds BRep solids or shells (entities 186, 514): its directory entries say."""
    with open(source, "rb") as handle:
        for record in handle:
            if len(record) >= 73 and record[72:73] == b"D" and record[:8].strip() in (b"186", b"514"):
                return True
    return False


@contextmanager
def _settings(kind: str, values: dict[str, int | str]) -> Iterator[None]:
    """OCCT's reader and writer parameters set to ``values`` for the block, then put back as they were."""
    from OCP.Interface import Interface_Static

    if kind == "STEP":
        from OCP.STEPCAFControl import STEPCAFControl_Reader, STEPCAFControl_Writer

        STEPCAFControl_Reader(), STEPCAFControl_Writer()  # register their parameters
    else:
        from OCP.IGESCAFControl import IGESCAFControl_Writer

        IGESCAFControl_Writer()
    before = {name: Interface_Static.CVal_s(name) for name in values}
    for name, value in values.items():
        Interface_Static.SetCVal_s(name, str(value))
    try:
        yield
    finally:
        for name, value in before.items():
            Interface_Static.SetCVal_s(name, value)


def _rewrite_wires(doc: Any, bound: float, spiral: str, unit: str, reach: float) -> tuple[list[tuple], list[str], int]:
    """Every wire of every shape of the document that is not G2 made G2 in place; (report rows, notes, how many edges
    the written file gains: each changed shape's new edges less its old ones, times the times it is placed)."""
    from OCP.TDF import TDF_LabelSequence
    from OCP.XCAFDoc import XCAFDoc_DocumentTool

    tool = XCAFDoc_DocumentTool.ShapeTool_s(doc.Main())
    labels = TDF_LabelSequence()
    tool.GetShapes(labels)
    paths: list[tuple] = []
    notes: list[str] = []
    kept = {"solid": 0, "shell": 0, "face": 0}
    whole, gained = _placed(tool), 0
    for i in range(1, labels.Length() + 1):
        label = labels.Value(i)
        if tool.IsAssembly_s(label) or tool.IsReference_s(label):
            continue
        old = tool.GetShape_s(label)
        for word, found in _counts(old).items():
            kept[word] += found
        name = _label_name(label) or f"shape {i}"
        new = _rewrite_shape(old, name, bound, spiral, unit, reach, paths)
        if new is not None:
            gained += _occurrences(whole, old) * (_edge_total(new) - _edge_total(old))
            tool.SetShape(label, new)
    tool.UpdateAssemblies()
    faces = ", ".join(f"{count} {word}(s)" for word, count in kept.items() if count)
    if faces:
        notes.append(f"{faces} kept as they are (a part's faces are not this command's job; g2_face and g2_fillet make them G2)")
    if not paths:
        notes.append("the file holds no wires or loose edges")
    return paths, notes, gained


def _placed(tool: Any) -> TopoDS_Shape:
    """Every free shape of the document, placed (a compound): what a reader of the file gets."""
    from OCP.TDF import TDF_LabelSequence

    free = TDF_LabelSequence()
    tool.GetFreeShapes(free)
    builder, compound = BRep_Builder(), TopoDS_Compound()
    builder.MakeCompound(compound)
    for i in range(1, free.Length() + 1):
        builder.Add(compound, tool.GetShape_s(free.Value(i)))
    return compound


def _occurrences(whole: TopoDS_Shape, shape: TopoDS_Shape) -> int:
    """How many times ``shape`` is placed in ``whole`` (a part instanced four times: 4; at least 1)."""
    count, explorer = 0, TopExp_Explorer(whole, shape.ShapeType())
    while explorer.More():
        count += explorer.Current().IsPartner(shape)
        explorer.Next()
    return max(count, 1)


def _edge_total(shape: TopoDS_Shape) -> int:
    from .readers import _edge_count

    return _edge_count(shape)[0]


def _check_written(source: str, written: str, kind: str, unit: str, gained: int) -> None:
    """Refuse a written file that does not hold the input's edges plus those gained: OCCT's XDE writer can drop a
    placed copy (IGES subfigure instances with a scale), and nothing may be lost in silence.

    Raises:
        ValueError: the counts differ (nothing is written).
    """
    from .readers import _edge_count, _read_whole

    before = _edge_count(_read_whole(Path(source), kind, unit)[0])[0]
    try:
        after = _edge_count(_read_whole(Path(written), kind, unit)[0])[0]
    except ValueError as error:  # our reader's verdict on what OCCT's writer made
        reason = str(error).split(": ", 1)[-1]
        raise ValueError(f"{Path(source).name}: OCCT's {kind} writer (XDE) made a file that does not read back whole "
                         f"({reason}); nothing written") from None  # fmt: skip
    if after != before + gained:
        raise ValueError(f"{Path(source).name}: OCCT's {kind} writer (XDE) would not write the document whole: it holds "
                         f"{after} edges, {before + gained} expected ({before} read, {gained:+d} made); nothing written")  # fmt: skip


def _read_document(source: str, kind: str, unit: str) -> Any:
    """The file in an XCAF document whose length unit is ``unit`` (the file's own: its numbers are kept)."""
    from OCP.IFSelect import IFSelect_RetDone
    from OCP.TCollection import TCollection_ExtendedString
    from OCP.TDocStd import TDocStd_Document
    from OCP.XCAFApp import XCAFApp_Application
    from OCP.XCAFDoc import XCAFDoc_DocumentTool

    from .console import captured_messages

    doc = TDocStd_Document(TCollection_ExtendedString("MDTV-XCAF"))
    XCAFApp_Application.GetApplication_s().InitDocument(doc)
    XCAFDoc_DocumentTool.SetLengthUnit_s(doc, MM_PER_UNIT[unit] / 1000.0)  # metres per unit
    if kind == "STEP":
        from OCP.STEPCAFControl import STEPCAFControl_Reader

        reader: Any = STEPCAFControl_Reader()
    else:
        from OCP.IGESCAFControl import IGESCAFControl_Reader

        reader = IGESCAFControl_Reader()
    for mode in ("SetNameMode", "SetColorMode", "SetLayerMode"):
        getattr(reader, mode)(True)
    with captured_messages():
        if reader.ReadFile(source) != IFSelect_RetDone or not reader.Transfer(doc):
            raise ValueError(f"{Path(source).name}: OCCT's {kind} reader with names and colours (XDE) could not read it")
    return doc


def _write_document(doc: Any, target: Path, kind: str, check: Callable[[str], None]) -> None:
    """Write the document whole or not at all (a temporary file in the target's folder, then renamed), its reals
    with 17 significant digits (``print_model``: OCCT prints 9 or 13, which moves a short spiral's inner control
    points enough to break G2 at its ends)."""
    from .console import captured_messages
    from .occ import print_model

    temporary = temporary_beside(target, target.suffix)
    try:
        with captured_messages():
            if kind == "STEP":
                from OCP.StepAP214 import StepAP214
                from OCP.STEPCAFControl import STEPCAFControl_Writer
                from OCP.STEPControl import STEPControl_AsIs
                from OCP.StepData import StepData_StepWriter

                writer: Any = STEPCAFControl_Writer()
                done = writer.Transfer(doc, STEPControl_AsIs)
                printer, protocol = StepData_StepWriter(writer.ChangeWriter().Model()), StepAP214.Protocol_s()
            else:
                from OCP.IGESCAFControl import IGESCAFControl_Writer
                from OCP.IGESData import IGESData_IGESWriter
                from OCP.IGESSelect import IGESSelect_WorkLibrary

                writer = IGESCAFControl_Writer()
                done = writer.Transfer(doc)
                writer.ComputeModel()
                printer, protocol = IGESData_IGESWriter(writer.Model()), IGESSelect_WorkLibrary.DefineProtocol_s()
        if not done:
            raise OSError(f"OCCT's {kind} writer could not transfer the document for {target.name}")
        print_model(printer, protocol, temporary, kind)
        check(temporary)
        os.replace(temporary, target)
    finally:
        if os.path.exists(temporary):
            os.unlink(temporary)


def _label_name(label: Any) -> str:
    from OCP.TDataStd import TDataStd_Name

    found = TDataStd_Name()
    return found.Get().ToExtString() if label.FindAttribute(TDataStd_Name.GetID_s(), found) else ""


def _counts(shape: TopoDS_Shape) -> dict[str, int]:
    """The solids, the shells outside solids and the faces outside shells of ``shape``."""
    found = {}
    for word, kind, inside in (("solid", TopAbs_SOLID, None), ("shell", TopAbs_SHELL, TopAbs_SOLID), ("face", TopAbs_FACE, TopAbs_SHELL)):
        explorer = TopExp_Explorer(shape, kind) if inside is None else TopExp_Explorer(shape, kind, inside)
        count = 0
        while explorer.More():
            count += 1
            explorer.Next()
        found[word] = count
    return found


def _free_wires(shape: TopoDS_Shape, reach: float = 0.0) -> list[tuple[TopoDS_Wire, list[TopoDS_Shape]]]:
    """Each wire of ``shape`` that bounds no face, and each chain of its loose edges joined into a wire (ends within
    ``reach``, at least 1e-7 and ``CHAIN_TOLERANCE`` of the size, are joined); with the shapes of the document it
    replaces (the wire itself, or the loose edges it was chained from)."""
    found: list[tuple[TopoDS_Wire, list[TopoDS_Shape]]] = []
    explorer = TopExp_Explorer(shape, TopAbs_WIRE, TopAbs_FACE)
    while explorer.More():
        wire = TopoDS.Wire_s(explorer.Current())
        found.append((wire, [wire]))
        explorer.Next()
    loose: list[TopoDS_Edge] = []
    explorer = TopExp_Explorer(shape, TopAbs_EDGE, TopAbs_WIRE)
    while explorer.More():
        loose.append(TopoDS.Edge_s(explorer.Current()))
        explorer.Next()
    if not loose:
        return found
    middles = np.array([_middle(e) for e in loose])
    size = float(np.abs(middles).max(initial=1.0))
    tree = cKDTree(middles)
    sequence = TopTools_HSequenceOfShape()
    for edge in loose:
        sequence.Append(edge)
    joined = TopTools_HSequenceOfShape()
    ShapeAnalysis_FreeBounds.ConnectEdgesToWires_s(sequence, max(1e-7, CHAIN_TOLERANCE * size, reach), False, joined)
    used = np.zeros(len(loose), dtype=bool)
    for k in range(1, joined.Length() + 1):
        wire = TopoDS.Wire_s(joined.Value(k))
        originals = []
        explorer = TopExp_Explorer(wire, TopAbs_EDGE)
        while explorer.More():  # the chained edges are copies: each is found by its middle point
            best = _nearest_unused(tree, _middle(TopoDS.Edge_s(explorer.Current())), used)
            if best is not None:
                used[best] = True
                originals.append(loose[best])
            explorer.Next()
        found.append((wire, originals))
    return found


def _nearest_unused(tree: cKDTree, point: tuple[float, float, float], used: np.ndarray) -> int | None:
    """The index of the unused point of ``tree`` nearest to ``point`` (None: all are used)."""
    count = 4
    while True:
        k = min(count, tree.n)
        _, found = tree.query(point, k=k)
        for i in np.atleast_1d(found).tolist():
            if i < tree.n and not used[i]:
                return int(i)
        if k == tree.n:
            return None
        count *= 4


def _size(shape: TopoDS_Shape) -> float:
    """The diagonal of the shape's bounding box (1 for an empty or unbounded one)."""
    from OCP.Bnd import Bnd_Box
    from OCP.BRepBndLib import BRepBndLib

    box = Bnd_Box()
    BRepBndLib.Add_s(shape, box)
    if box.IsVoid():
        return 1.0
    size = box.CornerMin().Distance(box.CornerMax())
    return size if math.isfinite(size) and size > 0.0 else 1.0


def _gaps(wires: list[TopoDS_Wire], size: float, reach: float, unit: str) -> list[str]:
    """The open ends of ``wires`` that lie closer together than ``SNAP_FRACTION`` of the model ``size`` without meeting
    (wider than the gaps chained and closed by make_g2): gaps the file has, left as they are (``spiral-cad check``
    chains such ends and reports a G0 failure there), in words."""
    ends: list[tuple[int, tuple[float, float, float]]] = []
    for number, wire in enumerate(wires, 1):
        first, last = TopExp.FirstVertex_s(_first_edge(wire, True), True), TopExp.LastVertex_s(_first_edge(wire, False), True)
        if first.IsNull() or last.IsNull() or first.IsSame(last):
            continue
        ends += [(number, BRep_Tool.Pnt_s(first).Coord()), (number, BRep_Tool.Pnt_s(last).Coord())]
    if len(ends) < 2:
        return []
    points = np.array([p for _, p in ends])
    found = []
    for i, j in sorted(cKDTree(points).query_pairs(SNAP_FRACTION * size)):
        gap = float(np.linalg.norm(points[i] - points[j]))
        if gap > max(reach, 1e-7):  # (a wire whose ends lie within reach is closed by make_g2)
            a, b = ends[i][0], ends[j][0]
            which = f"the two ends of wire {a}" if a == b else f"an end of wire {a} and one of wire {b}"
            found.append(f"{which} are {gap:.3g} {unit} apart, more than half the bound: a gap in the file")
    return found


def _first_edge(wire: TopoDS_Wire, first: bool) -> TopoDS_Edge:
    """The first (or last) edge of the wire in connection order."""
    explorer = BRepTools_WireExplorer(wire)
    edge = TopoDS.Edge_s(explorer.Current())
    while not first and explorer.More():
        edge = TopoDS.Edge_s(explorer.Current())
        explorer.Next()
    return edge


def _middle(edge: TopoDS_Edge) -> tuple[float, float, float]:
    curve = BRepAdaptor_Curve(edge)
    return curve.Value(0.5 * (curve.FirstParameter() + curve.LastParameter())).Coord()


def _edge_count(wire: TopoDS_Wire) -> int:
    count, explorer = 0, TopExp_Explorer(wire, TopAbs_EDGE)
    while explorer.More():
        count += 1
        explorer.Next()
    return count


def _analytic_wire(wire: TopoDS_Wire) -> TopoDS_Wire:
    """The wire with each B-spline edge that is exactly a line or a circular arc (a writer that stores every
    edge as a B-spline, ours among them) made a LINE or CIRCLE edge, in travel order; the wire itself when
    none is. An edge counts when points along it lie within ``ANALYTIC_TOLERANCE`` of its size from the
    line or the circle through its ends and middle."""
    explorer = BRepTools_WireExplorer(wire)
    edges: list[TopoDS_Edge] = []
    changed = False
    while explorer.More():
        edge = TopoDS.Edge_s(explorer.Current())
        made = _as_line_or_arc(edge)
        changed = changed or made is not None
        edges.append(made if made is not None else edge)
        explorer.Next()
    if not changed:
        return wire
    maker = BRepBuilderAPI_MakeWire()
    for edge in edges:
        maker.Add(edge)
    return maker.Wire() if maker.IsDone() else wire


def _as_line_or_arc(edge: TopoDS_Edge) -> TopoDS_Edge | None:
    """A LINE or CIRCLE edge running as the B-spline edge ``edge`` runs, when it is one exactly; else None."""
    curve = BRepAdaptor_Curve(edge)
    if curve.GetType() != GeomAbs_CurveType.GeomAbs_BSplineCurve:
        return None
    first, last = curve.FirstParameter(), curve.LastParameter()
    if edge.Orientation() == TopAbs_REVERSED:
        first, last = last, first
    points = [curve.Value(first + (last - first) * k / 16) for k in range(17)]
    start, middle, end = points[0], points[8], points[16]
    size = max(start.Distance(middle) + middle.Distance(end), 1e-300)
    tolerance = ANALYTIC_TOLERANCE * size
    if start.Distance(end) > tolerance:
        line = gce_MakeLin(start, end)
        if line.IsDone() and all(line.Value().Distance(p) <= tolerance for p in points):
            return BRepBuilderAPI_MakeEdge(start, end).Edge()
    circle = gce_MakeCirc(start, middle, end)
    if not circle.IsDone():
        return None
    if all(abs(circle.Value().Location().Distance(p) - circle.Value().Radius()) <= tolerance for p in points):
        arc = GC_MakeArcOfCircle(start, middle, end)
        if arc.IsDone():
            return BRepBuilderAPI_MakeEdge(arc.Value()).Edge()
    return None


def _rewrite_shape(shape: TopoDS_Shape, name: str, bound: float, spiral: str, unit: str, reach: float,
                   paths: list[tuple]) -> TopoDS_Shape | None:  # fmt: skip
    """``shape`` with its wires that are not G2 made G2 (None: nothing changed); one report row per wire added to
    ``paths``, and one per gap between wire ends that nearly meet (left as it is, below G2)."""
    reshape = BRepTools_ReShape()
    made: list[TopoDS_Wire] = []
    wires = _free_wires(shape, reach)
    gaps = _gaps([wire for wire, _ in wires], _size(shape), reach, unit)
    for number, (wire, originals) in enumerate(wires, 1):
        label = f"{name}, wire {number}" if len(wires) > 1 else f"{name}, wire"
        report = check_continuity(wire, units=unit)
        (piece,) = report.wires or (None,)
        edges = _edge_count(wire)
        joints = len(piece.joints) if piece is not None else max(edges - 1, 0)
        label += f" ({edges} edge(s){', closed' if piece is not None and piece.closed else ''})"
        if report.min_level >= Continuity.G2 and len(report.wires) == 1:
            paths.append((label, joints, 0, math.nan, 0, "G2 already", 0, True))
            continue
        try:
            new, result = g2_wire(_analytic_wire(wire), bound, shape=spiral, units=unit)
        except ValueError as error:  # NoSolutionError too: the wire is kept, named, with the reason
            paths.append((label, joints, 0, math.nan, 0, f"not made G2: {error}", 0, False))
            continue
        changed = sum(j.kind not in ("g2", "split") for j in result.joints)
        for old in originals:
            reshape.Remove(old)
        made.append(new)
        pieces = sum(len(c) for c in result.chains)
        paths.append((label, joints, changed, float(result.deviation), len(result.splits), "", pieces, True))
    for gap in gaps:  # an input joint left below G0: counted and named
        paths.append((f"{name}, a gap", 1, 0, math.nan, 0, gap, 0, False))
    if not made:
        return None
    if shape.ShapeType() in (TopAbs_WIRE, TopAbs_EDGE) and len(made) == 1:
        return made[0]
    rest = reshape.Apply(shape)
    builder, compound = BRep_Builder(), TopoDS_Compound()
    builder.MakeCompound(compound)
    if not rest.IsNull():
        if rest.ShapeType() == TopAbs_COMPOUND:
            children = TopoDS_Iterator(rest)
            while children.More():
                builder.Add(compound, children.Value())
                children.Next()
        else:
            builder.Add(compound, rest)
    for wire in made:
        builder.Add(compound, wire)
    return compound
