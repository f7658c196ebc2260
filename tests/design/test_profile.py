"""Vertical alignments, smooth superelevation and the 3-D centre line: numbers checked independently."""

import math

import numpy as np
import pytest
from scipy.integrate import quad

from spiral_cad import NoSolutionError
from spiral_cad.design import Alignment, Profile, ProfileCriteria, Superelevation, centerline_3d
from spiral_cad.design.roadway import roadway

PIS = [(0, 0), (600, 120), (1150, -80), (1700, 260), (2300, 200)]


@pytest.fixture(scope="module")
def highway() -> Alignment:
    return Alignment.from_pis(PIS, [450, 400, 600], units="m", design_speed=80, start_station=10000)


@pytest.fixture(scope="module")
def profile(highway) -> Profile:
    end = highway.end_station
    return Profile.from_pvis([(10000, 120), (10700, 132), (11500, 116), (end, 121)], units="m", design_speed=80,
                             alignment=highway)  # fmt: skip


# ------------------------------------------------------------------ profile


def parabola_through(profile, station, span):
    """Fit z = a + b·x + c·x² to three profile points around ``station`` (an independent read of the curve)."""
    x = np.array([-span, 0.0, span])
    z = profile.elevation(station + x)
    c = (z[0] - 2 * z[1] + z[2]) / (2 * span * span)
    b = (z[2] - z[0]) / (2 * span)
    return z[1], b, c


def test_a_symmetric_curve_is_the_parabola_between_the_grades():
    profile = Profile.from_pvis([(0, 100), (400, 112), (1000, 94)], curve_lengths=[200], units="m")
    (curve,) = profile.curves
    assert (curve.grade_in, curve.grade_out) == pytest.approx((0.03, -0.03))
    assert (curve.bvc, curve.evc, curve.kind) == (300.0, 500.0, "crest")
    # on the grade lines outside the curve, z is the straight line through the PVIs
    assert profile.elevation([0, 300, 500, 1000]) == pytest.approx([100, 109, 109, 94], abs=1e-12)
    # on the curve: constant d²z/ds² = A/L, K = L/|A| in m per percent; the tangent offset at the PVI is A·L/8
    _, _, c = parabola_through(profile, 400.0, 50.0)
    assert 2 * c == pytest.approx(-0.06 / 200, rel=1e-9)
    assert curve.k == pytest.approx(200 / 6, rel=1e-12)
    assert profile.elevation(400.0) == pytest.approx(112 - 0.06 * 200 / 8, abs=1e-12)
    assert curve.extreme_point() == pytest.approx(400.0)
    rising = Profile.from_pvis([(0, 100), (400, 112), (1000, 124.6)], curve_lengths=[200], units="m")
    assert rising.curves[0].extreme_point() == 500.0  # a crest between rising grades: highest at its end
    assert profile.grade([300, 400, 500]) == pytest.approx([0.03, 0.0, -0.03], abs=1e-15)


def test_an_asymmetric_curve_is_c1_and_meets_both_grades():
    profile = Profile.from_pvis([(0, 10), (500, 25), (1200, 4)], curve_lengths=[(100, 300)], units="m")
    (curve,) = profile.curves
    assert (curve.bvc, curve.evc) == (400.0, 800.0)
    for s in (400.0, 500.0, 800.0):  # value and grade continuous at every break: the piece before it, evaluated there
        before = profile.coefficients[np.searchsorted(profile.stations, s) - 1]
        d = s - profile.stations[np.searchsorted(profile.stations, s) - 1]
        assert before[0] + d * (before[1] + d * before[2]) == pytest.approx(profile.elevation(s), abs=1e-12)
        assert before[1] + 2 * d * before[2] == pytest.approx(profile.grade(s), abs=1e-15)
    assert profile.grade(400.0) == pytest.approx(0.03)
    assert profile.grade(800.0) == pytest.approx(-0.03)
    # the parabolas meet below the PVI with the grade (g1·L1 + g2·L2)/(L1 + L2)
    assert profile.grade(500.0) == pytest.approx((0.03 * 100 - 0.03 * 300) / 400, abs=1e-15)
    assert curve.k == pytest.approx(1 / (100 * abs(curve.rates[0])))


def test_k_values_give_the_lengths():
    profile = Profile.from_pvis([(0, 0), (500, 20), (1000, 0), (1500, 10)], k_values=[30, 20], units="m")
    assert [c.length for c in profile.curves] == pytest.approx([30 * 8, 20 * 6])


