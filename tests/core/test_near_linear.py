"""The near-linear spiral shape, checked without the solver's formulas.

Curvature and arc length are re-derived here from the returned control
points (Bernstein derivatives, dense sampling, trapezoid arc length); joins
are recomputed with mpmath at 40 digits (``test_never_wrong``). The figures
are those of NEAR_LINEAR.md (recomputed independently there).
"""

import math

import numpy as np
import pytest
from helpers import assert_meet_g2, assert_on_circle
from hypothesis import example, given, settings
from hypothesis import strategies as st

import spiral_cad as sc
from spiral_cad.core import batch

SHAPES = ("walton-meek", "near-linear")
EQUAL_LEG_LIMIT = math.acos(5.0 / 6.0)  # 33.557°: where the equal-leg member stops being monotone
LARGEST = math.radians(50.0)


# ------------------------------------------------ independent measurements


def derivatives(cp, u):
    """Q'(u) and Q''(u) of a cubic from its Bernstein form."""
    p = np.asarray(cp, dtype=float)
    u = u[:, None]
    d1 = 3 * ((1 - u) ** 2 * (p[1] - p[0]) + 2 * u * (1 - u) * (p[2] - p[1]) + u**2 * (p[3] - p[2]))
    d2 = 6 * ((1 - u) * (p[2] - 2 * p[1] + p[0]) + u * (p[3] - 2 * p[2] + p[1]))
    return d1, d2


def curvature_profile(cp, samples=200_001):
    """(s, κ) densely sampled: arc length by the trapezoid rule on the speed."""
    u = np.linspace(0.0, 1.0, samples)
    d1, d2 = derivatives(cp, u)
    speed = np.hypot(d1[:, 0], d1[:, 1])
    kappa = (d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]) / speed**3
    s = np.concatenate([[0.0], np.cumsum(0.5 * (speed[1:] + speed[:-1]) * np.diff(u))])
    return s, kappa


def peak_over_mean_rate(cp):
    """max dκ/ds over its mean κ_end/L, and whether κ is monotone."""
    s, kappa = curvature_profile(cp)
    rate = np.diff(kappa) / np.diff(s)
    return float(rate.max() * s[-1] / kappa[-1]), bool(np.all(np.diff(kappa) >= -1e-12 * kappa[-1]))


def legs(cp):
    p = np.asarray(cp)
    return np.linalg.norm(np.diff(p, axis=0), axis=1)


# ------------------------------------------------------ the figures


@pytest.mark.parametrize(
    "degrees, near_linear, walton_meek",
    [(2, 1.0009, 1.839), (5, 1.0055, 1.819), (8, 1.0140, 1.781), (15, 1.0502, 1.632), (30, 1.2161, 1.250)],
)
def test_peak_over_mean_curvature_rate_meets_the_figures(degrees, near_linear, walton_meek):
    theta = math.radians(degrees)
    for shape, figure in (("near-linear", near_linear), ("walton-meek", walton_meek)):
        spiral = sc.BezierSpiral((3.0, -2.0), (1.0, 2.0), theta, 1 / 500.0, shape=shape)
        ratio, monotone = peak_over_mean_rate(spiral.control_points)
        assert monotone
        assert ratio <= figure * 1.005 and ratio >= figure * 0.995, (shape, ratio)


@pytest.mark.parametrize("degrees", [1, 10, 20, 33])
def test_equal_leg_curvature_has_the_closed_form(degrees):
    """κ(u) = u / (R·[1 − 4 sin²(θ/2)·u²(1 − u²)]^{3/2}) with a = b = c = (2/3)·R·sin θ."""
    theta, radius = math.radians(degrees), 250.0
    spiral = sc.BezierSpiral((0, 0), (0, 1), theta, 1 / radius, shape="near-linear")
    assert legs(spiral.control_points) == pytest.approx([2 / 3 * radius * math.sin(theta)] * 3, rel=1e-13)
    u = np.linspace(0, 1, 101)
    closed = u / (radius * (1 - 4 * math.sin(theta / 2) ** 2 * u**2 * (1 - u**2)) ** 1.5)
    assert np.allclose(spiral.curvature(u), closed, rtol=1e-12, atol=1e-15)


