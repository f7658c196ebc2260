"""The one rule at every level: chains, alignments, circle chains, corner rounding and fillets
return verified geometry or raise ValueError / NoSolutionError — at magnitudes 1e-300 … 1e300
and offsets up to 1e12 times the feature size.

"Verified" means: the result passes the check its own layer applies (a ``Chain`` re-checks
every joint, a ``FilletedPath`` every joint it made, a CAD shape is graded by
``spiral_cad.cad.continuity``), and it starts and ends where it was asked to. Every refusal
shows plain numbers (no numpy reprs).
"""

import math

import numpy as np
import pytest
from hypothesis import event, given, settings
from hypothesis import strategies as st

import spiral_cad as sc
from spiral_cad.core.chain import JOIN_TOLERANCE, g2_mismatch
from spiral_cad.design import Alignment, RailCriteria, RoadCriteria, circle_chain, round_corners
from spiral_cad.design.fillets import fillet_path

#: log10 of the feature size, and offsets of the whole figure in feature sizes.
LOG_SCALE = st.one_of(st.floats(-300, 300), st.sampled_from([-300.0, -150.0, 0.0, 102.0, 150.0, 300.0]))
OFFSET = st.one_of(st.just(0.0), st.builds(lambda sign, e: sign * 10.0**e, st.sampled_from([-1.0, 1.0]), st.floats(-3, 12)))
NUMPY_REPRS = ("np.", "array(", "dtype")  # as conftest.NUMPY_REPRS: messages show plain numbers


def placed(points, log_scale, ox, oy):
    """``points`` (in feature sizes) scaled by 10**log_scale and moved by (ox, oy) feature sizes."""
    scale = 10.0**log_scale
    return [((x + ox) * scale, (y + oy) * scale) for x, y in points]


def assert_rechecked(chain):
    """The chain passes its own joint check again, from its segments alone."""
    again = sc.Chain(chain.segments, chain.tolerance, chain.units)
    assert math.isfinite(again.length) and again.length > 0


def assert_at(point, target, size):
    assert math.dist(tuple(point), tuple(target)) <= 1e-9 * size


# ---------------------------------------------------------------- Chain.join


@given(LOG_SCALE, OFFSET, OFFSET, st.floats(0.2, 5.0), st.floats(-1.0, 3.0))
def test_chain_join_returns_a_checked_chain_or_refuses(outcome, log_scale, ox, oy, radius, reach):
    """Line → spiral → arc → spiral → line round one circle; ``reach`` moves the start and end
    along their lines, also past the spirals (a fold that must be refused by name)."""
    far = 10.0**reach * 400 * radius
    a, b, centre, c, d = placed([(-far, 0), (0, 0), (100, 60 * radius), (300, 150), (300 + far, 150 + far)], log_scale, ox, oy)
    r = 50.0 * radius * 10.0**log_scale

    def build():
        enter = sc.line_to_circle(b, (1, 0), centre, r)
        leave = sc.line_to_circle(c, (-1, -1), centre, r).reversed()
        return sc.Chain.join([enter, leave], start=a, end=d)

    chain = outcome(build)
    if chain is not None:
        assert_rechecked(chain)
        assert_at(chain.start, a, chain.size)
        assert_at(chain.end, d, chain.size)


def test_scaled_chain_joins_of_the_issue_hold():
    """1e102 used to overflow and 1e-150 to divide by zero inside the joint check."""
    for scale in (1e102, 1e-150, 1e-300, 1e300):
        enter = sc.line_to_circle((0, 0), (1, 0), (100 * scale, 60 * scale), 50 * scale)
        leave = sc.line_to_circle((300 * scale, 150 * scale), (-1, -1), (100 * scale, 60 * scale), 50 * scale).reversed()
        chain = sc.Chain.join([enter, leave], start=(-20 * scale, 0), end=(400 * scale, 250 * scale))
        assert [type(s).__name__ for s in chain] == ["Line", "BezierSpiral", "Arc", "BezierSpiral", "Line"]
        assert chain.length == pytest.approx(chain.stations[-1]) and chain.length / scale == pytest.approx(
            sc.Chain.join([sc.line_to_circle((0, 0), (1, 0), (100, 60), 50),
                           sc.line_to_circle((300, 150), (-1, -1), (100, 60), 50).reversed()],
                          start=(-20, 0), end=(400, 250)).length, rel=1e-9)  # fmt: skip


