"""Exact OCCT edges: curve types, control points, planes, travel order, wires."""

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

pytest.importorskip("OCP")

from helpers import transition_chains
from OCP.BRep import BRep_Tool
from OCP.BRepAdaptor import BRepAdaptor_Curve
from OCP.BRepCheck import BRepCheck_Analyzer
from OCP.BRepTools import BRepTools_WireExplorer
from OCP.GeomAbs import GeomAbs_CurveType
from OCP.gp import gp_Ax3, gp_Dir, gp_Pnt, gp_Vec

from spiral_cad import Arc, BezierSpiral, Chain, Line, line_to_circle
from spiral_cad.cad.occ import chain_wire, segment_edge, segment_edges

EXPECTED_TYPE = {
    Line: GeomAbs_CurveType.GeomAbs_Line,
    Arc: GeomAbs_CurveType.GeomAbs_Circle,
    BezierSpiral: GeomAbs_CurveType.GeomAbs_BezierCurve,
}
CHAINS = transition_chains()
TILTED = gp_Ax3(gp_Pnt(3.0, -2.0, 5.0), gp_Dir(1.0, 2.0, 2.0), gp_Dir(2.0, -1.0, 0.0))


def xyz(p) -> np.ndarray:
    return np.array([p.X(), p.Y(), p.Z()])


def placed(points: np.ndarray, plane: gp_Ax3 | None) -> np.ndarray:
    """2-D points on ``plane`` by the documented rule origin + x·X + y·Y."""
    pts = np.atleast_2d(points)
    if plane is None:
        return np.column_stack([pts, np.zeros(len(pts))])
    o, x, y = xyz(plane.Location()), xyz(plane.XDirection()), xyz(plane.YDirection())
    return o + pts[:, :1] * x + pts[:, 1:] * y


def assert_edge_follows(edge, seg, plane, tol):
    """Same curve type and same points in travel order (the edge parameter maps linearly to u)."""
    curve = BRepAdaptor_Curve(edge)
    assert curve.GetType() == EXPECTED_TYPE[type(seg)]
    first, last = curve.FirstParameter(), curve.LastParameter()
    u = np.linspace(0.0, 1.0, 17)
    got = np.array([xyz(curve.Value(first + ui * (last - first))) for ui in u])
    assert np.abs(got - placed(seg.point(u), plane)).max() <= tol
    d = gp_Pnt()
    v = gp_Vec()
    curve.D1(first, d, v)
    tangent = xyz(v) / v.Magnitude()
    assert np.abs(tangent - (placed(seg.start_tangent, plane) - placed(np.zeros(2), plane))[0]).max() <= 1e-12


@pytest.mark.parametrize("name", sorted(CHAINS))
@pytest.mark.parametrize("plane", [None, TILTED], ids=["XY", "tilted"])
def test_every_segment_becomes_its_exact_curve(name, plane):
    chain = CHAINS[name]
    for seg, edge in zip(chain, segment_edges(chain, plane)):
        assert_edge_follows(edge, seg, plane, 1e-12 * chain.size)


def test_spiral_edge_keeps_the_four_control_points_bit_for_bit():
    spiral = CHAINS["S"][1]
    curve = BRepAdaptor_Curve(segment_edge(spiral)).Bezier()
    assert curve.Degree() == 3 and not curve.IsRational()
    poles = np.array([xyz(curve.Pole(i))[:2] for i in range(1, 5)])
    assert np.array_equal(poles, spiral.control_points)


@given(
    st.floats(-50, 50),
    st.floats(-50, 50),
    st.floats(0.01, 40).flatmap(lambda r: st.sampled_from([r, -r])),
    st.floats(-7, 7),
    st.floats(1e-3, 2 * math.pi),
)
def test_arc_edges_are_true_circles_in_travel_sense(cx, cy, radius, start, sweep):
    arc = Arc((cx, cy), radius, start, sweep)
    edge = segment_edge(arc, TILTED)
    circle = BRepAdaptor_Curve(edge).Circle()
    assert circle.Radius() == pytest.approx(abs(radius), rel=1e-15)
    assert np.abs(xyz(circle.Location()) - placed(np.array([cx, cy]), TILTED)[0]).max() <= 1e-12 * (1 + abs(cx) + abs(cy))
    size = abs(radius) + abs(cx) + abs(cy)
    assert_edge_follows(edge, arc, TILTED, 1e-12 * size)


