"""CadQuery plugin: registration, edge types, placement, sweep/extrude, continuity."""

from __future__ import annotations

import math

import numpy as np
import pytest

cq = pytest.importorskip("cadquery")

import spiral_cad as sc  # noqa: E402
import spiral_cad.cadquery as plugin  # noqa: E402
from spiral_cad.cad.continuity import Continuity, check_continuity  # noqa: E402

R, CX, H = 1.0, 3.0, 2.1  # racetrack: arcs of radius R about (±CX, H/2), straights on y = 0 and y = H


def open_chain() -> sc.Chain:
    """line → spiral → arc → spiral → line (a hairpin)."""
    into = sc.line_to_circle((0, 0), (1, 0), (CX, H / 2), R)
    out = sc.line_to_circle((0, H), (1, 0), (CX, H / 2), R).reversed()
    return sc.Chain.join([into, out], start=(-2.0, 0.0), end=(-2.0, H))


def closed_chain() -> sc.Chain:
    """A G2 racetrack: both hairpins joined by straights, ending where it starts."""
    t1 = sc.line_to_circle((0, 0), (1, 0), (CX, H / 2), R)
    t2 = sc.line_to_circle((0, H), (1, 0), (CX, H / 2), R).reversed()
    t3 = sc.line_to_circle((0, H), (-1, 0), (-CX, H / 2), R)
    t4 = sc.line_to_circle((0, 0), (-1, 0), (-CX, H / 2), R).reversed()
    return sc.Chain.join([t1, t2, t3, t4], end=t1.start)


def test_methods_are_registered():
    for method in plugin.METHODS:
        assert getattr(cq.Workplane, method.__name__) is method
    for name in ("spiralLineToCircle", "spiralCircleToCircle", "spiralLineToLine", "spiralCircleInCircle", "spiralChain"):
        assert callable(getattr(cq.Workplane("XY"), name))


def test_transitions_give_bezier_edges_queued_as_pending():
    cases = [
        (lambda wp: wp.spiralLineToCircle((0, 0), (1, 0), (0, 1.05), 1.0), sc.line_to_circle((0, 0), (1, 0), (0, 1.05), 1.0)),
        (lambda wp: wp.spiralCircleToCircle((0, 0), 2.0, (5, 1), 1.0), sc.circle_to_circle((0, 0), 2.0, (5, 1), 1.0)),
        (lambda wp: wp.spiralLineToLine((0, 0), (10, 0), (15, 8)), sc.line_to_line((0, 0), (10, 0), (15, 8))),
        (lambda wp: wp.spiralCircleInCircle((0, 0), 1.0, (0, 0.595), 0.4), sc.circle_in_circle((0, 0), 1.0, (0, 0.595), 0.4)),
    ]
    for place, transition in cases:
        result = place(cq.Workplane("XY"))
        edges = result.vals()
        assert [e.geomType() for e in edges] == ["BEZIER"] * len(transition.spirals)
        assert len(result.ctx.pendingEdges) == len(edges)
        for edge, spiral in zip(edges, transition.spirals):
            assert np.allclose(edge.startPoint().toTuple()[:2], spiral.start, atol=1e-12)
            assert np.allclose(edge.endPoint().toTuple()[:2], spiral.end, atol=1e-12)


def test_chain_edges_are_line_circle_bezier_in_order():
    chain = open_chain()
    wire = cq.Workplane("XY").spiralChain(chain).val()
    assert isinstance(wire, cq.Wire)
    expected = {sc.Line: "LINE", sc.Arc: "CIRCLE", sc.BezierSpiral: "BEZIER"}
    assert [e.geomType() for e in wire.Edges()] == [expected[type(s)] for s in chain]
    assert wire.Length() == pytest.approx(chain.length, rel=1e-9)


def test_offset_rotated_workplane_maps_to_global_coordinates():
    chain = open_chain()
    plane_wp = cq.Workplane("XZ", origin=(0, 5, 0))
    wire = plane_wp.spiralChain(chain).val()
    plane = plane_wp.plane
    for edge, segment in zip(wire.Edges(), chain):
        middle = segment.point(segment.parameter_at(0.5 * segment.length))  # positionAt is by length
        checks = ((edge.startPoint(), segment.start, 1e-12), (edge.endPoint(), segment.end, 1e-12), (edge.positionAt(0.5), middle, 1e-7))
        for got, local, tol in checks:
            want = plane.toWorldCoords((float(local[0]), float(local[1])))
            assert (got - want).Length < tol
            assert got.y == pytest.approx(5.0, abs=1e-12)  # the XZ plane through y = 5
    # Local y runs along global +Z on "XZ": the hairpin's far straight is at z = H.
    assert wire.endPoint().toTuple() == pytest.approx((-2.0, 5.0, H), abs=1e-12)


