"""Every entry point returns verified geometry or a clear ValueError / NoSolutionError.

Results are checked here independently of the package: joins are recomputed
from the returned control points with mpmath at 40 digits.
"""

import math

import mpmath as mp
import numpy as np
import pytest
from helpers import assert_meet_g2, assert_on_circle
from hypothesis import given
from hypothesis import strategies as st

import spiral_cad as sc
from spiral_cad import Status
from spiral_cad.core import _kernel_batches as KB
from spiral_cad.core import batch
from spiral_cad.design import Alignment, circle_chain, round_corners

mp.mp.dps = 40


# ------------------------------------------------ independent verification


# --------------------------------------------------- the reproducers


@pytest.mark.parametrize(
    "call",
    [
        lambda: sc.circle_to_circle((0, 0), 1, (1e9, 0), 1),
        lambda: sc.line_to_circle((0, 0), (1, 0), (0, 105), 1e-300),
        lambda: sc.line_to_line((0, 0), (100, 0), (160, 80), curvature=1e300),
        lambda: sc.line_to_line((0, 0), (100, 0), (160, 80), curvature=1e12),
        lambda: sc.line_to_circle((1e12, 0), (1, 0), (1e12, 105), 100),
        lambda: sc.BezierSpiral((0, 0), (1, 0), 0.6, 5e-324),
        lambda: sc.BezierSpiral((5, 5), (1, 0), 1e-300, 1.0),  # legs of 1e-300 vanish at 5
    ],
)
def test_extreme_input_is_refused_by_name_never_crashes(call):
    with pytest.raises(sc.NoSolutionError, match=r"float64|reproduces its contacts") as info:
        call()
    assert "nothing is returned for" in str(info.value)


def test_extreme_but_representable_geometry_works_at_any_magnitude():
    for scale in (1e-300, 1e-150, 1.0, 1e150, 1e300):
        t = sc.line_to_line((0, 0), (scale, 0), (2 * scale, scale))
        assert_meet_g2(t.spirals[0].control_points, t.spirals[1].control_points, scale)
        c = sc.circle_to_circle((0, 0), 2 * scale, (5 * scale, scale), scale)
        assert_on_circle(c.spirals[-1].control_points, (5 * scale, scale), scale, True)
        assert_on_circle(c.spirals[0].control_points, (0, 0), 2 * scale, False)
    spiral = sc.BezierSpiral((0, 0), (1, 0), 0.6, 1e-300)
    assert spiral.length > 1e299 and math.isclose(spiral.end_curvature, 1e-300, rel_tol=1e-9)
    tiny = sc.BezierSpiral((0, 0), (1, 0), 1e-300, 1.0)  # legs of 1e-300 near the origin are representable
    assert 0 < tiny.length < 1e-299 and abs(tiny.end_curvature - 1.0) * tiny.length <= 1e-9


def test_line_to_line_diagnoses_huge_and_tiny_directions_correctly():
    t = sc.line_to_line((0, 0), (1e300, 0), (2e300, 1e300))  # a 45° corner, not "folds back"
    assert math.isclose(t.theta, math.pi / 8, rel_tol=1e-12)
    t = sc.line_to_circle((0, 0), (1e-200, 1e-200), (0, 250), 100)
    assert t.spirals[0].start_tangent == pytest.approx([math.sqrt(0.5)] * 2)
    t = sc.line_to_circle((0, 0), (1e300, 1e300), (0, 250), 100)
    assert t.spirals[0].start_tangent == pytest.approx([math.sqrt(0.5)] * 2)


LOG_MAGNITUDE = st.floats(-300, 300)


@given(LOG_MAGNITUDE, st.floats(1.01, 1e6), st.floats(-1e3, 1e3), st.floats(-1e3, 1e3))
def test_line_to_circle_returns_verified_geometry_or_refuses(log_scale, rho, ox, oy):
    r = 10.0**log_scale
    origin = (ox * r, oy * r)
    try:
        t = sc.line_to_circle(origin, (1, 0), (origin[0], origin[1] + rho * r), r)
    except sc.NoSolutionError as error:
        assert "float64" in str(error) or "reproduces its contacts" in str(error)
        return
    assert_on_circle(t.spirals[0].control_points, (origin[0], origin[1] + rho * r), r, True)