@pytest.mark.parametrize("exponent", [400, -400, 1000, -1000])
def test_rounding_floor_scales_with_the_spiral_where_its_own_formula_leaves_float64(exponent):
    from spiral_cad.core.chain import rounding_floor

    cp = sc.line_to_circle((3, 1), (1, 0.2), (40, 30), 12).spirals[0].control_points
    unit, scaled = (sc.BezierSpiral.from_control_points(cp * 2.0**e) for e in (0, exponent))
    for at_end in (True, False):
        gap, angle, curvature = rounding_floor(unit, at_end)
        assert rounding_floor(scaled, at_end) == (gap * 2.0**exponent, angle, curvature * 2.0**-exponent)


# ---------------------------------------------------------------- alignments

PIS = [(0, 0), (1000, 0), (2000, 800), (3000, 600)]


@given(LOG_SCALE, OFFSET, OFFSET, st.floats(0.02, 2.0), st.floats(0.01, 1.5), st.floats(-400, 400), st.booleans())
def test_from_pis_returns_a_checked_alignment_or_refuses(outcome, log_scale, ox, oy, radius, theta, wiggle, by_length):
    pis = placed([(0, 0), (1000, 0), (2000, 800 + wiggle), (3000, 600)], log_scale, ox, oy)
    r = 300 * radius * 10.0**log_scale
    spiral = {"spiral_lengths": theta * r} if by_length else {"spiral_angles": theta}
    alignment = outcome(lambda: Alignment.from_pis(pis, r, **spiral))
    if alignment is not None:
        assert_rechecked(alignment.chain)
        assert_at(alignment.chain.start, pis[0], alignment.chain.size)
        assert_at(alignment.chain.end, pis[-1], alignment.chain.size)
        for curve in alignment.curves:
            assert 0 < curve.arc_length + curve.spiral_in_length + curve.spiral_out_length < math.inf


EXTREME = st.floats(-300, 300).map(lambda e: 10.0**e)
SPEED = st.one_of(st.floats(20, 130), st.floats(20, 130), EXTREME)
LIMIT = st.one_of(st.none(), st.none(), EXTREME, st.just(0.0))


@settings(max_examples=60)
# Criteria are physical (speeds, friction): half the examples at the scale they are written for.
@given(
    st.one_of(st.just(0.0), LOG_SCALE), OFFSET, st.floats(50, 3000), SPEED, LIMIT, LIMIT, st.sampled_from(["m", "ft", "mm"]), st.booleans()
)
def test_from_pis_with_criteria_returns_a_checked_alignment_or_refuses(outcome, log_scale, ox, radius, speed, low, high, units, rail):
    pis = placed(PIS, log_scale, ox, ox)
    scale = 10.0**log_scale

    def build():
        if rail:
            criteria = RailCriteria(speed, cant=None if low is None else min(low, 150.0))
        else:
            criteria = RoadCriteria(speed, side_friction=0.1, shift_min=low, shift_max=high)
        return Alignment.from_pis(pis, radius * scale, units=units, criteria=criteria)

    alignment = outcome(build)
    if alignment is not None:
        assert_rechecked(alignment.chain)
        assert_at(alignment.chain.end, pis[-1], alignment.chain.size)
        assert len(alignment.checks) == len(alignment.curves) == 2


def test_relaxed_limits_and_extreme_speeds_of_the_issue():
    loose = Alignment.from_pis(PIS, 300, units="m", criteria=RoadCriteria(80, shift_max=1e6))
    default = Alignment.from_pis(PIS, 300, units="m", criteria=RoadCriteria(80))
    assert all(c.ok for c in loose.checks)
    assert [c.theta_in for c in loose.curves] == [c.theta_in for c in default.curves]  # the jerk binds, not p_max
    tiny = Alignment.from_pis(PIS, 300, units="m", criteria=RoadCriteria(80, shift_min=1e-300))
    assert all(c.ok for c in tiny.checks)
    assert tiny.curves[0].spiral_in_length <= default.curves[0].spiral_in_length
    with pytest.raises(ValueError, match="outside the side friction table"):
        Alignment.from_pis(PIS, 300, units="m", design_speed=1e300)
    with pytest.raises(sc.NoSolutionError, match=r"PI 1: no spiral .* meets the criteria at 1e\+300 km/h"):
        Alignment.from_pis(PIS, 300, units="m", criteria=RoadCriteria(1e300, side_friction=0.1))
    with pytest.raises(sc.NoSolutionError, match=r"PI 1: no spiral .* at 1e\+300 km/h"):
        Alignment.from_pis(PIS, 300, units="m", criteria=RailCriteria(1e300))


