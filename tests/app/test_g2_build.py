"""`build FILE.dxf`, `build FILE.xml --max-deviation D`, `build FILE.xodr --max-deviation D` and the design type g2_path: lines and arcs
made G2 by make_g2, arcs kept true arcs, the input within the bound (measured here on the input's own geometry)."""

import json
import math
import re
from pathlib import Path

import ezdxf
import numpy as np
import pytest
from helpers import distance_to_chain

from spiral_cad.app.cli import main
from spiral_cad.app.designfile import DesignError, build
from spiral_cad.app.g2_build import g2_designs
from spiral_cad.core.segments import Arc

DATA = Path(__file__).parents[1] / "data"


def filleted_rectangle(path: Path, width=60.0, height=40.0, radius=8.0, version="R2010", insunits: int | None = 4) -> Path:
    """A rectangle with tangent fillets (as CAD's fillet makes it), its entities in scrambled order and direction."""
    doc = ezdxf.new(version)
    if insunits is not None:
        doc.header["$INSUNITS"] = insunits
    msp = doc.modelspace()
    w, h, r = width, height, radius
    msp.add_line((r, 0), (w - r, 0))
    msp.add_line((0, h - r), (0, r))
    msp.add_arc((w - r, h - r), r, 0, 90)
    msp.add_line((w - r, h), (r, h))
    msp.add_arc((r, r), r, 180, 270)
    msp.add_line((w, h - r), (w, r))  # against the travel
    msp.add_arc((w - r, r), r, 270, 360)
    msp.add_arc((r, h - r), r, 90, 180)
    doc.saveas(path)
    return path


def assert_g2_by_differences(chain) -> None:
    """Curvature either side of every joint by finite differences of the chain's points (not its own curvature)."""
    ends = np.cumsum(chain.lengths)[:-1]
    step = 2e-3 * float(np.min(chain.lengths))

    def curvature(s: float) -> float:
        a, b, c = chain.point_at(np.array([s - step, s, s + step]))
        d1, d2 = (c - a) / (2 * step), (c - 2 * b + a) / step**2
        return float((d1[0] * d2[1] - d1[1] * d2[0]) / np.linalg.norm(d1) ** 3)

    peak = max(abs(curvature(s)) for s in np.linspace(step, chain.length - step, 400))
    for s in ends:
        before, after = curvature(s - 1.5 * step), curvature(s + 1.5 * step)
        assert abs(before - after) <= 0.02 * peak, (s, before, after)


def input_points(path: Path, count: int = 40) -> np.ndarray:
    """Points along every LINE and ARC of a drawing, from ezdxf's own geometry (world coordinates)."""
    points = []
    for e in ezdxf.readfile(path).modelspace():
        if e.dxftype() == "LINE":
            a, b = np.array(e.dxf.start)[:2], np.array(e.dxf.end)[:2]
            points += [a + (b - a) * t for t in np.linspace(0, 1, count)]
        elif e.dxftype() == "ARC":
            points += [np.array(v)[:2] for v in e.construction_tool().vertices(np.linspace(e.dxf.start_angle,
                                                                                       e.dxf.start_angle + (e.dxf.end_angle - e.dxf.start_angle) % 360, count))]  # fmt: skip
    return np.array(points)


