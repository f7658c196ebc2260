"""Corner rounding in space: every corner in the plane of its legs, G2 by the curvature vector,
within max_deviation, at the spiral lengths asked for.

The checks here compute planes, curvature vectors, distances and lengths from
the control points with their own formulas (numpy only), not with the project's code.
"""

import math

import numpy as np
import pytest
from helpers import bezier_end  # the independent end frame (point, tangent, κN) of a cubic
from hypothesis import given, settings
from hypothesis import strategies as st

from spiral_cad import BezierSpiral, NoSolutionError
from spiral_cad.design import corner_legs, round_corners, round_corners_batch
from spiral_cad.design.rounding import deviation_factor

SHAPES = ["walton-meek", "near-linear", "g2cbs"]
U = np.linspace(0.0, 1.0, 4001)


def helix(count=14, radius=40.0, rise=9.0, step=0.9):
    """A polyline on a helix: every corner lies in another plane."""
    t = np.arange(count) * step
    return np.stack([radius * np.cos(t), radius * np.sin(t), rise * t], axis=1)


def bezier(cp, u):
    u = np.asarray(u)[:, None]
    return (1 - u) ** 3 * cp[0] + 3 * u * (1 - u) ** 2 * cp[1] + 3 * u**2 * (1 - u) * cp[2] + u**3 * cp[3]


def curvature_along(cp, u=U):
    """|κ| along a cubic in space: |B' × B''| / |B'|³."""
    u = u[:, None]
    d1 = 3 * ((1 - u) ** 2 * (cp[1] - cp[0]) + 2 * u * (1 - u) * (cp[2] - cp[1]) + u**2 * (cp[3] - cp[2]))
    d2 = 6 * ((1 - u) * (cp[2] - 2 * cp[1] + cp[0]) + u * (cp[3] - 2 * cp[2] + cp[1]))
    return np.linalg.norm(np.cross(d1, d2), axis=1) / np.linalg.norm(d1, axis=1) ** 3


def arc_length(cp):
    points = bezier(cp, np.linspace(0.0, 1.0, 200001))
    return float(np.linalg.norm(np.diff(points, axis=0), axis=1).sum())


def corner_normal(before, corner, after):
    n = np.cross(corner - before, after - corner)
    return n / np.linalg.norm(n)


def assert_corner_in_space(pair, before, corner, after, size):
    """The pair lies in the corner's plane, leaves and rejoins the legs G2 and meets itself G2.

    Positions are judged against the coordinates' size (their rounding), curvatures as the
    checker judges them: relative to max(|κ|, 1/L), L the spiral's chord.
    """
    n = corner_normal(before, corner, after)
    for cp in pair:
        assert cp.shape == (4, 3)
        assert np.abs((cp - corner) @ n).max() <= 1e-12 * size
    scale = 1.0 / min(np.linalg.norm(cp[3] - cp[0]) for cp in pair)
    t_in = (corner - before) / np.linalg.norm(corner - before)
    t_out = (after - corner) / np.linalg.norm(after - corner)
    for (p, t, kn), leg in ((bezier_end(pair[0], False), t_in), (bezier_end(pair[1], True), t_out)):
        assert np.linalg.norm(np.cross(p - corner, leg)) <= 1e-12 * size  # on its leg
        assert np.linalg.norm(np.cross(t, leg)) <= 1e-9 and t @ leg > 0  # along it
        assert np.linalg.norm(kn) <= 1e-9 * scale  # leaving the straight leg with κ = 0
    pa, ta, ka = bezier_end(pair[0], True)
    pb, tb, kb = bezier_end(pair[1], False)
    assert np.linalg.norm(pa - pb) <= 1e-12 * size
    assert np.linalg.norm(np.cross(ta, tb)) <= 1e-9 and ta @ tb > 0
    assert np.linalg.norm(ka - kb) <= 1e-9 * max(np.linalg.norm(ka), scale)


def deviation_by_sampling(pair, corner):
    return min(np.linalg.norm(bezier(cp, U) - corner, axis=1).min() for cp in pair)


# ------------------------------------------------------------ a helix of lines


