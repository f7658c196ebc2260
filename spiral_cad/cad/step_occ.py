"""STEP for shapes that are not chains (solids, faces, wires from build123d/CadQuery/OCP), through OCCT's writer.

The shape's numbers are taken to be in the given unit and written unscaled
with that unit declared (``write.step.unit`` with the model's local length
unit set to match); the product is named after the design and the header's
originating system is ``spiral_cad <version>``, with empty author and
organisation. Reals are printed with 17 significant digits.

OCCT's writer would print a name's non-ASCII characters as raw UTF-8 and a
quote before ``)`` in a form its own reader cannot parse, so it is given a
random ASCII placeholder that is then replaced by the name encoded as
ISO 10303-21 requires (``spiral_cad.io.names.step_string``); the
product is named exactly ``name`` (OCCT would append a counter).

**One product.** OCCT writes a compound as an assembly by default
(``write.step.assembly`` Auto): one product per member plus one above them,
which FreeCAD 0.20's ``Import.insert`` cannot take (it crashed on a solid and
its centre line written so). Assemblies are switched off for the transfer, so
every file holds ONE ``PRODUCT`` whose ``SHAPE_REPRESENTATION`` lists all its
items. **Wires stay wires.** OCCT writes wires and loose edges only as a
``GEOMETRIC_CURVE_SET`` of loose trimmed curves (readers get loose edges and
lose the order); so the solids, shells and faces go through OCCT and every
wire is written here as a ``CONNECTED_EDGE_SET`` of ``EDGE_CURVE`` entities in
wire order, consecutive edges sharing their vertex (as
``spiral_cad.io.step`` writes chains), in one
``EDGE_BASED_WIREFRAME_MODEL`` added to that same representation, in the
same context and unit. Each edge's curve is its exact B-spline (a rational
one as ``RATIONAL_B_SPLINE_CURVE``; other curves converted by
``GeomConvert``), trimmed to the edge and running with it.
"""

from __future__ import annotations

import os
import re
import secrets
from pathlib import Path
from typing import Any

from OCP.APIHeaderSection import APIHeaderSection_MakeHeader
from OCP.BRep import BRep_Builder, BRep_Tool
from OCP.BRepTools import BRepTools_WireExplorer
from OCP.Geom import Geom_BSplineCurve, Geom_TrimmedCurve
from OCP.GeomConvert import GeomConvert
from OCP.IFSelect import IFSelect_ReturnStatus
from OCP.Interface import Interface_Static
from OCP.StepAP214 import StepAP214
from OCP.STEPControl import STEPControl_AsIs, STEPControl_Writer
from OCP.StepData import StepData_StepWriter
from OCP.TCollection import TCollection_HAsciiString
from OCP.TopAbs import TopAbs_EDGE, TopAbs_FACE, TopAbs_REVERSED, TopAbs_SHELL, TopAbs_SOLID, TopAbs_VERTEX, TopAbs_WIRE
from OCP.TopExp import TopExp_Explorer
from OCP.TopoDS import TopoDS, TopoDS_Compound, TopoDS_Edge, TopoDS_Shape

from ..core.units import MM_PER_UNIT
from ..io.names import step_string
from ..io.step import real
from .console import captured_messages
from .occ import as_occ_shape, print_model

#: OCCT's names for ``write.step.unit``.
_STEP_UNIT = {"mm": "MM", "cm": "CM", "m": "M", "km": "KM", "in": "INCH", "ft": "FT"}


