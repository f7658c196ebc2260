"""STEP/IGES/DXF/SVG: every file re-read by a reader we did not write and compared with the chain.

Readers: OCCT's STEP and IGES readers (asked for another unit than the
file's), steputils (an independent STEP parser), ezdxf and svgelements.
"""

import math
import re
import xml.etree.ElementTree as ET

import numpy as np
import pytest

pytest.importorskip("OCP")
ezdxf = pytest.importorskip("ezdxf")
svgelements = pytest.importorskip("svgelements")
p21 = pytest.importorskip("steputils.p21")

from helpers import curvature_vector, transition_chains
from OCP.BRepAdaptor import BRepAdaptor_Curve
from OCP.BRepLProp import BRepLProp_CLProps
from OCP.BRepTools import BRepTools_WireExplorer
from OCP.GCPnts import GCPnts_AbscissaPoint
from OCP.GeomAbs import GeomAbs_CurveType
from OCP.TopAbs import TopAbs_EDGE, TopAbs_REVERSED, TopAbs_WIRE
from OCP.TopExp import TopExp, TopExp_Explorer
from OCP.TopoDS import TopoDS

from spiral_cad import Arc, BezierSpiral, Chain, Line
from spiral_cad.cad.export import export_dxf, export_iges, export_step, export_svg, originating_system
from spiral_cad.cad.readers import read_shape
from spiral_cad.core.units import MM_PER_UNIT, UNITS
from spiral_cad.io.dxf import BEZIER_KNOTS, INSUNITS

CHAINS = transition_chains()
WRITERS = {"step": export_step, "igs": export_iges}
#: a unit to read each file unit back in (never the file's own)
OTHER_UNIT = {"mm": "in", "cm": "m", "m": "mm", "km": "m", "in": "mm", "ft": "m"}


def vec(p) -> np.ndarray:
    return np.array([p.X(), p.Y(), p.Z()])


def wires_of(shape) -> list[list]:
    """Each wire's edges in connection order."""
    wires, explorer = [], TopExp_Explorer(shape, TopAbs_WIRE)
    while explorer.More():
        walk, edges = BRepTools_WireExplorer(TopoDS.Wire_s(explorer.Current())), []
        while walk.More():
            edges.append(walk.Current())
            walk.Next()
        wires.append(edges)
        explorer.Next()
    return wires


def all_edges(shape) -> list:
    found, explorer = [], TopExp_Explorer(shape, TopAbs_EDGE)
    while explorer.More():
        found.append(explorer.Current())
        explorer.Next()
    return found


def travel_range(edge) -> tuple[BRepAdaptor_Curve, float, float]:
    curve = BRepAdaptor_Curve(TopoDS.Edge_s(edge))
    first, last = curve.FirstParameter(), curve.LastParameter()
    return (curve, last, first) if edge.Orientation() == TopAbs_REVERSED else (curve, first, last)


def length_of(shape) -> float:
    """Total edge length, integrated to 1e-13 (GProp's default integration is looser)."""
    return sum(GCPnts_AbscissaPoint.Length_s(BRepAdaptor_Curve(TopoDS.Edge_s(e)), 1e-13) for e in all_edges(shape))


def assert_same_geometry(edge, seg, tol, scale=1.0):
    """``edge`` (read in a unit ``scale`` times smaller than the chain's) is ``seg``: same kind, same curve."""
    curve, t0, t1 = travel_range(edge)
    u = np.linspace(0.0, 1.0, 33)
    got = np.array([vec(curve.Value(t0 + ui * (t1 - t0))) for ui in u]) / scale
    assert np.abs(got[:, 2]).max() <= tol
    kind = curve.GetType()
    assert np.abs(got[:, :2] - seg.point(u)).max() <= tol
    if isinstance(seg, Line):
        assert kind == GeomAbs_CurveType.GeomAbs_Line
    elif isinstance(seg, Arc):
        assert kind == GeomAbs_CurveType.GeomAbs_Circle
        assert abs(curve.Circle().Radius() / scale - abs(seg.radius)) <= tol
    else:
        assert kind == GeomAbs_CurveType.GeomAbs_BSplineCurve
        spline = curve.BSpline()
        assert spline.Degree() == 3 and not spline.IsRational() and spline.NbPoles() == 4
        poles = np.array([vec(spline.Pole(i))[:2] for i in range(1, 5)]) / scale
        if edge.Orientation() == TopAbs_REVERSED:
            poles = poles[::-1]
        assert np.abs(poles - seg.control_points).max() <= tol


