"""What a newcomer types first: the kind of input told by its suffix, and refusals that name the right door."""

from __future__ import annotations

import importlib
import math
import re
import shutil
import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import ezdxf
import pytest

import spiral_cad as sc
from spiral_cad import Chain, line_to_circle
from spiral_cad.app.cli import main
from spiral_cad.app.files import EXPORTS
from spiral_cad.io.gcode import read_gcode

PROGRAM = "G21\nG0 X0 Y0 Z1\nG1 Z-1 F100\nG1 X10 F300\nG3 X20 Y10 I0 J10\nG0 Z1\nM2\n"


def test_build_takes_a_program_or_points_by_their_suffix(tmp_path, capsys):
    program = tmp_path / "plate.nc"
    program.write_text(PROGRAM)
    assert main(["build", str(program), "--max-deviation", "0.01", "-o", str(tmp_path / "out"), "--no-plots"]) == 0
    assert "plate" in capsys.readouterr().out and any((tmp_path / "out").glob("plate*.ngc"))
    points = tmp_path / "survey.csv"
    points.write_text("0,0\n10,0\n20,1\n30,3\n40,6\n")
    assert main(["build", str(points), "--tolerance", "0.5", "-o", str(tmp_path / "fit"), "--no-plots"]) == 0
    assert any((tmp_path / "fit").glob("survey*.step"))


def test_check_judges_a_programs_cutting_paths_run_by_run(tmp_path, capsys):
    """A CNC program: each run of feed moves between rapids one wire, in program order, in the program's
    unit. The plunge meets the first cut at a right angle (G0); the cut runs on tangent into a G3 arc of
    radius 10 (G1: the curvature jumps from 0 to 1/10); the rapid between the runs is not a joint."""
    path = tmp_path / "plate.nc"
    path.write_text(PROGRAM.replace("G0 Z1\nM2", "G0 Z1\nG0 X40 Y0\nG1 Z-1\nG2 X40 Y0 I5 J0\nG0 Z1\nM2"))
    assert main(["check", str(path)]) == 0
    out = capsys.readouterr().out
    assert "plate.nc: 2 wires (3, 2 edges); worst joint G0" in out
    assert "note: wire 0: the moves of program lines 3–5" in out and "note: wire 1: the moves of program lines 8–9" in out
    rows = [line.split() for line in out.splitlines() if line.startswith("      ")]
    assert [(row[0], row[-1]) for row in rows] == [("0", "G0"), ("1", "G1"), ("0", "G0")]
    assert float(rows[0][2]) == pytest.approx(1.5707963, abs=1e-3)  # plunge, then along X (the table's 4 figures)
    assert float(rows[1][2]) == 0.0 and float(rows[1][4]) == pytest.approx(0.1)  # tangent into the arc of radius 10
    assert float(rows[2][4]) == pytest.approx(0.2)  # the plunge, then a whole circle of radius 5
    assert "make_g2: spiral-cad g2 plate.nc -o OUT.nc --max-deviation D" in out
    assert main(["check", str(path), "--require", "G1"]) == 1
    assert "2 separate pieces, expected 1" in capsys.readouterr().out
    circle = tmp_path / "circle.ngc"  # a whole circle at depth, reached by rapids: one closed wire, G2 where it closes
    circle.write_text("G20\nG0 X0 Y0 Z-0.1\nG2 X0 Y0 I0.5 J0 F10\nG0 Z0.1\nM2\n")
    assert main(["check", str(circle), "--require", "G2"]) == 0
    out = capsys.readouterr().out
    assert "gap 1e-07 in" in out and "closed, 1 joint(s), worst G2" in out and out.splitlines()[-1].startswith("OK: ")


@pytest.mark.skipif(
    __import__("spiral_cad.io.rs274", fromlist=["x"]).rs274_executable() is None,
    reason="LinuxCNC's rs274 is not installed (Debian: apt-get install linuxcnc-uspace)",
)
def test_a_program_the_built_in_reader_refuses_is_read_by_rs274(tmp_path, capsys):
    """A drilling cycle (G81): LinuxCNC expands it into its feed moves, one cutting path per hole."""
    path = tmp_path / "drill.ngc"
    path.write_text("G21 G17 G90\nG0 Z5\nG81 X10 Y0 Z-3 R1 F100\nX20\nX30\nG80\nG0 Z5\nM2\n")
    assert main(["check", str(path)]) == 0
    out = capsys.readouterr().out
    assert "note: read by LinuxCNC's rs274 (the built-in reader refused it: drill.ngc line 3: G81 is refused" in out
    assert "note: 3 cutting path(s)" in out