def write_shape_step(
    obj: Any,
    path: str | os.PathLike,
    name: str,
    units: str,
    originating_system: str,
    description: str | None = None,
    *,
    occt_wires: bool = False,
) -> None:
    """Write any OCP/build123d/CadQuery shape as STEP AP214 in ``units``, as one product (``description``:
    the header's FILE_DESCRIPTION, printable ASCII without quotes or backslashes).

    ``occt_wires=True`` leaves wires and edges to OCCT too (loose trimmed curves: what OCCT's own
    writer makes of them, for comparison in benchmarks).

    Raises:
        ValueError: ``obj`` is not a shape, holds nothing or loose vertices.
        OSError: the transfer or the printing failed.
    """
    shape = as_occ_shape(obj)
    if description is not None and not (description.isascii() and description.isprintable() and not set("'\\") & set(description)):
        raise ValueError(f"a STEP description must be printable ASCII without quotes or backslashes; got {description!r:.80}")
    solids, wires = (shape, []) if occt_wires else _split(shape)
    placeholder = f"SPIRALCADNAME{secrets.token_hex(12).upper()}"
    STEPControl_Writer()  # registers the write.step.* parameters (a new model reads them when made)
    assembly = Interface_Static.IVal_s("write.step.assembly")
    unit, product = Interface_Static.CVal_s("write.step.unit"), Interface_Static.CVal_s("write.step.product.name")
    Interface_Static.SetIVal_s("write.step.assembly", 0)  # one product, never an assembly of its members
    Interface_Static.SetCVal_s("write.step.unit", _STEP_UNIT[units])
    Interface_Static.SetCVal_s("write.step.product.name", placeholder)
    try:
        writer = STEPControl_Writer()
        writer.Model().SetLocalLengthUnit(MM_PER_UNIT[units])  # the shape is in the file unit: no rescaling
        with captured_messages():
            status = writer.Transfer(solids, STEPControl_AsIs)
    finally:  # other writers in this process (build123d's, CadQuery's) keep their own settings: the unit above all
        Interface_Static.SetIVal_s("write.step.assembly", assembly)
        Interface_Static.SetCVal_s("write.step.unit", unit)
        Interface_Static.SetCVal_s("write.step.product.name", product)
    if status != IFSelect_ReturnStatus.IFSelect_RetDone:
        raise OSError(f"STEP transfer failed for {name!r}")
    header = APIHeaderSection_MakeHeader(writer.Model())
    header.SetName(TCollection_HAsciiString(placeholder))
    header.SetOriginatingSystem(TCollection_HAsciiString(originating_system))
    header.SetPreprocessorVersion(TCollection_HAsciiString(originating_system))
    header.SetAuthorValue(1, TCollection_HAsciiString(""))
    header.SetOrganizationValue(1, TCollection_HAsciiString(""))
    header.SetAuthorisation(TCollection_HAsciiString(""))
    if description is not None:
        header.SetDescriptionValue(1, TCollection_HAsciiString(description))
    print_model(StepData_StepWriter(writer.Model()), StepAP214.Protocol_s(), path, "STEP")
    text = Path(path).read_bytes()
    if wires:
        text = _add_wires(text, wires, name)
    # OCCT appends a per-session counter to the product name ("NAME 1", "NAME 2", …): drop it
    encoded = step_string(name)[1:-1].encode("ascii")
    text, count = re.subn(re.escape(placeholder.encode()) + rb"( \d+)?", lambda _: encoded, text)
    if count < 2:  # the product and the header
        raise OSError(f"the STEP writer did not write the product name for {name!r}")
    Path(path).write_bytes(text)


def _split(shape: TopoDS_Shape) -> tuple[TopoDS_Compound, list[list[TopoDS_Edge]]]:
    """The shape's solids, shells and faces (one compound, for OCCT) and its wires and loose edges
    (each as its edges in travel order).

    Raises:
        ValueError: the shape holds nothing to write, or loose vertices (no STEP curve holds them).
    """
    builder = BRep_Builder()
    solids = TopoDS_Compound()
    builder.MakeCompound(solids)
    wires: list[list[TopoDS_Edge]] = []
    count = 0
    for kind, inside in ((TopAbs_SOLID, None), (TopAbs_SHELL, TopAbs_SOLID), (TopAbs_FACE, TopAbs_SHELL)):
        explorer = TopExp_Explorer(shape, kind) if inside is None else TopExp_Explorer(shape, kind, inside)
        while explorer.More():
            builder.Add(solids, explorer.Current())
            count += 1
            explorer.Next()
    explorer = TopExp_Explorer(shape, TopAbs_WIRE, TopAbs_FACE)
    while explorer.More():
        walk = BRepTools_WireExplorer(TopoDS.Wire_s(explorer.Current()))
        edges = []
        while walk.More():
            edges.append(walk.Current())
            walk.Next()
        if edges:
            wires.append(edges)
        explorer.Next()
    explorer = TopExp_Explorer(shape, TopAbs_EDGE, TopAbs_WIRE)
    while explorer.More():
        wires.append([TopoDS.Edge_s(explorer.Current())])
        explorer.Next()
    if TopExp_Explorer(shape, TopAbs_VERTEX, TopAbs_EDGE).More():
        raise ValueError("the shape holds loose vertices; STEP here takes solids, shells, faces, wires and edges")
    if not count and not wires:
        raise ValueError("the shape is empty: nothing to write as STEP")
    return solids, wires


class _Numbered:
    """New DATA-section instances numbered on from ``start``."""

    def __init__(self, start: int) -> None:
        self.start = start
        self.lines: list[str] = []

    def add(self, text: str) -> str:
        self.lines.append(f"#{self.start + len(self.lines)} = {text};")
        return f"#{self.start + len(self.lines) - 1}"

    def point(self, xyz) -> str:
        return self.add(f"CARTESIAN_POINT('',({','.join(real(v) for v in xyz)}))")