@pytest.mark.parametrize("speed", [60, 80, 100, 120])
def test_minimum_k_from_the_stopping_sight_distance(speed):
    ssd = 0.278 * speed * 2.5 + 0.039 * speed**2 / 3.4  # by hand, AASHTO's metric form
    criteria = ProfileCriteria(speed)
    assert criteria.stopping_sight_distance("m") == pytest.approx(ssd, rel=1e-15)
    assert criteria.minimum_k(True, "m") == pytest.approx(ssd**2 / 658, rel=1e-15)
    assert criteria.minimum_k(False, "m") == pytest.approx(ssd**2 / (120 + 3.5 * ssd), rel=1e-15)
    # the same in a millimetre design: the numbers scale, the road does not change
    assert criteria.minimum_k(True, "mm") == pytest.approx(1000 * ssd**2 / 658, rel=1e-14)


def test_the_known_design_values():
    # 60 km/h by hand: SSD = 41.70 + 41.29 = 82.99 m; K = 82.99²/658 = 10.47 (crest), 82.99²/410.5 = 16.78 (sag)
    c60 = ProfileCriteria(60)
    assert c60.stopping_sight_distance("m") == pytest.approx(82.994, abs=1e-3)
    assert (c60.minimum_k(True, "m"), c60.minimum_k(False, "m")) == pytest.approx((10.468, 16.780), abs=1e-3)
    # US customary at 50 mph: SSD = 1.47·50·2.5 + 1.075·50²/11.2 = 423.7 ft, crest K = SSD²/2158
    us = ProfileCriteria(50)
    assert us.stopping_sight_distance("ft") == pytest.approx(1.47 * 50 * 2.5 + 1.075 * 2500 / 11.2, rel=1e-14)
    assert us.minimum_k(True, "ft") == pytest.approx(us.stopping_sight_distance("ft") ** 2 / 2158, rel=1e-14)
    assert us.grade_limit("ft") == 0.05 and ProfileCriteria(50, terrain="level").grade_limit("ft") == 0.04
    assert ProfileCriteria(100).grade_limit("m") == 0.04 and ProfileCriteria(100, terrain="level").grade_limit("m") == 0.03
    with pytest.raises(ValueError, match="outside the maximum grade table"):
        ProfileCriteria(30).grade_limit("m")


def test_the_shortest_curves_meet_the_criteria_and_violations_are_listed(profile):
    criteria = ProfileCriteria(80)
    for curve in profile.curves:
        k_min = criteria.minimum_k(curve.kind == "crest", "m")
        assert curve.k == pytest.approx(max(k_min, 48 / (100 * abs(curve.difference))), rel=1e-12)
    assert all(row.ok for row in profile.checks)
    short = Profile.from_pvis([(0, 100), (500, 120), (1000, 100)], curve_lengths=[100], units="m", design_speed=80)
    (row,) = [r for r in short.checks if r.violations]
    assert row.pvi == 1 and "crest K = 12.5 < K_min = 25.29" in row.violations[0]
    with pytest.raises(NoSolutionError, match=r"PVI 1: crest K = 12\.5 < K_min"):
        Profile.from_pvis([(0, 100), (500, 120), (1000, 100)], curve_lengths=[100], units="m", design_speed=80, strict=True)
    steep = Profile.from_pvis([(0, 100), (500, 130), (1000, 100)], k_values=50, units="m", design_speed=80)
    assert "grade 6 % > 5 %" in steep.checks[0].violations[0]


def test_profile_table_and_csv(profile, tmp_path):
    rows = profile.rows()
    assert [r["pvi"] for r in rows] == [1, 2]
    assert rows[0]["kind"] == "crest" and rows[1]["kind"] == "sag"
    assert all(type(v) in (int, float, str) for r in rows for v in r.values())
    path = profile.to_csv(tmp_path / "highway_profile.csv")
    head = path.read_text().splitlines()[0]
    assert "station [m]" in head and "K [m/%]" in head and "grade_in [%]" in head and "verdict" in head
    assert "K_min [m/%]" in profile.table()
    from helpers import assert_plain_csv

    assert_plain_csv(path)


