"""Chains in space: lines, arcs and planar spirals in 3-D, every joint G2 by the curvature vector κN.

The joint checks here compute κN from control points with their own formula
(Q' and Q'' of the cubic at its ends), not with the project's code.
"""

import math

import numpy as np
import pytest
from helpers import bezier_end, helix_chain
from hypothesis import given, settings
from hypothesis import strategies as st

import spiral_cad as sc
from spiral_cad import Arc, BezierSpiral, Chain, Line
from spiral_cad.core.errors import JointError
from spiral_cad.core.nurbs import chain_to_nurbs
from spiral_cad.core.space import PlaneFrame, place

# ------------------------------------------------------------ independent geometry


def segment_end(segment, at_end):
    """Point, tangent, κN of a Line, Arc or BezierSpiral end, from its defining data only."""
    if isinstance(segment, BezierSpiral):
        return bezier_end(segment.control_points, at_end)
    if isinstance(segment, Line):
        a, b = (np.asarray(p, dtype=float) for p in (segment.point(0.0), segment.point(1.0)))
        return (b if at_end else a), (b - a) / np.linalg.norm(b - a), np.zeros(3)
    c, n, r = segment.center, segment.normal, segment.radius
    p = np.asarray(segment.point(1.0 if at_end else 0.0))
    radial = p - c
    tangent = np.sign(r) * np.cross(n, radial) / np.linalg.norm(radial)
    return p, tangent, -radial / (radial @ radial)


def joint_mismatch(a, b):
    """(gap, tangent angle, |ΔκN|, κ scale) from a's end to b's start."""
    pa, ta, ka = segment_end(a, True)
    pb, tb, kb = segment_end(b, False)
    angle = math.atan2(np.linalg.norm(np.cross(ta, tb)), ta @ tb)
    scale = max(np.linalg.norm(ka), np.linalg.norm(kb), 1.0 / max(a.length, b.length))
    return np.linalg.norm(pb - pa), angle, np.linalg.norm(kb - ka), scale


def assert_g2_by_curvature_vector(chain, tol=1e-9):
    for a, b in zip(chain, chain[1:]):
        gap, angle, jump, scale = joint_mismatch(a, b)
        assert gap <= tol * chain.size and angle <= tol and jump <= tol * scale, (gap, angle, jump, scale)


# ------------------------------------------------------------ a helix-like path


def test_a_helix_of_lines_and_placed_spiral_pairs_is_g2_by_the_curvature_vector():
    chain, pairs, pts = helix_chain()
    assert chain.dim == 3 and len(chain) == 3 * len(pairs) + 1
    assert [type(s).__name__ for s in chain[:4]] == ["Line", "BezierSpiral", "BezierSpiral", "Line"]
    assert np.allclose(chain.start, pts[0]) and np.allclose(chain.end, pts[-1])
    assert_g2_by_curvature_vector(chain)
    # Every corner in its own plane: its spirals lie in the plane of its legs.
    normals = []
    for (spirals, _frame), (before, corner, after) in zip(pairs, zip(pts, pts[1:], pts[2:])):
        n = np.cross(corner - before, after - corner)
        n /= np.linalg.norm(n)
        normals.append(n)
        for spiral in spirals:
            assert spiral.dim == 3 and spiral.control_points.shape == (4, 3)
            assert np.abs((spiral.control_points - corner) @ n).max() <= 1e-12 * chain.size
            assert np.allclose(np.abs(spiral.normal @ n), 1.0, atol=1e-12)
    assert min(math.acos(min(1.0, abs(a @ b))) for a, b in zip(normals, normals[1:])) > math.radians(5)  # planes differ
    # The peak curvature sits where the two spirals of a corner meet, with the same κN on both sides.
    joint = pairs[0][0][0]
    kappa = np.linalg.norm(bezier_end(joint.control_points, True)[2])
    assert joint.end_curvature == pytest.approx(kappa, rel=1e-12)
    assert np.allclose(joint.end_curvature_vector, bezier_end(joint.control_points, True)[2], rtol=1e-12, atol=1e-15 * kappa)