def test_a_filleted_rectangle_drawing_is_made_g2_within_the_bound_keeping_its_arcs(tmp_path):
    drawing = filleted_rectangle(tmp_path / "plate.dxf")
    units, built = g2_designs(drawing, 0.01)
    assert units == "mm" and len(built) == 1
    chain = built[0].chain
    assert built[0].kind == "G2 path (DXF drawing)"
    assert_g2_by_differences(chain)
    arcs = [s for s in chain if isinstance(s, Arc)]
    assert len(arcs) == 4  # the fillets stay arcs: same centres, radius moved in by the shift
    centres = sorted(tuple(np.round(a.center, 9)) for a in arcs)
    assert centres == sorted([(8.0, 8.0), (52.0, 8.0), (52.0, 32.0), (8.0, 32.0)])
    assert all(7.98 < abs(a.radius) < 8.0 for a in arcs)
    # Hausdorff, measured here: the drawing's points within 0.01 of the chain, the chain's points within 0.01 of the drawing
    assert distance_to_chain(chain, input_points(drawing), 0.01).max() <= 0.01 * (1 + 1e-6)
    samples = chain.point_at(np.linspace(0, chain.length, 4000))
    to_rectangle = np.minimum.reduce([np.abs(samples[:, 1]), np.abs(samples[:, 1] - 40), np.abs(samples[:, 0]), np.abs(samples[:, 0] - 60)])
    corner = [(8, 8), (52, 8), (52, 32), (8, 32)]
    in_corner = np.array([any(abs(p[0] - c[0]) <= 8 and abs(p[1] - c[1]) <= 8 and (p[0] - c[0]) * (c[0] - 30) >= 0 and
                              (p[1] - c[1]) * (c[1] - 20) >= 0 for c in corner) for p in samples])  # fmt: skip
    to_arc = np.min([np.abs(np.hypot(*(samples - c).T) - 8) for c in corner], axis=0)
    assert np.where(in_corner, to_arc, to_rectangle).max() <= 0.01 * (1 + 1e-6)


def test_build_dxf_writes_every_output_and_refuses_by_name(tmp_path, capsys):
    drawing = filleted_rectangle(tmp_path / "plate.dxf")
    out = tmp_path / "out"
    assert main(["build", str(drawing), "--max-deviation", "0.01", "--no-plots", "--out", str(out)]) == 0
    assert {"plate.step", "plate.svg", "plate.dxf"} <= {p.name for p in out.iterdir()}
    text = capsys.readouterr().out
    assert "G2 path (DXF drawing)" in text and "plate: within" in text
    assert main(["build", str(drawing), "--no-plots", "--out", str(out)]) == 2
    assert "give --max-deviation" in capsys.readouterr().err
    assert main(["build", str(drawing), "--max-deviation", "0.01", "--interpreter", "rs274", "--out", str(out)]) == 2
    assert "--interpreter: not with a DXF drawing" in capsys.readouterr().err
    r12 = filleted_rectangle(tmp_path / "r12.dxf", version="R12", insunits=None)
    assert main(["build", str(r12), "--max-deviation", "0.001", "--no-plots", "--out", str(tmp_path / "r12")]) == 2
    assert "unitless" in capsys.readouterr().err
    assert main(["build", str(r12), "--max-deviation", "0.001", "--units", "in", "--no-plots", "--out", str(tmp_path / "r12")]) == 0
    assert "read in in as stated" in capsys.readouterr().out
    doc = ezdxf.new("R2010")
    doc.modelspace().add_spline([(0, 0), (1, 1), (2, 0), (3, 1)])  # fit points: the curve is not stated
    doc.saveas(tmp_path / "spline.dxf")
    assert main(["build", str(tmp_path / "spline.dxf"), "--max-deviation", "0.01", "--units", "mm", "--out", str(out)]) == 2
    assert "a SPLINE given by fit points only" in capsys.readouterr().err