@given(LOG_MAGNITUDE, st.floats(-1e4, 1e4), st.floats(-1e4, 1e4), st.floats(0.05, 20), st.booleans())
def test_circle_to_circle_returns_verified_geometry_or_refuses(log_scale, dx, dy, ratio, s_shape):
    r = 10.0**log_scale
    r1 = ratio * r * (-1 if s_shape else 1)
    centre = (dx * r, dy * r)
    try:
        t = sc.circle_to_circle((0, 0), r, centre, r1)
    except ValueError as error:  # infeasible or unrepresentable, named either way
        assert "circle_to_circle" in str(error)
        return
    assert_on_circle(t.spirals[0].control_points, (0, 0), r, False)
    assert_on_circle(t.spirals[-1].control_points, centre, r1, True)


def assert_leaves_line(cp, point, direction, tol=1e-9):
    """The spiral starts on the line (point, direction) along it: gap / first leg and tangent angle."""
    p = [[mp.mpf(float(v)) for v in row] for row in cp]
    d = [mp.mpf(float(v)) for v in direction]
    d_len = mp.sqrt(d[0] ** 2 + d[1] ** 2)
    a = [p[1][k] - p[0][k] for k in range(2)]
    leg = mp.sqrt(a[0] ** 2 + a[1] ** 2)
    off = [p[0][k] - mp.mpf(float(point[k])) for k in range(2)]
    assert abs(d[0] * off[1] - d[1] * off[0]) / d_len / leg <= tol
    assert abs(d[0] * a[1] - d[1] * a[0]) / d_len / leg <= tol and d[0] * a[0] + d[1] * a[1] > 0


@pytest.mark.parametrize("shape", ["walton-meek", "near-linear"])
@pytest.mark.parametrize("case", ["tiny turn", "far from the line's point"])
def test_rows_float64_cannot_resolve_are_refused_not_passed(case, shape):
    # Tiny turns (legs ~1e-7 of the radius) and lines given by a point 1e4…1e8 away: the gap
    # to the circle or to the line cancels large terms, and their rounding alone reaches 1e-9.
    rng = np.random.default_rng(11)
    n = 600
    angle = rng.uniform(0, 2 * np.pi, n)
    d = np.c_[np.cos(angle), np.sin(angle)]
    normal = np.c_[-d[:, 1], d[:, 0]]
    if case == "tiny turn":
        p = rng.uniform(-1, 1, (n, 2))
        c = p + rng.uniform(-1, 1, (n, 1)) * d + (1 + 10 ** rng.uniform(-18, -12, n))[:, None] * normal
    else:
        p = np.zeros((n, 2))
        c = 10 ** rng.uniform(4, 8, (n, 1)) * d + 1.05 * normal
    res = batch.line_to_circle(p, d, c, 1.0, shape=shape)
    for i in np.flatnonzero(res.ok).tolist():
        assert_leaves_line(res.spirals[0][i], p[i], d[i])
        assert_on_circle(res.spirals[0][i], c[i], 1.0, True)
    assert res.ok.any() and (res.status[~res.ok] == Status.UNVERIFIED).any()  # both verdicts exercised


# ------------------------------------------------------------------ batches


def test_poison_row_does_not_touch_the_good_rows():
    centers0 = np.zeros((3, 2))
    good = batch.circle_to_circle(centers0, [200, 200, 200], [[450, 60], [450, 60], [450, 60]], [120, 120, 120])
    poisoned = batch.circle_to_circle(centers0, [200, 1, 200], [[450, 60], [1e9, 0], [450, 60]], [120, 1, 120])
    assert list(poisoned.status) == [Status.OK, Status.UNVERIFIED, Status.OK]
    for k in range(2):
        assert np.array_equal(poisoned.spirals[k][[0, 2]], good.spirals[k][[0, 2]])  # bit for bit
        assert np.isnan(poisoned.spirals[k][1]).all()
    scalar = sc.circle_to_circle((0, 0), 200, (450, 60), 120)
    assert np.array_equal(poisoned.spirals[1][0], scalar.spirals[1].control_points)
    assert "float64" in poisoned.reason(1)