@pytest.mark.parametrize("degrees", [34, 38, 42, 46, 50])
def test_beyond_the_equal_legs_the_family_stays_monotone_and_beats_the_1996_spiral(degrees):
    theta = math.radians(degrees)
    nl = sc.BezierSpiral((0, 0), (1, 0), -theta, -0.01, shape="near-linear")
    wm = sc.BezierSpiral((0, 0), (1, 0), -theta, -0.01, shape="walton-meek")
    mirrored = nl.control_points * (1, -1)
    ratio, monotone = peak_over_mean_rate(mirrored)
    assert monotone and ratio < peak_over_mean_rate(wm.control_points * (1, -1))[0]
    assert nl.end_curvature == pytest.approx(-0.01, rel=1e-12) and nl.theta == pytest.approx(-theta, rel=1e-12)


def test_the_family_is_continuous_where_the_equal_legs_end():
    below = sc.BezierSpiral((0, 0), (1, 0), EQUAL_LEG_LIMIT * (1 - 1e-9), 1.0, shape="near-linear")
    above = sc.BezierSpiral((0, 0), (1, 0), EQUAL_LEG_LIMIT * (1 + 1e-9), 1.0, shape="near-linear")
    assert np.allclose(below.control_points, above.control_points, atol=1e-8)


def test_near_linear_spirals_end_at_fifty_degrees():
    sc.BezierSpiral((0, 0), (1, 0), LARGEST, 1.0, shape="near-linear")
    with pytest.raises(sc.NoSolutionError, match=r"at most 50°.*walton-meek"):
        sc.BezierSpiral((0, 0), (1, 0), math.radians(50.01), 1.0, shape="near-linear")
    with pytest.raises(ValueError, match="shape must be one of"):
        sc.BezierSpiral((0, 0), (1, 0), 0.3, 1.0, shape="clothoid")


# -------------------------------------------- existence conditions


def test_line_to_circle_uses_equal_legs_below_one_27th_and_reaches_fifty_degrees():
    r = 80.0
    for q, equal in ((1e-9, True), (1e-3, True), (1 / 27 * (1 - 1e-6), True), (1 / 27 * (1 + 1e-3), False), (0.1, False)):
        t = sc.line_to_circle((0, 0), (1, 0), (10, r * (1 + q)), r, shape="near-linear")
        assert t.shape == "near-linear" and t.spirals[0].shape == "near-linear"
        assert (t.theta < EQUAL_LEG_LIMIT) == equal
        leg = legs(t.spirals[0].control_points)
        assert np.allclose(leg, leg[0], rtol=1e-9) == equal
        assert_on_circle(t.spirals[0].control_points, (10, r * (1 + q)), r, True)
    t = sc.line_to_circle((0, 0), (1, 0), (10, r * 1.115), r, shape="near-linear")
    assert math.radians(49.9) < t.theta <= LARGEST
    with pytest.raises(sc.NoSolutionError, match=r"d/r < 1.115.*walton-meek"):
        sc.line_to_circle((0, 0), (1, 0), (10, r * 1.1152), r, shape="near-linear")
    assert sc.line_to_circle((0, 0), (1, 0), (10, r * 1.1152), r).theta > 0  # the 1996 spiral reaches it


def test_s_pair_uses_equal_legs_below_1_1476_and_ends_at_1_4108():
    r0, r1 = 30.0, 70.0
    for ratio, equal in ((1.0001, True), (1.1475, True), (1.1477, False), (1.41, False)):
        t = sc.circle_to_circle((0, 0), r0, (ratio * (r0 + r1), 0), -r1, shape="near-linear")
        assert (t.theta < EQUAL_LEG_LIMIT) == equal
        assert_on_circle(t.spirals[0].control_points, (0, 0), r0, False)
        assert_on_circle(t.spirals[1].control_points, (ratio * (r0 + r1), 0), -r1, True)
        assert_meet_g2(t.spirals[0].control_points, t.spirals[1].control_points, r0)
    with pytest.raises(sc.NoSolutionError, match=r"D/\(\|r0\| \+ \|r1\|\) < 1.4108.*walton-meek"):
        sc.circle_to_circle((0, 0), r0, (1.4109 * (r0 + r1), 0), -r1, shape="near-linear")