def _edge_bspline(edge: TopoDS_Edge) -> Geom_BSplineCurve:
    """The edge's curve as a B-spline on exactly the edge, running in the edge's direction."""
    first, last = BRep_Tool.Range_s(edge)
    curve = BRep_Tool.Curve_s(edge, first, last)  # (placed by the edge's location)
    if curve is None:
        raise ValueError("an edge without a 3-D curve cannot be written as STEP")
    spline = GeomConvert.CurveToBSplineCurve_s(Geom_TrimmedCurve(curve, first, last))
    if spline.FirstParameter() != first or spline.LastParameter() != last:
        spline = spline.Copy()  # (OCP hands back the B-spline itself)
        spline.Segment(first, last)
    if edge.Orientation() == TopAbs_REVERSED:
        spline = spline.Reversed()
    return spline


def _bspline_text(data: _Numbered, spline: Geom_BSplineCurve, start: str, end: str) -> str:
    """A B_SPLINE_CURVE_WITH_KNOTS (rational: the complex instance) whose first and last poles are ``start`` and ``end``."""
    poles = [start] + [data.point(spline.Pole(i).Coord()) for i in range(2, spline.NbPoles())] + [end]
    knots = ",".join(real(spline.Knot(i)) for i in range(1, spline.NbKnots() + 1))
    mults = ",".join(str(spline.Multiplicity(i)) for i in range(1, spline.NbKnots() + 1))
    degree, closed = spline.Degree(), ".F."
    if not spline.IsRational():
        return data.add(f"B_SPLINE_CURVE_WITH_KNOTS('',{degree},({','.join(poles)}),.UNSPECIFIED.,{closed},.F.,"
                        f"({mults}),({knots}),.UNSPECIFIED.)")  # fmt: skip
    weights = ",".join(real(spline.Weight(i)) for i in range(1, spline.NbPoles() + 1))
    return data.add(
        f"( BOUNDED_CURVE() B_SPLINE_CURVE({degree},({','.join(poles)}),.UNSPECIFIED.,{closed},.F.) "
        f"B_SPLINE_CURVE_WITH_KNOTS(({mults}),({knots}),.UNSPECIFIED.) CURVE() GEOMETRIC_REPRESENTATION_ITEM() "
        f"RATIONAL_B_SPLINE_CURVE(({weights})) REPRESENTATION_ITEM('') )"
    )


def _add_wires(text: bytes, wires: list[list[TopoDS_Edge]], name: str) -> bytes:
    """``text`` (OCCT's file) with ``wires`` as connected edge sets of one wireframe model in its product's representation."""
    # (a lone solid comes as an ADVANCED_BREP_SHAPE_REPRESENTATION, whose items may only be solids: it
    # becomes its supertype, the plain SHAPE_REPRESENTATION OCCT itself writes for mixed items)
    found = re.search(rb"#(\d+)\s*=\s*(?:ADVANCED_BREP_)?SHAPE_REPRESENTATION\s*\(\s*'[^']*'\s*,\s*\(([^)]*)\)\s*,\s*(#\d+)\s*\)\s*;", text)
    if found is None:
        raise OSError(f"the STEP writer wrote no shape representation for {name!r}")
    data = _Numbered(1 + max(int(n) for n in re.findall(rb"^#(\d+)\s*=", text, flags=re.M)))
    sets = []
    for edges in wires:
        splines = [_edge_bspline(e) for e in edges]
        ends = [data.point(splines[0].StartPoint().Coord())]
        for i, spline in enumerate(splines):
            following = splines[i + 1].StartPoint() if i + 1 < len(splines) else None
            if (
                following is None
                and len(splines) > 1
                and spline.EndPoint().Distance(splines[0].StartPoint()) <= BRep_Tool.Tolerance_s(edges[0])
            ):
                ends.append(ends[0])  # a closed wire ends on its first vertex
            else:
                ends.append(data.point((following or spline.EndPoint()).Coord()))
        vertices: dict[str, str] = {}
        for point in ends:
            if point not in vertices:
                vertices[point] = data.add(f"VERTEX_POINT('',{point})")
        curves = [_bspline_text(data, spline, a, b) for spline, a, b in zip(splines, ends, ends[1:])]
        edge_curves = [data.add(f"EDGE_CURVE('',{vertices[a]},{vertices[b]},{c},.T.)") for c, a, b in zip(curves, ends, ends[1:])]
        sets.append(data.add(f"CONNECTED_EDGE_SET('',({','.join(edge_curves)}))"))
    model = data.add(f"EDGE_BASED_WIREFRAME_MODEL('',({','.join(sets)}))")
    items = found.group(2).strip()
    representation = f"#{found.group(1).decode()} = SHAPE_REPRESENTATION('',({items.decode()},{model}),{found.group(3).decode()});"
    text = text[: found.start()] + representation.encode("ascii") + text[found.end() :]
    tail = text.rindex(b"ENDSEC;")
    return text[:tail] + ("\n".join(data.lines) + "\n").encode("ascii") + text[tail:]