def test_out_buffer_is_written_in_full():
    out = np.full((3, 1, 4, 2), 7.0)
    res = batch.line_to_circle([[0, 0], [0, 0], [0, 0]], [1, 0], [[0, 105], [0, 50], [0, 1e300]], [100, 100, 1e-300], out=out)
    assert res.status[0] == Status.OK and res.status[1] != Status.OK and res.status[2] != Status.OK
    assert np.isfinite(out[0]).all() and np.isnan(out[1:]).all()


@pytest.mark.parametrize(
    "call, message",
    [
        (lambda: batch.line_to_circle([[0, 0]] * 5, [1, 0], [[0, 105]] * 3, 100), r"center has 3 rows but point has 5"),
        (lambda: batch.line_to_circle([0, 0], [1, 0], [0, 105], [100 + 1j]), "radius must hold real numbers"),
        (lambda: batch.line_to_circle([0, 0], [1, 0], [0, 105], ["100"]), "radius must hold real numbers"),
        (lambda: batch.line_to_circle([0, 0], [1, 0], [0, 105], 100, out=[0]), "out must be a numpy array"),
        (lambda: batch.line_to_line([0, 0], [1, 0], [[1, 1], [2]]), "p1 must be a rectangular array"),
    ],
)
def test_batch_input_errors_name_the_argument(call, message):
    with pytest.raises(ValueError, match=message):
        call()


def test_every_input_mix_uses_one_compiled_kernel():
    n = 4
    full = np.tile([0.0, 0.0], (n, 1))
    mixes = [
        (full, np.tile([1.0, 0.0], (n, 1)), np.tile([0.0, 105.0], (n, 1)), np.full(n, 100.0)),
        ([0, 0], [1, 0], [0, 105], 100),
        (full, [1, 0], np.tile([0.0, 105.0], (n, 1)), 100),
        (np.asfortranarray(np.tile([0.0, 0.0], (n, 1))), [1.0, 0.0], [0, 105], np.full(n, 100, dtype=np.int32)),
    ]
    readonly = np.tile([0.0, 105.0], (n, 1))
    readonly.flags.writeable = False
    mixes.append((full, [1, 0], readonly, 100.0))
    for args in mixes:
        assert batch.line_to_circle(*args).ok.all()
    assert len(KB.line_to_circle_batch.signatures) == 1


# ---------------------------------------------------- chains never accept a kink


def test_chain_tolerance_must_be_finite_and_positive():
    lines = [sc.Line((0, 0), (1, 0)), sc.Line((1, 0), (2, 0))]
    for bad in (float("nan"), float("inf"), 0.0, -1e-9, 0.5, True, "1e-9"):
        with pytest.raises(ValueError, match="tolerance"):
            sc.Chain(lines, tolerance=bad)
    with pytest.raises(ValueError, match="tolerance"):
        sc.Chain.join([sc.Line((0, 0), (1, 0))], tolerance=float("nan"))
    with pytest.raises(ValueError, match="tolerance"):
        Alignment.from_pis([(0, 0), (100, 0), (200, 50)], 50, spiral_angles=0.1, tolerance=float("nan"))
    with pytest.raises(ValueError, match="tolerance"):
        round_corners([(0, 0), (1, 0), (1, 1)], tolerance=float("nan"))


def test_degenerate_spiral_is_refused_and_cannot_hide_a_kink():
    with pytest.raises(ValueError, match="degenerate spiral"):
        sc.BezierSpiral.from_control_points([[1, 0]] * 4)
    # a legal but tiny spiral at a 90° corner: the rounding allowance is capped
    tiny = sc.BezierSpiral.from_control_points([[1, 0], [1 + 1e-15, 0], [1 + 2e-15, 0], [1 + 3e-15, 1e-16]])
    with pytest.raises(ValueError, match="not G2 at joint"):
        sc.Chain([sc.Line((0, 0), (1, 0)), tiny, sc.Line((1 + 3e-15, 1e-16), (1 + 3e-15, 1))])


