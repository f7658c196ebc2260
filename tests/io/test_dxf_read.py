"""DXF in (spiral_cad.io.dxf_read): drawings written by ezdxf, R2010 and R12 (LINE/ARC only, as LibreCAD writes),
read back as chained lines and arcs; ezdxf's own geometry is the judge."""

import math

import ezdxf
import numpy as np
import pytest
from ezdxf.math import bulge_to_arc

from spiral_cad.core.segments import Arc, Line
from spiral_cad.io.dxf_read import read_dxf_paths


def joined(path, closed: bool) -> float:
    """The largest gap between consecutive segments of a path (and round its closing joint)."""
    segments = list(path.segments) + ([path.segments[0]] if closed else [])
    return max((float(np.abs(a.end - b.start).max()) for a, b in zip(segments[:-1], segments[1:])), default=0.0)


def drawing(version: str = "R2010", insunits: int | None = 4):
    doc = ezdxf.new(version)
    if insunits is not None:
        doc.header["$INSUNITS"] = insunits
    return doc, doc.modelspace()


def test_a_slot_drawn_in_any_order_and_direction_is_one_closed_path(tmp_path):
    doc, msp = drawing()
    msp.add_line((0, 0), (10, 0))
    msp.add_line((0, 10), (10, 10))  # drawn against the travel
    msp.add_arc((0, 5), 5, 90, 270)
    msp.add_arc((10, 5), 5, 270, 90)
    msp.add_text("a note")
    doc.saveas(tmp_path / "slot.dxf")
    read = read_dxf_paths(tmp_path / "slot.dxf")
    assert read.units == "mm" and len(read) == 1 and read.notes == ("left out 1 TEXT",)
    path = read.paths[0]
    assert path.closed and joined(path, True) < 1e-12
    assert [type(s).__name__ for s in path.segments] == ["Line", "Arc", "Line", "Arc"]
    lengths = sorted(s.length for s in path.segments)
    assert lengths == pytest.approx([10, 10, 5 * math.pi, 5 * math.pi])
    assert all(s.radius > 0 for s in path.segments if isinstance(s, Arc))  # a counterclockwise outline


def test_bulges_are_the_arcs_ezdxf_makes_of_them(tmp_path):
    doc, msp = drawing()
    vertices = [(0, 0, 0.3), (20, 0, -0.7), (30, 10, 1.5), (10, 25, 0.0), (0, 15, -0.2)]
    msp.add_lwpolyline(vertices, format="xyb", close=True)
    doc.saveas(tmp_path / "bulges.dxf")
    path = read_dxf_paths(tmp_path / "bulges.dxf").paths[0]
    assert path.closed and joined(path, True) < 1e-9
    arcs = [s for s in path.segments if isinstance(s, Arc)]
    ring = vertices + vertices[:1]
    expected = [bulge_to_arc(a[:2], b[:2], a[2]) for a, b in zip(ring[:-1], ring[1:]) if a[2]]
    assert len(arcs) == len(expected) == 4
    for arc, (centre, _, _, radius) in zip(arcs, expected):
        assert np.allclose(arc.center, (centre.x, centre.y), atol=1e-9) and abs(arc.radius) == pytest.approx(radius)
    assert [math.copysign(1, a.radius) for a in arcs] == [1, -1, 1, -1]  # the bulge's sign is the sense


def test_circles_and_mirrored_arcs(tmp_path):
    doc, msp = drawing(insunits=1)
    msp.add_circle((5, 5), 2)
    msp.add_arc((20, 0), 3, 0, 90, dxfattribs={"extrusion": (0, 0, -1)})  # mirrored: clockwise in the world
    doc.saveas(tmp_path / "mirror.dxf")
    read = read_dxf_paths(tmp_path / "mirror.dxf", units="mm")
    assert read.units == "mm" and len(read) == 2
    circle, mirrored = (p.segments[0] for p in read.paths)
    assert read.paths[0].closed and circle.sweep == pytest.approx(2 * math.pi) and circle.radius == pytest.approx(2 * 25.4)
    arc = doc.modelspace().query("ARC")[0]
    ends = np.array([arc.start_point, arc.end_point])[:, :2] * 25.4  # ezdxf's own world points of the OCS arc
    assert mirrored.radius < 0 and not read.paths[1].closed
    assert {tuple(np.round(mirrored.start, 9)), tuple(np.round(mirrored.end, 9))} == {tuple(np.round(p, 9)) for p in ends}