def test_sweep_along_chain_gives_valid_solid():
    path = cq.Workplane("XY").spiralChain(open_chain())
    start = path.val().startPoint()
    radius = 0.1
    solid = cq.Workplane("YZ", origin=start.toTuple()).circle(radius).sweep(path).val()
    assert solid.isValid()
    # Pappus: a disc swept along a planar path of curvature < 1/radius keeps area × length.
    assert solid.Volume() == pytest.approx(math.pi * radius**2 * open_chain().length, rel=1e-4)


def test_closed_chain_extrudes_to_its_area():
    chain = closed_chain()
    placed = cq.Workplane("XY").spiralChain(chain)
    assert placed.val().IsClosed()
    solid = placed.extrude(0.5).val()
    assert solid.isValid()
    x, y = chain.sample(4000).T
    area = 0.5 * abs(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))
    assert solid.Volume() == pytest.approx(0.5 * area, rel=1e-6)


def test_checker_reports_g2_on_placed_wires():
    open_wire = cq.Workplane("XZ", origin=(0, 5, 0)).spiralChain(open_chain()).val()
    report = check_continuity(open_wire)
    assert report.min_level is Continuity.G2 and len(report.joints) == len(open_chain()) - 1
    closed = check_continuity(cq.Workplane("XY").spiralChain(closed_chain()).val())
    (w,) = closed.wires
    assert w.closed and len(w.joints) == w.edge_count == len(closed_chain())
    assert closed.min_level is Continuity.G2


def test_edges_mode_and_construction_mode():
    chain = open_chain()
    edges = cq.Workplane("XY").spiralChain(chain, makeWire=False)
    assert len(edges.vals()) == len(edges.ctx.pendingEdges) == len(chain)
    assert edges.wire().val().IsClosed() is False
    ghost = cq.Workplane("XY").spiralChain(chain, forConstruction=True)
    assert ghost.ctx.pendingWires == [] and ghost.ctx.pendingEdges == []


def test_bad_arguments_name_the_value():
    with pytest.raises(ValueError, match="Chain"):
        cq.Workplane("XY").spiralChain([sc.Line((0, 0), (1, 0))])
    with pytest.raises(sc.NoSolutionError):
        cq.Workplane("XY").spiralLineToCircle((0, 0), (1, 0), (0, 0.5), 1.0)


def test_example_script_runs_from_plain_python(tmp_path):
    import subprocess
    import sys
    from pathlib import Path

    script = Path(__file__).resolve().parents[2] / "examples" / "cadquery_plugin.py"
    target = tmp_path / "tube.step"
    done = subprocess.run([sys.executable, str(script), str(target)], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    assert f"wrote {target}" in done.stdout and "worst joint G2" in done.stdout
    assert check_continuity(target).wires  # the file reads back


def _fits(message: str) -> float:
    import re

    found = re.search(r"up to ([0-9.e+-]+) fits$", message)
    assert found, message
    return float(found.group(1))


def test_refusals_name_a_value_that_builds_in_cadquery():
    """Issue 29: the box's plan corners and a sliver's corners were refused without a value; the value named
    now builds (a FORWARD solid fused onto the stack, a G2 wire)."""
    with pytest.raises(sc.NoSolutionError, match=r"both claim .*; radius up to [0-9.]+ fits$") as refused:
        cq.Workplane().continuousBox(10, 10, 10, 5)
    fits = _fits(str(refused.value))
    assert fits < 5
    part = cq.Workplane().box(20, 20, 4).continuousBox(10, 10, 10, fits)
    solid = part.val()
    assert solid.isValid() and 20 * 20 * 4 < solid.Volume() < 20 * 20 * 4 + 10 * 10 * 6
    sliver = cq.Workplane().polyline([(0, 0), (30, 0), (30, 1)]).close()
    with pytest.raises(sc.NoSolutionError, match=r"radius up to [0-9.]+ fits$") as refused:
        sliver.g2Fillet(2)
    fits = _fits(str(refused.value))
    wire = cq.Workplane().polyline([(0, 0), (30, 0), (30, 1)]).close().g2Fillet(fits).val()
    report = check_continuity(wire.wrapped)
    assert report.wires[0].closed and all(j.level >= Continuity.G2 for j in report.wires[0].joints)