def test_c_pair_reaches_as_far_as_fifty_degree_spirals():
    r0, r1 = 30.0, 70.0
    far = sc.circle_to_circle((0, 0), r0, (97.0, 0), r1, shape="near-linear")
    assert math.radians(45) < far.theta <= LARGEST
    with pytest.raises(sc.NoSolutionError, match=r"broken-back C.*D < 97.2.*here D = 100"):
        sc.circle_to_circle((0, 0), r0, (100.0, 0), r1, shape="near-linear")
    near = sc.circle_to_circle((0, 0), r0, (40.001, 0), r1, shape="near-linear")
    assert near.theta < EQUAL_LEG_LIMIT


def test_corner_pairs_round_deflections_up_to_one_hundred_degrees():
    for degrees in (1, 60, 90, 100):
        a = math.radians(degrees)
        t = sc.line_to_line((-10, 0), (0, 0), (10 * math.cos(a), 10 * math.sin(a)), shape="near-linear")
        assert t.theta == pytest.approx(a / 2, rel=1e-12)
        assert_meet_g2(t.spirals[0].control_points, t.spirals[1].control_points, 10.0)
    with pytest.raises(sc.NoSolutionError, match=r"at most 100° deflection.*101°.*walton-meek"):
        sc.line_to_line((-10, 0), (0, 0), (10 * math.cos(math.radians(101)), 10 * math.sin(math.radians(101))), shape="near-linear")


def test_nested_band_of_the_near_linear_spiral():
    r0, r1 = 100.0, 40.0
    with pytest.raises(sc.NoSolutionError, match=r"single near-linear spiral exists only for 0.98\d+ ≤ D"):
        sc.circle_in_circle((0, 0), r0, (0, 0.95 * (r0 - r1)), r1, shape="near-linear")
    t = sc.circle_in_circle((0, 0), r0, (0, 0.995 * (r0 - r1)), r1, shape="near-linear")
    assert 0 < t.theta <= LARGEST and 0 < t.parameter < 1
    cp = t.spirals[0].control_points
    assert_on_circle(cp, (0, 0), r0, False)
    assert_on_circle(cp, (0, 0.995 * (r0 - r1)), r1, True)
    assert peak_over_mean_rate(cp)[1]  # κ grows from 1/r0 to 1/r1
    back = sc.circle_in_circle((0, 0.995 * (r0 - r1)), -r1, (0, 0), -r0, shape="near-linear")
    assert np.allclose(back.spirals[0].control_points, cp[::-1], atol=1e-12 * r0)


def test_g2cbs_is_a_corner_shape():
    t = sc.line_to_line((-10, 0), (0, 0), (5, 8), shape="g2cbs")
    assert t.shape == "g2cbs"
    ratio = legs(t.spirals[0].control_points)
    assert ratio[0] / ratio[1] == pytest.approx(2 * (math.sqrt(6) - 1) / 5, rel=1e-12)
    with pytest.raises(ValueError, match="g2cbs is a corner shape"):
        sc.line_to_circle((0, 0), (1, 0), (0, 105), 100, shape="g2cbs")


# ---------------------------------------- any position, orientation and scale


scales = st.floats(-6, 6).map(lambda e: 10.0**e)
angles = st.floats(-math.pi, math.pi)
offsets = st.floats(-1e4, 1e4)


@settings(max_examples=60)
@given(scales, angles, st.floats(1e-6, 0.114), st.sampled_from([1.0, -1.0]), offsets, offsets)
def test_line_to_circle_near_linear_anywhere(scale, a, q, side, ox, oy):
    direction = np.array([math.cos(a), math.sin(a)])
    normal = side * np.array([-direction[1], direction[0]])
    point = np.array([ox, oy]) * scale
    center = point + 3.0 * scale * direction + scale * (1 + q) * normal
    try:
        t = sc.line_to_circle(point, direction, center, scale, shape="near-linear")
    except sc.NoSolutionError as error:  # a tiny turn far from the origin: README, θ → 0
        assert "float64 cannot hold it" in str(error) and q < 1e-4
        return
    assert_on_circle(t.spirals[0].control_points, center, side * scale, True)