def test_an_r12_drawing_of_lines_and_arcs_is_unitless_until_its_unit_is_stated(tmp_path):
    doc, msp = drawing("R12", insunits=None)  # R12 has no $INSUNITS, as LibreCAD's R12 export
    msp.add_line((0, 0), (40, 0))
    msp.add_arc((40, 10), 10, 270, 0)
    msp.add_line((50, 10), (50, 30))
    msp.add_line((80, 80), (90, 80))  # a second, separate path
    doc.saveas(tmp_path / "r12.dxf")
    assert ezdxf.readfile(tmp_path / "r12.dxf").dxfversion == "AC1009"
    with pytest.raises(ValueError, match=r"r12.dxf: the drawing is unitless .*--units mm"):
        read_dxf_paths(tmp_path / "r12.dxf")
    read = read_dxf_paths(tmp_path / "r12.dxf", drawing_units="in", units="mm")
    assert read.units == "mm" and "the drawing is unitless: read in in as stated" in read.notes
    first, second = read.paths
    assert [type(s) for s in first.segments] == [Line, Arc, Line] and not first.closed and joined(first, False) < 1e-9
    assert first.segments[-1].end.tolist() == pytest.approx([50 * 25.4, 30 * 25.4])
    assert len(second.segments) == 1


def test_a_drawing_without_a_header_states_no_unit_wherever_it_is_read(tmp_path, capsys):
    """Many R12 writers leave the HEADER section out; ezdxf then fills in its own defaults, $INSUNITS 6
    (metres) among them. Such a drawing states no unit: read, checked, built and rewritten, it is unitless."""
    from spiral_cad.app.cli import main

    bare = tmp_path / "bare.dxf"
    lines = ["0", "SECTION", "2", "ENTITIES", "0", "LINE", "8", "0", "10", "0", "20", "0", "30", "0", "11", "40", "21", "0", "31", "0"]
    bare.write_text("\n".join([*lines, "0", "ENDSEC", "0", "EOF", ""]), encoding="ascii")
    assert ezdxf.readfile(bare).header.get("$INSUNITS") == 6  # what ezdxf assumes
    with pytest.raises(ValueError, match="the drawing is unitless"):
        read_dxf_paths(bare)
    assert read_dxf_paths(bare, drawing_units="in").units == "in"
    assert main(["check", str(bare)]) == 0
    assert "model size 40 (model units)" in capsys.readouterr().out
    assert main(["g2", str(bare), "--max-deviation", "0.1", "-o", str(tmp_path / "out.dxf")]) == 0
    assert "drawing units" in capsys.readouterr().out
    assert "$INSUNITS" not in (tmp_path / "out.dxf").read_text(encoding="ascii", errors="replace")


def test_refusals_name_the_entity(tmp_path):
    doc, msp = drawing()
    msp.add_line((0, 0), (1, 0))
    spline = msp.add_rational_spline([(0, 0), (1, 1), (2, 0)], [1, 0.5, 1], degree=2)
    doc.saveas(tmp_path / "spline.dxf")
    with pytest.raises(ValueError, match=rf"spline.dxf: SPLINE {spline.dxf.handle}: a rational SPLINE \(weights from 0.5 to 1\)"):
        read_dxf_paths(tmp_path / "spline.dxf")
    for made, message in (
        (lambda m: m.add_spline(fit_points=[(0, 0), (1, 1), (2, 0), (3, 1)]), "given by fit points only"),
        (
            lambda m: m.add_open_spline([(0, 0, 0), (1, 1, 0), (2, 0, 1), (3, 1, 0)]),
            r"off the XY plane \(control points at z from 0 to 1\)",
        ),
        (lambda m: m.add_open_spline([(k, k % 2) for k in range(6)], degree=4), "a SPLINE of degree 4"),
    ):
        doc, msp = drawing()
        handle = made(msp).dxf.handle
        doc.saveas(tmp_path / "spline.dxf")
        with pytest.raises(ValueError, match=rf"SPLINE {handle}: .*{message}"):
            read_dxf_paths(tmp_path / "spline.dxf")
    doc, msp = drawing()
    msp.add_ellipse((0, 0), (2, 0), 0.5)
    doc.saveas(tmp_path / "ellipse.dxf")
    with pytest.raises(ValueError, match=r"is an ELLIPSE .*only LINE, ARC, CIRCLE, LWPOLYLINE, POLYLINE and SPLINE are read"):
        read_dxf_paths(tmp_path / "ellipse.dxf")
    doc, msp = drawing(insunits=3)  # miles
    msp.add_line((0, 0), (1, 0))
    doc.saveas(tmp_path / "miles.dxf")
    with pytest.raises(ValueError, match=r"\$INSUNITS 3 is not a unit read here"):
        read_dxf_paths(tmp_path / "miles.dxf")
    (tmp_path / "text.dxf").write_text("not a drawing")
    with pytest.raises(ValueError, match=r"text.dxf: not a DXF file"):
        read_dxf_paths(tmp_path / "text.dxf")


