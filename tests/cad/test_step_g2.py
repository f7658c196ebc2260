"""``spiral-cad g2`` on STEP and IGES files: the wires made G2 in place, judged by OCCT's own readers and FreeCAD."""

from __future__ import annotations

import os
import re
import subprocess
from pathlib import Path

import build123d as bd
import pytest
from OCP.BRepAdaptor import BRepAdaptor_Curve
from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeVertex
from OCP.BRepExtrema import BRepExtrema_DistShapeShape
from OCP.BRepTools import BRepTools_WireExplorer
from OCP.gp import gp_Pnt, gp_Vec
from OCP.IFSelect import IFSelect_RetDone
from OCP.ShapeAnalysis import ShapeAnalysis_FreeBounds
from OCP.TopAbs import TopAbs_EDGE, TopAbs_FACE, TopAbs_REVERSED, TopAbs_SOLID, TopAbs_WIRE
from OCP.TopExp import TopExp_Explorer
from OCP.TopoDS import TopoDS
from OCP.TopTools import TopTools_HSequenceOfShape

from spiral_cad.app.cli import main
from spiral_cad.app.g2_document import make_document_g2
from spiral_cad.cad.export import export_iges, export_step

FREECAD = Path("/usr/lib/freecad-python3/lib")


def _occt_read(path: Path, mm_per_unit: float):
    """The file read by OCCT's own reader (not ours), in a unit of ``mm_per_unit`` millimetres."""
    if path.suffix.lower() in (".step", ".stp"):
        from OCP.STEPControl import STEPControl_Reader

        reader = STEPControl_Reader()
        assert reader.ReadFile(str(path)) == IFSelect_RetDone
        reader.SetSystemLengthUnit(mm_per_unit)
    else:
        from OCP.IGESControl import IGESControl_Reader

        reader = IGESControl_Reader()
        assert reader.ReadFile(str(path)) == IFSelect_RetDone
        section = reader.IGESModel().GlobalSection()
        section.SetCascadeUnit(mm_per_unit)
        reader.IGESModel().SetGlobalSection(section)
    assert reader.TransferRoots() > 0
    return reader.OneShape()


def _wires(shape) -> list:
    """The shape's wires that bound no face and its loose edges chained by OCCT (ShapeAnalysis_FreeBounds)."""
    wires = []
    explorer = TopExp_Explorer(shape, TopAbs_WIRE, TopAbs_FACE)
    while explorer.More():
        wires.append(TopoDS.Wire_s(explorer.Current()))
        explorer.Next()
    loose = TopTools_HSequenceOfShape()
    explorer = TopExp_Explorer(shape, TopAbs_EDGE, TopAbs_WIRE)
    while explorer.More():
        loose.Append(explorer.Current())
        explorer.Next()
    if loose.Length():
        joined = TopTools_HSequenceOfShape()
        ShapeAnalysis_FreeBounds.ConnectEdgesToWires_s(loose, 1e-7, False, joined)
        wires += [TopoDS.Wire_s(joined.Value(i)) for i in range(1, joined.Length() + 1)]
    return wires


def _frame(edge, at_start: bool):
    """(point, unit tangent, curvature vector) at an end of ``edge`` in its travel sense, from OCCT's D2."""
    curve = BRepAdaptor_Curve(edge)
    reverse = edge.Orientation() == TopAbs_REVERSED
    u = curve.FirstParameter() if at_start != reverse else curve.LastParameter()
    p, d1, d2 = gp_Pnt(), gp_Vec(), gp_Vec()
    curve.D2(u, p, d1, d2)
    speed = d1.Magnitude()
    t = d1.Divided(speed)
    k = d2.Subtracted(t.Multiplied(d2.Dot(t))).Divided(speed * speed)
    return p, (t.Reversed() if reverse else t), k