def test_check_reads_the_programs_cam_systems_write_and_says_how(tmp_path, capsys):
    """An arc whose end lies 0.001 mm off its circle (rs274 runs it) is judged about the centre on its chord's
    bisector, and said so; a move on an axis not yet named (from wherever the machine is) is not judged; an arc of three
    turns is one turn and the rest; a run that ends where it began stays open (the tool stops there)."""
    path = tmp_path / "cam.ngc"
    path.write_text("G21 G90 G17\nG1 X0 Y0 Z0 F100\nG1 X10\nG3 X20 Y10 I0 J10.001\nG1 Y20\nG2 X20 Y20 I5 J0 P3\n"
                    "G1 X10 Y30\nG1 X0 Y0\nM2\n")  # fmt: skip
    report = sc.check(path)
    notes = " | ".join(report.notes)
    assert "starts where the program has not said" not in notes  # line 2 names every axis
    after_lift = tmp_path / "lift.ngc"
    after_lift.write_text("G21 G90 G17 F100\nG0 Z5\nG1 X10 Y0\nG1 X20 Y0\nG1 X20 Y10\nM2\n")
    lifted = sc.check(after_lift)  # X and Y are first named on line 3: its move starts where the machine is
    assert "line 3: the move starts where the program has not said (X not named before it): not judged" in lifted.notes
    assert [w.edge_count for w in lifted.wires] == [2]
    assert "line 4: the arc's end lies 0.001 off its circle: judged about the centre moved 0.000707 onto the bisector" in notes
    assert "line 6: an arc of 3 turns, judged on its last two (the turns before run on the same circle)" in notes
    (wire,) = report.wires
    assert not wire.closed and wire.edge_count == 7  # line, arc, line, two halves of the turns, line, line
    with pytest.raises(ValueError, match=r"a program's unit is mm \(G21\) or in \(G20\); got 'cm'"):
        sc.check(path, units="cm")
    assert sc.check(line_to_circle((0, 0), (1, 0), (100, 60), 50.0)).source == "Transition"


def test_check_leaves_helical_moves_out_and_says_so(tmp_path, capsys):
    path = tmp_path / "helix.nc"
    path.write_text("G21\nG0 X0 Y0 Z1\nG1 X10 Z0 F100\nG2 X10 Y0 Z-2 I-5 J0\nG1 X20\nM2\n")
    assert main(["check", str(path)]) == 0
    out = capsys.readouterr().out
    assert "note: 1 helical arc(s) left out: each parts its path" in out
    assert "2 wires (1, 1 edges)" in out


def test_check_judges_a_landxml_alignment_with_the_files_own_radii(capsys):
    """Civil 3D's basic road joins lines and arcs without spirals: every joint G1, the curvature after each
    line the reciprocal of the arc's radius as the file states it (read here with ElementTree)."""
    path = Path(__file__).parents[1] / "data" / "landxml" / "civil3d_gsg_basic_road.xml"
    radii = [float(e.get("radius")) for e in ET.parse(path).iter() if e.tag.endswith("}Curve")]
    assert main(["check", str(path), "--require", "G1"]) == 0
    out = capsys.readouterr().out
    rows = [line.split() for line in out.splitlines() if line.startswith("      ")]
    assert [row[-1] for row in rows] == ["G1"] * 4 and "ft" in out
    assert len(radii) == 2 and [float(row[4]) for row in rows[::2]] == pytest.approx([1 / r for r in radii], rel=1e-5)
    spiral = path.with_name("civil3d_spiral_r63.xml")
    assert main(["check", str(spiral), "--require", "G2"]) == 0
    assert "note: judged on the file's own numbers" in capsys.readouterr().out


LANDXML = (
    '<LandXML xmlns="http://www.landxml.org/schema/LandXML-1.2">{units}<Alignments><Alignment name="K" staStart="0">'
    "<CoordGeom>{elements}</CoordGeom></Alignment></Alignments></LandXML>"
)
METRES = '<Units><Metric linearUnit="meter" angularUnit="radians" directionUnit="radians"/></Units>'


def test_check_finds_a_kink_and_a_radius_jump_the_rebuild_would_smooth(tmp_path):
    """A kink of 0.004 rad between two lines (the reader rebuilds it as one G2 run) is a G0 joint of that
    angle; an arc of radius 300 onto one of radius 400, tangent, is a G1 joint whose curvature jumps by
    1/300 − 1/400 (the file's radii)."""
    kink = tmp_path / "kink.xml"
    kink.write_text(LANDXML.format(units=METRES, elements="<Line><Start>0 0</Start><End>0 100</End></Line>"
                                   "<Line><Start>0 100</Start><End>0.4 200</End></Line>"))  # fmt: skip
    report = sc.check(kink)
    (joint,) = report.wires[0].joints
    assert joint.level.name == "G0" and joint.angle == pytest.approx(0.004, rel=1e-5) and joint.gap == 0.0
    # two arcs turning left through the joint (northing 0, easting 0), heading north there: radius 300 then 400
    # (LandXML points are "northing easting"; the centres lie west of the joint)
    arcs = ('<Curve rot="ccw" radius="300"><Start>-300 -300</Start><Center>0 -300</Center><End>0 0</End></Curve>'
            '<Curve rot="ccw" radius="400"><Start>0 0</Start><Center>0 -400</Center><End>240 -80</End></Curve>')  # fmt: skip
    compound = tmp_path / "compound.xml"
    compound.write_text(LANDXML.format(units=METRES, elements=arcs))
    report = sc.check(compound)
    (joint,) = report.wires[0].joints
    assert joint.level.name == "G1" and joint.curvature_jump == pytest.approx(1 / 300 - 1 / 400, rel=1e-9)
    bare = tmp_path / "bare.xml"
    bare.write_text(LANDXML.format(units="", elements="<Line><Start>0 0</Start><End>0 100</End></Line>"))
    assert "the file states no unit (<Units>): read in m" in sc.check(bare).notes