# ---------------------------------------------------------------- circle chains


@given(
    LOG_SCALE,
    OFFSET,
    OFFSET,
    st.lists(st.tuples(st.floats(-30, 30), st.floats(-30, 30), st.floats(0.5, 8.0), st.booleans()), min_size=2, max_size=4),
)
def test_circle_chain_returns_a_checked_chain_or_refuses(outcome, log_scale, ox, oy, circles):
    scale = 10.0**log_scale
    centres = placed([(x, y) for x, y, _, _ in circles], log_scale, ox, oy)
    items = [(c, r * scale * (1 if ccw else -1)) for c, (_, _, r, ccw) in zip(centres, circles)]
    result = outcome(lambda: circle_chain(items))
    if result is not None:
        assert_rechecked(result.chain)
        assert all(s >= 0 for s in result.sweeps)


def test_circle_chain_at_the_issues_magnitudes():
    nested = (12.0 + 0.993 * 2.4 * math.cos(0.524), 0.993 * 2.4 * math.sin(0.524))
    base = [((0.0, 0.0), 3.0), ((12.0, 0.0), 4.0), (nested, 1.6), ((nested[0] + 8, nested[1] + 2.4), -2.0)]
    reference = circle_chain(base).chain.length
    for scale in (1e102, 1e-150, 1e-300, 1e300):
        chain = circle_chain([((x * scale, y * scale), r * scale) for (x, y), r in base]).chain
        assert chain.length / scale == pytest.approx(reference, rel=1e-9)


# ---------------------------------------------------------------- corner rounding


@given(LOG_SCALE, OFFSET, OFFSET, st.lists(st.tuples(st.floats(-10, 10), st.floats(-10, 10)), min_size=3, max_size=6),
       st.sampled_from(["walton-meek", "g2cbs"]), st.one_of(st.none(), st.floats(-2, 3)))  # fmt: skip
def test_round_corners_returns_a_checked_chain_or_refuses(outcome, log_scale, ox, oy, points, method, log_curvature):
    pts = placed(points, log_scale, ox, oy)
    scale = 10.0**log_scale
    curvature = None if log_curvature is None else 10.0**log_curvature / scale
    result = outcome(lambda: round_corners(pts, max_curvature=curvature, shape=method))
    if result is not None:
        assert_rechecked(result.chain)
        assert_at(result.chain.start, pts[0], result.chain.size)
        assert_at(result.chain.end, pts[-1], result.chain.size)


def test_round_corners_at_the_issues_magnitudes():
    base = np.array(PIS, dtype=float)
    reference = round_corners(base).chain.length
    for scale in (1e102, 1e-150, 1e-300, 1e300):
        assert round_corners(base * scale).chain.length / scale == pytest.approx(reference, rel=1e-9)


# ---------------------------------------------------------------- fillets


def assert_fillet_checked(path, first, last):
    """Every joint touching a rounded corner passes the chain rule again; an open path keeps its ends."""
    pieces = path.segments
    pairs = list(zip(pieces, pieces[1:], path.owners, path.owners[1:]))
    if path.closed:
        pairs.append((pieces[-1], pieces[0], path.owners[-1], path.owners[0]))
    for a, b, owner_a, owner_b in pairs:
        if owner_a is not None or owner_b is not None:
            assert g2_mismatch(a, b, JOIN_TOLERANCE) is None
    if not path.closed:
        size = max(s.length for s in pieces)
        assert_at(pieces[0].start, first, size)
        assert_at(pieces[-1].end, last, size)


@given(LOG_SCALE, OFFSET, OFFSET, st.lists(st.tuples(st.floats(-10, 10), st.floats(-10, 10)), min_size=3, max_size=6),
       st.floats(-3, 0.5), st.floats(0.05, 1.0), st.booleans())  # fmt: skip
def test_fillet_path_returns_checked_corners_or_refuses(outcome, log_scale, ox, oy, points, log_radius, transition, closed):
    pts = placed(points + points[:1] if closed else points, log_scale, ox, oy)
    radius = 10.0**log_radius * 10.0**log_scale
    path = outcome(lambda: fillet_path(pts, radius, transition=transition))
    if path is not None:
        assert len(path.owners) == len(path.segments)
        assert_fillet_checked(path, pts[0], pts[-1])


