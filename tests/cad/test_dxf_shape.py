"""A DXF drawing's curves as exact edges (spiral_cad.cad.dxf_shape), judged by the wire checker: what ezdxf's
own geometry says each entity is, corners inside splines and at their seams included."""

from __future__ import annotations

import math

import ezdxf
import numpy as np
import pytest

pytest.importorskip("build123d")
from OCP.BRepAdaptor import BRepAdaptor_Curve
from OCP.TopAbs import TopAbs_EDGE
from OCP.TopExp import TopExp_Explorer
from OCP.TopoDS import TopoDS

from spiral_cad.cad import dxf_shape as module
from spiral_cad.cad.continuity import check_continuity
from spiral_cad.cad.dxf_shape import dxf_shape

pytestmark = pytest.mark.cad


def _judged(tmp_path, draw) -> tuple:
    doc = ezdxf.new("R2010")
    doc.header["$INSUNITS"] = 4
    draw(doc, doc.modelspace())
    path = tmp_path / "d.dxf"
    doc.saveas(path)
    shape, units, notes = dxf_shape(path)
    return check_continuity(shape, units=units), shape, notes


def _ends(shape) -> list[tuple[np.ndarray, np.ndarray]]:
    found, explorer = [], TopExp_Explorer(shape, TopAbs_EDGE)
    while explorer.More():
        curve = BRepAdaptor_Curve(TopoDS.Edge_s(explorer.Current()))
        found.append((np.array(curve.Value(curve.FirstParameter()).Coord()), np.array(curve.Value(curve.LastParameter()).Coord())))
        explorer.Next()
    return found


def test_a_corner_inside_a_spline_and_at_its_seam_is_a_joint(tmp_path):
    """A triple inner knot of a cubic is a corner (ezdxf: tangent (1, 0) before, (0, 1) after); a closed
    spline's seam may be one too: each is cut there and judged, never passed as the inside of one curve."""
    corner = [(0, 0), (1, 0), (2, 0), (3, 0), (3, 1), (3, 2), (3, 3)]
    report, shape, _ = _judged(tmp_path, lambda doc, msp: msp.add_open_spline(corner, degree=3, knots=[0] * 4 + [1] * 3 + [2] * 4))
    spline = ezdxf.math.BSpline(corner, order=4, knots=[0] * 4 + [1] * 3 + [2] * 4)
    before, after = spline.derivative(1 - 1e-9, 1)[1], spline.derivative(1 + 1e-9, 1)[1]
    assert abs(before.normalize().dot(after.normalize())) < 1e-6  # ezdxf's own: a right angle at the knot
    assert len(report.wires[0].joints) == 1 and str(report.min_level) == "G0"
    kink = [(0, 0), (10, 0), (10, 10), (0, 0)]  # starts along +x, ends along −x… −y: a turn at the seam
    report, _, _ = _judged(tmp_path, lambda doc, msp: msp.add_open_spline(kink, degree=3))
    assert report.wires[0].closed and str(report.min_level) == "G0"
    bezier_chain = [(0, 0), (1, 1), (2, 1), (3, 0), (3, 0), (4, -1), (5, -1), (6, 0)]  # knots of multiplicity 4 inside
    report, shape, _ = _judged(tmp_path, lambda doc, msp: msp.add_open_spline(bezier_chain, degree=3, knots=[0] * 4 + [1] * 4 + [2] * 4))
    assert len(_ends(shape)) == 2 and str(report.min_level) == "G1"  # tangent (1, −1) both sides, curvature flips


def test_arcs_ellipses_and_block_grids_are_what_ezdxf_draws(tmp_path):
    def draw(doc, msp):
        msp.add_arc((0, 0), 5, 0, 360)  # a whole turn written as an ARC
        msp.add_ellipse((50, 0), (0, 4, 0), 0.5, 0.3, 2.0)
        block = doc.blocks.new("PEG")
        block.add_circle((0, 0), 1)
        grid = msp.add_blockref("PEG", (100, 0), dxfattribs={"zscale": 0})  # LibreCAD's flat blocks say zscale 0
        grid.grid(size=(3, 3), spacing=(10, 10))

    report, shape, notes = _judged(tmp_path, draw)
    assert notes == [] and len(report.wires) == 1 + 1 + 9
    whole, ellipse, *pegs = report.wires
    assert whole.closed and len(whole.joints) == 2 and str(whole.min_level) == "G2"
    assert all(p.closed and str(p.min_level) == "G2" for p in pegs)
    doc = ezdxf.readfile(tmp_path / "d.dxf")
    tool = next(e for e in doc.modelspace() if e.dxftype() == "ELLIPSE").construction_tool()
    ends = [e for pair in _ends(shape) for e in pair]
    for point in (tool.start_point, tool.end_point):  # ezdxf's own ends of the ellipse arc are ends of our edges
        assert min(np.linalg.norm(e - np.array(point)) for e in ends) < 1e-9
    assert not ellipse.closed and not ellipse.joints


def test_an_ellipse_whose_ratio_is_above_one_is_the_same_ellipse_axes_swapped():
    """Other writers give ratios above 1 (1.0095, 4.0); OCCT's ellipse needs the major axis first. Every point
    of the edges lies where the DXF definition puts it: C + cos t · M + sin t · ratio · (N × M)."""
    doc = ezdxf.new("R2010")
    ellipse = doc.modelspace().add_ellipse((50, 0, 0), (0, 4, 0), 0.5, 0.3, 2.0)
    ellipse.dxf.unprotected_set("ratio", 2.5)  # as read from such a file (ezdxf's own setter refuses it)
    (edge,) = module._ellipse(ellipse)
    curve = BRepAdaptor_Curve(edge)
    centre, major = np.array([50.0, 0, 0]), np.array([0.0, 4, 0])
    minor = 2.5 * np.cross([0.0, 0, 1], major)
    for t, u in zip(np.linspace(0.3, 2.0, 9), np.linspace(curve.FirstParameter(), curve.LastParameter(), 9)):
        expected = centre + math.cos(t) * major + math.sin(t) * minor
        assert np.linalg.norm(np.array(curve.Value(u).Coord()) - expected) < 1e-12


def test_blocks_that_multiply_are_refused_by_name_not_left_running(tmp_path, monkeypatch):
    monkeypatch.setattr(module, "MAX_ENTITIES", 1_000)
    doc = ezdxf.new("R2010")
    doc.blocks.new("L0").add_line((0, 0), (1, 0))
    for level in range(1, 12):  # each block two references to the one below: 2¹¹ lines
        block = doc.blocks.new(f"L{level}")
        block.add_blockref(f"L{level - 1}", (0, 0))
        block.add_blockref(f"L{level - 1}", (0, 1))
    doc.modelspace().add_blockref("L11", (0, 0))
    doc.saveas(tmp_path / "many.dxf")
    with pytest.raises(ValueError, match=r"many.dxf: more than 1,000 entities with its polylines and blocks taken apart"):
        dxf_shape(tmp_path / "many.dxf")