@settings(max_examples=60)
@given(scales, angles, st.floats(0.2, 5.0), st.floats(1e-3, 0.4), st.booleans(), offsets)
# Each spiral within the tolerance of the common tangent, the two 1.3e-9 apart: the pair's own joint is checked.
@example(scale=10.0, a=1.0, ratio=1.01, e=0.001, s_shape=False, offset=6553.0)
def test_circle_to_circle_near_linear_anywhere(scale, a, ratio, e, s_shape, offset):
    r0 = scale
    r1 = ratio * scale * (-1 if s_shape else 1)
    gap = abs(r0) + abs(r1) if s_shape else abs(abs(r1) - abs(r0))
    dist = gap + e * min(abs(r0), abs(r1))
    c0 = np.array([offset, -offset]) * scale
    c1 = c0 + dist * np.array([math.cos(a), math.sin(a)])
    try:
        t = sc.circle_to_circle(c0, r0, c1, r1, shape="near-linear")
    except sc.NoSolutionError as error:  # a C pair beyond 50° spirals, or circles float64 cannot resolve
        assert "walton-meek shape reaches it" in str(error) or "float64" in str(error)
        return
    assert_on_circle(t.spirals[0].control_points, c0, r0, False)
    assert_on_circle(t.spirals[1].control_points, c1, r1, True)
    joint_leg = min(legs(t.spirals[0].control_points)[-1], legs(t.spirals[1].control_points)[0])
    assert_meet_g2(t.spirals[0].control_points, t.spirals[1].control_points, joint_leg)


@settings(max_examples=60)
@given(scales, angles, st.floats(0.5, 99.0), st.floats(0.2, 5.0), offsets)
def test_line_to_line_near_linear_anywhere(scale, a, deflection, leg, offset):
    corner = np.array([offset, offset / 3]) * scale
    t_in = np.array([math.cos(a), math.sin(a)])
    b = a + math.radians(deflection)
    p0 = corner - scale * t_in
    p1 = corner + leg * scale * np.array([math.cos(b), math.sin(b)])
    t = sc.line_to_line(p0, corner, p1, shape="near-linear")
    assert_meet_g2(t.spirals[0].control_points, t.spirals[1].control_points, scale)


def test_scalar_and_batch_agree_bit_for_bit():
    rng = np.random.default_rng(5)
    n = 64
    p = rng.normal(size=(n, 2)) * 100
    d = rng.normal(size=(n, 2))
    r = rng.uniform(10, 200, n)
    normal = np.stack([-d[:, 1], d[:, 0]], axis=1) / np.linalg.norm(d, axis=1, keepdims=True)
    c = p + r[:, None] * (1 + rng.uniform(0, 0.11, n))[:, None] * normal
    res = batch.line_to_circle(p, d, c, r, shape="near-linear")
    assert res.ok.all() and res.shape == "near-linear"
    for i in range(n):
        assert np.array_equal(res.spirals[0][i], sc.line_to_circle(p[i], d[i], c[i], r[i], shape="near-linear").spirals[0].control_points)
    c1 = p + rng.uniform(1.01, 1.4, n)[:, None] * (r + 50)[:, None] * normal
    res = batch.circle_to_circle(p, r, c1, -np.full(n, 50.0), shape="near-linear")
    assert res.ok.all()
    for i in range(n):
        t = sc.circle_to_circle(p[i], r[i], c1[i], -50.0, shape="near-linear")
        assert all(np.array_equal(res.spirals[k][i], t.spirals[k].control_points) for k in range(2))
    res = batch.circle_in_circle([0, 0], 100.0, np.stack([np.zeros(n), np.linspace(59.5, 59.9, n)], 1), 40.0, shape="near-linear")
    assert res.ok.all()
    for i in range(n):
        t = sc.circle_in_circle((0, 0), 100.0, (0, res.inputs["center1"][i, 1]), 40.0, shape="near-linear")
        assert np.array_equal(res.spirals[0][i], t.spirals[0].control_points) and res.parameter[i] == t.parameter
    bad = batch.line_to_circle([0, 0], [1, 0], [0, 150], 100, shape="near-linear")
    assert not bad.ok[0] and "walton-meek shape reaches it" in bad.reason(0)