@pytest.mark.parametrize("shape", SHAPES)
@pytest.mark.parametrize("options", [{}, {"max_curvature": 0.3}, {"max_deviation": 0.4}, {"spiral_lengths": 2.5}, {"curvature": 0.25}])
def test_every_corner_of_a_helix_is_rounded_in_its_own_plane_and_g2(shape, options):
    pts = helix()
    path = round_corners(pts, shape=shape, **options)
    chain = path.chain
    assert chain.dim == 3 and len(path.corners) == len(pts) - 2
    assert np.array_equal(chain.start, pts[0]) and np.array_equal(chain.end, pts[-1])
    normals = []
    for corner in path.corners:
        i = corner.index
        pair = [s.control_points for s in corner.spirals]
        assert_corner_in_space(pair, pts[i - 1], pts[i], pts[i + 1], chain.size)
        normals.append(corner_normal(*pts[i - 1 : i + 2]))
        assert corner.deviation == pytest.approx(deviation_by_sampling(pair, pts[i]), rel=1e-6)
    # every corner in another plane
    assert min(math.acos(min(1.0, abs(a @ b))) for a, b in zip(normals, normals[1:])) > math.radians(5)
    # the straight pieces between corners: G2 there by κ = 0 on both sides
    ends = [end_of(s) for s in chain]
    for (_, (pa, ta, ka)), ((pb, tb, kb), _) in zip(ends, ends[1:]):
        assert np.linalg.norm(pa - pb) <= 1e-12 * chain.size and np.linalg.norm(np.cross(ta, tb)) <= 1e-9
        assert np.linalg.norm(ka - kb) <= 1e-9 * max(np.linalg.norm(ka), 1.0 / chain.size)


def end_of(segment):
    """(start, end) as (point, tangent, κN) of a Line or BezierSpiral in space."""
    if isinstance(segment, BezierSpiral):
        cp = segment.control_points
        return bezier_end(cp, False), bezier_end(cp, True)
    a, b = (np.asarray(p, dtype=float) for p in (segment.point(0.0), segment.point(1.0)))
    t = (b - a) / np.linalg.norm(b - a)
    return (a, t, np.zeros(3)), (b, t, np.zeros(3))


def test_the_bounds_and_lengths_hold_when_measured():
    pts = helix()
    peak = round_corners(pts, max_curvature=0.3)
    assert max(curvature_along(s.control_points).max() for c in peak.corners for s in c.spirals) <= 0.3 * (1 + 1e-9)
    lengths = round_corners(pts, spiral_lengths=2.5, shape="near-linear")
    for corner in lengths.corners:
        for s in corner.spirals:
            assert arc_length(s.control_points) == pytest.approx(2.5, rel=1e-8)
    for shape in SHAPES:
        within = round_corners(pts, max_deviation=0.4, shape=shape)
        for corner in within.corners:
            pair = [s.control_points for s in corner.spirals]
            measured = deviation_by_sampling(pair, pts[corner.index])
            assert 0.99 * 0.4 <= measured <= 0.4  # tight: the legs allow larger pairs here
        assert within.max_deviation <= 0.4


def test_max_deviation_is_tight_or_bounded_by_the_legs_and_passes_closest_at_the_joint():
    rng = np.random.default_rng(7)
    pts = np.cumsum(rng.uniform(-4, 4, size=(40, 3)), axis=0)
    p0, corners, p1, _ = corner_legs(pts)
    bound = rng.uniform(0.01, 1.5, len(corners))
    for shape in SHAPES:
        result = round_corners_batch(p0, corners, p1, max_deviation=bound, shape=shape)
        fit = round_corners_batch(p0, corners, p1, shape=shape)  # the largest pairs the legs allow
        for i in np.flatnonzero(result.ok):
            pair = result.control_points[i]
            measured = deviation_by_sampling(pair, corners[i])
            assert measured <= bound[i]
            assert measured == pytest.approx(result.deviation[i], rel=1e-6)
            if fit.ok[i] and fit.deviation[i] > bound[i]:
                assert measured >= 0.99 * bound[i]  # the legs allow more: the bound is met within 1 %
            else:
                assert measured == pytest.approx(fit.deviation[i], rel=1e-9)  # the legs decide
        # near-linear refuses deflections above 100°, the others round every corner here
        assert result.ok.all() or shape == "near-linear"


