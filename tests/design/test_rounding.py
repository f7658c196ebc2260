"""G2 corner rounding: Walton–Meek and G2CBS pairs, curvature bounds, batch path."""

import math
import re

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from spiral_cad import BezierSpiral, Line, NoSolutionError
from spiral_cad.design import corner_legs, round_corners, round_corners_batch
from spiral_cad.design.rounding import G2CBS_C1, G2CBS_C2, G2CBS_C3, G2CBS_C4

U = np.linspace(0.0, 1.0, 401)
ZIGZAG = np.array([(0, 0), (4, 0), (6, 3), (9, 3), (11, 0), (15, 1)], dtype=float)


def measured_peak(chain):
    return max(float(np.max(np.abs(seg.curvature(U)))) for seg in chain.segments)


def assert_g2(chain, tol=1e-12):
    for j in chain.joins():
        assert j.gap <= tol * chain.size and j.angle <= tol
        assert j.curvature_jump * chain.size <= 1e-11


@pytest.mark.parametrize("method", ["walton-meek", "g2cbs"])
def test_joins_are_g2_and_curvature_monotone(method):
    path = round_corners(ZIGZAG, shape=method)
    assert_g2(path.chain)
    assert [c.index for c in path.corners] == [1, 2, 3, 4]
    for corner in path.corners:
        for spiral in corner.spirals:
            k = np.abs(spiral.curvature(U))
            d = np.diff(k)
            assert np.all(d >= -1e-12 * k.max()) or np.all(d <= 1e-12 * k.max())
        first, second = corner.spirals
        assert first.start_curvature == pytest.approx(0.0, abs=1e-12)
        assert second.end_curvature == pytest.approx(0.0, abs=1e-12)
        # The peak is at the joint and equals the reported curvature.
        assert abs(first.end_curvature) == pytest.approx(corner.curvature, rel=1e-12)


def test_g2cbs_constants_and_lower_peak():
    assert G2CBS_C2 == pytest.approx(0.5798, abs=1e-4)
    # The exact c1, not the paper's rounded 7.2364 (which leaves a gap at the join).
    assert G2CBS_C1 == (G2CBS_C2 + 1) * (G2CBS_C2 + 4)
    assert G2CBS_C3 == (G2CBS_C2 + 4) / (G2CBS_C1 + 6)
    assert G2CBS_C4 == pytest.approx(1.12249, abs=1e-5)
    # Same corner distance d → ~24 % lower peak than Walton–Meek.
    p0, corner, p1 = np.array([[-3.0, 0.0]]), np.array([[0.0, 0.0]]), np.array([[2.0, 2.5]])
    wm = round_corners_batch(p0, corner, p1, shape="walton-meek")
    yang = round_corners_batch(p0, corner, p1, shape="g2cbs")
    assert wm.distance[0] == yang.distance[0] == pytest.approx(3.0)  # the shorter leg
    peaks = [
        max(float(np.max(np.abs(BezierSpiral.from_control_points(cp).curvature(U)))) for cp in r.control_points[0]) for r in (wm, yang)
    ]
    assert peaks[1] / peaks[0] == pytest.approx(G2CBS_C4 / (40 / 27), rel=1e-6)
    assert 0.74 < peaks[1] / peaks[0] < 0.78


def test_g2cbs_legs_have_yang_sukkarieh_ratios():
    path = round_corners([(0, 0), (5, 0), (7, 4)], shape="g2cbs")
    cp = path.corners[0].spirals[0].control_points
    g, h, k = (np.hypot(*(cp[i + 1] - cp[i])) for i in range(3))
    theta = path.corners[0].theta
    assert g / h == pytest.approx(G2CBS_C2, rel=1e-12)
    assert h == pytest.approx(G2CBS_C3 * path.corners[0].distance, rel=1e-12)
    assert k == pytest.approx(6 * h * h * math.cos(theta) / (g + 4 * h), rel=1e-12)
    # κ'(1) = 0: curvature flat at the joint.
    spiral = path.corners[0].spirals[0]
    assert spiral.curvature(1 - 1e-4) == pytest.approx(spiral.curvature(1.0), rel=1e-6)


def test_fit_mode_uses_half_of_interior_legs():
    path = round_corners(ZIGZAG)
    chain = path.chain
    # Corollary 4.5 per corner: distance = min(available legs).
    legs = np.hypot(*np.diff(ZIGZAG, axis=0).T)
    for c in path.corners:
        i = c.index
        left = legs[i - 1] * (1.0 if i == 1 else 0.5)
        right = legs[i] * (1.0 if i == len(ZIGZAG) - 2 else 0.5)
        assert c.distance == pytest.approx(min(left, right), rel=1e-12)
    assert np.allclose(chain.start, ZIGZAG[0]) and np.allclose(chain.end, ZIGZAG[-1])


def test_collinear_points_are_passed_through():
    pts = [(0, 0), (1, 0), (2, 0), (2.5, 0.5)]
    path = round_corners(pts)
    assert [c.index for c in path.corners] == [2]
    first = path.chain.segments[0]
    assert isinstance(first, Line)
    assert np.allclose(first.start, (0, 0)) and first.end[0] > 1.0  # (1, 0) lies on it
    # The merged leg (0,0)-(2,0) is the corner's first leg: used in full if shorter.
    assert path.corners[0].distance == pytest.approx(math.hypot(0.5, 0.5))
    p0, corners, p1, index = corner_legs(pts)
    assert index.tolist() == [2] and np.allclose(p0[0], (0, 0))


def test_straight_polyline_is_one_line():
    path = round_corners([(0, 0), (1, 1), (2, 2)])
    assert path.corners == [] and len(path.chain) == 1 and path.max_curvature == 0.0