@pytest.mark.parametrize(
    "kwargs, message",
    [
        (dict(points=[(0, 0)]), "at least 2 PVIs"),
        (dict(points=[(0, 0), (0, 1), (5, 0)], curve_lengths=[1]), "PVI 1: station 0.0 must be after PVI 0"),
        (dict(points=[(0, 0), (10, float("nan"))]), "PVI 1: station and elevation must be finite"),
        (dict(points=[(0, 0), (100, 5), (200, 0)], curve_lengths=[-5]), "PVI 1: curve lengths must be positive"),
        (dict(points=[(0, 0), (100, 5), (200, 0)], curve_lengths=[1], k_values=[1]), "at most one"),
        (dict(points=[(0, 0), (100, 5), (200, 0)]), "give curve_lengths or k_values"),
        (dict(points=[(0, 0), (100, 5), (200, 0)], curve_lengths=[(1, 2, 3)]), r"PVI 1\) must be a length"),
        (dict(points=[(0, 0), (100, 5), (200, 0)], curve_lengths="12"), "must be a real number"),
        (
            dict(points=[(0, 0), (100, 5), (200, 10)], curve_lengths=[5]),
            r"PVI 1 at station 100.0 lies on the grade of its neighbours \(5.0 %\)",
        ),
    ],
)
def test_malformed_profiles_name_the_pvi(kwargs, message):
    with pytest.raises(ValueError, match=message):
        Profile.from_pvis(units="m", **kwargs)


def test_overlapping_curves_and_curves_past_the_ends_are_refused(highway):
    with pytest.raises(NoSolutionError, match="PVI 1 and PVI 2: the vertical curves overlap: PVI 1's ends at 300"):
        Profile.from_pvis([(0, 0), (200, 5), (400, 0), (600, 5)], curve_lengths=[200, 300], units="m")
    with pytest.raises(NoSolutionError, match="PVI 1: the curve .* starts at -50, before the profile's start PVI 0"):
        Profile.from_pvis([(0, 0), (100, 5), (400, 0)], curve_lengths=[300], units="m")
    with pytest.raises(NoSolutionError, match="PVI 1: the shortest curve that meets the criteria .* past the profile's end"):
        Profile.from_pvis([(0, 0), (500, 0), (520, -1)], units="m", design_speed=80)
    end = highway.end_station
    with pytest.raises(NoSolutionError, match="must cover the alignment"):
        Profile.from_pvis([(10100, 0), (end, 5)], units="m", alignment=highway)
    with pytest.raises(NoSolutionError, match="PVI 1: its vertical curve .* runs past the alignment's start"):
        Profile.from_pvis([(9000, 0), (10010, 5), (end, 0)], curve_lengths=[100], units="m", alignment=highway)
    with pytest.raises(ValueError, match="the alignment is in m; units='ft'"):
        Profile.from_pvis([(10000, 0), (end, 5)], units="ft", alignment=highway)


@pytest.mark.parametrize(
    "points, kwargs, message",
    [
        ([(0, 0), (1e300, 1), (2e300, 0)], dict(curve_lengths=[1e299]), "cannot be held in float64 at these numbers"),
        ([(0, 1e308), (100, -1e308)], {}, "PVI 0 and PVI 1: the stations and elevations give a grade float64 cannot hold"),
        ([(0, 0), (200, 10), (400, 0)], dict(design_speed=1e300, criteria=None), "PVI 1: its vertical curve would be longer"),
    ],
)
def test_numbers_beyond_float64_are_refused_by_name(points, kwargs, message):
    with pytest.raises(ValueError, match=message):
        Profile.from_pvis(points, units="m", **kwargs)


def test_profile_stations_are_checked(profile):
    with pytest.raises(ValueError, match="station 9000.0 is outside the profile"):
        profile.elevation(9000.0)
    assert profile.elevation([[10000, 10500], [11000, 12000]]).shape == (2, 2)


# --------------------------------------------------------- superelevation


def test_superelevation_is_c1_at_every_ramp_end(highway):
    bank = Superelevation.from_alignment(highway)
    ends = bank.ramp_ends()
    assert len(ends) == 4 * len(highway.curves)
    for s in ends:  # the maliput-style check: slope jump at each ramp end
        left = bank.coefficients[np.searchsorted(bank.stations, s) - 1]
        d = s - bank.stations[np.searchsorted(bank.stations, s) - 1]
        value_left = left[0] + d * (left[1] + d * (left[2] + d * left[3]))
        slope_left = left[1] + d * (2 * left[2] + 3 * d * left[3])
        assert abs(value_left - bank.roll(s)) <= 1e-12
        assert abs(slope_left - bank.roll(s, 1)) <= 1e-9


def test_superelevation_reaches_e_on_the_circle_and_falls_to_the_inside(highway):
    bank = Superelevation.from_alignment(highway)
    for curve, check in zip(highway.curves, highway.checks):
        middle = 0.5 * (curve.sc + curve.cs)
        assert bank.cross_slope(middle) == pytest.approx(-math.copysign(check.cross_slope, curve.deflection), rel=1e-14)
        assert bank.share(middle) == pytest.approx(1.0)
        # half way along each spiral: half the roll (cubic ease is symmetric), peak rate 1.5× the mean
        half = 0.5 * (curve.ts + curve.sc)
        assert bank.roll(half) == pytest.approx(0.5 * bank.roll(middle), rel=1e-12)
        assert abs(bank.roll(half, 1)) == pytest.approx(1.5 * abs(bank.roll(middle)) / (curve.sc - curve.ts), rel=1e-12)
    assert bank.roll(highway.start_station) == 0.0 and bank.roll(highway.end_station) == 0.0


