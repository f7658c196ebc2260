"""The five G2 transitions: joins, travel senses, feasibility and errors."""

import math
import re

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from spiral_cad import NoSolutionError, circle_in_circle, circle_to_circle, line_to_circle, line_to_line
from spiral_cad.core._kernel_circles import nested_band_lower as band_lower
from spiral_cad.core._kernels import WALTON_MEEK


def nested_band_lower(q):
    return band_lower(q, WALTON_MEEK)


TOL = 1e-12
UTM = np.array([6.5e5, 5.4e6])

angles = st.floats(-math.pi, math.pi)
radii = st.floats(0.3, 3.0)
signs = st.sampled_from([1.0, -1.0])
# Well-conditioned inputs: θ stays away from 0 and π/2 (README: conditioning).
clearances = st.floats(-3.0, 1.0).map(lambda e: 10.0**e)  # relative gap 1e-3 … 10
wide_clearances = st.floats(-0.7, 0.5).map(lambda e: 10.0**e)  # 0.2 … 3.2


def unit(a):
    return np.array([math.cos(a), math.sin(a)])


def assert_g2(t, scale):
    """Every contact and joint G2 to TOL: gap / scale, angle, Δκ × local radius.

    At a joint between spirals (κ = 0 in C and S) the local radius is that of
    the sharper adjacent spiral.
    """
    sp = t.spirals
    inner = [max(abs(a.start_curvature), abs(b.end_curvature)) for a, b in zip(sp, sp[1:])]
    kappas = [sp[0].start_curvature, *inner, sp[-1].end_curvature]
    for j, k in zip(t.joins(), kappas):
        assert j.gap <= TOL * scale, j
        assert j.angle <= TOL, j
        assert j.curvature_jump <= TOL * max(abs(k), 1 / scale), j


def assert_monotone(t):
    u = np.linspace(0, 1, 201)
    for s in t.spirals:
        k = np.abs(s.curvature(u))
        d = np.diff(k)
        peak = k.max()
        assert np.all(d >= -1e-12 * peak) or np.all(d <= 1e-12 * peak)


# --------------------------------------------------------- line → circle


@given(angles, radii, clearances, st.floats(-5, 5), signs, st.floats(-5, 5))
def test_line_to_circle_is_g2_and_turns_toward_the_circle(a, r, e, along, side, offset):
    p = np.array([offset, -offset])
    t_dir = unit(a)
    n = np.array([-t_dir[1], t_dir[0]])
    c = p + along * r * t_dir + side * r * (1 + e) * n
    t = line_to_circle(p, t_dir, c, r)
    assert len(t.spirals) == 1 and 0 < t.theta < math.pi / 2
    assert math.copysign(1, t.spirals[0].theta) == side
    assert t.end_circle.radius == side * r
    assert np.allclose(t.start_tangent, t_dir, atol=1e-14)
    assert_g2(t, r)
    assert_monotone(t)
    back = t.reversed()
    assert back.kind == "circle-line" and back.start_circle.radius == -side * r
    assert_g2(back, r)


def test_line_to_circle_matches_closed_form():
    rho = 1.7
    t = line_to_circle((0, 0), (1, 0), (3, rho), 1.0)
    x = math.cos(t.theta)
    assert 4 * x * x - 9 * rho * x + 5 == pytest.approx(0, abs=1e-14)


# ------------------------------------------------------ circle → circle


@given(radii, radii, signs, angles, wide_clearances, st.booleans())
def test_circle_to_circle_is_g2_with_the_right_senses(r0, r1, sign, a, e, s_shape):
    r0, r1 = sign * r0, (-sign if s_shape else sign) * r1
    gap = abs(r0) + abs(r1) if s_shape else abs(abs(r1) - abs(r0))
    if not s_shape and gap < 1e-3:
        gap = 0.0
    size = max(abs(r0), abs(r1))
    dist = gap + e * size
    c0 = np.array([0.1, 0.2]) * size
    c1 = c0 + dist * unit(a)
    t = circle_to_circle(c0, r0, c1, r1)
    assert t.kind == ("S" if s_shape else "C")
    assert t.spirals[0].start_curvature == pytest.approx(1 / r0, rel=1e-12)
    assert t.spirals[-1].end_curvature == pytest.approx(1 / r1, rel=1e-12)
    assert abs(t.spirals[0].end_curvature) <= 1e-9 / min(abs(r0), abs(r1))  # κ = 0 at the joint
    assert_g2(t, max(abs(r0), abs(r1)))
    assert_monotone(t)
    assert_g2(t.reversed(), max(abs(r0), abs(r1)))