def assert_g2_joins(edges, size):
    def derivatives(edge, t):
        props = BRepLProp_CLProps(BRepAdaptor_Curve(TopoDS.Edge_s(edge)), t, 2, 1e-12)
        return vec(props.Value()), vec(props.D1()), vec(props.D2())

    for a, b in zip(edges, edges[1:]):
        pa, d1a, d2a = derivatives(a, travel_range(a)[2])
        pb, d1b, d2b = derivatives(b, travel_range(b)[1])
        assert np.linalg.norm(pa - pb) <= 1e-9 * size
        ta, tb = d1a / np.linalg.norm(d1a), d1b / np.linalg.norm(d1b)
        ta, tb = (-ta if a.Orientation() == TopAbs_REVERSED else ta), (-tb if b.Orientation() == TopAbs_REVERSED else tb)
        assert np.linalg.norm(ta - tb) <= 1e-9
        assert np.linalg.norm(curvature_vector(d1a, d2a) - curvature_vector(d1b, d2b)) * size <= 1e-8


# ------------------------------------------------------------ STEP and IGES


@pytest.mark.parametrize("name", sorted(CHAINS))
@pytest.mark.parametrize("fmt", sorted(WRITERS))
def test_each_chain_reads_back_as_one_connected_wire_of_exact_curves(tmp_path, name, fmt):
    chain = CHAINS[name]
    path = tmp_path / f"chain.{fmt}"
    WRITERS[fmt](chain, path)
    (edges,) = wires_of(read_shape(path))
    assert len(edges) == len(chain)
    for a, b in zip(edges, edges[1:]):  # shared vertices: one connected wire
        assert TopExp.LastVertex_s(TopoDS.Edge_s(a), True).IsSame(TopExp.FirstVertex_s(TopoDS.Edge_s(b), True))
    for edge, seg in zip(edges, chain):
        assert_same_geometry(edge, seg, 1e-9)
    assert_g2_joins(edges, chain.size)


def test_step_keeps_every_double_and_iges_loses_at_most_two_ulp(tmp_path):
    chain = CHAINS["mixed"]
    for fmt, exact in (("step", True), ("igs", False)):
        path = tmp_path / f"mixed.{fmt}"
        WRITERS[fmt](chain, path)
        (edges,) = wires_of(read_shape(path))
        for edge, seg in zip(edges, chain):
            curve, _, _ = travel_range(edge)
            if isinstance(seg, BezierSpiral):
                poles = np.array([vec(curve.BSpline().Pole(i))[:2] for i in range(1, 5)])
                poles = poles[::-1] if edge.Orientation() == TopAbs_REVERSED else poles
                # STEP keeps every bit; OCCT's IGES reader parses decimals to within an ulp or two
                ulps = np.abs(poles - seg.control_points) / np.spacing(np.abs(seg.control_points))
                assert np.all(ulps == 0) if exact else np.all(ulps <= 2)
            elif isinstance(seg, Arc):
                radius, centre = curve.Circle().Radius(), vec(curve.Circle().Location())[:2]
                ulps = abs(radius - abs(seg.radius)) / math.ulp(abs(seg.radius))
                assert (ulps == 0) if exact else (ulps <= 2)
                assert np.array_equal(centre, seg.center)


@pytest.mark.parametrize("units", UNITS)
@pytest.mark.parametrize("fmt", sorted(WRITERS))
def test_files_declare_their_unit_so_readers_convert_to_the_right_size(tmp_path, units, fmt):
    chain = Chain(CHAINS["mixed"].segments, units=units)
    path = tmp_path / f"mixed.{fmt}"
    WRITERS[fmt](chain, path)
    target = OTHER_UNIT[units]
    scale = MM_PER_UNIT[units] / MM_PER_UNIT[target]
    shape = read_shape(path, units=target)
    assert length_of(shape) == pytest.approx(chain.length * scale, rel=1e-12)
    (edges,) = wires_of(shape)
    for edge, seg in zip(edges, chain):
        assert_same_geometry(edge, seg, 1e-9, scale)