@pytest.mark.parametrize("method", ["walton-meek", "g2cbs"])
def test_curvature_too_small_names_corner_and_needed_curvature(method):
    fit = round_corners(ZIGZAG, shape=method)
    bound = 0.8 * fit.max_curvature
    # The first corner (in travel order) that needs more than the bound is reported.
    first = next(c for c in fit.corners if c.curvature > bound)
    with pytest.raises(NoSolutionError, match=rf"corner {first.index}\b") as info:
        round_corners(ZIGZAG, max_curvature=bound, shape=method)
    needed = float(re.search(r"needs curvature ≥ ([0-9.e+-]+)", str(info.value)).group(1))
    assert needed == pytest.approx(first.curvature, rel=1e-5)


@pytest.mark.parametrize("method", ["walton-meek", "g2cbs"])
def test_joint_curvature_is_exact(method):
    fit = round_corners(ZIGZAG, shape=method)
    k = 1.01 * fit.max_curvature
    path = round_corners(ZIGZAG, curvature=k, shape=method)
    for c in path.corners:
        assert abs(c.spirals[0].end_curvature) == pytest.approx(k, rel=1e-12)
    assert measured_peak(path.chain) == pytest.approx(k, rel=1e-9)
    assert_g2(path.chain)


@given(
    # Turns of at least 0.05 rad: tiny turns under a tight bound make spiral
    # pairs so small that absolute rounding dominates their join curvature.
    st.lists(st.tuples(st.floats(0.3, 3.0), st.floats(0.05, 2.4), st.sampled_from([1.0, -1.0])), min_size=1, max_size=6),
    st.floats(1.0, 4.0),
    st.sampled_from(["walton-meek", "g2cbs"]),
)
def test_max_curvature_bound_is_respected(steps, factor, method):
    # A polyline of legs with bounded turns; κmax at least what every corner needs.
    heading, pts = 0.0, [np.zeros(2)]
    for length, turn, sign in [(1.0, 0.0, 1.0), *steps]:
        heading += sign * turn
        pts.append(pts[-1] + length * np.array([math.cos(heading), math.sin(heading)]))
    fit = round_corners(np.array(pts), shape=method)
    if not fit.corners:
        return
    kmax = factor * fit.max_curvature
    # Tight bounds make tiny pairs at gentle corners, whose join curvature is
    # only as exact as ε·|coordinates|/(g·h·sin θ): check G2 to 1e-7 here.
    path = round_corners(np.array(pts), max_curvature=kmax, shape=method)
    assert measured_peak(path.chain) <= kmax * (1 + 1e-9)
    for c in path.corners:
        assert c.curvature == pytest.approx(kmax, rel=1e-12)


def test_batch_matches_chain_and_reports_failures():
    p0, corners, p1, index = corner_legs(ZIGZAG)
    batch = round_corners_batch(p0, corners, p1)
    path = round_corners(ZIGZAG)
    for j, c in enumerate(path.corners):
        assert np.array_equal(batch.control_points[j, 0], c.spirals[0].control_points)
    # One row that cannot reach its curvature; the others are unaffected.
    k = np.full(len(corners), 1.01 * path.max_curvature)
    k[2] = 0.1 * batch.curvature[2]
    mixed = round_corners_batch(p0, corners, p1, curvature=k)
    assert mixed.ok.tolist() == [True, True, False, True]
    assert "corner 2" in mixed.reason(2) and mixed.reason(0) == "ok"
    assert np.isnan(mixed.control_points[2]).all()


def test_malformed_input():
    with pytest.raises(ValueError, match="points 1 and 2 coincide"):
        round_corners([(0, 0), (1, 0), (1, 0), (2, 1)])
    with pytest.raises(ValueError, match="folds straight back at point 1"):
        round_corners([(0, 0), (1, 0), (0.5, 0)])
    with pytest.raises(ValueError, match="shape must be one of 'walton-meek', 'near-linear', 'g2cbs'; got 'clothoid'"):
        round_corners(ZIGZAG, shape="clothoid")
    with pytest.raises(ValueError, match="not both"):
        round_corners(ZIGZAG, curvature=1.0, max_curvature=2.0)
    with pytest.raises(ValueError, match="max_curvature must be positive"):
        round_corners(ZIGZAG, max_curvature=-1.0)


def test_a_bad_per_corner_value_names_the_corner_as_geometry_errors_do():
    points = [[0, 0], [10, 0], [10, 10], [20, 10], [20, 20]]  # corners 1, 2, 3: the interior points
    with pytest.raises(ValueError, match=r"max_deviation must be positive and finite; got nan \(corner 2\)"):
        round_corners(points, max_deviation=[0.1, float("nan"), 0.1])


def test_method_is_the_deprecated_name_of_shape_and_never_overrides_it():
    """``method=`` still works for one release and warns; given beside a different ``shape`` (the default's
    own name included) it is refused, where it used to win silently."""
    with pytest.warns(DeprecationWarning, match=r"method= is deprecated and will be removed: the same choice is shape="):
        old = round_corners(ZIGZAG, method="g2cbs")
    assert old.chain.length == round_corners(ZIGZAG, shape="g2cbs").chain.length
    for shape in ("walton-meek", "near-linear"):
        with pytest.warns(DeprecationWarning), pytest.raises(ValueError, match=rf"got shape='{shape}', method='g2cbs'"):
            round_corners(ZIGZAG, shape=shape, method="g2cbs")
    with pytest.warns(DeprecationWarning):
        same = round_corners_batch([(0, 0)], [(5, 0)], [(7, 4)], shape="g2cbs", method="g2cbs")
    assert same.ok.all()