def _joints(wire) -> list[tuple[float, float]]:
    """(tangent angle, relative curvature jump) at every joint of the wire (its closing joint when closed)."""
    edges = []
    explorer = BRepTools_WireExplorer(wire)
    while explorer.More():
        edges.append(explorer.Current())
        explorer.Next()
    pairs = list(zip(edges, edges[1:]))
    first, last = _frame(edges[0], True), _frame(edges[-1], False)
    if len(edges) > 1 and first[0].Distance(last[0]) < 1e-7:
        pairs.append((edges[-1], edges[0]))
    found = []
    for a, b in pairs:
        (_, ta, ka), (_, tb, kb) = _frame(a, False), _frame(b, True)
        angle = ta.Angle(tb)
        scale = max(ka.Magnitude(), kb.Magnitude(), 1e-3)
        found.append((angle, ka.Subtracted(kb).Magnitude() / scale))
    return found


def _samples(wire, count: int = 12) -> list[gp_Pnt]:
    points = []
    explorer = TopExp_Explorer(wire, TopAbs_EDGE)
    while explorer.More():
        curve = BRepAdaptor_Curve(TopoDS.Edge_s(explorer.Current()))
        u0, u1 = curve.FirstParameter(), curve.LastParameter()
        points += [curve.Value(u0 + (u1 - u0) * k / count) for k in range(count + 1)]
        explorer.Next()
    return points


def _distance(points: list[gp_Pnt], wire) -> float:
    """The largest distance from the points to the wire (OCCT's BRepExtrema)."""
    worst = 0.0
    for p in points:
        measure = BRepExtrema_DistShapeShape(BRepBuilderAPI_MakeVertex(p).Vertex(), wire)
        worst = max(worst, measure.Value())
    return worst


def _judge(source: Path, target: Path, bound: float, mm_per_unit: float, read_in: float) -> int:
    """The output read by OCCT in another unit: every wire G2 at every joint and within the bound of its input wire,
    both ways; returns the number of wires."""
    scale = mm_per_unit / read_in  # file units → the units read in
    before, after = _wires(_occt_read(source, read_in)), _wires(_occt_read(target, read_in))
    assert len(before) == len(after)
    for wire in after:
        for angle, jump in _joints(wire):
            assert angle <= 1e-6 and jump <= 1e-5, (angle, jump)
        twin = min(before, key=lambda w: _distance(_samples(wire, 2)[:3], w))
        assert _distance(_samples(wire), twin) <= bound * scale * (1 + 1e-6)
        assert _distance(_samples(twin), wire) <= bound * scale * (1 + 1e-6)
    return len(after)


def _solids(shape) -> list:
    found, explorer = [], TopExp_Explorer(shape, TopAbs_SOLID)
    while explorer.More():
        found.append(bd.Solid(explorer.Current()))
        explorer.Next()
    return found


def _freecad(path: Path) -> tuple[int, int, int] | None:
    """(wires, edges, solids) as FreeCAD's Part.read reads the file; None without FreeCAD."""
    if not FREECAD.is_dir():
        return None
    code = f"import sys; sys.path.append({str(FREECAD)!r}); import FreeCAD, Part; s = Part.read({str(path)!r}); print(len(s.Wires), len(s.Edges), len(s.Solids))"
    done = subprocess.run(["python3", "-c", code], capture_output=True, text=True, timeout=60, env={**os.environ, "PYTHONPATH": ""})
    numbers = re.findall(r"^(\d+) (\d+) (\d+)$", done.stdout, flags=re.M)
    assert numbers, done.stdout + done.stderr
    wires, edges, solids = (int(n) for n in numbers[-1])
    return wires, edges, solids


def _part(tmp_path: Path) -> Path:
    """A STEP file as build123d writes it: a filleted polyline (lines and tangent arcs), a square and a named box."""
    contour = bd.FilletPolyline((0, 0), (40, 0), (40, 20), (0, 20), radius=5, close=True)
    square = bd.Polyline((50, 0), (60, 0), (60, 10), (50, 10), close=True)
    block = bd.Box(10, 10, 10).moved(bd.Location((100, 0, 0)))
    part = bd.Compound([contour, square, block])
    part.label = "plate contour"
    path = tmp_path / "part.step"
    bd.export_step(part, path)
    return path


