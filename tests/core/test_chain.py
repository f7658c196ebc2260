"""Chains: G2 checking, connectors, stations, reversal."""

import math

import numpy as np
import pytest

from spiral_cad import Arc, BezierSpiral, Chain, Line, circle_to_circle, line_to_circle, line_to_line


def road():
    """Line → spiral → arc → spiral → line around one circle."""
    enter = line_to_circle((0, 0), (1, 0), (100, 60), 50.0)
    leave = line_to_circle((300, 150), (-1, -1), (100, 60), 50.0).reversed()
    return Chain.join([enter, leave], start=(-20, 0), end=(400, 250)), enter, leave


def test_join_inserts_the_arc_between_contacts():
    chain, enter, leave = road()
    kinds = [type(s).__name__ for s in chain]
    assert kinds == ["Line", "BezierSpiral", "Arc", "BezierSpiral", "Line"]
    arc = chain[2]
    assert arc.radius == pytest.approx(50.0)
    assert np.allclose(arc.start, enter.end, atol=1e-12) and np.allclose(arc.end, leave.start, atol=1e-9)
    for j in chain.joins():
        assert j.gap <= 1e-12 * chain.size and j.angle <= 1e-12 and j.curvature_jump * chain.size <= 1e-10


def test_stations_and_queries_by_arc_length():
    chain, *_ = road()
    lengths = [s.length for s in chain]
    assert chain.length == pytest.approx(sum(lengths))
    assert np.allclose(np.diff(chain.stations), lengths)
    s = np.linspace(0, chain.length, 101)
    pts = chain.point_at(s)
    assert np.allclose(pts[0], chain.start) and np.allclose(pts[-1], chain.end)
    # chord lengths never exceed station differences, and nearly equal them
    chords = np.hypot(*np.diff(pts, axis=0).T)
    assert np.all(chords <= np.diff(s) * (1 + 1e-9)) and np.all(chords >= np.diff(s) * 0.99)
    k = chain.curvature_at(s)
    assert np.nanmax(np.abs(k)) == pytest.approx(1 / 50.0, rel=1e-9)
    t = chain.tangent_at(chain.stations[2] + 1.0)
    assert np.allclose(t, chain[2].tangent(chain[2].parameter_at(1.0)))
    with pytest.raises(ValueError, match="stations must lie"):
        chain.point_at(chain.length * 1.1)


def test_reversed_chain_runs_backwards_with_negated_curvature():
    chain, *_ = road()
    back = chain.reversed()
    s = np.linspace(0, chain.length, 23)
    assert np.allclose(back.point_at(s), chain.point_at(chain.length - s), atol=1e-9)
    assert np.allclose(back.curvature_at(s), -chain.curvature_at(chain.length - s), atol=1e-12)


def test_a_g1_only_joint_is_rejected_with_its_numbers():
    line = Line((-10, 0), (0, 0))
    arc = Arc((0, 5), 5.0, -math.pi / 2, 1.0)  # tangent to the line, curvature jumps 0 → 0.2
    with pytest.raises(ValueError, match=r"joint 0 .*gap .*curvature jump 0.2"):
        Chain([line, arc])
    with pytest.raises(ValueError, match="tangent angle 0.785"):
        Chain([line, Line((0, 0), (10, 10))])
    with pytest.raises(ValueError, match="gap 1"):
        Chain([line, Line((1, 0), (10, 0))])


def test_mixed_chain_with_c_s_and_corners():
    c = circle_to_circle((0, 0), 20.0, (60, 10), 15.0)
    s = circle_to_circle((60, 10), 15.0, (120, -20), -25.0)
    chain = Chain.join([c, s])
    assert len(chain) == 5  # spiral, spiral, arc, spiral, spiral
    ll = line_to_line((0, 0), (50, 0), (80, 60))  # Cor 4.5: the spirals use all of the shorter leg
    corner = Chain.join([ll], start=(0, 0), end=(80, 60))
    assert [type(x).__name__ for x in corner] == ["BezierSpiral", "BezierSpiral", "Line"]


def test_chain_rejects_non_segments_and_empty():
    with pytest.raises(ValueError, match="at least one"):
        Chain([])
    with pytest.raises(ValueError, match="Line, Arc or BezierSpiral"):
        Chain([(0, 0)])


def test_arc_between_takes_the_travel_sense():
    ccw = Arc.between((0, 0), 1.0, (1, 0), (0, 1))
    cw = Arc.between((0, 0), -1.0, (1, 0), (0, 1))
    assert ccw.sweep == pytest.approx(math.pi / 2) and cw.sweep == pytest.approx(3 * math.pi / 2)
    assert np.allclose(cw.end, (0, 1)) and np.allclose(cw.point(1 / 3), (0, -1), atol=1e-12)
    assert ccw.curvature(0.3) == pytest.approx(1.0) and cw.curvature(0.3) == pytest.approx(-1.0)


def test_single_spiral_chain_and_repr():
    chain = Chain([BezierSpiral((0, 0), (1, 0), 0.5, 1.0)])
    assert "BezierSpiral" in repr(chain) and len(chain) == 1


def test_survey_coordinates_build_at_the_default_tolerance_and_still_catch_g1():
    o = np.array([6.5e5, 5.4e6])
    enter = line_to_circle(o, (1, 0), o + (600, 360), 300.0)
    leave = line_to_circle(o + (1800, 900), (-1, -1), o + (600, 360), 300.0).reversed()
    chain = Chain.join([enter, leave])  # default 1e-9 plus the rounding floor of 1e6 coordinates
    assert len(chain) == 3
    tangent_arc = Arc.between(o + (0, 300), 300.0, o, o + (300, 300))
    with pytest.raises(ValueError, match="curvature jump 0.00333"):
        Chain([Line(o - (100, 0), o), tangent_arc])