def test_a_landxml_alignment_of_lines_and_arcs_is_made_g2(tmp_path, capsys):
    from spiral_cad.io import read_landxml

    source = DATA / "landxml" / "civil3d_gsg_basic_road.xml"
    alignment = read_landxml(source)[0]
    assert len(alignment.chains) > 1  # G1: broken where a line meets an arc
    units, built = g2_designs(source, 0.1)
    assert units == "ft" and built and all(b.kind == "G2 path (LandXML file)" for b in built)
    chain = built[0].chain
    file_points = np.concatenate([c.point_at(np.linspace(0, c.length, 400)) for c in alignment.chains])
    assert distance_to_chain(chain, file_points, 0.5).max() <= 0.1 * (1 + 1e-6)
    arcs_in = sum(isinstance(s, Arc) for c in alignment.chains for s in c)
    assert sum(isinstance(s, Arc) for s in chain) == arcs_in  # every arc kept an arc
    out = tmp_path / "out"
    assert main(["build", str(source), "--max-deviation", "0.1", "--no-plots", "--out", str(out)]) == 0
    assert (out / f"{built[0].name}.xodr").exists() and (out / f"{built[0].name}.step").exists()
    capsys.readouterr()
    assert main(["build", str(source), "--g2", "0.1", "--max-deviation", "0.1", "--out", str(out)]) == 2
    assert "give --max-deviation only (--g2 is its old name, the same bound)" in capsys.readouterr().err
    again = tmp_path / "again"  # the old name still works for one release, and says so
    assert main(["build", str(source), "--g2", "0.1", "--no-plots", "--out", str(again)]) == 0
    assert "warning: --g2 is deprecated and will be removed: the same bound is --max-deviation D" in capsys.readouterr().err
    undated = [re.sub(r' date="[^"]*"', "", (folder / f"{built[0].name}.xodr").read_text()) for folder in (again, out)]
    assert undated[0] == undated[1]  # the same file, but for the time it was written


def test_opendrive_roads_of_lines_and_arcs_are_made_g2_and_spirals_refused(tmp_path, capsys):
    # a road of a line, a quarter circle (radius 50) and a line, written by hand: G1 at both tangent joints
    (tmp_path / "g1.xodr").write_text("""<?xml version="1.0" encoding="UTF-8"?>
<OpenDRIVE><header revMajor="1" revMinor="6" name="g1"/>
<road name="g1" length="278.5398163397448" id="1" junction="-1"><planView>
<geometry s="0" x="0" y="0" hdg="0" length="100"><line/></geometry>
<geometry s="100" x="100" y="0" hdg="0" length="78.53981633974483"><arc curvature="0.02"/></geometry>
<geometry s="178.53981633974483" x="150" y="50" hdg="1.5707963267948966" length="100"><line/></geometry>
</planView><lanes><laneSection s="0"><center><lane id="0" type="none" level="false"/></center></laneSection></lanes></road>
</OpenDRIVE>
""")
    line = np.column_stack([np.linspace(0, 100, 200), np.zeros(200)])
    angle = np.linspace(-math.pi / 2, 0, 200)
    arc = np.column_stack([100 + 50 * np.cos(angle), 50 + 50 * np.sin(angle)])
    up = np.column_stack([np.full(200, 150.0), np.linspace(50, 150, 200)])
    file_points = np.concatenate([line, arc, up])
    assert main(["build", str(tmp_path / "g1.xodr"), "--max-deviation", "0.05", "--no-plots", "--out", str(tmp_path / "out")]) == 0
    units, built = g2_designs(tmp_path / "g1.xodr", 0.05)
    chain = built[0].chain
    assert units == "m" and distance_to_chain(chain, file_points, 0.2).max() <= 0.05 * (1 + 1e-6)
    assert [type(s).__name__ for s in chain].count("Arc") == 1
    assert main(["build", str(DATA / "esmini_lane_offset_junction.xodr"), "--max-deviation", "0.05", "--out", str(tmp_path / "x")]) == 2
    assert "has spiral geometries: --max-deviation makes roads of lines and arcs G2" in capsys.readouterr().err
    assert main(["build", str(tmp_path / "g1.xodr"), "--out", str(tmp_path / "x")]) == 2
    assert "an OpenDRIVE file is built with --max-deviation D" in capsys.readouterr().err