def test_deviation_factor_is_the_joints_distance_from_the_corner():
    # A plane corner of deflection 2θ with a known pair: |corner − joint| = D(θ)/κ.
    for shape in SHAPES:
        for theta in np.radians([0.5, 10.0, 30.0, 45.0, 49.0]):
            corner = np.zeros(2)
            p0 = np.array([-10.0, 0.0])
            p1 = 10.0 * np.array([math.cos(2 * theta), math.sin(2 * theta)])
            result = round_corners_batch(p0, corner, p1, curvature=0.7, shape=shape)
            joint = result.control_points[0, 0, 3]
            expected = deviation_factor(math.sin(theta), math.cos(theta), shape) / 0.7
            assert np.linalg.norm(joint - corner) == pytest.approx(expected, rel=1e-12)


def test_a_plane_polyline_tilted_into_space_rounds_as_in_the_plane():
    pts2 = np.array([(0, 0), (4, 0), (6, 3), (9, 3), (11, 0), (15, 1)], dtype=float)
    flat = round_corners(np.column_stack([pts2, np.zeros(len(pts2))]), max_deviation=0.3)
    assert flat.chain.dim == 2  # z = 0 everywhere: plane points, as everywhere in the API
    plane = round_corners(pts2, max_deviation=0.3)
    assert flat.chain.length == plane.chain.length
    a, b = math.radians(35), math.radians(-20)
    rotation = np.array([[1, 0, 0], [0, math.cos(a), -math.sin(a)], [0, math.sin(a), math.cos(a)]]) @ np.array(
        [[math.cos(b), 0, math.sin(b)], [0, 1, 0], [-math.sin(b), 0, math.cos(b)]]
    )
    tilted = np.column_stack([pts2, np.zeros(len(pts2))]) @ rotation.T + (100.0, -50.0, 20.0)
    space = round_corners(tilted, max_deviation=0.3)
    assert space.chain.dim == 3
    assert space.chain.length == pytest.approx(plane.chain.length, rel=1e-12)
    for c2, c3 in zip(plane.corners, space.corners):
        assert c3.curvature == pytest.approx(c2.curvature, rel=1e-12)
        assert c3.deviation == pytest.approx(c2.deviation, rel=1e-9)
        for s2, s3 in zip(c2.spirals, c3.spirals):
            placed = np.column_stack([s2.control_points, np.zeros(4)]) @ rotation.T + (100.0, -50.0, 20.0)
            assert np.abs(placed - s3.control_points).max() <= 1e-12 * space.chain.size


@settings(max_examples=25, deadline=None)
@given(st.lists(st.tuples(*[st.floats(-20, 20)] * 3), min_size=3, max_size=7), st.sampled_from(SHAPES),
       st.sampled_from(["max_curvature", "max_deviation", None]), st.floats(-2, 1))  # fmt: skip
def test_random_polylines_in_space_round_g2_or_refuse_by_name(points, shape, option, log_value):
    pts = np.array(points)
    kwargs = {} if option is None else {option: 10.0**log_value}
    try:
        path = round_corners(pts, shape=shape, **kwargs)
    except ValueError as error:
        message = str(error)
        assert ("corner" in message or "point" in message) and "array(" not in message
        return
    size = path.chain.size
    for corner in path.corners:
        pair = [s.control_points for s in corner.spirals]
        if pair[0].shape[1] == 3:  # one plane: spanned by the first spiral's start leg and the second's end leg
            n = np.cross(pair[0][1] - pair[0][0], pair[1][3] - pair[1][2])
            n /= np.linalg.norm(n)
            assert max(np.abs((cp - pts[corner.index]) @ n).max() for cp in pair) <= 1e-9 * size
            assert_corner_in_space(pair, *legs_of(pts, corner.index), size)
        if option == "max_deviation":
            assert deviation_by_sampling(pair, pts[corner.index, : pair[0].shape[1]]) <= kwargs["max_deviation"]


def legs_of(pts, i):
    """The nearest points before and after point i that are not collinear with it (as the rounding skips them)."""
    before = next(pts[j] for j in range(i - 1, -1, -1) if np.linalg.norm(np.cross(pts[i] - pts[j], pts[i + 1] - pts[i])) > 0)
    return before, pts[i], pts[i + 1]


# ------------------------------------------------------------ refusals, by name