def test_demo_highway_in_metres_reads_back_in_millimetres(tmp_path):
    from spiral_cad.app.cli import DEMO_DESIGN
    from spiral_cad.app.designfile import build

    chain = build(DEMO_DESIGN)[1][0].chain
    assert chain.units == "m" and 2398 < chain.length < 2399
    for fmt in WRITERS:
        WRITERS[fmt](chain, tmp_path / f"highway.{fmt}")
        assert length_of(read_shape(tmp_path / f"highway.{fmt}")) == pytest.approx(chain.length * 1000, rel=1e-12)


@pytest.mark.parametrize("fmt", sorted(WRITERS))
def test_two_chains_read_back_as_exactly_two_wires(tmp_path, fmt):
    chains = [CHAINS["S"], CHAINS["line-line"]]
    path = tmp_path / f"two.{fmt}"
    WRITERS[fmt](chains, path)
    wires = wires_of(read_shape(path))
    assert [len(w) for w in wires] == [len(c) for c in chains]
    for edges, chain in zip(wires, chains):
        for edge, seg in zip(edges, chain):
            assert_same_geometry(edge, seg, 1e-9)


def test_step_header_product_and_units_read_by_an_independent_parser(tmp_path):
    chain = Chain(CHAINS["C"].segments, units="ft")
    path = tmp_path / "ramp.step"
    export_step(chain, path, name="Ramp 'B' — north")
    step = p21.readfile(str(path))  # steputils parses the whole exchange structure
    text = path.read_text()
    assert step.header["FILE_NAME"].params[4] == originating_system()
    assert "Open CASCADE" not in text and "Author" not in text
    products = [i for i in step.data[0].instances.values() if getattr(i, "entity", None) and i.entity.name == "PRODUCT"]
    assert products and products[0].entity.params[0] == "Ramp 'B' — north"
    assert "CONVERSION_BASED_UNIT('FOOT'" in text and "LENGTH_MEASURE(304.8)" in text
    assert text.count("CONNECTED_EDGE_SET(") == 1 and text.count("EDGE_CURVE(") == len(chain)


LOOPS = {
    "halves": Chain([Arc((0, 0), 5, 0.0, math.pi), Arc((0, 0), 5, math.pi, math.pi)]),
    "circle": Chain([Arc((3, 4), -5, 1.0, 2 * math.pi)]),
}


@pytest.mark.parametrize("name", ["mixed", "halves", "circle"])
def test_step_edges_share_their_vertices_in_travel_order(tmp_path, name):
    # one wire to any reader: each edge starts on the vertex the previous one ends on; a closed chain ends on its first
    chain = LOOPS.get(name) or CHAINS[name]
    path = tmp_path / f"{name}.step"
    export_step(chain, path)
    entities = {k: i.entity for k, i in p21.readfile(str(path)).data[0].instances.items() if hasattr(i, "entity")}
    (edge_set,) = [e for e in entities.values() if e.name == "CONNECTED_EDGE_SET"]
    edges = [entities[ref] for ref in edge_set.params[1]]
    assert [e.name for e in edges] == ["EDGE_CURVE"] * len(chain) and all(e.params[4] == ".T." for e in edges)
    ends = [(e.params[1], e.params[2]) for e in edges]
    assert all(a[1] == b[0] for a, b in zip(ends, ends[1:]))
    assert (ends[-1][1] == ends[0][0]) == (name in LOOPS)
    starts = [entities[entities[start].params[1]].params[1] for start, _ in ends]
    assert np.array_equal(np.array(starts)[:, :2], [s.start for s in chain])
    (wire,) = wires_of(read_shape(path, units="in"))  # and OCCT reads one wire of the same edges, closed or not
    assert len(wire) == len(chain)
    first, last = TopExp.FirstVertex_s(TopoDS.Edge_s(wire[0]), True), TopExp.LastVertex_s(TopoDS.Edge_s(wire[-1]), True)
    assert first.IsSame(last) == (name in LOOPS)
    for edge, seg in zip(wire, chain):
        assert_same_geometry(edge, seg, 1e-9, 1 / 25.4)