def test_superelevation_values_and_errors(highway):
    flat = Alignment.from_pis(PIS, [450, 400, 600], spiral_angles=0.1, units="m")
    assert not Superelevation.from_alignment(flat).coefficients.any()
    given = Superelevation.from_alignment(flat, cross_slopes=0.05)
    assert np.tan(np.abs(given.coefficients[:, 0])).max() == pytest.approx(0.05)
    with pytest.raises(ValueError, match="PI 2: the cross slope must lie in"):
        Superelevation.from_alignment(flat, cross_slopes=[0.05, -0.1, 0.05])
    with pytest.raises(ValueError, match="one value per curve"):
        Superelevation.from_alignment(flat, cross_slopes=[0.05])


# ---------------------------------------------------------- 3-D centre line


def arc_length_to(segment, u):
    """Independent arc length (adaptive quadrature of |B'(u)|)."""
    if hasattr(segment, "control_points"):
        cp = segment.control_points
        speed = lambda t: np.linalg.norm(3 * ((1 - t) ** 2 * (cp[1] - cp[0]) + 2 * t * (1 - t) * (cp[2] - cp[1]) + t * t * (cp[3] - cp[2])))  # noqa: E731
        return quad(speed, 0.0, u, epsabs=0, epsrel=1e-13)[0]
    return u * segment.length


def test_the_3d_centre_line_is_within_its_tolerance_sampled_densely(highway, profile):
    line = centerline_3d(highway, profile, tolerance=1e-7)
    assert line.deviation <= 1e-7 and line.tolerance == 1e-7
    t = np.linspace(0, 1, 41)
    points = line.point(t)
    worst_z = worst_plan = 0.0
    for piece, (k, (u0, u1)) in enumerate(zip(line.segment, line.parameters)):
        segment = highway.chain[int(k)]
        if hasattr(segment, "control_points"):  # spirals: the piece is the same Bézier on [u0, u1]
            u = u0 + t * (u1 - u0)
            plan = segment.point(u)
            stations = [highway.start_station + highway.chain.stations[k] + arc_length_to(segment, x) for x in u]
        elif segment.curvature(0) == 0:  # lines: the distance along
            plan = segment.start + np.outer(u0 + t * (u1 - u0), segment.end - segment.start)
            stations = highway.start_station + highway.chain.stations[k] + np.linalg.norm(points[piece, :, :2] - segment.start, axis=1)
        else:  # arcs: the point on the circle, the station from its polar angle
            offset = points[piece, :, :2] - segment.center
            r = abs(segment.radius)
            plan = segment.center + offset * (r / np.linalg.norm(offset, axis=1))[:, None]
            turned = np.mod(np.sign(segment.radius) * (np.arctan2(offset[:, 1], offset[:, 0]) - segment.start_angle), 2 * np.pi)
            turned = np.where(turned > np.pi + segment.sweep / 2, turned - 2 * np.pi, turned)
            stations = highway.start_station + highway.chain.stations[k] + r * np.clip(turned, 0, segment.sweep)
        worst_plan = max(worst_plan, np.abs(points[piece, :, :2] - plan).max())
        worst_z = max(worst_z, np.abs(points[piece, :, 2] - profile.elevation(np.asarray(stations))).max())
    assert worst_plan <= 1e-9 and worst_z <= 1e-7


def test_lines_and_level_stretches_are_exact(highway):
    level = Profile.from_pvis([(10000, 50), (highway.end_station, 50)], units="m")
    line = centerline_3d(highway, level)
    assert line.exact.all() and line.deviation <= 1e-12 * 2400
    assert np.all(line.control_points[..., 2] == 50.0)
    graded = Profile.from_pvis([(10000, 50), (highway.end_station, 60)], units="m")
    line = centerline_3d(highway, graded)
    lines = [type(highway.chain[int(k)]).__name__ == "Line" for k in line.segment]
    assert (line.exact == np.array(lines)).all()
    assert "plan exact" in line.describe()


def test_the_centre_line_pieces_end_at_the_profile_breaks(highway, profile):
    line = centerline_3d(highway, profile)
    for curve in profile.curves:
        assert np.min(np.abs(line.stations - curve.bvc)) <= 1e-9 and np.min(np.abs(line.stations - curve.evc)) <= 1e-9
    assert line.deviation <= line.tolerance == pytest.approx(1e-6 * highway.chain.length)


