"""STEP/IGES/DXF/SVG writers: re-read files and compare geometry and G2 joins."""

import math
import re
import xml.etree.ElementTree as ET

import numpy as np
import pytest

pytest.importorskip("OCP")
ezdxf = pytest.importorskip("ezdxf")

from cad_cases import curvature_vector, transition_chains
from OCP.BRepAdaptor import BRepAdaptor_Curve
from OCP.BRepLProp import BRepLProp_CLProps
from OCP.GeomAbs import GeomAbs_CurveType
from OCP.TopAbs import TopAbs_EDGE, TopAbs_REVERSED
from OCP.TopExp import TopExp_Explorer
from OCP.TopoDS import TopoDS

from spiral_cad import Arc, BezierSpiral, Line
from spiral_cad.export import (
    BEZIER_KNOTS,
    export_dxf,
    export_iges,
    export_step,
    export_svg,
)
from spiral_cad.occ import read_shape

CHAINS = transition_chains()
FORMATS = {"step": (export_step, read_shape), "iges": (export_iges, read_shape)}


def vec(p) -> np.ndarray:
    return np.array([p.X(), p.Y(), p.Z()])


def edges_of(shape) -> list:
    found, explorer = [], TopExp_Explorer(shape, TopAbs_EDGE)
    while explorer.More():
        found.append(explorer.Current())
        explorer.Next()
    return found


def travel_range(edge) -> tuple[BRepAdaptor_Curve, float, float]:
    """The edge's curve and its parameters at the start and end of travel."""
    curve = BRepAdaptor_Curve(TopoDS.Edge_s(edge))
    first, last = curve.FirstParameter(), curve.LastParameter()
    return (curve, last, first) if edge.Orientation() == TopAbs_REVERSED else (curve, first, last)