def test_a_chain_in_space_is_written_as_exact_3d_edges_of_one_wire(tmp_path):
    from helpers import helix_chain

    from spiral_cad.cad.continuity import check_continuity

    helix, _, _ = helix_chain()
    normal = np.array([0.0, -1.0, 1.0])
    arcs = Chain.join([Arc.in_space((1.0, 2.0, 3.0), normal, (6.0, 2.0, 3.0), 0.5),
                       Arc.in_space((1.0, 2.0, 3.0), normal, (6.0, 2.0, 3.0), -0.8).reversed()])  # fmt: skip
    for chain in (helix, arcs):
        path = tmp_path / "space.step"
        export_step(chain, path)
        (edges,) = wires_of(read_shape(path, units="in"))
        assert len(edges) == len(chain)
        for edge, seg in zip(edges, chain):
            curve, t0, t1 = travel_range(edge)
            u = np.linspace(0.0, 1.0, 9)
            got = np.array([vec(curve.Value(t0 + ui * (t1 - t0))) for ui in u]) * 25.4
            assert np.abs(got - seg.point(u)).max() <= 1e-9 * chain.size
        assert check_continuity(path).passes("G2")


def test_iges_global_section_names_the_design_and_no_login(tmp_path):
    import getpass

    path = tmp_path / "loop.igs"
    export_iges(Chain(CHAINS["S"].segments, units="m"), path)
    globals_ = "".join(line[:72] for line in path.read_text().splitlines() if line[72:73] == "G")
    assert "4Hloop" in globals_ and originating_system() in globals_
    assert ",6,1HM," in globals_  # unit flag 6, unit name M
    assert f"H{getpass.getuser()}," not in globals_


def test_build123d_shapes_are_written_in_their_unit(tmp_path):
    build123d = pytest.importorskip("build123d")
    from spiral_cad.build123d import chain_to_wire

    chain = CHAINS["C"]
    rail = chain_to_wire(chain, build123d.Plane.XZ)
    solid = build123d.sweep(build123d.Plane(origin=rail @ 0, z_dir=rail % 0) * build123d.Circle(0.1), path=rail)
    path = tmp_path / "solid.step"
    export_step(solid, path, units="cm", name="tube")
    back = build123d.Solid(read_shape(path))  # read in mm: 10× the numbers
    assert back.is_valid and back.volume == pytest.approx(solid.volume * 1000, rel=1e-9)
    assert "PRODUCT('tube" in path.read_text()
    iges = tmp_path / "rail.iges"
    export_iges(rail, iges)
    assert len(all_edges(read_shape(iges))) == len(chain)


def test_writers_reject_other_objects_and_mislabelled_units(tmp_path):
    for write in (export_dxf, export_svg):
        with pytest.raises(ValueError, match="expected a Chain"):
            write(42, tmp_path / "x")
    for write in (export_step, export_iges):
        with pytest.raises(ValueError, match="expected a Chain"):
            write(42, tmp_path / "x")
    with pytest.raises(ValueError, match="would mislabel"):
        export_step(CHAINS["C"], tmp_path / "x.step", units="m")
    with pytest.raises(ValueError, match="share a unit"):
        export_svg([CHAINS["C"], Chain(CHAINS["S"].segments, units="m")], tmp_path / "x.svg")


# ---------------------------------------------------------------------- DXF


@pytest.mark.parametrize("units", UNITS)
def test_dxf_header_declares_the_unit_both_ways(tmp_path, units):
    path = tmp_path / "d.dxf"
    export_dxf(Chain(CHAINS["C"].segments, units=units), path, name="ramp-3")
    doc = ezdxf.readfile(path)
    assert doc.header["$INSUNITS"] == INSUNITS[units] == {"in": 1, "ft": 2, "mm": 4, "cm": 5, "m": 6, "km": 7}[units]
    assert doc.header["$MEASUREMENT"] == (0 if units in ("in", "ft") else 1)
    assert {e.dxf.layer for e in doc.modelspace()} == {"ramp-3"}