def bulged(a, b, bulge):
    """The arc from ``a`` to ``b`` whose sagitta is ``bulge`` times half the chord (right of the
    chord when positive), or the line when ``bulge`` is 0."""
    (ax, ay), (bx, by) = a, b
    half = math.dist(a, b) / 2.0
    if bulge == 0.0 or half == 0.0:
        return sc.Line(a, b)
    nx, ny = -(by - ay) / (2 * half), (bx - ax) / (2 * half)  # left normal
    offset = half * (1.0 - bulge * bulge) / (2.0 * bulge)
    centre = (ax / 2 + bx / 2 + nx * offset, ay / 2 + by / 2 + ny * offset)
    return sc.Arc.between(centre, math.copysign(half * (1.0 + bulge * bulge) / (2.0 * abs(bulge)), bulge), a, b)


@given(LOG_SCALE, OFFSET, st.lists(st.tuples(st.floats(-10, 10), st.floats(-10, 10), st.sampled_from([0.0, 0.0, 0.3, -0.3, 0.9, -0.9])), min_size=3, max_size=5),
       st.floats(-3, 0.5), st.floats(0.05, 1.0), st.sampled_from(["nested", "C"]), st.booleans())  # fmt: skip
def test_fillet_path_with_arcs_returns_checked_corners_or_refuses(
    outcome, log_scale, offset, points, log_radius, transition, same_sense, closed
):
    xy = placed([(x, y) for x, y, _ in points], log_scale, offset, offset)
    ends = xy + xy[:1] if closed else xy
    radius = 10.0**log_radius * 10.0**log_scale

    def build():
        segments = [bulged(a, b, bulge) for a, b, (_, _, bulge) in zip(ends, ends[1:], points)]
        return fillet_path(segments, radius, transition=transition, same_sense=same_sense)

    path = outcome(build)
    if path is not None:
        assert_fillet_checked(path, ends[0], ends[-1])


def test_fillet_path_at_1e200_and_far_from_the_origin():
    square = np.array([(0, 0), (1, 0), (1, 1), (0, 1), (0, 0)], dtype=float)
    big = fillet_path(square * 1e200, 0.1e200)
    assert len(big.corners) == 4 and big.chain.length / 1e200 == pytest.approx(fillet_path(square, 0.1).chain.length, rel=1e-9)
    triangle = np.array([(0, 0), (10, 0), (5, 8), (0, 0)]) + 1e9
    with pytest.raises(sc.NoSolutionError, match=r"corner 0 at \(1000000000, 1000000000\): .*float64"):
        fillet_path(triangle, 1)


@pytest.mark.parametrize("bad", [[1.5], ["1"], [True], [np.float64(1.0)], 1, "1", [None]])
def test_fillet_vertices_must_be_integers(bad):
    with pytest.raises(ValueError, match="vertices") as info:
        fillet_path([(0, 0), (1, 0), (1, 1)], 0.1, vertices=bad)
    assert "np." not in str(info.value)
    assert len(fillet_path([(0, 0), (1, 0), (1, 1)], 0.1, vertices=[np.int64(1)]).corners) == 1


# ---------------------------------------------------------------- g2_fillet (CAD)


def TILTED(bd):
    return bd.Plane(origin=(1, 2, 3), x_dir=(1, 1, 0), z_dir=(1, -1, 1))


@settings(max_examples=80)  # random polygons are often refused (self-crossing): enough examples to build some
@given(st.floats(-8, 60), OFFSET, st.lists(st.tuples(st.floats(-10, 10), st.floats(-10, 10)), min_size=3, max_size=5),
       st.floats(-3, 0), st.floats(0.05, 1.0), st.sampled_from(["polygon", "face", "D"]), st.sampled_from(["XY", "XZ", "tilted"]))  # fmt: skip
