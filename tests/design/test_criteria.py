"""Road and rail criteria from a design speed, judged on the real Bézier spiral."""

import math

import numpy as np
import pytest

import spiral_cad as sc
from spiral_cad import NoSolutionError
from spiral_cad.core.bezier import curvature_rate, peak_curvature_rate
from spiral_cad.core.factors import unit_spirals
from spiral_cad.design import Alignment, RailCriteria, RoadCriteria
from spiral_cad.design.criteria import SIDE_FRICTION_KMH

PIS = [[0, 0], [600, 120], [1150, -80], [1700, 260], [2300, 200]]


def dense_peak_jerk(spiral, speed_ms: float, metres: float = 1.0) -> float:
    """v³·max|dκ/ds| sampled densely (independent of the golden-section search)."""
    u = np.linspace(0.0, 1.0, 20001)
    return speed_ms**3 * float(np.abs(curvature_rate(spiral.control_points, u)).max()) / metres**2


def test_minimum_radius_follows_the_published_formulas():
    metric = RoadCriteria(100)
    assert metric.friction("m") == 0.12 and metric.minimum_radius("m") == pytest.approx(100**2 / (127 * (0.08 + 0.12)))
    assert RoadCriteria(95).friction("m") == pytest.approx(0.125)  # linear between 90 and 100 km/h
    imperial = RoadCriteria(60, superelevation_max=0.06)
    assert imperial.minimum_radius("ft") == pytest.approx(60**2 / (15 * (0.06 + 0.12)))
    assert imperial.minimum_radius("m") == pytest.approx(60**2 / (127 * 0.23))  # 60 km/h in a metric design
    assert metric.minimum_radius("mm") == pytest.approx(metric.minimum_radius("m") * 1000)
    with pytest.raises(ValueError, match="outside the side friction table"):
        RoadCriteria(200).minimum_radius("m")
    assert RoadCriteria(200, side_friction=0.07).minimum_radius("m") == pytest.approx(200**2 / (127 * 0.15))
    assert [v for v, _ in SIDE_FRICTION_KMH] == sorted(v for v, _ in SIDE_FRICTION_KMH)


@pytest.mark.parametrize("shape", ["walton-meek", "near-linear"])
@pytest.mark.parametrize("speed, jerk", [(80, 0.6), (60, 0.3), (70, 0.9)])
def test_chosen_spirals_are_the_shortest_whose_peak_jerk_meets_the_limit(speed, jerk, shape):
    a = Alignment.from_pis(PIS, [450, 400, 600], units="m", design_speed=speed, max_jerk=jerk, shape=shape)
    v = speed / 3.6
    low, high = a.criteria.shifts("m")
    for curve, check in zip(a.curves, a.checks):
        assert check.ok, check.violations
        for spiral in (curve.entry.spirals[0], curve.exit.spirals[0]):
            peak = dense_peak_jerk(spiral, v)
            assert peak <= jerk * (1 + 1e-9)
        binding_jerk = math.isclose(check.peak_rates[0], jerk, rel_tol=1e-6)
        binding_shift = math.isclose(check.shifts[0], low, rel_tol=1e-6)
        assert binding_jerk or binding_shift  # the shortest spiral sits on one of its lower bounds
        shorter = curve.theta_in * (1 - 1e-4)
        spiral = sc.BezierSpiral((0, 0), (1, 0), shorter, 1 / curve.radius, shape=shape)
        peak, length = peak_curvature_rate(spiral.control_points)[0], spiral.length
        (row,) = a.criteria.evaluate([curve.index], [curve.radius], [[shorter, shorter]], "m", [check.length_bounds],
                                     [[length, length]], [[peak, peak]], shape)  # fmt: skip
        assert row.violations  # any shorter spiral breaks a criterion


def test_the_bezier_spiral_needs_more_length_than_the_clothoid_rule():
    r, v, c = 1000.0, 100 / 3.6, 0.6
    criteria = RoadCriteria(100, c, shift_min=0.0)
    a = Alignment.from_pis([[0, 0], [1000, 0], [2000, 600]], r, units="m", criteria=criteria, shape="walton-meek")
    clothoid = v**3 / (r * c)
    ratio = a.curves[0].spiral_in_length / clothoid
    assert 1.7 < ratio < 1.85  # small θ: the peak dκ/ds is ~1.84× the mean
    near = Alignment.from_pis([[0, 0], [1000, 0], [2000, 600]], r, units="m", criteria=criteria)
    assert 1.0 < near.curves[0].spiral_in_length / clothoid < 1.002  # the near-linear spiral: the clothoid's length