@pytest.mark.parametrize("name", sorted(CHAINS))
def test_dxf_has_lines_arcs_and_exact_bezier_splines(tmp_path, name):
    chain = CHAINS[name]
    path = tmp_path / "chain.dxf"
    export_dxf(chain, path)
    entities = list(ezdxf.readfile(path).modelspace())
    assert [e.dxftype() for e in entities] == [{Line: "LINE", Arc: "ARC", BezierSpiral: "SPLINE"}[type(s)] for s in chain]
    tol = 1e-9 * chain.size
    for entity, seg in zip(entities, chain):
        if isinstance(seg, Line):
            got = np.array([entity.dxf.start, entity.dxf.end])[:, :2]
            assert np.abs(got - [seg.start, seg.end]).max() <= tol
        elif isinstance(seg, Arc):
            assert abs(entity.dxf.radius - abs(seg.radius)) <= tol
            ends = [seg.start, seg.end] if seg.radius > 0 else [seg.end, seg.start]  # DXF arcs run CCW
            assert np.abs(np.array([entity.start_point, entity.end_point])[:, :2] - ends).max() <= tol
        else:
            assert entity.dxf.degree == 3 and list(entity.knots) == list(BEZIER_KNOTS) and len(entity.weights) == 0
            assert np.array_equal(np.array(entity.control_points)[:, :2], seg.control_points)


@pytest.mark.parametrize("name", sorted(CHAINS))
def test_dxf_extents_and_limits_are_the_drawings(tmp_path, name):
    """$EXTMIN/$EXTMAX are the exact bounding box (not ezdxf's ±1e20), $LIMMIN/$LIMMAX that box
    with a margin, in the drawing's unit (not a 420 × 297 page)."""
    chain = Chain(CHAINS[name].segments, units="m")
    path = tmp_path / "d.dxf"
    export_dxf(chain, path)
    doc = ezdxf.readfile(path)
    low, high = np.array(doc.header["$EXTMIN"])[:2], np.array(doc.header["$EXTMAX"])[:2]
    dense = np.vstack([seg.point(np.linspace(0.0, 1.0, 4097)) for seg in chain])
    tol = 1e-6 * chain.size  # a dense sample misses an extreme by at most this
    assert np.all(dense.min(axis=0) >= low - 1e-12 * chain.size) and np.all(dense.max(axis=0) <= high + 1e-12 * chain.size)
    assert np.allclose(dense.min(axis=0), low, atol=tol) and np.allclose(dense.max(axis=0), high, atol=tol)
    lim_low, lim_high = np.array(doc.header["$LIMMIN"]), np.array(doc.header["$LIMMAX"])
    pad = 0.05 * np.hypot(*(high - low))
    assert np.allclose(lim_low, low - pad) and np.allclose(lim_high, high + pad)
    msp = doc.modelspace()
    assert np.allclose(np.array(msp.dxf.extmin)[:2], low) and np.allclose(np.array(msp.dxf.limmax)[:2], lim_high)


def test_iges_names_the_top_entity_so_importers_show_the_design(tmp_path):
    """FreeCAD imports through OCCT's XDE reader, which labels a shape by its IGES name (406-15)."""
    from helpers import iges_names

    path = tmp_path / "pair.igs"
    export_iges([CHAINS["S"], CHAINS["C"]], path, name="highway ramps")
    assert iges_names(path) == ("highway ramps", ["highway ramps"])
    entities = "".join(line[:64] for line in path.read_text().splitlines() if line[72:73] == "P")
    assert entities.count("406,1,13Hhighway ramps;") == 1
    assert entities.count("406,1,15Hhighway ramps-1;") == entities.count("406,1,15Hhighway ramps-2;") == 1


# ---------------------------------------------------------------------- SVG