# ------------------------------------------------ roads at a jerk limit


def test_a_100_kmh_highway_builds_at_the_clothoid_length():
    """100 km/h, R = 500 and 700 m, C = 0.5 m/s³: refused with the 1996 spiral, built with near-linear ones."""
    from spiral_cad.design import Alignment, RoadCriteria

    pis = [[0, 0], [900, 150], [1900, -120], [2900, 60]]
    criteria = RoadCriteria(100, max_jerk=0.5)
    with pytest.raises(sc.NoSolutionError, match="criteria conflict"):
        Alignment.from_pis(pis, [500, 700], units="m", criteria=criteria, shape="walton-meek")
    road = Alignment.from_pis(pis, [500, 700], units="m", criteria=criteria)
    v = 100 / 3.6
    for curve, check in zip(road.curves, road.checks):
        assert check.ok, check.violations
        clothoid = v**3 / (curve.radius * 0.5)
        for spiral in (curve.entry.spirals[0], curve.exit.spirals[0]):
            assert spiral.shape == "near-linear"
            s, kappa = curvature_profile(spiral.control_points)
            assert abs(s[-1] / clothoid - 1) < 0.01
            assert v**3 * np.abs(np.diff(kappa) / np.diff(s)).max() <= 0.5 * (1 + 1e-6)
    assert road.curves[0].spiral_in_length == pytest.approx(86.19, abs=0.02)  # NEAR_LINEAR.md's table


# ------------------------------------------- corners, circle chains, fillets, CAD


def test_round_corners_with_every_corner_shape_respects_the_bound():
    from spiral_cad.design import round_corners

    points = [(0, 0), (4, 0), (6, 2.5), (9, 2.0), (11, 4.5)]
    for shape in ("walton-meek", "near-linear", "g2cbs"):
        path = round_corners(points, max_curvature=3.0, shape=shape)
        assert path.shape == shape and all(s.shape == shape for c in path.corners for s in c.spirals)
        for corner in path.corners:
            for spiral in corner.spirals:
                _, kappa = curvature_profile(spiral.control_points, 20001)
                assert np.abs(kappa).max() <= 3.0 * (1 + 1e-9)
    with pytest.raises(sc.NoSolutionError, match=r"corner 1 .*deflection 120° is beyond what near-linear"):
        round_corners([(0, 0), (4, 0), (2, 3.4641016151377544)], shape="near-linear")
    with pytest.raises(ValueError, match="give shape or method"), pytest.warns(DeprecationWarning, match="method= is deprecated"):
        round_corners(points, shape="near-linear", method="g2cbs")


def test_circle_chain_of_near_linear_transitions():
    from spiral_cad.design import circle_chain

    circles = [((0, 0), 60.0), ((29.85, 0), 30.0), ((90, 0), 40.0), ((90, 80), -35.0)]
    chain = circle_chain(circles, shape="near-linear")
    assert chain.shape == "near-linear" and [t.kind for t in chain.transitions] == ["circle-circle-nested", "C", "S"]
    with pytest.raises(sc.NoSolutionError, match=r"circles 1 and 2: .*broken-back C.*walton-meek shape reaches it"):
        circle_chain([((0, 0), 60.0), ((29.85, 0), 30.0), ((150, -10), 40.0), ((150, 120), -35.0)], shape="near-linear")
    for segment in chain.chain:
        if isinstance(segment, sc.BezierSpiral):
            assert segment.shape == "near-linear"