def test_g2_fillet_returns_what_the_checker_grades_g2_or_refuses(outcome, log_scale, offset, points, log_radius, transition, kind, plane):
    bd = pytest.importorskip("build123d")
    from spiral_cad.build123d import g2_fillet
    from spiral_cad.cad.continuity import check_continuity

    scale = 10.0**log_scale
    try:  # the input itself must exist in OCCT (it refuses coordinates past ~1e100 and edges below 1e-7)
        if kind == "face":
            shape = bd.Pos(offset * scale, offset * scale) * bd.Rectangle(
                abs(points[0][0]) * scale + scale, abs(points[0][1]) * scale + scale
            )
        elif kind == "D":  # lines and an arc that bulges out (or in) by points[1][0] / 10
            a, b, c, d = placed([(0, 0), (10, 0), (10, 6), (0, 6)], log_scale, offset, offset)
            bulge = placed([(10 + points[1][0] / 2, 3)], log_scale, offset, offset)[0]
            shape = bd.Wire(
                [bd.Edge.make_line(a, b), bd.Edge.make_three_point_arc(b, bulge, c), bd.Edge.make_line(c, d), bd.Edge.make_line(d, a)]
            )
        else:
            shape = bd.Polyline(*placed(points, log_scale, offset, offset), close=True)
        shape = TILTED(bd) * shape if plane == "tilted" else getattr(bd.Plane, plane) * shape
        assert shape.is_valid
    except Exception:
        event("no such input in OCCT")
        return
    result = outcome(lambda: g2_fillet(shape, 10.0**log_radius * scale, transition=transition))
    if result is not None:
        report, given = check_continuity(result), check_continuity(shape)
        g1 = [[j for j in r.joints if j.level.name == "G1"] for r in (report, given)]
        assert report.pieces == 1 and report.min_level.name in ("G1", "G2"), report
        assert len(g1[0]) <= len(g1[1])  # only joints already tangent (a line onto an arc) may stay G1
        assert report.wires[0].closed or not given.wires[0].closed  # a closed path stays closed


def test_g2_fillet_of_the_issue():
    bd = pytest.importorskip("build123d")
    from spiral_cad.build123d import g2_fillet
    from spiral_cad.cad.continuity import check_continuity

    with pytest.raises(sc.NoSolutionError, match=r"corner \d: a \w+ of the fillet is \S+ long; OCCT merges points closer than 1e-07"):
        g2_fillet(bd.Rectangle(2e-6, 1e-6), 1e-7)  # was StdFail_NotDone
    big = g2_fillet(bd.Rectangle(2e9, 1e9), 1e8)  # was a false "does not connect"
    assert check_continuity(big).passes("G2") and len(big.edges()) == 16
    with pytest.raises(sc.NoSolutionError, match=r"corner 0 at \(1000000000, 1000000000\): .*float64"):
        g2_fillet(bd.Polyline((1e9, 1e9), (1e9 + 10, 1e9), (1e9 + 5, 1e9 + 8), close=True), 1)  # was a G0 joint
    with pytest.raises(ValueError, match=r"got a Box with 1 solid.*give the edges to round, g2_fillet\(part.edges\(\), 0.2\)"):
        g2_fillet(bd.Box(1, 2, 3), 0.2)
    assert g2_fillet(bd.Box(1, 2, 3).edges(), 0.2).is_valid  # the advice builds
    with bd.BuildLine() as line:
        bd.Polyline((0, 0), (1, 0), (1, 1), (0, 1), close=True)
        bd.Polyline((3, 0), (4, 0), (4, 1), (3, 1), close=True)
        g2_fillet(line.vertices(), 0.1)
    report = check_continuity(line.line)
    assert report.passes("G2", pieces=2) and len(line.line.edges()) == 32
    squares = bd.Curve([bd.Polyline((0, 0), (1, 0), (1, 1), (0, 1), close=True), bd.Polyline((3, 0), (4, 0), (4, 1), (3, 1), close=True)])
    rounded = g2_fillet(squares, 0.1)
    assert isinstance(rounded, bd.Curve) and check_continuity(rounded).passes("G2", pieces=2) and len(rounded.edges()) == 32
    with_line = g2_fillet(bd.Curve([*squares.wires(), bd.Edge.make_line((5, 0), (6, 1))]), 0.1)
    assert len(with_line.wires()) == 3 and len(with_line.edges()) == 33  # the straight line passes through


# ---------------------------------------------------------------- input and messages


MASKED = np.ma.masked_array([[0.0, 0.0], [5.0, 5.0]], mask=[[False, False], [True, True]])