def derivatives(edge, t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    props = BRepLProp_CLProps(BRepAdaptor_Curve(TopoDS.Edge_s(edge)), t, 2, 1e-12)
    return vec(props.Value()), vec(props.D1()), vec(props.D2())


def assert_same_geometry(edge, seg, tol):
    curve, t0, t1 = travel_range(edge)
    u = np.linspace(0.0, 1.0, 33)
    got = np.array([vec(curve.Value(t0 + ui * (t1 - t0))) for ui in u])
    assert np.abs(got[:, 2]).max() <= tol
    kind = curve.GetType()
    if isinstance(seg, Line):
        assert kind == GeomAbs_CurveType.GeomAbs_Line
        assert np.abs(got[:, :2] - seg.point(u)).max() <= tol
    elif isinstance(seg, Arc):
        assert kind == GeomAbs_CurveType.GeomAbs_Circle
        circle = curve.Circle()
        assert abs(circle.Radius() - abs(seg.radius)) <= tol
        assert np.abs(vec(circle.Location())[:2] - seg.center).max() <= tol
        assert np.abs(got[:, :2] - seg.point(u)).max() <= tol  # angle-linear both ways
    else:
        # IGES and STEP carry a Bézier as a one-span B-spline with the same poles
        assert kind in (GeomAbs_CurveType.GeomAbs_BSplineCurve, GeomAbs_CurveType.GeomAbs_BezierCurve)
        spline = curve.BSpline() if kind == GeomAbs_CurveType.GeomAbs_BSplineCurve else curve.Bezier()
        assert spline.Degree() == 3 and not spline.IsRational() and spline.NbPoles() == 4
        poles = np.array([vec(spline.Pole(i))[:2] for i in range(1, 5)])
        if edge.Orientation() == TopAbs_REVERSED:
            poles = poles[::-1]
        assert np.abs(poles - seg.control_points).max() <= tol
        assert np.abs(got[:, :2] - seg.point(u)).max() <= tol


def assert_g2_joins(edges, size):
    for a, b in zip(edges, edges[1:]):
        _, _, end_a = travel_range(a)
        _, start_b, _ = travel_range(b)
        pa, d1a, d2a = derivatives(a, end_a)
        pb, d1b, d2b = derivatives(b, start_b)
        assert np.linalg.norm(pa - pb) <= 1e-9 * size
        ta, tb = d1a / np.linalg.norm(d1a), d1b / np.linalg.norm(d1b)
        if a.Orientation() == TopAbs_REVERSED:
            ta = -ta
        if b.Orientation() == TopAbs_REVERSED:
            tb = -tb
        assert np.linalg.norm(ta - tb) <= 1e-9
        # the curvature vector does not depend on parametrisation or direction
        assert np.linalg.norm(curvature_vector(d1a, d2a) - curvature_vector(d1b, d2b)) * size <= 1e-8


@pytest.mark.parametrize("name", sorted(CHAINS))
@pytest.mark.parametrize("fmt", sorted(FORMATS))
def test_step_and_iges_round_trip_keeps_exact_curves_and_g2_joins(tmp_path, name, fmt):
    chain = CHAINS[name]
    write, read = FORMATS[fmt]
    path = tmp_path / f"chain.{fmt}"
    write(chain, path)
    edges = edges_of(read(path))
    assert len(edges) == len(chain)
    for edge, seg in zip(edges, chain):
        assert_same_geometry(edge, seg, 1e-9)
    assert_g2_joins(edges, chain.size)


@pytest.mark.parametrize("fmt", sorted(FORMATS))
def test_several_chains_become_several_wires(tmp_path, fmt):
    write, read = FORMATS[fmt]
    chains = [CHAINS["S"], CHAINS["line-line"]]
    path = tmp_path / f"two.{fmt}"
    write(chains, path)
    shape = read(path)
    edges = edges_of(shape)
    assert len(edges) == sum(len(c) for c in chains)
    for edge, seg in zip(edges, [s for c in chains for s in c]):
        assert_same_geometry(edge, seg, 1e-9)


def test_build123d_shapes_are_written_as_they_are(tmp_path):
    build123d = pytest.importorskip("build123d")
    chain = CHAINS["C"]
    rail = chain.to_wire(build123d.Plane.XZ)
    solid = build123d.sweep(
        build123d.Plane(origin=rail @ 0, z_dir=rail % 0) * build123d.Circle(0.1), path=rail
    )
    path = tmp_path / "solid.step"
    export_step(solid, path)
    back = build123d.Solid(read_shape(path))
    assert back.is_valid and back.volume == pytest.approx(solid.volume, rel=1e-9)
    iges = tmp_path / "rail.iges"
    export_iges(rail, iges)
    assert len(edges_of(read_shape(iges))) == len(chain)


def test_writers_reject_other_objects(tmp_path):
    for write in (export_step, export_iges, export_dxf, export_svg):
        with pytest.raises(ValueError, match="expected a Chain"):
            write(42, tmp_path / "x")
    with pytest.raises(ValueError, match="cannot read"):
        export_step("not a file.txt", tmp_path / "x.step")


@pytest.mark.parametrize("name", sorted(CHAINS))
def test_dxf_has_lines_arcs_and_exact_bezier_splines(tmp_path, name):
    chain = CHAINS[name]
    path = tmp_path / "chain.dxf"
    export_dxf(chain, path)
    entities = list(ezdxf.readfile(path).modelspace())
    assert [e.dxftype() for e in entities] == [
        {Line: "LINE", Arc: "ARC", BezierSpiral: "SPLINE"}[type(s)] for s in chain
    ]
    tol = 1e-9 * chain.size
    for entity, seg in zip(entities, chain):
        if isinstance(seg, Line):
            got = np.array([entity.dxf.start, entity.dxf.end])[:, :2]
            assert np.abs(got - [seg.start, seg.end]).max() <= tol
        elif isinstance(seg, Arc):
            assert abs(entity.dxf.radius - abs(seg.radius)) <= tol
            assert np.abs(np.array(entity.dxf.center)[:2] - seg.center).max() <= tol
            ends = [seg.start, seg.end] if seg.radius > 0 else [seg.end, seg.start]  # DXF arcs run CCW
            got = np.array([entity.start_point, entity.end_point])[:, :2]
            assert np.abs(got - ends).max() <= tol
            span = (entity.dxf.end_angle - entity.dxf.start_angle) % 360.0 or 360.0
            assert math.radians(span) == pytest.approx(seg.sweep, abs=1e-9)
        else:
            assert entity.dxf.degree == 3
            assert list(entity.knots) == list(BEZIER_KNOTS)
            assert len(entity.weights) == 0
            points = np.array(entity.control_points)
            assert np.abs(points[:, :2] - seg.control_points).max() <= 1e-12 * chain.size
            assert np.abs(points[:, 2]).max() == 0.0


def test_dxf_takes_several_chains(tmp_path):
    path = tmp_path / "two.dxf"
    export_dxf([CHAINS["C"], CHAINS["nested"]], path)
    assert len(ezdxf.readfile(path).modelspace()) == len(CHAINS["C"]) + len(CHAINS["nested"])


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
    root = ET.parse(path).getroot()
    assert root.tag == "{http://www.w3.org/2000/svg}svg"
    paths = root.findall(".//{http://www.w3.org/2000/svg}path")
    assert len(paths) == 1
    commands = parse_path(paths[0].get("d"))
    assert commands[0] == ("M", [pytest.approx(chain.start[0], abs=1e-9), pytest.approx(-chain.start[1], abs=1e-9)])
    flip = np.array([1.0, -1.0])
    rest = iter(commands[1:])
    tol = 1e-12 * chain.size
    for seg in chain:
        if isinstance(seg, Line):
            letter, numbers = next(rest)
            assert letter == "L" and np.abs(np.array(numbers) - seg.end * flip).max() <= tol
        elif isinstance(seg, BezierSpiral):
            letter, numbers = next(rest)
            assert letter == "C"
            assert np.abs(np.reshape(numbers, (3, 2)) - seg.control_points[1:] * flip).max() <= tol
        else:
            pieces = math.ceil(seg.sweep / math.pi - 1e-12)
            for k in range(1, pieces + 1):
                letter, (rx, ry, rot, large, sweep_flag, x, y) = next(rest)
                assert letter == "A" and rx == ry == pytest.approx(abs(seg.radius))
                assert (rot, large) == (0, 0) and sweep_flag == (0 if seg.radius > 0 else 1)
                assert np.abs(np.array([x, y]) - seg.point(k / pieces) * flip).max() <= tol
    assert next(rest, None) is None
    # viewBox holds the whole drawing
    vx, vy, vw, vh = map(float, root.get("viewBox").split())
    pts = chain.sample(64) * flip
    assert np.all(pts[:, 0] > vx) and np.all(pts[:, 0] < vx + vw)
    assert np.all(pts[:, 1] > vy) and np.all(pts[:, 1] < vy + vh)


def test_svg_draws_one_path_per_chain(tmp_path):
    path = tmp_path / "two.svg"
    export_svg([CHAINS["S"], CHAINS["mixed"]], path)
    assert len(ET.parse(path).getroot().findall(".//{http://www.w3.org/2000/svg}path")) == 2