@pytest.mark.parametrize("units", ["mm", "m", "ft"])
def test_svg_is_drawn_at_true_size_with_model_units_in_the_viewbox(tmp_path, units):
    chain = Chain(CHAINS["mixed"].segments, units=units)
    path = tmp_path / "mixed.svg"
    export_svg(chain, path, name="mixed", margin=0.0)
    svg = svgelements.SVG.parse(str(path), reify=True)
    pixels_per_unit = MM_PER_UNIT[units] / 25.4 * 96.0  # svgelements: CSS px at 96 per inch
    extent = chain.sample(256)
    width = extent[:, 0].max() - extent[:, 0].min()
    assert svg.width == pytest.approx(width * pixels_per_unit, rel=1e-3)
    root = ET.parse(path).getroot()
    assert root.find("{http://www.w3.org/2000/svg}title").text.startswith("mixed")
    (element,) = [e for e in svg.elements() if isinstance(e, svgelements.Path)]
    assert element.id == "mixed"
    # the path as svgelements reads it, mapped back through the viewBox, is the chain (y flipped)
    vx, vy, _, _ = map(float, root.get("viewBox").split())

    def model(point) -> np.ndarray:
        return np.array([point.x / pixels_per_unit + vx, -(point.y / pixels_per_unit + vy)])

    drawn = [piece for piece in element if not isinstance(piece, svgelements.Move)]
    tol = 1e-6 * chain.size  # svgelements maps through mm → px → user units in its own arithmetic
    for seg in chain:
        if isinstance(seg, Arc):
            count = math.ceil(seg.sweep / math.pi - 1e-12)
            pieces, drawn = drawn[:count], drawn[count:]
            assert all(isinstance(p, svgelements.Arc) for p in pieces)
            assert np.abs(model(pieces[-1].end) - seg.end).max() <= tol
            continue
        piece, drawn = drawn[0], drawn[1:]
        if isinstance(seg, Line):
            assert isinstance(piece, svgelements.Line) and np.abs(model(piece.end) - seg.end).max() <= tol
        else:
            assert isinstance(piece, svgelements.CubicBezier)
            got = np.array([model(p) for p in (piece.start, piece.control1, piece.control2, piece.end)])
            assert np.abs(got - seg.control_points).max() <= tol
    assert not drawn


def parse_path(d: str) -> list[tuple[str, list[float]]]:
    tokens = re.findall(r"[MLCA]|[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?", d)
    commands, i = [], 0
    while i < len(tokens):
        letter, i = tokens[i], i + 1
        numbers = []
        while i < len(tokens) and tokens[i] not in "MLCA":
            numbers.append(float(tokens[i]))
            i += 1
        commands.append((letter, numbers))
    return commands


@pytest.mark.parametrize("name", sorted(CHAINS))
def test_svg_paths_use_exact_commands_with_y_flipped(tmp_path, name):
    chain = CHAINS[name]
    path = tmp_path / "chain.svg"
    export_svg(chain, path)
    paths = ET.parse(path).getroot().findall(".//{http://www.w3.org/2000/svg}path")
    assert len(paths) == 1
    commands = parse_path(paths[0].get("d"))
    flip = np.array([1.0, -1.0])
    rest = iter(commands[1:])
    tol = 1e-12 * chain.size
    for seg in chain:
        if isinstance(seg, Line):
            letter, numbers = next(rest)
            assert letter == "L" and np.abs(np.array(numbers) - seg.end * flip).max() <= tol
        elif isinstance(seg, BezierSpiral):
            letter, numbers = next(rest)
            assert letter == "C" and np.abs(np.reshape(numbers, (3, 2)) - seg.control_points[1:] * flip).max() <= tol
        else:
            pieces = math.ceil(seg.sweep / math.pi - 1e-12)
            for k in range(1, pieces + 1):
                letter, (rx, ry, rot, large, sweep_flag, x, y) = next(rest)
                assert letter == "A" and rx == ry == pytest.approx(abs(seg.radius))
                assert (rot, large) == (0, 0) and sweep_flag == (0 if seg.radius > 0 else 1)
                assert np.abs(np.array([x, y]) - seg.point(k / pieces) * flip).max() <= tol
    assert next(rest, None) is None


def test_svg_draws_one_named_path_per_chain(tmp_path):
    path = tmp_path / "two.svg"
    export_svg([CHAINS["S"], CHAINS["mixed"]], path, name="pair")
    ids = [p.get("id") for p in ET.parse(path).getroot().findall(".//{http://www.w3.org/2000/svg}path")]
    assert ids == ["pair-1", "pair-2"]


@pytest.mark.parametrize("scale", [1e155, 1e-200])
def test_step_directions_of_huge_and_tiny_paths_are_unit_vectors(tmp_path, scale):
    from spiral_cad.design import round_corners

    chain = round_corners(np.array([[0, 0, 0], [1, 0, 0], [1, 1, 1]]) * scale, units="m").chain
    export_step(chain, tmp_path / "p.step")
    directions = re.findall(r"DIRECTION\('',\(([^)]*)\)\)", (tmp_path / "p.step").read_text())
    vectors = np.array([[float(v) for v in d.split(",")] for d in directions])
    assert len(vectors) >= 3 and np.allclose(np.linalg.norm(vectors, axis=1), 1.0, rtol=1e-15)
