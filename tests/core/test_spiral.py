"""Theorem 3.1: the cubic Bézier spiral and its evaluation."""

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from scipy.integrate import quad

from spiral_cad import BezierSpiral, line_to_circle
from spiral_cad.core import bezier

thetas = st.floats(0.05, 1.45).flatmap(lambda t: st.sampled_from([t, -t]))
curvatures = st.floats(1e-3, 1e3)
angles = st.floats(-math.pi, math.pi)


def make(theta, k, angle=0.3, start=(1.0, -2.0)):
    """A spiral whose start offset is comparable to its size (well conditioned)."""
    start = (start[0] / k, start[1] / k)
    return BezierSpiral(start, (math.cos(angle), math.sin(angle)), theta, math.copysign(k, theta))


@given(thetas, curvatures, angles)
def test_theorem_3_1_end_conditions(theta, k, angle):
    s = make(theta, k, angle)
    c = math.copysign(k, theta)
    assert s.start_curvature == pytest.approx(0.0, abs=1e-12 * k)
    assert s.end_curvature == pytest.approx(c, rel=1e-12)
    h = 1e-4
    one_sided = [(s.curvature(1.0) - s.curvature(1.0 - d)) / d for d in (h, h / 2)]
    slope = 2 * one_sided[1] - one_sided[0]  # Richardson: κ'(1) + O(h²)
    assert abs(slope) <= 1e-6 * k
    assert np.allclose(s.start_tangent, (math.cos(angle), math.sin(angle)), atol=1e-14)
    assert np.allclose(s.end_tangent, (math.cos(angle + theta), math.sin(angle + theta)), atol=1e-12)
    assert s.theta == pytest.approx(theta, rel=1e-12)


def paper_curvature_ratio(u, cos_t):
    """κ(u)/c of the 1996 spiral, the paper's closed form (MATH.md §1)."""
    c2 = cos_t * cos_t
    base = 25.0 + 10.0 * u * u * (6.0 * c2 - 5.0) + u**4 * (25.0 - 24.0 * c2)
    return 216.0 * u * c2 * cos_t / base**1.5


@given(thetas, curvatures)
def test_curvature_is_monotone_and_matches_closed_form(theta, k):
    s = make(theta, k)
    u = np.linspace(0.0, 1.0, 401)
    kappa = s.curvature(u)
    c = math.copysign(k, theta)
    assert np.all(np.diff(np.abs(kappa)) >= -1e-12 * k)
    closed = paper_curvature_ratio(u, math.cos(theta)) * c
    assert np.allclose(kappa, closed, rtol=1e-11, atol=1e-12 * k)


@pytest.mark.parametrize("theta", [1e-6, 1e-3, 0.01])
def test_almost_straight_spirals(theta):
    """θ → 0: legs shrink like θ/c; from an exact start the formulas stay exact.

    (Away from the origin the end curvature is only as good as
    eps·|P|·c/θ², the rounding of the coordinates over the turn: see README.)
    """
    s = BezierSpiral((0.0, 0.0), (1.0, 0.0), theta, 1.0)
    assert s.start_curvature == 0.0
    assert s.end_curvature == pytest.approx(1.0, rel=1e-12)
    assert s.theta == pytest.approx(theta, rel=1e-12)
    assert np.all(np.diff(s.curvature(np.linspace(0, 1, 101))) >= 0)


@pytest.mark.parametrize("theta", [0.05, 0.5, 1.0, 1.396])
def test_length_matches_adaptive_quadrature(theta):
    s = make(theta, 0.7)
    speed = lambda u: np.linalg.norm(bezier.derivative(s.control_points, u))  # noqa: E731
    exact, _ = quad(speed, 0, 1, epsabs=0, epsrel=1e-13, limit=200)
    assert s.length == pytest.approx(exact, rel=1e-13)


def test_exact_case_r1_d105_gives_atan_three_quarters():
    t = line_to_circle((0, 0), (1, 0), (0, 1.05), 1.0)
    assert t.theta == pytest.approx(math.atan(0.75), abs=1e-15)
    assert t.spirals[0].end_curvature == pytest.approx(1.0, rel=1e-14)


def test_control_points_layout():
    s = make(0.6, 2.0, angle=0.0, start=(0, 0))
    cp = s.control_points
    assert cp.shape == (4, 2) and cp.dtype == np.float64
    g = 25 * math.tan(0.6) / (54 * 2.0 * math.cos(0.6))
    h = 5 * math.tan(0.6) / (9 * 2.0)
    assert np.allclose(cp[:3], [[0, 0], [g, 0], [2 * g, 0]], atol=1e-15)
    assert np.allclose(cp[3], [2 * g + h * math.cos(0.6), h * math.sin(0.6)], atol=1e-15)
    with pytest.raises(ValueError):
        cp[0, 0] = 1.0  # read-only