def test_broken_back_c_satisfies_its_equation():
    r0, r1, d = 1.0, 2.5, 4.0
    t = circle_to_circle((0, 0), r0, (d, 0), r1)
    th = t.theta
    g1 = 5 / 9 * math.tan(th) * math.sin(th) + math.cos(th)
    g2 = 25 * math.tan(th) / (27 * math.cos(th)) - 4 / 9 * math.sin(th)
    paper_r0 = -r0  # the paper's Q0 leaves the joint turning the other way
    assert (r1 + paper_r0) ** 2 * g1**2 + (r1 - paper_r0) ** 2 * g2**2 == pytest.approx(d * d, rel=1e-14)


def test_s_satisfies_its_quadratic():
    r0, r1, d = 1.0, 1.5, 4.0
    t = circle_to_circle((0, 0), -r0, (d, 0), r1)
    y = math.cos(t.theta) ** 2
    rho = d / (r0 + r1)
    assert (1104 - 729 * rho**2) * y * y - 1000 * y + 625 == pytest.approx(0, abs=1e-11)


def test_intersecting_circles_still_join_as_c():
    t = circle_to_circle((0, 0), 1.0, (1.5, 0), 1.2)
    assert_g2(t, 1.2)


# ---------------------------------------------------------- line → line


@given(angles, st.floats(0.3, 2.9), st.floats(0.5, 20), st.floats(0.5, 20), signs, st.floats(0.2, 1.0))
def test_line_to_line_is_g2(a, deflection, l0, l1, turn, fraction):
    corner = np.array([3.0, -1.0])
    t0 = unit(a)
    t1 = unit(a + turn * deflection)
    p0 = corner - l0 * t0
    p1 = corner + l1 * t1
    auto = line_to_line(p0, corner, p1)
    theta = deflection / 2
    assert auto.theta == pytest.approx(theta, rel=1e-9)
    # Corollary 4.5: a spiral starts exactly at the nearer end point.
    near = p0 if l0 <= l1 else p1
    ends = [auto.start, auto.end]
    assert min(np.hypot(*(e - near)) for e in ends) <= 1e-12 * max(l0, l1)
    k_auto = abs(auto.spirals[0].end_curvature)
    chosen = line_to_line(p0, corner, p1, curvature=k_auto / fraction)
    for t in (auto, chosen):
        scale = 1 / abs(t.spirals[0].end_curvature)
        assert_g2(t, scale)
        assert_monotone(t)
        assert math.copysign(1, t.spirals[0].theta) == turn
    assert abs(chosen.spirals[0].end_curvature) == pytest.approx(k_auto / fraction, rel=1e-12)


def test_line_to_line_start_distance_formula():
    t = line_to_line((-10, 0), (0, 0), (10, 10), curvature=0.5)
    theta = math.pi / 8
    a = 40 * math.tan(theta) / (27 * 0.5 * math.cos(theta))
    assert np.allclose(t.start, (-a, 0), atol=1e-14)


# --------------------------------------------------- circle in circle


# 0.25 ≤ r1/r0 ≤ 0.8: for smaller ratios the larger circle is met where the
# spiral is nearly straight (t → 0), for larger ones the piece turns little;
# either way its end curvatures are only good to ~1e-12 over the conditioning;
# f ≤ 0.9 keeps θ above ~10° (θ → 0 as D → r0 − r1).
@given(st.floats(0.25, 0.8), st.floats(0.02, 0.9), angles, st.booleans(), signs)
def test_circle_in_circle_is_g2_both_ways(q, f, a, inward, sign):
    r_big, r_small = 3.0, 3.0 * q
    low = nested_band_lower(q)
    dist = (r_big - r_small) * (low + f * (1 - low))
    c_big = np.array([-0.2, 0.1])
    c_small = c_big + dist * unit(a)
    if inward:
        t = circle_in_circle(c_big, sign * r_big, c_small, sign * r_small)
        r0, r1 = r_big, r_small
    else:
        t = circle_in_circle(c_small, sign * r_small, c_big, sign * r_big)
        r0, r1 = r_small, r_big
    assert 0 < t.parameter < 1
    assert t.spirals[0].start_curvature == pytest.approx(sign / r0, rel=1e-11)
    assert t.spirals[0].end_curvature == pytest.approx(sign / r1, rel=1e-11)
    assert_g2(t, r_big)
    assert_monotone(t)