def test_a_branch_ends_every_path_through_it_and_near_ends_join(tmp_path):
    doc, msp = drawing()
    msp.add_line((0, 0), (10, 0))
    msp.add_line((10, 0), (20, 0))
    msp.add_line((10, 0), (10, 10))  # three ends meet at (10, 0)
    msp.add_line((20, 1e-9), (30, 0))  # within the join tolerance of (20, 0)
    doc.saveas(tmp_path / "tee.dxf")
    read = read_dxf_paths(tmp_path / "tee.dxf")
    assert sorted(len(p.segments) for p in read.paths) == [1, 1, 2]


def test_3d_polylines_and_elevations_are_paths_in_space(tmp_path):
    doc, msp = drawing()
    msp.add_polyline3d([(0, 0, 0), (10, 0, 2), (10, 10, 4)])
    msp.add_lwpolyline([(10, 10, 0.5), (20, 10, 0)], format="xyb", dxfattribs={"elevation": 4})
    doc.saveas(tmp_path / "space.dxf")
    read = read_dxf_paths(tmp_path / "space.dxf")
    assert len(read) == 1 and read.paths[0].segments[0].dim == 3 and joined(read.paths[0], False) < 1e-9
    arc = read.paths[0].segments[-1]
    assert isinstance(arc, Arc) and np.allclose(arc.end, (20, 10, 4))


def test_our_own_drawing_reads_back_as_its_chain(tmp_path):
    """``export_dxf`` writes lines, arcs and each spiral as a cubic SPLINE: read back, the same segments."""
    from helpers import curve_road

    import spiral_cad as sc
    from spiral_cad.core.spiral import BezierSpiral

    chain = curve_road()
    assert {type(s) for s in chain.segments} == {Line, BezierSpiral, Arc}
    sc.export(chain, tmp_path / "road.dxf")
    (path,) = sc.read(tmp_path / "road.dxf").paths
    assert [type(s) for s in path.segments] == [type(s) for s in chain.segments]
    for ours, back in zip(chain.segments, path.segments):
        assert np.allclose(back.start, ours.start, rtol=0, atol=1e-12) and np.allclose(back.end, ours.end, rtol=0, atol=1e-12)
        if isinstance(ours, BezierSpiral):
            assert np.array_equal(back.control_points, ours.control_points)  # exactly as written


def test_a_free_form_spline_is_cut_into_spiral_pieces_on_ezdxf_s_curve(tmp_path):
    """A cubic B-spline with an inflection and curvature peaks (as drawing programs write one) comes back as
    spiral pieces, end to start, every piece on ezdxf's own curve, its curvature monotone."""
    from spiral_cad.core import bezier

    doc, msp = drawing()
    spline = msp.add_open_spline([(0, 0), (10, 10), (20, 0), (30, 10), (40, 0), (50, 20)], degree=3)
    msp.add_line((50, 20), (60, 20))
    doc.saveas(tmp_path / "wave.dxf")
    (path,) = read_dxf_paths(tmp_path / "wave.dxf").paths
    curve = spline.construction_tool()
    pieces = [s for s in path.segments if not isinstance(s, Line)]
    assert len(pieces) > 3 and joined(path, closed=False) < 1e-12
    assert np.allclose(path.segments[0].start, (0, 0)) and np.allclose(path.segments[-1].end, (60, 20))
    for piece in pieces:
        for point in piece.point(np.linspace(0, 1, 9)):
            on = curve.point(curve.point_inversion(point.tolist()))  # ezdxf's nearest point of its curve
            assert math.dist(point, tuple(on)[:2]) < 1e-7  # ezdxf's Newton stops near 1e-9
        kappa = bezier.curvature(piece.control_points, np.linspace(0, 1, 50))
        assert np.all(np.diff(np.abs(kappa)) >= -1e-9) or np.all(np.diff(np.abs(kappa)) <= 1e-9)