def test_step_wires_made_g2_solid_and_names_kept(tmp_path: Path, capsys) -> None:
    source = _part(tmp_path)
    target = tmp_path / "part_g2.step"
    original = source.read_bytes()
    assert main(["g2", str(source), "--max-deviation", "0.01", "-o", str(target)]) == 0
    out = capsys.readouterr().out
    assert "2 of 2 path(s) made G2" in out and "1 solid(s) kept" in out
    assert source.read_bytes() == original and target.read_bytes() != original
    assert _judge(source, target, 0.01, 1.0, 1000.0) == 2  # written in mm, read in metres
    (solid_in,), (solid_out,) = _solids(_occt_read(source, 1.0)), _solids(_occt_read(target, 1.0))
    assert solid_out.volume == pytest.approx(solid_in.volume, rel=1e-12) and len(solid_out.faces()) == len(solid_in.faces())
    names = re.compile(rb"PRODUCT\('([^']*)'")
    assert names.findall(target.read_bytes()) == names.findall(original) == [b"plate contour"]
    fc_in, fc_out = _freecad(source), _freecad(target)
    if fc_in is not None:  # FreeCAD reads as many wires and solids; each G1 joint became a spiral (more edges)
        assert (fc_out[0], fc_out[2]) == (fc_in[0], fc_in[2]) and fc_out[1] > fc_in[1]


def test_idempotent(tmp_path: Path) -> None:
    source = _part(tmp_path)
    once, twice = tmp_path / "once.step", tmp_path / "twice.step"
    make_document_g2(source, once, 0.01)
    report = make_document_g2(once, twice, 0.01)
    assert [p.kept for p in report.paths] == ["G2 already"] * 2 and not report.below_g2
    a, b = _wires(_occt_read(once, 1.0)), _wires(_occt_read(twice, 1.0))
    assert len(a) == len(b) == 2
    for wire in b:
        assert min(_distance(_samples(wire), w) for w in a) <= 1e-9


def test_iges_in_inches(tmp_path: Path) -> None:
    contour = bd.FilletPolyline((0, 0), (4, 0), (4, 2), (0, 2), radius=0.5, close=True)
    square = bd.Polyline((5, 0), (6, 0), (6, 1), (5, 1), close=True)
    source, target = tmp_path / "plate.igs", tmp_path / "plate_g2.igs"
    export_iges(bd.Compound([contour, square, bd.Box(1, 1, 1).moved(bd.Location((10, 0, 0)))]), source, units="in")
    report = make_document_g2(source, target, 0.001)
    assert report.units == "in" and len(report.paths) == 2 and not report.below_g2
    (solid_in,), (solid_out,) = _solids(_occt_read(source, 1.0)), _solids(_occt_read(target, 1.0))  # a BRep solid stays one
    assert solid_out.volume == pytest.approx(solid_in.volume, rel=1e-12) and solid_in.volume == pytest.approx(25.4**3)  # in mm
    assert 0 < report.worst <= 0.001
    assert b"4HINCH" in target.read_bytes()
    assert _judge(source, target, 0.001, 25.4, 1.0) == 2  # written in inches, read in mm
    fc_in, fc_out = _freecad(source), _freecad(target)
    if fc_in is not None:
        assert (fc_out[0], fc_out[2]) == (fc_in[0], fc_in[2]) == (8, 1)  # the two wires and the box's six faces' wires


def test_step_in_inches_of_connected_edge_sets(tmp_path: Path) -> None:
    """Our own writer: wires as CONNECTED_EDGE_SETs of B-spline edges (lines and arcs as B-splines), in inches."""
    contour = bd.FilletPolyline((0, 0), (4, 0), (4, 2), (0, 2), radius=0.5, close=True)
    source, target = tmp_path / "inch.step", tmp_path / "inch_g2.stp"
    export_step(bd.Compound([contour, bd.Box(1, 1, 1)]), source, units="in")
    report = make_document_g2(source, target, 0.002)
    assert report.units == "in" and [p.changed for p in report.paths] == [8] and not report.below_g2
    assert b"'INCH'" in target.read_bytes()
    assert _judge(source, target, 0.002, 25.4, 1.0) == 1
    imported = bd.import_step(target)  # build123d reads millimetres
    assert imported.bounding_box().size.X == pytest.approx(4.5 * 25.4, rel=1e-6)  # the box reaches x = -0.5 in


