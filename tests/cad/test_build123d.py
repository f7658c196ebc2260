"""build123d line objects: placement on the builder's plane, exact edge types, sweeps."""

import numpy as np
import pytest

pytest.importorskip("build123d")

from build123d import (
    BuildLine,
    BuildPart,
    BuildSketch,
    Circle,
    GeomType,
    Plane,
    Rectangle,
    SkipClean,
    Vector,
    sweep,
)
from helpers import transition_chains

from spiral_cad import Arc, BezierSpiral, Chain, Line, circle_in_circle, circle_to_circle, line_to_circle, line_to_line
from spiral_cad.build123d import (
    SpiralChain,
    SpiralCircleInCircle,
    SpiralCircleToCircle,
    SpiralLineToCircle,
    SpiralLineToLine,
    chain_edges,
    chain_to_wire,
)

CHAINS = transition_chains()
GEOM = {Line: GeomType.LINE, Arc: GeomType.CIRCLE, BezierSpiral: GeomType.BEZIER}
NESTED_DISTANCE = (3.0 - 1.2) * 0.9935
TRANSITIONS = [
    (SpiralLineToCircle, ((0, 0), (1, 0), (6, 4), 2.5), line_to_circle),
    (SpiralCircleToCircle, ((0, 0), 2.0, (8, -1), -1.5), circle_to_circle),
    (SpiralCircleToCircle, ((0, 0), 2.0, (7, 1), 1.5), circle_to_circle),
    (SpiralLineToLine, ((-10, 0), (0, 0), (6, 8)), line_to_line),
    (SpiralCircleInCircle, ((0, 0), 3.0, (NESTED_DISTANCE, 0), 1.2), circle_in_circle),
]
PLANES = {"XZ": Plane.XZ, "tilted": Plane(origin=(1, 2, 3), x_dir=(1, 1, 0), z_dir=(1, -1, 1))}


def on_plane(plane: Plane, xy) -> Vector:
    return plane.origin + plane.x_dir * float(xy[0]) + plane.y_dir * float(xy[1])


def assert_in_plane(edges, plane: Plane, size: float):
    for edge in edges:
        for u in np.linspace(0, 1, 9):
            offset = (edge @ u) - plane.origin
            assert abs(offset.dot(plane.z_dir)) <= 1e-9 * size


@pytest.mark.parametrize("name", sorted(CHAINS))
@pytest.mark.parametrize("plane_name", sorted(PLANES))
def test_spiral_chain_lands_on_the_builder_plane_with_exact_edge_types(name, plane_name):
    chain, plane = CHAINS[name], PLANES[plane_name]
    with BuildLine(plane) as builder:
        SpiralChain(chain)
    edges = builder.line.edges()
    assert_in_plane(edges, plane, chain.size)
    types = sorted(e.geom_type.name for e in edges)
    if name == "mixed":  # crosses itself: the builder splits edges at crossings but keeps their kinds
        assert set(types) == {"LINE", "CIRCLE", "BEZIER"}
    else:
        assert types == sorted(GEOM[type(s)].name for s in chain)
    vertices = [v.center() for v in builder.line.vertices()]
    for seg in chain:
        target = on_plane(plane, seg.start)
        assert min((v - target).length for v in vertices) <= 1e-9 * chain.size


@pytest.mark.parametrize("name", sorted(CHAINS))
def test_standalone_objects_are_in_travel_order_on_xy(name):
    chain = CHAINS[name]
    obj = SpiralChain(chain)
    assert obj.chain is chain
    edges = obj.edges()
    assert [e.geom_type for e in edges] == [GEOM[type(s)] for s in chain]
    for edge, seg in zip(edges, chain):
        for u in (0.0, 1.0):
            assert (edge @ u - Vector(*seg.point(u), 0)).length <= 1e-12 * chain.size