def test_left_handed_plane_keeps_counterclockwise_from_x_to_y():
    left = gp_Ax3(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1), gp_Dir(1, 0, 0))
    left.YReverse()
    assert not left.Direct()
    arc = Arc((1.0, 2.0), 1.5, 0.3, 2.0)
    assert_edge_follows(segment_edge(arc, left), arc, left, 1e-12)


@pytest.mark.parametrize("name", sorted(CHAINS))
def test_chain_wire_is_valid_and_in_travel_order(name):
    chain = CHAINS[name]
    wire = chain_wire(chain, TILTED)
    assert BRepCheck_Analyzer(wire).IsValid()
    explorer = BRepTools_WireExplorer(wire)
    starts = []
    while explorer.More():
        edge = explorer.Current()
        curve = BRepAdaptor_Curve(edge)
        starts.append(xyz(curve.Value(curve.FirstParameter())))
        assert BRep_Tool.Tolerance_s(edge) <= 1e-7
        explorer.Next()
    expected = placed(np.array([s.start for s in chain]), TILTED)
    assert np.abs(np.array(starts) - expected).max() <= 1e-12 * chain.size


def test_a_whole_circle_inside_a_chain_runs_from_its_vertex_back_to_it():
    """A program's plunge, a whole circle and a cut away (segments in travel order, not a G2 chain): one
    valid wire of three edges, the circle's edge closed on one vertex."""
    plunge = Line((40.0, 0.0, 1.0), (40.0, 0.0, -1.0))
    circle = Arc.in_space(center=(45.0, 0.0, -1.0), normal=(0.0, 0.0, 1.0), start=(40.0, 0.0, -1.0), sweep=-2 * math.pi)
    away = Line((40.0, 0.0, -1.0), (30.0, 0.0, -1.0))
    wire = chain_wire([plunge, circle, away])
    assert BRepCheck_Analyzer(wire).IsValid()
    explorer, edges = BRepTools_WireExplorer(wire), []
    while explorer.More():
        edges.append(explorer.Current())
        explorer.Next()
    assert len(edges) == 3 and BRep_Tool.IsClosed_s(edges[1])


def test_bad_inputs_name_the_problem():
    with pytest.raises(ValueError, match="segment must be"):
        segment_edge("not a segment")
    with pytest.raises(ValueError, match="gp_Ax3"):
        segment_edge(Line((0, 0), (1, 0)), plane=(0, 0, 1))
    with pytest.raises(ValueError, match="at least one"):
        chain_wire([])
    with pytest.raises(ValueError, match="does not connect"):
        chain_wire([Line((0, 0), (1, 0)), Line((5, 5), (6, 5))])


def test_chain_wire_shares_vertices_and_closes_loops():
    from OCP.TopExp import TopExp
    from OCP.TopoDS import TopoDS_Vertex

    enter = line_to_circle((0, 0), (1, 0), (5, 3), 2.0)
    open_chain = Chain.join([enter], start=(-20, 0))
    wire = chain_wire(open_chain)
    assert BRepCheck_Analyzer(wire).IsValid() and not wire.Closed()
    first, second = segment_edges_of(wire)
    assert TopExp.CommonVertex_s(first, second, TopoDS_Vertex())  # one vertex object at the joint
    loop = Chain([Arc((0, 0), 1.0, 0.0, 3.0), Arc((0, 0), 1.0, 3.0, 2 * np.pi - 3.0)])
    ring = chain_wire(loop)
    assert ring.Closed() and BRepCheck_Analyzer(ring).IsValid()


def segment_edges_of(wire):
    edges, explorer = [], BRepTools_WireExplorer(wire)
    while explorer.More():
        edges.append(explorer.Current())
        explorer.Next()
    return edges