def test_nested_band_lower_is_the_limit_of_the_solutions():
    q = 0.4
    assert nested_band_lower(q) == pytest.approx(0.98707, abs=1e-5)
    assert nested_band_lower(0.1) == pytest.approx(0.98212, abs=1e-5)
    assert nested_band_lower(0.9) == pytest.approx(0.99810, abs=1e-5)
    # just inside the band θ approaches π/2
    low = nested_band_lower(q)
    t = circle_in_circle((0, 0), 1.0, (0, 0.6 * (low + 1e-6)), 0.4)
    assert t.theta > 1.4


# ---------------------------------------------------- survey coordinates


def test_survey_coordinates_keep_joins_within_a_nanometre():
    cases = [
        lambda o: line_to_circle(o + (0, 0), (1, 0.2), o + (40, 500), 300.0),
        lambda o: circle_to_circle(o + (0, 0), 400.0, o + (900, 150), 250.0),
        lambda o: circle_to_circle(o + (0, 0), -400.0, o + (1200, 150), 250.0),
        lambda o: line_to_line(o + (-500, 0), o + (0, 0), o + (400, 300), 1 / 350),
        lambda o: circle_in_circle(o + (0, 0), 500.0, o + (0, 0.9925 * 300), 200.0),
    ]
    for make in cases:
        local, survey = make(np.zeros(2)), make(UTM)
        for j in survey.joins():
            assert j.gap <= 1e-9 and j.angle <= 1e-9
        for a, b in zip(local.spirals, survey.spirals):
            assert np.abs(b.control_points - UTM - a.control_points).max() <= 1e-9


# ------------------------------------------------------------ errors


@pytest.mark.parametrize(
    "call, match",
    [
        (lambda: line_to_circle((0, 0), (1, 0), (0, 0.9), 1.0), r"d/r = 0.90000"),
        (lambda: line_to_circle((0, 0), (1, 0), (0, -1.0), 1.0), r"d/r = 1.00000"),
        (lambda: circle_to_circle((0, 0), 3.0, (1, 0), 1.0), r"enclose.*= 0.50000"),
        (lambda: circle_to_circle((0, 0), -1.0, (1.5, 0), 1.0), r"disjoint.*= 0.75000"),
        (lambda: line_to_line((0, 0), (1, 0), (2, 0)), "collinear"),
        (lambda: line_to_line((0, 0), (1, 0), (0, 0)), "folds back"),
        (lambda: line_to_line((0, 0), (1, 0), (1, 1), curvature=0.01), "shorter leg"),
        (
            lambda: circle_in_circle((0, 0), 1.0, (0, 0.3), 0.4),
            r"0.98707 ≤ D/\(r0 − r1\) < 1 at r1/r0 = 0.40; here D/\(r0 − r1\) = 0.50000",
        ),
        (lambda: circle_in_circle((0, 0), 1.0, (0, 0.6), 0.4), r"here D/\(r0 − r1\) = 1.00000"),
        (lambda: circle_in_circle((0, 0), 1.0, (0, 0.5), 1.0), "different radii"),
    ],
)
def test_infeasible_inputs_raise_no_solution(call, match):
    with pytest.raises(NoSolutionError, match=match):
        call()


@pytest.mark.parametrize(
    "call, match",
    [
        (lambda: line_to_circle((0, math.nan), (1, 0), (0, 2), 1.0), r"point\[1\] must be finite"),
        (lambda: line_to_circle((0, 0), (0, 0), (0, 2), 1.0), "direction must be a non-zero"),
        (lambda: line_to_circle((0, 0), (1, 0), (0, 2), 0.0), "radius must be positive"),
        (lambda: line_to_circle((0, 0), (1, 0), (0, 2), -1.0), "radius must be positive"),
        (lambda: circle_to_circle((0, 0), 0.0, (3, 0), 1.0), "non-zero"),
        (lambda: circle_to_circle((1, 1), 1.0, (1, 1), 2.0), "coincide"),
        (lambda: circle_in_circle((0, 0), 1.0, (0, 0.59), -0.4), "share their sign"),
        (lambda: line_to_line((0, 0), (0, 0), (1, 1)), "differ from the corner"),
        (lambda: line_to_line((0, 0), (1, 0), (1, 1), curvature=-2.0), "positive finite"),
        (lambda: line_to_line((0, 0), (1, 0), (1, 1), curvature=math.inf), "curvature must be finite"),
        (lambda: circle_to_circle((0, 0), math.inf, (3, 0), 1.0), "radius0 must be finite"),
        (lambda: line_to_circle((0, 0), (1, 0), "x", 1.0), "center"),
    ],
)
def test_malformed_inputs_raise_value_error(call, match):
    with pytest.raises(ValueError, match=match) as info:
        call()
    assert not isinstance(info.value, NoSolutionError)