def test_check_quiet_prints_the_summary_and_the_verdict(tmp_path, capsys):
    path = tmp_path / "plate.nc"
    path.write_text(PROGRAM)
    assert main(["check", str(path), "--quiet", "--require", "G0"]) == 0
    assert capsys.readouterr().out.splitlines() == ["plate.nc: 1 wire of 3 edges; worst joint G0",
                                                    "OK: 1 wire of 3 edges, every joint at least G0"]  # fmt: skip


def test_the_check_verb_judges_files_and_objects(tmp_path):
    bd = pytest.importorskip("build123d")
    program = tmp_path / "plate.nc"
    program.write_text(PROGRAM)
    report = sc.check(program)
    assert report.units == "mm" and len(report.wires) == 1 and report.notes[0].startswith("1 cutting path")
    assert type(sc.check(bd.fillet(bd.Box(10, 10, 10).edges(), 1))).__name__ == "FaceReport"
    assert sc.check(line_to_circle((0, 0), (1, 0), (100, 60), 50.0)).min_level.name == "G2"
    assert sc.check(Chain.join([line_to_circle((0, 0), (1, 0), (100, 60), 50.0)], start=(-20, 0))).units == "mm"
    roads = Path(__file__).parents[1] / "data" / "esmini_lane_offset_junction.xodr"
    assert type(sc.check(roads)).__name__ == "OpenDriveReport"
    with pytest.raises(ValueError, match=r"'plate.nc': check_continuity takes the options gap_tol, .*; got 'feature_angle'"):
        sc.check(program, feature_angle=5)
    with pytest.raises(ValueError, match=r"check: expected a Chain, .*; got int"):
        sc.check(42)
    with pytest.raises(ValueError, match=r"check: format= names a file's format"):
        sc.check(Chain.join([line_to_circle((0, 0), (1, 0), (100, 60), 50.0)], start=(-20, 0)), format="step")