@pytest.mark.parametrize("cls, args, solver", TRANSITIONS, ids=lambda v: getattr(v, "__name__", ""))
def test_transition_objects_give_the_solver_spirals(cls, args, solver):
    expected = solver(*args)
    obj = cls(*args)
    assert obj.transition.kind == expected.kind
    edges = obj.edges()
    assert [e.geom_type for e in edges] == [GeomType.BEZIER] * len(expected.spirals)
    for edge, spiral in zip(edges, expected.spirals):
        poles = np.array([(p.X(), p.Y()) for p in edge.geom_adaptor().Bezier().Poles()])
        assert np.array_equal(poles, spiral.control_points)
    with BuildLine(Plane.XZ) as builder:
        cls(*args)
    assert len(builder.line.edges()) == len(expected.spirals)
    assert {e.geom_type for e in builder.line.edges()} == {GeomType.BEZIER}
    assert_in_plane(builder.line.edges(), Plane.XZ, 10.0)


def test_two_transitions_in_one_builder_keep_their_edges():
    with BuildLine(Plane.YZ) as builder:
        SpiralCircleToCircle((0, 0), 2.0, (8, -1), -1.5)
        SpiralLineToLine((-10, 0), (0, 0), (6, 8))
    assert len(builder.line.edges()) == 4
    assert_in_plane(builder.line.edges(), Plane.YZ, 10.0)


def test_enclosing_skip_clean_stays_in_force():
    with SkipClean():
        with BuildLine():
            SpiralChain(CHAINS["C"])
        assert SkipClean.clean is False
    assert SkipClean.clean is True


@pytest.mark.parametrize("plane_name", sorted(PLANES))
def test_chain_to_edges_and_to_wire_on_a_plane(plane_name):
    chain, plane = CHAINS["S"], PLANES[plane_name]
    edges = chain_edges(chain, plane)
    wire = chain_to_wire(chain, plane)
    assert [e.geom_type for e in edges] == [GEOM[type(s)] for s in chain]
    assert [e.geom_type for e in wire.edges()] == [GEOM[type(s)] for s in chain]
    for edge, seg in zip(edges, chain):
        assert (edge @ 0 - on_plane(plane, seg.start)).length <= 1e-12 * chain.size
        assert (edge @ 1 - on_plane(plane, seg.end)).length <= 1e-12 * chain.size
    assert wire.length == pytest.approx(chain.length, rel=1e-6)  # OCCT integrates to ~1e-8
    with pytest.raises(ValueError, match="build123d Plane"):
        chain_to_wire(chain, "XZ")


@pytest.mark.parametrize("name", [n for n in sorted(CHAINS) if n != "mixed"])
def test_profile_swept_along_a_chain_is_a_valid_solid(name):
    chain = CHAINS[name]
    with BuildPart() as part:
        with BuildLine(Plane.XZ) as path:
            SpiralChain(chain)
        rail = path.wire()
        with BuildSketch(Plane(origin=rail @ 0, z_dir=rail % 0)):
            Rectangle(0.2, 0.1)
        sweep(path=rail)
    assert part.part.is_valid
    # Pappus: a profile carried square to a planar path sweeps area × length
    assert part.part.volume == pytest.approx(0.02 * chain.length, rel=2e-3)


def test_round_profile_swept_along_a_tilted_chain_wire():
    chain, plane = CHAINS["mixed"], PLANES["tilted"]
    rail = chain_to_wire(chain, plane)
    with BuildPart() as part:
        with BuildSketch(Plane(origin=rail @ 0, z_dir=rail % 0)):
            Circle(0.5)
        sweep(path=rail)
    assert part.part.is_valid
    assert part.part.volume == pytest.approx(np.pi * 0.25 * chain.length, rel=2e-3)


def test_bad_inputs():
    with pytest.raises(ValueError, match="center"):
        SpiralLineToCircle((0, 0), (1, 0), (6, 4, 1), 2.5)
    with pytest.raises(ValueError, match="Chain"):
        SpiralChain([Line((0, 0), (1, 0))])
    with pytest.raises(RuntimeError):
        with BuildPart():
            SpiralChain(Chain([Line((0, 0), (1, 0))]))


@pytest.mark.parametrize(
    ("args", "message"),
    [
        ((0,), r"chain must be a Chain or segments"),
        (("x",), r"chain must be a Chain"),
        ((None, "Plane"), r"plane must be a build123d Plane"),
    ],
)
def test_chain_edges_and_wire_name_a_wrong_argument(args, message):
    from build123d import Plane

    chain = CHAINS["C"]
    call = (chain, Plane) if args[-1] == "Plane" else args
    for function in (chain_edges, chain_to_wire):
        with pytest.raises(ValueError, match=message):
            function(*call)