def test_the_design_type_g2_path(tmp_path):
    filleted_rectangle(tmp_path / "plate.dxf", insunits=None)
    design = {"units": "in", "designs": [{"name": "plate", "type": "g2_path", "source": "plate.dxf", "max_deviation": 0.001,
                                          "source_units": "in"}]}  # fmt: skip
    (tmp_path / "design.json").write_text(json.dumps(design))
    units, built = build(tmp_path / "design.json")
    assert units == "in" and built[0].chain.units == "in" and len(built) == 1
    design["designs"][0]["source"] = "../plate.dxf"
    (tmp_path / "design.json").write_text(json.dumps(design))
    with pytest.raises(DesignError, match=r"climbs out with '\.\.'"):
        build(tmp_path / "design.json")
    design["designs"][0]["source"] = "plate.step"
    (tmp_path / "design.json").write_text(json.dumps(design))
    with pytest.raises(DesignError, match=r"source.*must be the path of a \.dxf"):
        build(tmp_path / "design.json")


def test_a_bound_below_float64_is_refused_with_a_bound_that_builds(tmp_path, capsys):
    # make_g2's refusal goes through the split-at-corners fallback; the message it ends with is make_g2's own
    drawing = filleted_rectangle(tmp_path / "plate.dxf")
    out = tmp_path / "out"
    assert main(["build", str(drawing), "--max-deviation", "1e-14", "--no-plots", "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: ") and "internal error" not in err and "works (built and checked)" in err
    advised = float(err.split("max_deviation ")[-1].split(" ")[0])
    assert main(["build", str(drawing), "--max-deviation", repr(advised), "--no-plots", "--out", str(out)]) == 0


def test_a_split_path_is_reported_plainly_and_fails_unless_splits_are_allowed(tmp_path, capsys):
    """A drawing whose path folds straight back (a reversal) is split there: the parts are
    named as parts, the split is printed with its joint and reason, no part is shown as plain G2, and the
    build exits 1 unless --allow-splits."""
    doc = ezdxf.new("R2010")
    doc.header["$INSUNITS"] = 4
    msp = doc.modelspace()
    msp.add_line((0, 0), (20, 0))
    msp.add_arc((20, 3), 3, 270, 360)
    msp.add_line((23, 3), (23, 10))
    msp.add_line((23, 10), (23, 4))  # straight back down over itself: a reversal (a sharp corner would be rounded)
    path = tmp_path / "hairpin.dxf"
    doc.saveas(path)
    _, built = g2_designs(path, 0.01)
    assert len(built) == 2 and all(b.split_at for b in built)
    assert all(b.kind.startswith("part of a split path") for b in built)
    assert "reversal" in built[0].split_at[0]
    status = main(["build", str(path), "--max-deviation", "0.01", "-o", str(tmp_path / "out"), "--no-plots"])
    out = capsys.readouterr().out
    assert status == 1
    assert "1 split(s) left a kink (G0)" in out and "FAIL: the path was split" in out
    rows = [line for line in out.splitlines() if line.startswith("hairpin_") and "part of a split path" in line]
    assert len(rows) == 2 and all(" G0 at 1 split(s) of its path; this part G2" in row for row in rows)
    status = main(["build", str(path), "--max-deviation", "0.01", "-o", str(tmp_path / "out2"), "--no-plots", "--allow-splits"])
    assert status == 0 and "FAIL" not in capsys.readouterr().out


def test_allow_splits_is_refused_where_it_means_nothing(tmp_path, capsys):
    """A G-code build splits a program's path where it folds back by design: --allow-splits there is told, not ignored."""
    program = tmp_path / "p.nc"
    program.write_text("G21\nG0 X0 Y0 Z1\nG1 Z-1 F100\nG1 X10\nG1 Y10\nG0 Z1\nM2\n")
    argv = ["build", "--from-gcode", str(program), "--max-deviation", "0.01", "-o", str(tmp_path / "out"), "--allow-splits"]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: --allow-splits: only with a path made G2") and "spiral-cad g2" in err
    assert not (tmp_path / "out").exists()