def test_evaluation_is_vectorised():
    s = make(0.8, 1.0)
    u = np.linspace(0, 1, 12).reshape(3, 4)
    assert s.point(u).shape == (3, 4, 2)
    assert s.tangent(u).shape == (3, 4, 2)
    assert s.curvature(u).shape == (3, 4)
    assert np.allclose(np.linalg.norm(s.tangent(u), axis=-1), 1.0)
    assert np.allclose(s.point(0.0), s.start) and np.allclose(s.point(1.0), s.end)


@given(st.floats(0.0, 0.9), st.floats(0.05, 0.99))
def test_piece_is_exact_subcurve(t0, width):
    s = make(1.1, 1.5)
    t1 = min(1.0, t0 + width)
    p = s.piece(t0, t1)
    v = np.linspace(0, 1, 17)
    assert np.allclose(p.point(v), s.point(t0 + (t1 - t0) * v), atol=1e-13)
    assert np.allclose(p.curvature(v), s.curvature(t0 + (t1 - t0) * v), rtol=1e-9, atol=1e-12)


def test_reversed_flips_direction_and_curvature_sign():
    s = make(0.9, 3.0)
    r = s.reversed()
    v = np.linspace(0, 1, 9)
    assert np.allclose(r.point(v), s.point(1 - v))
    assert np.allclose(r.tangent(v), -s.tangent(1 - v))
    assert np.allclose(r.curvature(v), -s.curvature(1 - v))
    assert r.theta == pytest.approx(-s.theta)
    assert r.length == pytest.approx(s.length, rel=1e-14)


def test_parameter_at_inverts_arc_length():
    s = make(1.2, 0.5)
    stations = np.linspace(0, s.length, 11)
    u = s.parameter_at(stations)
    assert np.allclose(bezier.arc_length(s.control_points, u), stations, atol=1e-12 * s.length)


@pytest.mark.parametrize(
    "args, match",
    [
        (((0, 0), (1, 0), 0.0, 1.0), r"\|theta\|"),
        (((0, 0), (1, 0), math.pi / 2, 1.0), r"\|theta\|"),
        (((0, 0), (1, 0), -2.0, -1.0), r"\|theta\|"),
        (((0, 0), (1, 0), 0.5, -1.0), "sign of theta"),
        (((0, 0), (1, 0), 0.5, 0.0), "non-zero"),
        (((0, 0), (0, 0), 0.5, 1.0), "direction must be a non-zero"),
        (((0, math.nan), (1, 0), 0.5, 1.0), r"start\[1\] must be finite"),
        (((0, 0), (1, 0), math.inf, 1.0), "theta must be finite"),
        (((0, 0, 1), (1, 0), 0.5, 1.0), "2 coordinates"),
        (("ab", (1, 0), 0.5, 1.0), "start"),
    ],
)
def test_malformed_spiral_input(args, match):
    with pytest.raises(ValueError, match=match):
        BezierSpiral(*args)


def test_from_control_points_validates_shape():
    with pytest.raises(ValueError, match="shape"):
        BezierSpiral.from_control_points(np.zeros((3, 2)))
    with pytest.raises(ValueError, match="finite"):
        BezierSpiral.from_control_points([[0, 0], [1, 0], [2, 0], [math.nan, 1]])


def test_evaluation_keeps_the_parameter_shape_and_matches_the_bernstein_form():
    s = BezierSpiral((3, -2), (1, 0.5), 0.9, 0.2)
    cp = s.control_points
    u = np.random.default_rng(0).random((7, 5))
    v = 1 - u
    bernstein = sum(w[..., None] * p for w, p in zip((v**3, 3 * u * v * v, 3 * u * u * v, u**3), cp))
    assert s.point(u).shape == (7, 5, 2) and np.allclose(s.point(u), bernstein, rtol=0, atol=1e-13)
    assert s.point(0.5).shape == (2,) and s.point([]).shape == (0, 2)
    assert isinstance(s.curvature(0.5), float) and s.curvature(u).shape == (7, 5)
    assert s.curvature([0.0, 1.0]) == pytest.approx([0.0, 0.2], abs=1e-15)
    assert np.isnan(s.point([np.nan])).all() and np.isnan(s.curvature([np.nan])).all()