def test_join_bridges_the_placed_pairs_with_lines_and_matches_the_hand_built_chain():
    chain, pairs, pts = helix_chain()
    joined = Chain.join([s for spirals, _ in pairs for s in spirals], start=pts[0], end=pts[-1])
    assert joined.dim == 3 and len(joined) == len(chain)
    assert joined.length == pytest.approx(chain.length, rel=1e-15)
    assert joined[1] is pairs[0][0][0]  # parts are kept as the chain's segments
    assert_g2_by_curvature_vector(joined)


def test_station_queries_in_space():
    chain, _, _ = helix_chain()
    s = np.linspace(0.0, chain.length, 301)
    points, tangents = chain.point_at(s), chain.tangent_at(s)
    kappa, vectors = chain.curvature_at(s), chain.curvature_vector_at(s)
    assert points.shape == (301, 3) and tangents.shape == (301, 3) and vectors.shape == (301, 3)
    assert np.allclose(np.linalg.norm(tangents, axis=1), 1.0, atol=1e-12)
    assert np.all(kappa >= 0.0) and np.allclose(np.linalg.norm(vectors, axis=1), kappa, rtol=1e-12, atol=1e-15)
    assert np.abs(np.einsum("ij,ij->i", vectors, tangents)).max() <= 1e-12 * kappa.max()  # κN ⟂ T
    chords = np.linalg.norm(np.diff(points, axis=0), axis=1)
    assert np.all(chords <= np.diff(s) * (1 + 1e-9)) and np.all(chords >= np.diff(s) * 0.99)
    back = chain.reversed()
    assert back.dim == 3 and np.allclose(back.point_at(s), chain.point_at(chain.length - s), atol=1e-9 * chain.size)


def test_a_turn_of_the_osculating_plane_at_nonzero_curvature_is_refused():
    entry = sc.line_to_circle((0, 0), (1, 0), (0, 1.2), 1.0).spirals[0].placed(PlaneFrame())
    p, t, kn = segment_end(entry, True)
    center = p + kn / (kn @ kn)  # the circle the spiral reaches
    for degrees, ok in ((0.0, True), (20.0, False)):
        # Rotate that circle about the joint's tangent: same point, tangent and |κ|, another plane.
        a = math.radians(degrees)
        radial = center - p
        turned = radial * math.cos(a) + np.cross(t, radial) * math.sin(a)
        normal = np.cross(-turned, t)
        arc = Arc.in_space(p + turned, normal, p, 0.8)
        gap, angle, jump, scale = joint_mismatch(entry, arc)
        assert gap <= 1e-12 and angle <= 1e-12
        if ok:
            Chain([entry, arc])
            assert jump <= 1e-9 * scale
        else:
            assert jump == pytest.approx(2 * math.sin(a / 2), rel=1e-9)  # |Δ(κN)| with κ = 1
            with pytest.raises(JointError, match=r"joint 0 \(between segments 0 and 1\).*curvature jump 0\.347") as caught:
                Chain([entry, arc])
            assert caught.value.joint == 0