def test_theta_near_half_pi_is_verified_or_refused():
    # A far circle drives θ toward π/2 and the legs grow like 1.5·r·(d/r)².
    t = line_to_circle((0, 0), (1, 0), (0, 100.0), 1.0)
    assert math.pi / 2 - t.theta < 0.01
    for j in t.joins():
        assert j.gap <= 1e-9 and j.angle <= 1e-9 and j.curvature_jump <= 1e-9
    with pytest.raises(NoSolutionError, match="reproduces its contacts only to"):
        line_to_circle((0, 0), (1, 0), (0, 1e6), 1.0)


def test_spiral_angle_is_atan2_of_its_sine_and_cosine_to_an_ulp():
    """θ comes from the kernels' arctangent (shared by scalar and batch rows): within
    0.7 ulp of the exact atan2 over the whole quadrant, as libm's own."""
    import mpmath as mp

    from spiral_cad.core._kernels import angle

    mp.mp.dps = 40
    rng = np.random.default_rng(3)
    thetas = np.concatenate([rng.uniform(0, math.pi / 2, 3000), 10.0 ** rng.uniform(-300, -1, 300),
                             math.pi / 2 - 10.0 ** rng.uniform(-15, -1, 300),
                             (np.arctan([0.4375, 0.6875, 1.1875, 2.4375]) + rng.uniform(-1e-9, 1e-9, (100, 4))).ravel()])  # fmt: skip
    for t in thetas.ravel().tolist():
        y, x = math.sin(t), math.cos(t)
        exact = mp.atan2(y, x)
        assert abs(mp.mpf(angle(y, x)) - exact) <= 0.7 * math.ulp(float(exact))
    assert angle(0.0, 1.0) == 0.0 and angle(1.0, 0.0) == math.pi / 2 and math.isnan(angle(math.nan, 1.0))


@pytest.mark.parametrize(
    "point, message",
    [
        ([True, 0.0], r"point\[0\] must be a real number"),
        ((0.0, math.inf), r"point\[1\] must be finite"),
        ([0, 10**400], r"point\[1\] is too large"),
        ((1.5, "2"), r"point\[1\] must be a real number"),
        ([0.0, 0.0, 1.0], "point must have 2 coordinates"),
    ],  # fmt: skip
)
def test_two_number_points_are_checked_item_by_item(point, message):
    """Tuples and lists of two floats take a short path; anything else in them is named as before."""
    with pytest.raises(ValueError, match=message):
        line_to_circle(point, (1, 0), (0, 105), 100)
    as_list = line_to_circle([0, 0.0], [1, 0], (0, 105), 100).spirals[0].control_points
    assert np.array_equal(as_list, line_to_circle((0, 0), (1, 0), (0, 105), 100).spirals[0].control_points)


@pytest.mark.parametrize(
    ("r1", "message"),
    [
        (1e-200, r"needs r1/r0 well above 0; here r1/r0 = 0 \(radius0=1e\+200, radius1=1e-200\)"),
        (1e-20 * 1e200, r"1 − [0-9.e-]+ ≤ D/\(r0 − r1\) < 1"),
    ],
)
def test_a_nested_circle_far_smaller_than_its_outer_is_refused_by_name_not_by_division(r1, message):
    """r1/r0 underflowing to 0, or so small that the band is narrower than the digits shown."""
    from spiral_cad import batch

    with pytest.raises(NoSolutionError, match=message):
        circle_in_circle((0, 0), 1e200, (5, 0), r1)
    assert re.search(message, batch.circle_in_circle((0, 0), 1e200, (5, 0), r1).reason(0))


def test_scalar_results_are_python_floats_before_and_after_the_kernels_compile():
    """The scalar API runs plain Python until its process compiles: the same types either way."""
    from spiral_cad.core import _kernels as K

    before = circle_in_circle((0, 0), 1.0, (0.595, 0), 0.4)
    K.KERNELS.compile()
    after = circle_in_circle((0, 0), 1.0, (0.595, 0), 0.4)
    for t in (before, after):
        assert type(t.theta) is float and type(t.parameter) is float and repr(t.theta) == repr(float(t.theta))
    assert (before.theta, before.parameter) == (after.theta, after.parameter)