def test_round_corners_refuses_a_curvature_float64_cannot_hold():
    points = [(0, 0), (1.0, 0.1), (1.4, 0.9), (2.4, 1.0)]
    for method in ("walton-meek", "g2cbs"):
        with pytest.raises(sc.NoSolutionError, match=r"corner 1 .*float64 at these coordinates: .*use a lower curvature$"):
            round_corners(points, max_curvature=1e15, shape=method)
    with pytest.raises(sc.NoSolutionError, match=r"would start .*e-301 from the corner.* cannot be told apart; use a lower curvature$"):
        round_corners(points, max_curvature=1e300)
    with pytest.raises(sc.NoSolutionError, match=r"float64 at these coordinates: .*; use a larger max_deviation$"):
        round_corners(points, max_deviation=1e-12)


# ----------------------------------------------------------- input coercion


@pytest.mark.parametrize(
    "call, message",
    [
        (lambda: sc.line_to_circle("12", (1, 0), (0, 105), 100), "point must be a 2-D point"),
        (lambda: sc.line_to_circle({0: 1, 1: 2}, (1, 0), (0, 105), 100), "point must be a 2-D point"),
        (lambda: sc.line_to_circle((0, 0), (1, 0), (0, 105), True), "radius must be a real number"),
        (lambda: sc.line_to_circle((0, 0), (1, 0), (0, 105), 100 + 0j), "radius must be a real number"),
        (lambda: sc.line_to_circle((0, 0), (1, 0), (0, 105), 10**400), "radius is too large"),
        (lambda: sc.line_to_circle((0, 0), (1, 0), (0, "105"), 100), r"center\[1\] must be a real number"),
        (lambda: sc.Line((0, 0), (1, 0)).piece(0.8, 0.2), "0 ≤ t0 < t1 ≤ 1"),
        (lambda: sc.Arc((0, 0), 1, 0, 1).piece(-1, 5), "0 ≤ t0 < t1 ≤ 1"),
        (lambda: sc.Chain([sc.Line((0, 0), (1, 0))]).point_at(float("nan")), "stations must lie in"),
        (lambda: sc.Chain(None), "segments must be a list"),
        (lambda: sc.Chain.join(sc.line_to_circle((0, 0), (1, 0), (0, 105), 100)), "wrap one part in a list"),
        (lambda: Alignment.from_pis([(0, 0), (100, 0), (200, 50)], {}, spiral_angles=0.1), "radii must"),
        (lambda: round_corners([(0, 0), (1, 0), (1, 1)], shape=["g2cbs"]), "shape must be one of"),
        (lambda: circle_chain([None, ((0, 0), 1)]), "circle 0 must be"),
    ],
)
def test_non_real_and_malformed_input_is_refused_by_name(call, message):
    with pytest.raises(ValueError, match=message):
        call()


def test_a_corner_in_space_whose_legs_tilt_off_its_plane_is_refused_or_g2():
    # In plane and off it, each part of the joint angle was within 1e-9, their sum 1.1e-9.
    points = np.array([[-775.5831054160924, -812.2974304480725, 1875.4182928908224],
                       [-775.5859132617687, -812.297853187196, 1875.4170295860029],
                       [-775.5863482726035, -812.2992942464253, 1875.415649761706],
                       [-775.591179005107, -812.2994049310744, 1875.416555656958]])  # fmt: skip
    try:
        path = round_corners(points, max_deviation=0.0006972261259975527)
    except sc.NoSolutionError as error:
        assert "corner 1" in str(error)
        return
    segments = list(path.chain)
    for a, b in zip(segments, segments[1:]):
        ta, tb = a.tangent(1.0), b.tangent(0.0)
        assert np.linalg.norm(np.cross(ta, tb)) <= 1e-9