def test_collinear_points_pass_and_folds_are_refused_by_name():
    pts = np.array([(0, 0, 0), (1, 1, 1), (2, 2, 2), (3, 2, 5), (3, 4, 5)], dtype=float)
    path = round_corners(pts)
    assert [c.index for c in path.corners] == [2, 3]
    with pytest.raises(ValueError, match=r"folds straight back at point 2"):
        round_corners([(0, 0, 0), (1, 1, 1), (2, 2, 2), (1.5, 1.5, 1.5)])
    batch = round_corners_batch([(0, 0, 0), (0, 0, 0)], [(1, 1, 1), (1, 1, 1)], [(2, 2, 2), (0, 0, 0.5)])
    assert batch.status.tolist() != [0, 0]
    assert "collinear" in batch.reason(0) and "corner 0 at (1, 1, 1)" in batch.reason(0)


def test_hostile_values_are_refused_by_name():
    pts = helix(5)
    bad = pts.copy()
    bad[2, 1] = np.nan
    with pytest.raises(ValueError, match="points must be finite; point 2"):
        round_corners(bad)
    with pytest.raises(ValueError, match="max_deviation must be positive and finite"):
        round_corners(pts, max_deviation=-1.0)
    with pytest.raises(ValueError, match="max_deviation needs one value or one per interior point"):
        round_corners(pts, max_deviation=[0.1, 0.2])
    with pytest.raises(ValueError, match="not both"):
        round_corners(pts, spiral_lengths=1.0, max_deviation=0.1)
    with pytest.raises(ValueError, match="2 or 3 coordinates"):
        round_corners(np.zeros((4, 4)))
    with pytest.raises(ValueError, match="must all be 2-D or all 3-D points"):
        round_corners_batch([(0, 0)], [(1, 0, 0)], [(1, 1, 1)])
    with pytest.raises(ValueError, match="too far apart for float64"):
        round_corners([(-1e308, 0, 0), (1e308, 0, 1), (1e308, 5, 1)])
    # a tolerance below what float64 resolves at the coordinates
    far = pts + 1e9
    with pytest.raises(NoSolutionError, match=r"corner 1 at .*max_deviation 1e-12 is below what float64 resolves"):
        round_corners(far, max_deviation=1e-12)
    # spirals too long for the legs: the corner, the length asked for and the longest that fits
    with pytest.raises(NoSolutionError, match=r"corner 1 at .*spirals 100 long .* at most [0-9.]+ long"):
        round_corners(pts, spiral_lengths=100.0)
    # both bounds: the deviation allows only so large a pair, whose curvature is above κmax
    with pytest.raises(NoSolutionError, match=r"corner 1 at .*within max_deviation 0.01 .* above max_curvature 0.1"):
        round_corners(pts, max_deviation=0.01, max_curvature=0.1)


def test_magnitudes_from_tiny_to_huge():
    pts = helix(6)
    reference = round_corners(pts, max_deviation=0.4)
    for scale in (1e-150, 1e-300, 1e102, 1e300):
        path = round_corners(pts * scale, max_deviation=0.4 * scale)
        assert path.chain.length / scale == pytest.approx(reference.chain.length, rel=1e-9)
        assert path.max_deviation <= 0.4 * scale


def test_a_bad_row_of_a_batch_in_space_fails_alone():
    p0, corners, p1, _ = corner_legs(helix(8))
    p0, corners = p0.copy(), corners.copy()
    corners[1, 2] = np.nan
    p0[3] = (1e300, -1e300, 1e300)
    good = round_corners_batch(*corner_legs(helix(8))[:3], max_deviation=0.4)
    mixed = round_corners_batch(p0, corners, p1, max_deviation=0.4)
    assert mixed.ok.tolist() == [True, False, True, False, True, True]
    assert "corner 1 at (" in mixed.reason(1) and "nan" in mixed.reason(1)
    assert mixed.reason(3).startswith("corner 3 at (") and "float64 cannot round it at these magnitudes" in mixed.reason(3)
    assert np.isnan(mixed.control_points[[1, 3]]).all() and np.isnan(mixed.deviation[[1, 3]]).all()
    for i in (0, 2, 4, 5):
        assert np.array_equal(mixed.control_points[i], good.control_points[i])