def test_a_plane_chain_placed_in_space_keeps_its_geometry():
    enter = sc.line_to_circle((0, 0), (1, 0), (100, 60), 50.0)
    leave = sc.line_to_circle((300, 150), (-1, -1), (100, 60), 50.0).reversed()
    flat = Chain.join([enter, leave], start=(-20, 0), end=(400, 250), units="m")
    frame = PlaneFrame((5.0, -3.0, 7.0), x_dir=(1.0, 1.0, 0.5), normal=(0.2, -0.3, 1.0))
    space = flat.placed(frame)
    assert space.dim == 3 and space.units == "m" and len(space) == len(flat)
    assert [type(s).__name__ for s in space] == [type(s).__name__ for s in flat]
    assert np.allclose(space.lengths, flat.lengths, rtol=1e-14)
    s = np.linspace(0.0, flat.length, 97)
    assert np.allclose(space.point_at(s), frame.point(flat.point_at(s)), atol=1e-12 * flat.size)
    assert np.allclose(space.curvature_at(s), np.abs(flat.curvature_at(s)), rtol=1e-9, atol=1e-15)
    assert np.allclose(space.curvature_vector_at(s), frame.vector(flat.curvature_vector_at(s)), atol=1e-12)
    arc = space[2]
    assert np.allclose(arc.normal, frame.normal) and arc.radius == flat[2].radius
    assert_g2_by_curvature_vector(space)
    with pytest.raises(ValueError, match="already in space"):
        space.placed(frame)
    with pytest.raises(ValueError, match="plane chain"):
        space.to_nurbs()


def test_join_continues_an_arc_in_space_on_its_own_circle():
    normal = np.array([0.0, -1.0, 1.0])
    first = Arc.in_space((1.0, 2.0, 3.0), normal, (1.0 + 5.0, 2.0, 3.0), 0.5)
    second = first.piece(0.5, 1.0)
    later = Arc._of(second.center, second.radius, second.start_angle + 1.0, second.sweep, second.basis)
    chain = Chain.join([first, later])
    assert [type(s).__name__ for s in chain] == ["Arc", "Arc", "Arc"]
    assert chain[1].sweep == pytest.approx(1.0 - 0.25, rel=1e-12)
    assert np.allclose(chain[1].normal, normal / np.linalg.norm(normal))
    assert chain.length == pytest.approx(5.0 * (0.5 + 0.75 + 0.25), rel=1e-12)
    assert_g2_by_curvature_vector(chain)


def test_plane_and_space_segments_mix_in_the_xy_plane():
    chain = Chain([Line((0, 0), (1, 0)), Line((1, 0, 0), (2, 0, 1e-20)), Line((2, 0, 1e-20), (3, 0, 2e-20))])
    assert chain.dim == 3 and all(s.dim == 3 for s in chain)
    assert chain[0].end.tolist() == [1.0, 0.0, 0.0]
    assert Line((0, 0, 0), (1, 2, 0)).dim == 2  # z = 0 everywhere: a plane line, as every plane input
    assert Chain([Line((0, 0), (1, 0))]).placed(PlaneFrame()).dim == 3


def test_arc_in_space_properties():
    arc = Arc.in_space((0, 0, 1), (0, 0, 2), (3, 0, 1), -math.pi / 2)  # clockwise about +z
    assert arc.dim == 3 and arc.radius == -3.0 and arc.sweep == pytest.approx(math.pi / 2)
    assert np.allclose(arc.end, (0, -3, 1), atol=1e-15) and np.allclose(arc.start_tangent, (0, -1, 0), atol=1e-15)
    assert arc.curvature(0.3) == pytest.approx(1 / 3) and np.allclose(arc.curvature_vector(0.0), (-1 / 3, 0, 0))
    assert arc.length == pytest.approx(1.5 * math.pi)
    back = arc.reversed()
    assert np.allclose(back.start, arc.end) and np.allclose(back.point(0.25), arc.point(0.75))
    with pytest.raises(ValueError, match="off the plane"):
        Arc.in_space((0, 0, 0), (0, 0, 1), (1, 0, 1), 1.0)
    with pytest.raises(ValueError, match="non-zero vector"):
        Arc.in_space((0, 0, 0), (0, 0, 0), (1, 0, 0), 1.0)
    with pytest.raises(ValueError, match="sweep"):
        Arc.in_space((0, 0, 0), (0, 0, 1), (1, 0, 0), 7.0)
    with pytest.raises(ValueError, match="plane circle"):
        arc.circle