@pytest.mark.parametrize("same_sense", ["nested", "C"])
def test_fillets_of_lines_and_arcs_with_near_linear_transitions(same_sense):
    from spiral_cad.design.fillets import corner_distance, fillet_path

    line = sc.Line((0, -10), (0, 10))
    arc = sc.Arc((0, 0), 10.0, math.pi / 2, math.pi)  # a D: line then half circle
    path = fillet_path([line, arc], 2.0, transition=0.5, same_sense=same_sense, shape="near-linear")
    path.chain  # every joint G2, or this raises
    spirals = [s for s in path.segments if isinstance(s, sc.BezierSpiral)]
    assert spirals and all(s.shape == "near-linear" for s in spirals)
    square = fillet_path([(0, 0), (40, 0), (40, 40), (0, 40), (0, 0)], 5.0, transition=0.6, shape="near-linear")
    start = square.corners[1].transitions[0].start  # corner 1 at (40, 0): its fillet starts corner_distance before it
    assert 40 - start[0] == pytest.approx(corner_distance(5.0, math.pi / 2, 0.6, "near-linear"), rel=1e-12)
    with pytest.raises(sc.NoSolutionError, match=r"corner 1 .*beyond 50° for near-linear spirals"):
        fillet_path([(0, 0), (40, 0), (20, 30)], 2.0, transition=1.0, shape="near-linear")


def test_cad_objects_take_the_shape():
    import cadquery as cq
    from build123d import Rectangle, extrude

    import spiral_cad.cadquery  # noqa: F401  (registers the Workplane methods)
    from spiral_cad.build123d import ContinuousRectangle, SpiralLineToCircle, g2_fillet
    from spiral_cad.cad.continuity import check_continuity

    face = g2_fillet(Rectangle(60, 30), radius=5, transition=0.5, shape="near-linear")
    assert check_continuity(face.faces()[0].outer_wire()).passes("G2")
    slab = extrude(ContinuousRectangle(70, 145, radius=9, transition=0.6, shape="near-linear"), 8)
    assert slab.is_valid
    edge = SpiralLineToCircle((0, 0), (1, 0), (0, 105), 100, shape="near-linear").edges()[0]
    expected = sc.line_to_circle((0, 0), (1, 0), (0, 105), 100, shape="near-linear").spirals[0].length
    assert edge.length == pytest.approx(expected, rel=1e-9)
    solid = cq.Workplane("XY").rect(40, 20).g2Fillet(4, shape="near-linear").extrude(5).val()
    assert solid.isValid()
    assert check_continuity(cq.Workplane().continuousRect(30, 20, 3, shape="near-linear").val().wrapped).passes("G2")


def test_the_100_kmh_design_file_builds_end_to_end(tmp_path):
    """Through ``spiral-cad build``: criteria met at the clothoid's length, and the .xodr holds the
    near-linear spirals exactly (read back by our reader here; the XSD, the ASAM checker and pyxodr
    read the demo highway, which is near-linear too, in test_opendrive)."""
    import csv
    import json
    import subprocess
    import sys

    from spiral_cad.design import Alignment, RoadCriteria
    from spiral_cad.io.opendrive import read_opendrive

    pis = [[0, 0], [900, 150], [1900, -120], [2900, 60]]
    design = {"units": "m", "designs": [{"name": "autobahn", "type": "alignment", "pis": pis, "radii": [500, 700],
                                         "design_speed": 100, "max_jerk": 0.5, "strict": True}]}  # fmt: skip
    path = tmp_path / "design.json"
    path.write_text(json.dumps(design))
    done = subprocess.run([sys.executable, "-m", "spiral_cad.app.cli", "build", str(path), "--out", str(tmp_path / "out"), "--no-plots"],
                          capture_output=True, text=True, timeout=300)  # fmt: skip
    assert done.returncode == 0, done.stderr
    with open(tmp_path / "out" / "autobahn_criteria.csv", newline="") as handle:
        rows = list(csv.DictReader(handle))
    v = 100 / 3.6
    for row in rows:
        assert row["verdict"] == "ok" and row["spiral_shape"] == "near-linear"
        clothoid = v**3 / (float(row["radius [m]"]) * 0.5)
        assert abs(float(row["L_in [m]"]) / clothoid - 1) < 0.01
        assert float(row["peak_lateral_jerk_in [m/s³]"]) <= 0.5 * (1 + 1e-9)
    (road,) = read_opendrive(tmp_path / "out" / "autobahn.xodr")
    ours = Alignment.from_pis(pis, [500, 700], units="m", criteria=RoadCriteria(100, 0.5)).chain
    back = road.chain()
    assert len(back) == len(ours)
    for a, b in zip(ours, back):
        if isinstance(a, sc.BezierSpiral):
            assert np.allclose(b.control_points, a.control_points, rtol=0, atol=1e-9)