@pytest.mark.parametrize(
    "call, name",
    [
        (lambda: sc.batch.line_to_circle(MASKED, [1, 0], [0, 105], 100), "point"),
        (lambda: sc.batch.line_to_line([0, 0], [1, 0], [1, 1], np.ma.masked_array([0.5], mask=[True])), "curvature"),
        (lambda: sc.batch.circle_to_circle([[0, 0], MASKED[1]], 1, [9, 0], 1), "center0"),
        (lambda: round_corners(np.ma.masked_array([(0, 0), (1, 0), (1, 1)], mask=[[0, 0], [1, 1], [0, 0]])), "points"),
        (
            lambda: Alignment.from_pis([(0, 0), (1000, 0), (2000, 800)], np.ma.masked_array([300.0], mask=[True]), spiral_angles=0.1),
            "radii",
        ),
        (lambda: sc.line_to_circle((0, 0), (1, 0), (0, 105), np.ma.masked), "radius"),
        (lambda: sc.line_to_circle(MASKED[1], (1, 0), (0, 105), 100), "point"),
        (lambda: sc.Chain([sc.Line((0, 0), (1, 0))]).point_at(np.ma.masked_array([0.5], mask=[True])), "stations"),
    ],
)
def test_masked_input_is_refused_by_name(call, name):
    """numpy drops a mask when it converts: the masked value would be solved as the number under it."""
    import spiral_cad.core.batch  # noqa: F401  (sc.batch)

    with pytest.raises(ValueError, match=rf"{name} is a masked array: masked values have no geometry"):
        call()


@pytest.mark.parametrize(
    "call, expected",
    [
        (lambda: sc.Line((0, 0), (0, 0)), "Line needs distinct end points; both are (0.0, 0.0)"),
        (lambda: sc.Line(np.array([1.5, 2.0]), np.array([1.5, 2.0])), "both are (1.5, 2.0)"),
        (lambda: sc.line_to_circle(np.array([0.0, 0.0, 1.0]), (1, 0), (0, 5), 1), "point must have 2 coordinates; got [0.0, 0.0, 1.0]"),
        (lambda: sc.line_to_circle((0, 0), (1, 0), (0, 5), np.complex128(1j)), "radius must be a real number; got complex128 1j"),
        (lambda: sc.line_to_circle((0, 0), (1, 0), (0, 5), np.str_("5")), "radius must be a real number; got str_ '5'"),
        (lambda: RoadCriteria(80, max_jerk=np.float64(-1)), "max_jerk must be positive; got -1.0"),
        (
            lambda: circle_chain([np.array([1.0, 2.0, 3.0, 4.0]), ((0, 0), 1)]),
            "circle 0 must be a Circle, (center, radius) or (x, y, radius); got [1.0, 2.0, 3.0, 4.0]",
        ),
        (
            lambda: fillet_path([(0, 0), (1, 0), (1, 1)], 0.1, vertices=[np.float64(1)]),
            "vertices[0] must be a vertex index (an integer); got float64 1.0",
        ),
        (lambda: fillet_path([(0, 0), (1, 0), (1, 0), (2, 1)], 0.1), "path points 1 and 2 coincide at (1.0, 0.0)"),
    ],
)
def test_messages_show_plain_python_numbers(call, expected):
    with pytest.raises(ValueError) as info:
        call()
    assert expected in str(info.value)
    assert not any(r in str(info.value) for r in NUMPY_REPRS)


def test_chain_join_names_a_start_or_end_that_would_fold_back():
    enter = sc.line_to_circle((0, 0), (1, 0), (100, 60), 50)
    leave = sc.line_to_circle((300, 150), (-1, -1), (100, 60), 50).reversed()
    with pytest.raises(ValueError, match=r"start \(90.0, 0.0\) lies ahead of where parts\[0\] begins"):
        sc.Chain.join([enter, leave], start=(90, 0))
    with pytest.raises(ValueError, match=r"end \(200.0, 50.0\) lies behind where parts\[1\] ends"):
        sc.Chain.join([enter, leave], end=(200, 50))


def test_a_joint_error_names_the_part_it_belongs_to():
    from spiral_cad.core.errors import JointError

    enter = sc.line_to_circle((0, 0), (1, 0), (100, 60), 50)
    with pytest.raises(JointError, match=r"Chain is not G2 at joint 1 .*\(at parts\[1\]\)$") as info:
        sc.Chain.join([enter, sc.Line((500, 500), (600, 500))])  # the arc to it ends on the circle, not at the line
    assert (info.value.joint, info.value.part) == (1, 1)


def test_a_joint_float64_cannot_hold_names_the_pi():
    """Spirals of θ ≈ 1e-4 rad on R = 300 m at 1 km from the origin: their end curvature holds
    only to ~1e-6 relative, which no G2 check accepts."""
    with pytest.raises(
        sc.NoSolutionError,
        match=r"^PI 1: float64 cannot hold its curve G2 at these coordinates: Chain is not G2 at joint \d .*\(at parts\[[01]\]\)$",
    ):
        Alignment.from_pis(PIS, 300, units="m", criteria=RoadCriteria(5, side_friction=0.1, shift_min=0), shape="walton-meek")