def test_space_spirals_must_be_planar_and_plane_only_methods_refuse_them():
    cp = sc.line_to_circle((0, 0), (1, 0), (0, 1.2), 1.0).spirals[0].control_points
    lifted = np.hstack([cp, np.zeros((4, 1))])
    assert BezierSpiral.from_control_points(lifted).dim == 2  # z = 0: a plane spiral
    tilted = place(cp, (0, 0, 1), (1, 0, 0), (0, 0.6, 0.8))
    spiral = BezierSpiral.from_control_points(tilted)
    assert spiral.dim == 3 and spiral.theta == pytest.approx(abs(BezierSpiral.from_control_points(cp).theta), rel=1e-12)
    # A full spiral starts straight (B0, B1, B2 on a line), so its points are always coplanar; a piece is not.
    piece = spiral.piece(0.2, 0.9)
    assert piece.dim == 3 and np.allclose(piece.normal, spiral.normal, atol=1e-12)
    bent = piece.control_points + np.outer([0, 0, 0, 1e-3], spiral.normal)
    with pytest.raises(ValueError, match="lie in one plane"):
        BezierSpiral.from_control_points(bent)
    with pytest.raises(ValueError, match="already in space"):
        spiral.placed(PlaneFrame())
    with pytest.raises(ValueError, match="plane frames"):
        spiral.ends
    with pytest.raises(ValueError, match="segment 0 is in space"):
        chain_to_nurbs([spiral])


def test_plane_frames():
    frame = PlaneFrame.of_corner((0, 0, 0), (1, 0, 0), (1, 0, 1))
    assert np.allclose(frame.normal, (0, -1, 0)) and np.allclose(frame.x_dir, (1, 0, 0))
    assert np.allclose(frame.local([(1, 0, 0), (1, 0, 1), (0, 0, 0)]), [(0, 0), (0, 1), (-1, 0)])
    corners = np.array([[0.0, 0.0, 0.0], [1.0, 2.0, 3.0]])
    x = np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
    y = np.array([[0.0, 1.0, 0.0], [0.0, 0.0, 1.0]])
    many = place(np.ones((2, 4, 2)), corners[:, None], x[:, None], y[:, None])  # N frames, k points each
    assert many.shape == (2, 4, 3) and np.allclose(many[1], (1.0, 3.0, 4.0))
    with pytest.raises(ValueError, match="collinear"):
        PlaneFrame.of_corner((0, 0, 0), (1, 0, 0), (2, 0, 0))
    with pytest.raises(ValueError, match="x_dir off the normal"):
        PlaneFrame(x_dir=(0, 0, 1))


# ------------------------------------------------------------ the array store and the rule written once


def test_joins_of_the_vectorised_pass_equal_the_per_joint_rule():
    from spiral_cad.core.chain import g2_mismatch
    from spiral_cad.core.segments import measure_join

    for chain in (helix_chain()[0], Chain.join([sc.circle_to_circle((0, 0), 20.0, (60, 10), 15.0),
                                                 sc.circle_to_circle((60, 10), 15.0, (120, -20), -25.0)])):  # fmt: skip
        for join, (a, b) in zip(chain.joins(), zip(chain, chain[1:])):
            assert join == measure_join(a, b, join.index)
            assert g2_mismatch(a, b, chain.tolerance) is None


def test_rows_hold_the_chain_and_segments_are_made_when_asked():
    chain, _, _ = helix_chain()
    rows = chain.rows
    assert len(rows) == len(chain) and rows.dim == 3 and rows.geometry.shape == (len(chain), 4, 3)
    assert np.array_equal(rows.geometry[1], np.asarray(chain[1].control_points))
    assert chain.lengths.sum() == pytest.approx(chain.length, rel=1e-15)
    with pytest.raises(ValueError):
        rows.geometry[0, 0, 0] = 1.0  # read-only views


# ------------------------------------------------------------ CAD: exact 3-D edges