def test_check_refuses_another_kind_of_file_naming_every_kind_it_judges(tmp_path, capsys):
    path = tmp_path / "notes.txt"
    path.write_text("x")
    assert main(["check", str(path)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: notes.txt: check judges STEP/IGES") and "LandXML (.xml)" in err and ".ngc" in err


def test_check_judges_a_drawing_as_drawn(tmp_path, capsys):
    """A DXF drawing's curves, exact, chained by their ends: our own G2 export passes G2; a drawing made with
    ezdxf's own entities (a slot of bulged polyline arcs, a mirrored arc, an ellipse, a spline, a rotated
    block of a circle) is judged at each joint for what it is."""
    g2 = tmp_path / "g2.dxf"
    enter = line_to_circle((0, 0), (1, 0), (100, 60), 50.0)
    leave = line_to_circle((300, 150), (-1, -1), (100, 60), 50.0).reversed()
    sc.export(Chain.join([enter, leave], start=(-20, 0), end=(400, 250), units="mm"), g2)  # line, spiral, arc, spiral, line
    assert main(["check", str(g2), "--require", "G2"]) == 0
    assert "OK: 1 loose piece of 5 edges, every joint at least G2" in capsys.readouterr().out

    doc = ezdxf.new("R2010")
    doc.header["$INSUNITS"] = 4
    msp = doc.modelspace()
    # a slot: lines and half circles as bulges, tangent (G1: the curvature jumps from 0 to 1/5)
    msp.add_lwpolyline([(0, 0, 0, 0, 0), (20, 0, 0, 0, 1), (20, 10, 0, 0, 0), (0, 10, 0, 0, 1)], format="xyseb", close=True)
    # a line, then a clockwise arc drawn in a mirrored coordinate system (extrusion -z), tangent to it
    msp.add_line((100, 0), (110, 0))
    msp.add_arc((-110, -5), 5, 90, 180, dxfattribs={"extrusion": (0, 0, -1)})  # OCS x is −WCS x: centre (110, −5), clockwise
    msp.add_ellipse((200, 0), (10, 0, 0), 0.5)  # whole: closed, G2 all round
    block = doc.blocks.new("HOLE")
    block.add_circle((0, 0), 3)
    msp.add_blockref("HOLE", (300, 0), dxfattribs={"rotation": 30, "xscale": 2, "yscale": 2})
    drawing = tmp_path / "drawing.dxf"
    doc.saveas(drawing)
    assert main(["check", str(drawing), "--require", "G1", "--pieces", "4"]) == 0
    out = capsys.readouterr().out
    assert "4 loose pieces" in out and "worst joint G1" in out and "gap 1e-07 mm" in out
    assert main(["check", str(drawing), "--require", "G2", "--pieces", "4"]) == 1
    out = capsys.readouterr().out
    assert "make_g2: spiral-cad g2 drawing.dxf -o OUT.dxf --max-deviation D" in out and "FAIL: worst joint is G1" in out

    from spiral_cad.cad.continuity import check_continuity
    from spiral_cad.cad.dxf_shape import dxf_shape

    shape, units, notes = dxf_shape(drawing)
    report = check_continuity(shape, units=units)
    slot, line_arc, *whole = report.wires  # the pieces in the drawing's order
    assert units == "mm" and notes == [] and len(slot.joints) == 4 and slot.closed and len(whole) == 2
    assert [str(j.level) for j in slot.joints] == ["G1"] * 4  # tangent, the curvature 0 then 1/5
    assert [str(j.level) for j in line_arc.joints] == ["G1"] and line_arc.joints[0].gap < 1e-9  # the mirrored arc in place
    # the ellipse and the placed circle: each in two halves, so that its closing point is judged too
    assert all(w.closed and len(w.joints) == 2 and str(w.min_level) == "G2" for w in whole)
    assert main(["check", str(drawing), "--zebra", str(tmp_path / "z.png")]) == 2
    assert "a DXF drawing holds curves" in capsys.readouterr().err


def test_a_unitless_drawing_is_named_once_and_told_the_flag(tmp_path, capsys):
    doc = ezdxf.new("R2010")
    doc.header["$INSUNITS"] = 0
    doc.modelspace().add_lwpolyline([(0, 0), (10, 0), (10, 10)])
    doc.saveas(tmp_path / "unitless.dxf")
    assert main(["build", str(tmp_path / "unitless.dxf"), "--max-deviation", "0.01", "-o", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert err.count("unitless.dxf") == 1 and "--units mm" in err


def test_the_straight_move_reader_names_the_reader_of_arcs(tmp_path):
    program = tmp_path / "arcs.nc"
    program.write_text(PROGRAM)
    with pytest.raises(ValueError, match=r"arcs.nc line 5: G3 .* read_gcode_chain"):
        read_gcode(program)


def test_check_advises_a_bound_to_use_and_it_builds(tmp_path, capsys):
    """The make_g2 advice of check is a value to use (a thousandth of the piece's size), in the file's
    unit, beside the smallest that works; the advised bound makes the wire G2 within it."""
    bd = pytest.importorskip("build123d")
    import re

    from spiral_cad.cad.fillet import planar_frame, wire_path
    from spiral_cad.design import make_g2

    wire = bd.FilletPolyline((0, 0), (40, 0), (40, 20), (0, 20), radius=5, close=True)
    path = tmp_path / "plate.step"
    bd.export_step(wire, str(path))
    assert main(["check", str(path)]) == 0
    advice = capsys.readouterr().out.splitlines()[-1]
    found = re.search(r"becomes G2 with max_deviation (\S+) mm \(built and checked; any bound from (\S+) mm works", advice)
    assert found, advice
    use, smallest = float(found[1]), float(found[2])
    assert use == pytest.approx(0.04) and smallest < use  # a thousandth of the 44.7 mm diagonal, one figure
    segments, closed = wire_path(wire.wrapped, planar_frame(wire.wrapped))
    made = make_g2(segments, use, closed=closed)
    assert made.deviation <= use and all(j.kind != "split" for j in made.joints)


def _road() -> Chain:
    return Chain.join([line_to_circle((0, 0), (1, 0), (50, 40), 30)], start=(-100, 0), units="m")


def test_export_writes_every_format_by_its_suffix_and_their_own_readers_take_them(tmp_path):
    """One verb for every format written; each file judged by a reader we did not write."""
    import ifcopenshell
    import xmlschema
    from OCP.IFSelect import IFSelect_RetDone
    from OCP.IGESControl import IGESControl_Reader
    from OCP.STEPControl import STEPControl_Reader

    chain = _road()
    suffixes = {s for suffixes, _ in EXPORTS.values() for s in suffixes[:1]}
    for suffix in sorted(suffixes):
        options = {"step": 1.0} if suffix == ".csv" else {}
        sc.export(chain, tmp_path / f"road{suffix}", **options)
    for reader in (STEPControl_Reader(), IGESControl_Reader()):
        path = tmp_path / ("road.step" if isinstance(reader, STEPControl_Reader) else "road.iges")
        assert reader.ReadFile(str(path)) == IFSelect_RetDone and reader.TransferRoots() > 0
    assert {e.dxftype() for e in ezdxf.readfile(tmp_path / "road.dxf").modelspace()} == {"LINE", "SPLINE"}
    xmlschema.XMLSchema(str(Path(__file__).parents[1] / "data" / "landxml" / "LandXML-1.2.xsd")).validate(str(tmp_path / "road.xml"))
    assert len(ifcopenshell.open(str(tmp_path / "road.ifc")).by_type("IfcAlignment")) == 1
    assert ET.parse(tmp_path / "road.xodr").getroot().tag == "OpenDRIVE"
    assert ET.parse(tmp_path / "road.svg").getroot().tag.endswith("svg")
    assert "G21" in (tmp_path / "road.nc").read_text() and (tmp_path / "road.csv").read_text().count("\n") > 100


def test_read_reads_every_format_by_its_suffix_or_the_format_named(tmp_path):
    chain = _road()
    for suffix in (".step", ".ngc", ".xml", ".xodr", ".ifc"):
        sc.export(chain, tmp_path / f"road{suffix}")
    assert type(sc.read(tmp_path / "road.step")).__name__ == "TopoDS_Shape"
    assert sc.read(tmp_path / "road.ngc").length == pytest.approx(chain.length * 1000.0, rel=1e-6)  # a program in mm
    (tmp_path / "ring.nc").write_text((Path(__file__).parents[2] / "examples" / "pocket.nc").read_text(encoding="utf-8"), encoding="utf-8")
    pocket = sc.read(tmp_path / "ring.nc")  # an ordinary program: its square corners are read, not refused
    assert len(pocket) == 1 and pocket.units == "mm" and pocket.lines[0][0] == 9
    assert pocket.length == pytest.approx(3 + 2 * (50 + 40) + 1 + 50 + 40 + 50 + 35)  # plunge, first ring, plunge, second ring
    for suffix in (".xml", ".xodr", ".ifc"):
        (road,) = sc.read(tmp_path / f"road{suffix}")
    (tmp_path / "road.xml").rename(tmp_path / "road.landxml")
    (alignment,) = sc.read(tmp_path / "road.landxml", format="landxml")
    assert alignment.chain.length == pytest.approx(chain.length, rel=1e-9)
    assert sc.read(tmp_path / "road.step", units="m") is not None  # the reader's own option, passed on
    assert sc.read(tmp_path / "road.step", format="STEP") is not None and sc.read(tmp_path / "road.step", format=".stp") is not None
    sc.export([chain, chain], tmp_path / "two.xml")  # a list of chains: one alignment each, named by place
    assert [a.name for a in sc.read(tmp_path / "two.xml")] == ["spiral_cad 1", "spiral_cad 2"]


def test_a_refused_svg_leaves_the_file_it_would_have_replaced(tmp_path):
    path = tmp_path / "road.svg"
    sc.export(_road(), path)
    before = path.read_bytes()
    for margin in ("x", float("nan"), -1.0):
        with pytest.raises(ValueError, match=r"margin must be a finite number ≥ 0"):
            sc.export(_road(), path, margin=margin)
    assert path.read_bytes() == before


@pytest.mark.parametrize(
    ("call", "message"),
    [
        (
            lambda p: sc.export(_road(), p / "road.pdf"),
            r"export 'road.pdf': the suffix '.pdf' names no format export knows \(.*\.step.*\.xodr",
        ),
        (
            lambda p: sc.export(_road(), p / "road.step", format="parasolid"),
            r"format must be one of step, iges, .* for export; got 'parasolid'",
        ),
        (lambda p: sc.export(_road(), p / "road.dxf", units="m"), r"'road.dxf': export_dxf takes the options name; got 'units'"),
        (lambda p: sc.read(p / "road", format=None), r"read 'road': the suffix '\(none\)' names no format read knows"),
        (lambda p: sc.read(p / "road.svg"), r"the suffix '.svg' names no format read knows"),
        (lambda p: sc.read(p / "road.step", format="iges"), r"'road.step': format='iges' but the suffix '.step' names step"),
        (lambda p: sc.read(p / "gone.xml"), r"read 'gone.xml': the file does not exist"),
        (lambda p: sc.read(p), r"read '.*': the file is a folder"),
        (lambda p: sc.read(None), r"read: path must be a file's path \(str or os.PathLike\); got NoneType"),
        (lambda p: sc.export(_road(), p / "no" / "road.dxf"), r"export 'road.dxf': its folder .* does not exist"),
        (lambda p: sc.export(_road(), p / "road.dxf", format=["dxf"]), r"format must be one of .* got \['dxf'\]"),
        (lambda p: sc.export([], p / "road.xml"), r"write_landxml needs a Chain or an Alignment, or a non-empty list"),
        (lambda p: sc.export(_road(), p / "road.xml", units="mm"), r"the chains are in m; units='mm' would mislabel them"),
    ],
)
def test_the_verbs_refuse_by_name_with_what_they_take(tmp_path, call, message):
    for name in ("road", "road.svg", "road.step"):
        (tmp_path / name).write_text("x")
    with pytest.raises(ValueError, match=message):
        call(tmp_path)


def test_the_verbs_load_the_formats_only_when_used():
    done = subprocess.run([sys.executable, "-c", "import sys, spiral_cad; print('spiral_cad.app.files' in sys.modules); "
                           "spiral_cad.export; print('spiral_cad.app.files' in sys.modules)"], capture_output=True, text=True)  # fmt: skip
    assert done.stdout.split() == ["False", "True"], done.stderr
    loaded = ("'spiral_cad.app.files' in sys.modules, 'spiral_cad.design.g2' in sys.modules, "
              "'spiral_cad.design.rounded_paths' in sys.modules, 'matplotlib' in sys.modules")  # fmt: skip
    done = subprocess.run([sys.executable, "-c", f"import sys, spiral_cad; print({loaded}); spiral_cad.make_g2, spiral_cad.round_corners, "
                           f"spiral_cad.plot; print({loaded})"], capture_output=True, text=True)  # fmt: skip
    assert done.stdout.split() == ["False"] * 4 + ["False", "True", "True", "True"], done.stderr


def test_the_first_verbs_are_at_the_top_level_each_from_its_home():
    from spiral_cad.app.plots import plot
    from spiral_cad.design import make_g2, round_corners

    assert sc.make_g2 is make_g2 and sc.round_corners is round_corners and sc.plot is plot
    assert {"make_g2", "round_corners", "plot", "check", "export", "read"} <= set(sc.__all__)


def test_plot_draws_the_plan_with_its_comb_beside_the_curvature_and_saves_by_suffix(tmp_path):
    from PIL import Image

    chain = _road()
    figure = sc.plot(chain, tmp_path / "road.png")
    plan, profile = figure.axes
    kinds = {type(s).__name__ for s in chain.segments}
    assert {c.get_gid() for c in plan.collections} == {f"{part}-{k}" for part in ("plan", "comb", "envelope") for k in kinds}
    assert {c.get_gid() for c in profile.collections} == {f"curvature-{k}" for k in kinds}
    assert Image.open(tmp_path / "road.png").size == (1100, 450)
    sc.plot(sc.make_g2([(0, 0), (10, 0), (10, 10)], 0.1), tmp_path / "corner.svg", comb=False)  # make_g2's one chain
    assert ET.parse(tmp_path / "corner.svg").getroot().tag.endswith("svg")
    transition = sc.line_to_circle((0, 0), (1, 0), (50, 40), 30)
    assert len(sc.plot(transition).axes[1].collections) == 1  # its spiral
    with pytest.raises(ValueError, match="plot: expected a Chain, a Transition or what holds one chain .*; got int"):
        sc.plot(5)
    with pytest.raises(ValueError, match=r"plot: cannot save '.*road.xyz': Format 'xyz' is not supported"):
        sc.plot(chain, tmp_path / "road.xyz")
    assert not (tmp_path / "road.xyz").exists()


@pytest.mark.parametrize("namespace", ["spiral_cad.io", "spiral_cad.cad"])
def test_the_namespaces_name_their_doors_each_from_its_own_module_loaded_on_first_use(namespace):
    module = importlib.import_module(namespace)
    for name in module.__all__:
        found = getattr(module, name)
        home = importlib.import_module(f"{namespace}.{module._HOMES[name]}")
        assert found is getattr(home, name) and found.__doc__, name
    done = subprocess.run([sys.executable, "-c", f"import sys, {namespace}; print(sorted(m for m in sys.modules if m.startswith('{namespace}.') or m == 'OCP'))"],
                          capture_output=True, text=True)  # fmt: skip
    assert done.stdout.strip() == "[]", done.stderr


def test_build_help_states_the_default_shape_of_each_input(capsys):
    """A newcomer found "default walton-meek" in `build --help` while a drawing was built near-linear."""
    from spiral_cad.app.cli import main

    with pytest.raises(SystemExit):
        main(["build", "--help"])
    text = re.sub(r"-\s+", "-", " ".join(capsys.readouterr().out.split()))  # argparse wraps lines after a hyphen
    assert "default near-linear for a drawing, a road file and --from-points; walton-meek for --from-gcode" in text


def test_batch_imports_as_a_module_and_continuity_names_its_measures():
    done = subprocess.run([sys.executable, "-c", "import spiral_cad.batch as b, spiral_cad; from spiral_cad.batch import line_to_circle; "
                           "print(b is spiral_cad.batch, callable(line_to_circle))"], capture_output=True, text=True)  # fmt: skip
    assert done.stdout.split() == ["True", "True"], done.stderr
    continuity = importlib.import_module("spiral_cad.continuity")
    assert continuity.__all__ and all(getattr(continuity, name).__doc__ for name in continuity.__all__)


def test_names_near_the_file_systems_limit_are_written_and_longer_ones_refused(tmp_path):
    """A file named with 250 characters is written in every format whose writer replaces a file whole (its
    temporary name beside it is cut short); a name past 255 bytes is refused by name, never an OSError."""
    chain = _road()
    for suffix in (".xml", ".nc", ".ifc", ".dxf", ".step"):
        path = tmp_path / ("r" * (250 - len(suffix)) + suffix)
        sc.export(chain, path)
        assert path.stat().st_size > 0
    assert sorted(p.name[:1] for p in tmp_path.iterdir()) == ["r"] * 5  # no temporary file left
    with pytest.raises(ValueError, match=r"a file name of 303 bytes; file systems hold at most 255"):
        sc.export(chain, tmp_path / ("r" * 300 + ".nc"))


def test_check_takes_the_unit_of_a_program_that_states_none_and_never_relabels_one(tmp_path, capsys):
    bare = tmp_path / "bare.nc"
    bare.write_text("G0 X0 Y0\nG1 X10 F100\nM2\n")
    assert main(["check", str(bare)]) == 2
    assert "never says G20 (inches) or G21 (mm)" in capsys.readouterr().err
    assert main(["check", str(bare), "--units", "in", "--require", "G2"]) == 0
    assert "gap 1e-07 in" in capsys.readouterr().out
    stated = tmp_path / "stated.nc"
    stated.write_text(PROGRAM)
    assert main(["check", str(stated), "--units", "in"]) == 2
    assert "error: stated.nc states its unit, mm; the unit given (in) would relabel it" in capsys.readouterr().err
    assert sc.check(bare, units="mm").units == "mm"


def test_check_reads_a_program_of_g5_cubics_as_the_curves_it_states(tmp_path, capsys):
    """Our own LinuxCNC program (spirals as G5 cubics) is judged on its cubics: G2 at every joint."""
    path = tmp_path / "first.ngc"
    enter = line_to_circle((0, 0), (1, 0), (100, 60), 50.0)
    leave = line_to_circle((-20, 120), (1, 0), (100, 60), 50.0).reversed()
    sc.export(Chain.join([enter, leave], start=(-20, 0), end=(-20, 120), units="mm"), path, feed=800)
    report = sc.check(path, curvature_tol=1e-4)  # the printed decimals of the cubics
    assert "G5" in path.read_text() and len(report.wires) == 1 and report.min_level.name == "G2"
    assert [w.edge_count for w in report.wires] == [5]  # line, spiral, arc, spiral, line


def test_a_star_import_after_build123ds_keeps_build123ds_names():
    """``from build123d import *; from spiral_cad import *``: build123d's Circle, Line and Transition stay
    build123d's, and no name the star import brings is one build123d or CadQuery means otherwise."""
    build123d = pytest.importorskip("build123d")
    cadquery = pytest.importorskip("cadquery")
    scope: dict = {}
    exec("from build123d import *\nfrom spiral_cad import *", scope)
    assert scope["Circle"] is build123d.Circle and scope["Line"] is build123d.Line and scope["Transition"] is build123d.Transition
    assert scope["Circle"](5).area == pytest.approx(78.5398, rel=1e-5)
    theirs = set(dir(build123d)) | set(getattr(cadquery, "__all__", dir(cadquery)))
    assert not set(sc.__all__) & theirs, set(sc.__all__) & theirs
    assert {name: getattr(sc, name).__module__ for name in sc.SHADOWING} == {
        "Circle": "spiral_cad.core.segments", "Line": "spiral_cad.core.segments", "Transition": "spiral_cad.core.transitions"}  # fmt: skip


def test_a_programs_many_runs_keep_the_summary_line_short_and_whole_number_tolerances_are_taken(tmp_path, capsys):
    path = tmp_path / "holes.ngc"
    path.write_text("G21\nG0 Z1\n" + "".join(f"G0 X{k} Y0\nG1 Z-1 F100\nG0 Z1\n" for k in range(40)) + "M2\n")
    assert main(["check", str(path), "--quiet"]) == 0
    (summary,) = capsys.readouterr().out.splitlines()
    assert summary.startswith("holes.ngc: 40 wires (1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, … edges; 28 edges in the other 28); worst")
    assert sc.check(path, curvature_tol=1, gap_tol=0).wires


def test_an_arc_whose_ends_are_too_close_for_any_circle_near_its_centre_is_left_out(tmp_path):
    """A nearly whole turn whose end lies 0.0004 mm off its circle: no circle through both ends lies near
    its centre (the chord's bisector is 5 mm away), so it is left out and said so, not judged as a tiny arc."""
    path = tmp_path / "nearly.ngc"
    path.write_text("G21\nG0 X0.0004 Y10 Z0\nG1 X0.0004 Y0 F100\nG3 X0 Y0 I4.9996 J0\nG1 X0 Y-10\nM2\n")
    report = sc.check(path)
    assert "line 4: an arc whose end lies 0.0004 off its circle with ends 0.0004 apart is no arc: left out" in " | ".join(report.notes)
    assert [w.edge_count for w in report.wires] == [1, 1] and all(j.curvature_after < 1 for w in report.wires for j in w.joints)


def test_short_arcs_printed_to_a_few_decimals_are_read_as_arcs(tmp_path):
    """A half circle of radius 10 in 120 arcs of 1.5°, printed to 6 decimals (as CAM writes them): each end
    lies up to 7e-7 off its circle, and the centre must move 1e-5 onto the chord's bisector — many times the
    radius difference, far within LinuxCNC's path tolerance (0.005 mm). Every arc is read; none parts the path."""
    import numpy as np

    angles = np.linspace(0.0, np.pi, 121)
    arcs = [
        f"G3 X{10 * np.cos(a):.6f} Y{10 * np.sin(a):.6f} I{-10 * np.cos(b):.6f} J{-10 * np.sin(b):.6f}"
        for b, a in zip(angles[:-1], angles[1:])
    ]
    path = tmp_path / "arcs.ngc"
    path.write_text("G21 G17 G90\nG0 X10 Y0 Z0\nG1 Z-1 F100\n" + "\n".join(arcs) + "\nM2\n", encoding="ascii")
    report = sc.check(path, angle_tol=1e-4, curvature_tol=1e-3)
    assert not any("is no arc" in note for note in report.notes), report.notes[:3]
    assert [w.edge_count for w in report.wires] == [121]  # the plunge and the 120 arcs
    assert all(str(j.level) == "G2" for j in report.wires[0].joints[1:])


def test_a_landxml_check_takes_its_tolerances_from_the_alignments_own_numbers(tmp_path):
    """Coordinates printed to 3 decimals: a joint the printing leaves 0.0004 apart (its End and the next
    Start as printed) and a spiral's End as printed are judged within what 3 decimals resolve; a parcel's
    coarser numbers elsewhere in the file do not loosen them, and a kink of 0.001 rad still shows."""
    lines = ('<Line><Start>0.000 0.000</Start><End>0.000 100.000</End></Line>'
             '<Line><Start>0.000 100.000</Start><End>0.000 200.000</End></Line>'
             '<Line><Start>0.000 200.000</Start><End>0.100 300.000</End></Line>')  # fmt: skip
    parcel = '<Parcels><Parcel name="P"><CoordGeom><Line><Start>0 0</Start><End>1 1</End></Line></CoordGeom></Parcel></Parcels>'
    path = tmp_path / "road.xml"
    path.write_text(LANDXML.format(units=METRES, elements=lines).replace("</Alignments>", "</Alignments>" + parcel))
    report = sc.check(path)
    first, second = report.wires[0].joints
    assert first.level.name == "G2" and second.level.name == "G0" and second.angle == pytest.approx(0.001, rel=1e-3)
    assert "tolerances from the file's numbers (3 printed decimals) and its size: gap 0.005" in " | ".join(report.notes)
    assert report.gap_tol == 0.005 and report.angle_tol == pytest.approx(1e-4)


def test_old_names_work_for_one_release_with_a_warning():
    """The OCCT layer's slab maker was g2_slab, build123d's name for a Part: it is rolled_slab now."""
    import spiral_cad.cad as cad
    from spiral_cad.cad.slabs import rolled_slab

    with pytest.warns(DeprecationWarning, match=r"spiral_cad.cad.g2_slab is now rolled_slab; the old name goes in the next release"):
        assert cad.g2_slab is rolled_slab
    assert "g2_slab" not in cad.__all__ and "rolled_slab" in cad.__all__


def test_read_of_a_program_counts_every_turn_keeps_a_run_in_one_dimension_and_takes_what_rs274_reads(tmp_path):
    """An arc of three turns is three turns long (as LinuxCNC runs it); a run at z = 0 with an arc is all in the
    plane; a program with parameters (the built-in reader refuses) is read by LinuxCNC's rs274 where installed."""
    (tmp_path / "turns.nc").write_text("G21 G17 G90\nG0 X0 Y0 Z0\nG1 X5 Y0 F100\nG2 X5 Y0 I-5 J0 P3\nG1 X5 Y-1\nM2\n")
    read = sc.read(tmp_path / "turns.nc")
    assert read.length == pytest.approx(5 + 3 * 2 * math.pi * 5 + 1, rel=1e-12)
    assert {segment.dim for run in read.runs for segment in run} == {2}
    program = tmp_path / "oword.ngc"
    program.write_text(
        "G21 G90\n#1 = 5\nG0 X1 Y1 Z0\nG0 X0 Y0\nG1 X[#1] Y0 F100\nG1 X[#1] Y[#1]\nM2\n"
    )  # the first move: from where the machine is
    if shutil.which("rs274") is None:
        with pytest.raises(ValueError, match="rs274, which reads more programs, is not installed"):
            sc.read(program)
        return
    read = sc.read(program)
    assert read.length == pytest.approx(10.0) and read.notes[0].startswith("read by LinuxCNC's rs274")