def test_wires_that_cannot_be_made_g2_are_kept_and_named(tmp_path: Path, capsys) -> None:
    contour = bd.FilletPolyline((0, 0), (40, 0), (40, 20), (0, 20), radius=5, close=True)
    crooked = bd.Polyline((50, 0, 0), (60, 0, 0), (60, 10, 5), (50, 10, 0))  # not planar: make_g2 takes plane paths
    source, target = tmp_path / "bad.step", tmp_path / "bad_g2.step"
    bd.export_step(bd.Compound([contour, crooked]), source)
    assert main(["g2", str(source), "--max-deviation", "0.01", "-o", str(target)]) == 1
    out = capsys.readouterr().out
    kept = [line for line in out.splitlines() if "kept as is" in line]
    assert len(kept) == 1 and "(3 edge(s))" in kept[0] and "not made G2" in kept[0] and "plane" in kept[0]
    assert "1 of 2 path(s) made G2" in out and "FAIL: 1 left below G2" in out
    crooked_in = [w for w in _wires(_occt_read(source, 1.0)) if len(_samples(w, 1)) == 6]
    crooked_out = [w for w in _wires(_occt_read(target, 1.0)) if len(_samples(w, 1)) == 6]
    assert len(crooked_in) == len(crooked_out) == 1
    assert _distance(_samples(crooked_out[0]), crooked_in[0]) <= 1e-9  # kept as it was
    assert main(["g2", str(source), "--max-deviation", "0.01", "-o", str(target), "--allow-splits"]) == 0


def test_refusals(tmp_path: Path, capsys) -> None:
    source = _part(tmp_path)
    with pytest.raises(ValueError, match="is the input"):
        make_document_g2(source, source, 0.01)
    with pytest.raises(ValueError, match="not the kind"):
        make_document_g2(source, tmp_path / "part.igs", 0.01)
    with pytest.raises(ValueError, match="units"):
        make_document_g2(source, tmp_path / "out.step", 0.01, units="in")
    assert main(["g2", str(source), "--max-deviation", "-1", "-o", str(tmp_path / "o.step")]) == 2
    assert "max_deviation" in capsys.readouterr().err
    broken = tmp_path / "broken.step"
    broken.write_text("ISO-10303-21;\nHEADER;\n")
    assert main(["g2", str(broken), "--max-deviation", "0.01", "-o", str(tmp_path / "o.step")]) == 2
    assert not (tmp_path / "o.step").exists()


def _names_and_colours(path: Path) -> dict[str, tuple[str, list]]:
    """Every shape label's name → (shape type, its colours), as OCCT's XDE reads the file."""
    from OCP.Quantity import Quantity_Color
    from OCP.STEPCAFControl import STEPCAFControl_Reader
    from OCP.TCollection import TCollection_ExtendedString
    from OCP.TDataStd import TDataStd_Name
    from OCP.TDF import TDF_LabelSequence
    from OCP.TDocStd import TDocStd_Document
    from OCP.XCAFApp import XCAFApp_Application
    from OCP.XCAFDoc import XCAFDoc_ColorType, XCAFDoc_DocumentTool

    doc = TDocStd_Document(TCollection_ExtendedString("MDTV-XCAF"))
    XCAFApp_Application.GetApplication_s().InitDocument(doc)
    reader = STEPCAFControl_Reader()
    reader.SetColorMode(True)
    reader.SetNameMode(True)
    assert reader.ReadFile(str(path)) == IFSelect_RetDone and reader.Transfer(doc)
    shapes, colours = XCAFDoc_DocumentTool.ShapeTool_s(doc.Main()), XCAFDoc_DocumentTool.ColorTool_s(doc.Main())
    labels = TDF_LabelSequence()
    shapes.GetShapes(labels)
    found = {}
    for i in range(1, labels.Length() + 1):
        label, name = labels.Value(i), TDataStd_Name()
        assert label.FindAttribute(TDataStd_Name.GetID_s(), name)
        shape, its = shapes.GetShape_s(label), []
        for kind in (XCAFDoc_ColorType.XCAFDoc_ColorGen, XCAFDoc_ColorType.XCAFDoc_ColorSurf, XCAFDoc_ColorType.XCAFDoc_ColorCurv):
            colour = Quantity_Color()
            if colours.GetColor(shape, kind, colour):
                its.append((round(colour.Red(), 3), round(colour.Green(), 3), round(colour.Blue(), 3)))
        found[name.Get().ToExtString()] = (shape.ShapeType().name, its)
    return found