def test_a_chain_in_space_reaches_occt_as_exact_edges_and_checks_g2():
    pytest.importorskip("build123d")
    from OCP.BRepAdaptor import BRepAdaptor_Curve
    from OCP.GeomAbs import GeomAbs_BezierCurve, GeomAbs_Circle, GeomAbs_Line

    from spiral_cad.build123d import chain_edges, chain_to_wire
    from spiral_cad.cad.continuity import check_continuity

    chain, _, _ = helix_chain()
    arc = Arc.in_space(chain.end, (0.3, 0.2, 1.0), chain.end + (10.0, 0.0, -3.0), 1.0)
    wire = chain_to_wire(chain)
    edges = wire.edges()
    assert len(edges) == len(chain)
    kinds = [BRepAdaptor_Curve(e.wrapped).GetType() for e in edges]
    assert kinds[:3] == [GeomAbs_Line, GeomAbs_BezierCurve, GeomAbs_BezierCurve]
    for edge, segment in zip(edges, chain):
        for u in (0.0, 0.37, 1.0):
            p = edge.position_at(u)
            assert np.allclose((p.X, p.Y, p.Z), segment.point(segment.parameter_at(u * segment.length)), atol=1e-9 * chain.size)
    report = check_continuity(wire)
    assert report.passes("G2"), report.format_table()
    (edge,) = chain_edges(Chain([arc]))
    assert BRepAdaptor_Curve(edge.wrapped).GetType() == GeomAbs_Circle
    for u in (0.0, 0.5, 1.0):
        p = edge.position_at(u)
        assert np.allclose((p.X, p.Y, p.Z), arc.point(u), atol=1e-12 * abs(arc.radius))
    clockwise = Arc.in_space((0, 0, 0), (1, 1, 1), (1, -1, 0), -2.0)
    (edge,) = chain_edges(Chain([clockwise]))
    p = edge.position_at(0.5)
    assert np.allclose((p.X, p.Y, p.Z), clockwise.point(0.5), atol=1e-12)


# ------------------------------------------------------------ the one rule in space

UNIT = st.tuples(st.floats(-1, 1), st.floats(-1, 1), st.floats(-1, 1)).filter(lambda v: 0.1 < math.hypot(*v))


@settings(max_examples=40)
@given(st.floats(-300, 300), st.floats(-3, 12), UNIT, UNIT)
def test_a_placed_chain_at_any_scale_and_offset_is_checked_or_refused_by_name(log_scale, log_offset, normal, direction):
    """The road chain, scaled by 10**log_scale, placed in a plane of any orientation 10**log_offset
    sizes from the origin: a 3-D chain that starts and ends where the plane puts it, or a plain ValueError."""
    scale = 10.0**log_scale
    enter = sc.line_to_circle((0, 0), (1, 0), (100 * scale, 60 * scale), 50 * scale)
    leave = sc.line_to_circle((300 * scale, 150 * scale), (-1, -1), (100 * scale, 60 * scale), 50 * scale).reversed()
    flat = Chain.join([enter, leave], start=(-20 * scale, 0), end=(400 * scale, 250 * scale))
    if abs(np.dot(normal, direction)) > 0.99 * math.hypot(*normal) * math.hypot(*direction):
        return  # x_dir along the normal: no frame
    with np.errstate(over="ignore"):  # an origin beyond float64 is one of the cases: refused below
        origin = np.array(direction) * 10.0**log_offset * 400 * scale
    try:
        frame = PlaneFrame(origin, x_dir=direction, normal=normal)
        space = flat.placed(frame)
    except ValueError as error:
        message = str(error)
        assert message and "np." not in message and "array(" not in message, message
        return
    assert space.dim == 3 and len(space) == len(flat)
    rounding = 64 * np.spacing(np.abs(origin).max() + flat.size)  # what the placed coordinates can hold
    for got, want in ((space.start, flat.start), (space.end, flat.end)):
        assert math.dist(got, frame.point(want)) <= 1e-9 * space.size + rounding
    assert space.length == pytest.approx(flat.length, rel=1e-9, abs=len(flat) * rounding)