def test_a_malformed_drawing_ezdxf_trips_on_is_a_named_refusal(tmp_path):
    doc, msp = drawing()
    msp.add_line((0, 0), (1, 0), dxfattribs={"color": 1})
    doc.saveas(tmp_path / "inf.dxf")
    text = (tmp_path / "inf.dxf").read_text().splitlines()
    at = next(k for k in range(text.index("LINE"), len(text)) if text[k].strip() == "62")  # the colour, a whole number
    text[at + 1] = "inf"
    (tmp_path / "inf.dxf").write_text("\n".join(text) + "\n")
    with pytest.raises(ValueError, match=r"inf.dxf: not a DXF file ezdxf can read \(OverflowError"):
        read_dxf_paths(tmp_path / "inf.dxf")


def test_splines_as_drawing_programs_write_them_and_the_broken_ones_refused(tmp_path):
    """A polyline-like degree-1 SPLINE is its lines; equal weights are no weights; a knot vector that breaks the
    curve (an inner knot repeated past the degree, knots that go back) is refused by the entity's handle."""
    rng = np.random.default_rng(1)
    points = np.column_stack([np.arange(20.0), rng.normal(0.0, 5.0, 20)])
    doc, msp = drawing()
    polyline = msp.add_spline(degree=1)
    polyline.control_points, polyline.knots = points.tolist(), [0.0, *map(float, range(20)), 19.0]
    doc.saveas(tmp_path / "poly.dxf")
    (path,) = read_dxf_paths(tmp_path / "poly.dxf").paths
    assert [type(s) for s in path.segments] == [Line] * 19  # not cut where rounding makes a straight cubic "turn"
    assert np.allclose([s.start for s in path.segments], points[:-1], atol=1e-12)
    doc, msp = drawing()
    msp.add_rational_spline([(0, 0), (1, 1), (2, 0), (3, 1)], [2.0] * 4)  # equal weights: no weights
    doc.saveas(tmp_path / "weights.dxf")
    assert read_dxf_paths(tmp_path / "weights.dxf").paths[0].segments[0].start.tolist() == [0.0, 0.0]
    for knots, message in (([0, 0, 0, 0, 1, 1, 1, 1, 2, 2, 2, 2], "an inner knot repeated 4 times"),
                           ([0, 0, 0, 0, 2, 1, 1, 1, 1], "knots are not 9 non-decreasing numbers")):  # fmt: skip
        doc, msp = drawing()
        spline = msp.add_spline(degree=3)
        spline.control_points = [(0, 0), (1, 1), (2, 0), (3, 1), (10, 10), (11, 9), (12, 10), (13, 9)][: len(knots) - 4]
        spline.knots = [float(k) for k in knots]
        doc.saveas(tmp_path / "broken.dxf")
        with pytest.raises(ValueError, match=rf"SPLINE {spline.dxf.handle}: a SPLINE .*{message}"):
            read_dxf_paths(tmp_path / "broken.dxf")


@pytest.mark.parametrize("eps", [0.01, 0.001, -0.01])
def test_a_spline_near_a_cusp_comes_back_in_pieces_each_one_signed_and_monotone(tmp_path, eps):
    """The curvature turns and peaks within a small part of a grid step there: the pieces are cut about it."""
    from spiral_cad.core import bezier

    doc, msp = drawing()
    spline = msp.add_spline(degree=3)
    spline.control_points, spline.knots = [(0, 0), (2, 2), (0, 2 + eps), (2, 0)], [0.0] * 4 + [1.0] * 4
    doc.saveas(tmp_path / "cusp.dxf")
    (path,) = read_dxf_paths(tmp_path / "cusp.dxf").paths
    assert len(path.segments) == 6
    for piece in path.segments:
        kappa = np.asarray(bezier.curvature(piece.control_points, np.linspace(0.0, 1.0, 20_001)))
        floor = 1e-6 * np.abs(kappa).max()
        assert kappa.min() >= -floor or kappa.max() <= floor  # one sign
        step = np.diff(np.abs(kappa))
        assert (step >= -floor).all() or (step <= floor).all()  # monotone


def test_coordinates_near_the_float_range_are_chained(tmp_path):
    doc, msp = drawing()
    msp.add_line((1e200, 0), (2e200, 0))
    msp.add_line((2e200, 0), (2e200, 1e200))
    doc.saveas(tmp_path / "huge.dxf")
    (path,) = read_dxf_paths(tmp_path / "huge.dxf").paths
    assert len(path.segments) == 2