def test_design_files_name_the_spiral_shape():
    from spiral_cad.app.designfile import DesignError, build

    def one(design):
        return build({"units": "m", "designs": [design]})[1][0]

    highway = {"name": "h", "type": "alignment", "pis": [[0, 0], [600, 120], [1150, -80]], "radii": [450], "design_speed": 80}
    assert one(highway).source.shape == "near-linear"
    assert one({**highway, "spiral_shape": "walton-meek"}).source.shape == "walton-meek"
    with pytest.raises(DesignError, match=r"designs\[0\] \(h\)\.spiral_shape: must be one of walton-meek, near-linear; got 'g2cbs'"):
        one({**highway, "spiral_shape": "g2cbs"})
    robot = {"name": "r", "type": "rounded_polyline", "points": [[0, 0], [2, 0], [3, 1]]}
    assert one({**robot, "spiral_shape": "g2cbs"}).source.shape == "g2cbs"
    assert one({**robot, "method": "g2cbs"}).source.shape == "g2cbs"
    with pytest.raises(DesignError, match="give spiral_shape or method"):
        one({**robot, "method": "g2cbs", "spiral_shape": "g2cbs"})
    t = one({"name": "t", "type": "transition", "case": "line_to_circle", "point": [0, 0], "direction": [1, 0],
             "center": [0, 105], "radius": 100, "spiral_shape": "near-linear"})  # fmt: skip
    assert t.source.shape == "near-linear"


def test_line_to_circle_beyond_the_equal_legs_solves_the_shift_to_a_few_ulp():
    """Past 33.56° the angle is a root (Newton on the shift cubic in cos θ); it must match
    the exact root of g1(θ) − 1 = q as closely as the closed forms do."""
    import mpmath as mp

    mp.mp.dps = 40

    def shift(c):  # the continuation member: r = 1.8c − 0.5, γ = (r + 4)/(9c)
        gamma = (mp.mpf(1.8) * c + mp.mpf(3.5)) / (9 * c)
        return (1 - c * c) * (gamma - 1 / (1 + c))

    for q in np.linspace(1 / 27 + 1e-6, 0.115, 25).tolist():
        t = sc.line_to_circle((0, 0), (1, 0), (0, 1 + q), 1.0, shape="near-linear")
        assert t.theta > math.acos(5 / 6)
        exact = mp.acos(mp.findroot(lambda c: shift(c) - (mp.mpf(1 + q) - 1), mp.mpf(math.cos(t.theta))))
        assert abs(t.theta - exact) <= 4 * math.ulp(t.theta)


@pytest.mark.parametrize("shape", ["walton-meek", "near-linear"])
def test_peak_rate_factor_is_the_measured_peak_and_its_branch_ends_where_the_peak_moves(shape):
    from spiral_cad.core import factors
    from spiral_cad.core.bezier import peak_curvature_rate

    low, high = factors.search_range(shape)
    theta = np.random.default_rng(3).uniform(low, high, 64)
    measured = peak_curvature_rate(factors.unit_spirals(theta, shape))[0]
    assert np.max(np.abs(factors.peak_rate_factor(theta, shape) / measured - 1.0)) < 1e-9
    start, stop, _ = factors._interior_branch(shape)
    switch, inside_before = (start, False) if shape == "walton-meek" else (stop, True)
    sides = peak_curvature_rate(factors.unit_spirals(np.array([switch - 1e-9, switch + 1e-9]), shape))[1] > 1e-6
    assert list(sides) == [inside_before, not inside_before]