def test_centre_line_errors(highway, profile):
    with pytest.raises(ValueError, match="profile must be a Profile"):
        centerline_3d(highway, "profile")
    with pytest.raises(ValueError, match="tolerance must be positive"):
        centerline_3d(highway, profile, tolerance=0)
    feet = Profile.from_pvis([(10000, 0), (13000, 5)], units="ft")
    with pytest.raises(ValueError, match="the profile is in ft but the alignment in m"):
        centerline_3d(highway, feet)
    with pytest.raises(ValueError, match="tolerance 1e-12 m is below what float64 can hold at these coordinates"):
        centerline_3d(highway, profile, tolerance=1e-12)


# ------------------------------------------------------------------ roadway


def test_roadway_edges_follow_crown_banking_and_profile(highway, profile):
    road = roadway(highway, profile, [6.0, -6.0], crossfall=0.02, depth=0.4, tolerance=1e-6)
    assert road.deviation <= 1e-6 and list(road.offsets) == [6.0, 0.0, -6.0]
    bank = Superelevation.from_alignment(highway)
    first, last = road.stations[0], road.stations[-1]
    # on the first tangent: crown, both edges 2 % below the centre
    s0 = road.edges[:, 0, 0]
    assert s0[1, 2] == pytest.approx(profile.elevation(first))
    assert s0[0, 2] - s0[1, 2] == pytest.approx(-0.12) and s0[2, 2] - s0[1, 2] == pytest.approx(-0.12)
    # on a circle: a plane section at the curve's roll
    curve = highway.curves[0]
    piece = int(np.searchsorted(road.stations, 0.5 * (curve.sc + curve.cs))) - 1
    start = road.edges[:, piece, 0]
    slope = (start[0, 2] - start[2, 2]) / np.linalg.norm(start[0, :2] - start[2, :2])
    assert slope == pytest.approx(np.tan(bank.roll(road.stations[piece])), rel=1e-12)
    assert road.section(0).shape == (6, 3) and last == pytest.approx(highway.end_station)


def test_roadway_errors(highway, profile):
    for kwargs, message in [
        (dict(offsets=[]), "offsets must be finite"),
        (dict(offsets=[0.0]), "reach off the centre line"),
        (dict(offsets=[3.0], crossfall=1.5), "crossfall must lie in"),
        (dict(offsets=[3.0], depth=0), "depth must be positive"),
        (dict(offsets=[3.0], tolerance=-1), "tolerance must be positive"),
        (dict(offsets=[-460.0, 3.0]), r"PI 1: the cross-section reaches 460 m to the right, towards the curve's centre 450 m away"),
        (dict(offsets=[400.0]), r"PI 2: the cross-section reaches 400 m to the left, towards the curve's centre 400 m away"),
    ]:
        with pytest.raises(ValueError, match=message):
            roadway(highway, profile, **kwargs)


def test_grades_equal_to_the_last_ulp_make_a_straight_curve_not_a_crash():
    profile = Profile.from_pvis([[0, 0], [100, 1], [200, 2.0000000000000004]], k_values=50)
    row = profile.rows()[0]
    assert row["BVC"] <= row["extreme_point"] <= row["EVC"]
    assert profile.elevation([50.0, 150.0]).tolist() == pytest.approx([0.5, 1.5])


@pytest.mark.parametrize(
    "make, message",
    [
        (lambda: ProfileCriteria(np.float64(-3)), "design_speed must be positive; got -3.0$"),
        (lambda: ProfileCriteria(80, max_grade=np.float64(-1)), "max_grade must be positive; got -1.0$"),
    ],
)
def test_messages_show_plain_numbers(make, message):
    with pytest.raises(ValueError, match=message):
        make()


@pytest.mark.parametrize(
    "make, message",
    [
        (lambda: Profile.from_pvis([[0, 0], [100, 1], [200, 0]], 50, alignment="x"), "alignment must be an Alignment; got str"),
        (lambda: Profile.from_pvis([[0, 0], [100, 1], [200, 0]], 50, strict="no"), "strict must be True or False; got 'no'"),
    ],
)
def test_arguments_of_the_wrong_kind_are_value_errors(make, message):
    with pytest.raises(ValueError, match=message):
        make()


def test_a_superelevation_of_the_wrong_kind_is_named(highway, profile):
    with pytest.raises(ValueError, match="superelevation must be a Superelevation; got str"):
        roadway(highway, profile, [3.0], superelevation="x")