def test_conflicting_criteria_name_the_pi_and_the_numbers():
    with pytest.raises(NoSolutionError, match=r"PI 1: the criteria conflict at R = 450 m: .* at least 136\.\d+ m .* at most 130\.\d+ m"):
        Alignment.from_pis(PIS, [450, 400, 600], units="m", design_speed=100, shape="walton-meek")
    assert all(check.ok for check in Alignment.from_pis(PIS, [450, 400, 600], units="m", design_speed=100).checks)
    with pytest.raises(NoSolutionError, match=r"PI 1: the shortest spirals that meet the criteria turn 2 × .* deflection is only"):
        Alignment.from_pis([[0, 0], [1000, 0], [2000, 30]], 3000, units="m", design_speed=80)


def test_given_spirals_are_checked_and_violations_listed_or_raised():
    a = Alignment.from_pis(PIS, [450, 400, 600], spiral_angles=0.05, units="m", design_speed=80, shape="walton-meek")
    broken = [c for c in a.checks if not c.ok]
    assert broken and any("peak jerk" in v for v in broken[0].violations)
    with pytest.raises(NoSolutionError, match=r"design criteria violated: PI 1: in: peak jerk"):
        Alignment.from_pis(PIS, [450, 400, 600], spiral_angles=0.05, units="m", design_speed=80, strict=True, shape="walton-meek")
    small = Alignment.from_pis(PIS, [150, 400, 600], spiral_angles=0.1, units="m", design_speed=80)
    assert "R = 150 < R_min = 229.062" in small.checks[0].violations[0]


def test_us_units_take_mph_and_feet():
    feet = [[x / 0.3048 for x in p] for p in PIS]
    a = Alignment.from_pis(feet, [1500, 1400, 2000], units="ft", design_speed=50, max_jerk=0.6)
    v = 50 * 0.44704
    for curve in a.curves:
        assert dense_peak_jerk(curve.entry.spirals[0], v, metres=0.3048) <= 0.6 * (1 + 1e-9)
    assert a.checks[0].minimum_radius == pytest.approx(50**2 / (15 * (0.08 + 0.14)))
    assert "ft" in a.criteria_table() and "mph" in a.criteria_table()


def test_rail_criteria_limit_cant_and_its_rates():
    rail = RailCriteria(160)
    assert rail.minimum_radius("m") == pytest.approx(1.5 * (160 / 3.6) ** 2 / (9.80665 * 0.290))
    a = Alignment.from_pis([[0, 0], [3000, 0], [6000, 900]], 2500, units="m", criteria=rail)
    (check,) = a.checks
    assert check.ok and check.quantity == "peak cant deficiency rate" and check.rate_unit == "mm/s"
    cant = rail.applied_cant(2500, "m")
    v = 160 / 3.6
    length = a.curves[0].spiral_in_length
    assert v * cant / length <= rail.cant_rate_max * (1 + 1e-9)
    assert cant / length <= rail.cant_gradient_max * (1 + 1e-9)
    assert check.peak_rates[0] <= rail.cant_deficiency_rate_max * (1 + 1e-9)
    assert check.banking == pytest.approx(min(1500 * v * v / (9.80665 * 2500), 160))
    with pytest.raises(NoSolutionError, match="PI 1"):
        Alignment.from_pis([[0, 0], [3000, 0], [6000, 900]], 900, units="m", criteria=rail, strict=True)


def test_criteria_tables_and_stations_carry_units_and_the_jerk(tmp_path):
    a = Alignment.from_pis(PIS, [450, 400, 600], units="m", design_speed=80)
    header = a.criteria_to_csv(tmp_path / "c.csv").read_text().splitlines()[0]
    assert "R_min [m]" in header and "peak_lateral_jerk_in [m/s³]" in header and "verdict" in header
    stations = a.to_csv(tmp_path / "s.csv").read_text().splitlines()[0]
    assert "peak_lateral_jerk_out [m/s³]" in stations


@pytest.mark.parametrize(
    "kwargs, message",
    [
        (dict(design_speed=-5), "design_speed must be positive"),
        (dict(design_speed=80, max_jerk=0), "max_jerk must be positive"),
        (dict(max_jerk=0.5), "max_jerk needs a design_speed"),
        (dict(design_speed=80, criteria=RoadCriteria(80)), "not both"),
        (dict(criteria="road"), "criteria must be a RoadCriteria"),
        (dict(design_speed="80"), "design_speed must be a real number"),
    ],
)
def test_bad_criteria_are_refused_by_name(kwargs, message):
    with pytest.raises(ValueError, match=message):
        Alignment.from_pis(PIS, 450, units="m", **kwargs)


def test_unit_spirals_are_theorem_31():
    cps = unit_spirals([0.3, 0.6])
    assert np.allclose(cps[:, 0], 0) and np.allclose(cps[:, 1:3, 1], 0)