def test_assembly_names_and_colours_kept(tmp_path: Path) -> None:
    """A CadQuery assembly: a blue block and a red contour, each a named product; the contour is made G2 in place."""
    import cadquery as cq

    contour = bd.FilletPolyline((0, 0), (40, 0), (40, 20), (0, 20), radius=5, close=True)
    assembly = cq.Assembly(name="plate")
    assembly.add(cq.Workplane().box(10, 10, 10).translate((100, 0, 0)), name="block", color=cq.Color("blue"))
    assembly.add(cq.Shape.cast(contour.wrapped), name="contour", color=cq.Color("red"))
    source, target = tmp_path / "plate.step", tmp_path / "plate_g2.step"
    assembly.export(str(source))
    report = make_document_g2(source, target, 0.01)
    assert [(p.name.split(",")[0], p.changed) for p in report.paths] == [("contour", 8)]
    before, after = _names_and_colours(source), _names_and_colours(target)
    assert after == before and after["block"][1] == [(0.0, 0.0, 1.0)] and after["contour"][1] == [(1.0, 0.0, 0.0)]
    assert _judge(source, target, 0.01, 1.0, 1000.0) == 1


def test_short_spirals_stay_g2_through_the_written_digits(tmp_path: Path) -> None:
    """An arrow of sharp corners in inches: its spiral pairs are short, so OCCT's 9-digit IGES reals would break G2
    at their ends (a curvature jump of 0.006); the file is printed with 17 digits."""
    arrow = bd.Polyline((0, 0), (4, 0), (4, -0.3), (4.6, 0.25), (4, 0.8), (4, 0.5), (0, 0.5), close=True)
    source, target = tmp_path / "arrow.igs", tmp_path / "arrow_g2.igs"
    export_iges(arrow, source, units="in")
    report = make_document_g2(source, target, 0.01)
    assert [p.changed for p in report.paths] == [7]
    assert _judge(source, target, 0.01, 25.4, 1.0) == 1


def test_gaps_closed_within_half_the_bound_and_wider_ones_named(tmp_path: Path, capsys) -> None:
    """Loose edges that almost meet: gaps up to half the bound are closed (one closed G2 wire, as `check` chains them);
    a wider gap, as `check` would call a G0 failure, is named and counted below G2."""
    near = bd.Compound([bd.Polyline((0, 0), (10, 0), (10, 10)), bd.Polyline((10.001, 10), (0, 10), (0, 0.0005))])
    source, target = tmp_path / "near.step", tmp_path / "near_g2.step"
    bd.export_step(near, source)
    report = make_document_g2(source, target, 0.01)
    assert [(p.changed, p.joints) for p in report.paths] == [(4, 4)] and not report.below_g2
    (wire,) = _wires(_occt_read(target, 1.0))
    assert len(_joints(wire)) == 12 and all(angle <= 1e-6 and jump <= 1e-5 for angle, jump in _joints(wire))  # closed
    apart = bd.Compound([bd.Polyline((0, 0), (10, 0), (10, 10)), bd.Polyline((10.05, 10), (0, 10), (0, 0))])
    source = tmp_path / "apart.step"
    bd.export_step(apart, source)
    assert main(["g2", str(source), "--max-deviation", "0.01", "-o", str(tmp_path / "apart_g2.step")]) == 1
    out = capsys.readouterr().out
    assert "a gap: kept as is (the two ends of wire 1 are 0.05 mm apart" in out and "FAIL: 1 left below G2" in out
