"""Horizontal alignments from PIs: geometry, stationing, dκ/ds, CSV and validation."""

import csv
import math

import numpy as np
import pytest

from spiral_cad import Arc, BezierSpiral, NoSolutionError
from spiral_cad.design import Alignment, curvature_rate, peak_curvature_rate
from spiral_cad.design.alignment import theta_for_length

PIS = np.array([(0.0, 0.0), (1000.0, 0.0), (1600.0, 700.0), (2500.0, 600.0)])
ORIGIN = np.array([6.5e5, 5.4e6])  # survey-sized coordinates


def assert_joins(chain, tol=1e-9):
    for j in chain.joins():
        assert j.gap <= tol * chain.size and j.angle <= tol and j.curvature_jump * chain.size <= tol


def test_symmetric_curves_are_g2_and_honour_theta():
    al = Alignment.from_pis(PIS, [300.0, 400.0], spiral_angles=0.2)
    assert_joins(al.chain)
    assert np.allclose(al.chain.start, PIS[0]) and np.allclose(al.chain.end, PIS[-1])
    for c in al.curves:
        assert c.theta_in == pytest.approx(0.2, rel=1e-12) and c.theta_out == pytest.approx(0.2, rel=1e-12)
        assert c.spiral_in_length == pytest.approx(c.spiral_out_length, rel=1e-12)
        # Total turning: spirals plus arc sweep equal the deflection.
        sweep = c.arc_length / c.radius
        assert c.theta_in + sweep + c.theta_out == pytest.approx(abs(c.deflection), rel=1e-12)
        # Symmetric curve: centre on the bisector, equidistant from both tangents.
        center = np.array(c.center)
        assert np.hypot(*(c.entry.end - center)) == pytest.approx(c.radius, rel=1e-12)


@pytest.mark.parametrize("origin", [np.zeros(2), ORIGIN])
def test_asymmetric_angles(origin):
    # Survey coordinates: the join curvature is only as exact as ε·|x|/(h sin θ)
    # (about 1e-9 relative to the chain size here), so the check is 1e-8 there;
    # Chain itself allows for that rounding floor, so it builds at its default.
    tol = 1e-9 if origin[0] == 0 else 1e-8
    al = Alignment.from_pis(PIS + origin, [300.0, 400.0], spiral_angles=[(0.15, 0.35), (0.3, 0.1)])
    assert_joins(al.chain, tol)
    got = [(c.theta_in, c.theta_out) for c in al.curves]
    assert np.allclose(got, [(0.15, 0.35), (0.3, 0.1)], rtol=1e-9, atol=0)
    assert al.curves[0].spiral_in_length < al.curves[0].spiral_out_length
    for c in al.curves:
        assert abs(c.entry.spirals[0].end_curvature) == pytest.approx(1 / c.radius, rel=1e-9)


def test_spiral_length_spec_is_honoured():
    lengths = [(80.0, 120.0), 100.0]
    al = Alignment.from_pis(PIS, [300.0, 400.0], spiral_lengths=lengths)
    assert_joins(al.chain)
    assert al.curves[0].spiral_in_length == pytest.approx(80.0, rel=1e-9)
    assert al.curves[0].spiral_out_length == pytest.approx(120.0, rel=1e-9)
    assert al.curves[1].spiral_in_length == pytest.approx(100.0, rel=1e-9)
    assert al.curves[1].spiral_out_length == pytest.approx(100.0, rel=1e-9)


def test_theta_for_length_round_trip():
    for theta in (0.01, 0.3, 1.2):
        length = BezierSpiral((0, 0), (1, 0), theta, 1 / 250.0).length
        assert theta_for_length(length, 250.0) == pytest.approx(theta, rel=1e-12)
    with pytest.raises(NoSolutionError, match="outside the range"):
        theta_for_length(1e-12, 250.0)


def test_stationing_is_monotone_and_consistent():
    al = Alignment.from_pis(PIS, [300.0, 400.0], spiral_lengths=90.0, start_station=1000.0)
    keys = [k for c in al.curves for k in (c.ts, c.sc, c.cs, c.st)]
    assert all(a < b for a, b in zip(keys, keys[1:]))
    assert al.start_station < keys[0] and keys[-1] < al.end_station
    assert al.end_station - al.start_station == pytest.approx(al.chain.length, rel=1e-15)
    for c in al.curves:
        assert c.sc - c.ts == pytest.approx(c.spiral_in_length, rel=1e-12)
        assert c.st - c.cs == pytest.approx(c.spiral_out_length, rel=1e-12)
        # Chainages locate the key points on the chain.
        for station, point in ((c.ts, c.entry.start), (c.sc, c.entry.end), (c.cs, c.exit.start), (c.st, c.exit.end)):
            assert np.allclose(al.chain.point_at(station - al.start_station), point, atol=1e-9 * al.chain.size)
    # Arcs in the chain have the tabled lengths.
    arcs = [s for s in al.chain.segments if isinstance(s, Arc)]
    assert [a.length for a in arcs] == pytest.approx([c.arc_length for c in al.curves], rel=1e-9)


def test_csv_round_trip_with_units_in_the_headers(tmp_path):
    al = Alignment.from_pis(PIS, [300.0, 400.0], spiral_angles=[(0.15, 0.35), 0.25], units="ft")
    path = al.to_csv(tmp_path / "stations.csv")
    with path.open() as f:
        rows = list(csv.DictReader(f))
    assert len(rows) == 2
    assert {"radius [ft]", "TS [ft]", "peak_dk_ds_in [1/ft²]", "theta_in [deg]"} <= set(rows[0])
    for row, curve in zip(rows, al.curves):
        assert int(row["pi"]) == curve.index
        assert float(row["TS [ft]"]) == curve.ts and float(row["ST [ft]"]) == curve.st
        assert float(row["theta_in [deg]"]) == pytest.approx(math.degrees(curve.theta_in))
    text = al.table()
    assert "TS [ft]" in text and "peak_dk_ds_in [1/ft²]" in text and len(text.splitlines()) == 4


def test_curvature_rate_matches_finite_differences():
    spiral = BezierSpiral((0, 0), (1, 0), 0.6, 0.02)
    u, h = 0.37, 1e-6
    dk = (spiral.curvature(u + h) - spiral.curvature(u - h)) / (2 * h)
    ds = np.linalg.norm(spiral.point(u + h) - spiral.point(u - h)) / 1.0
    assert curvature_rate(spiral.control_points, u) == pytest.approx(dk * 2 * h / ds, rel=1e-6)


@pytest.mark.parametrize("theta", [0.1, 0.6, 1.0])
def test_peak_rate_exceeds_mean_and_matches_sampling(theta):
    al = Alignment.from_pis(PIS, 300.0, spiral_angles=theta * 0.4)
    for c in al.curves:
        mean = 1.0 / (c.radius * c.spiral_in_length)
        assert c.peak_rate_in >= mean  # curvature is not linear in arc length
        s = np.linspace(c.ts, c.sc, 4001)
        k = al.chain.curvature_at(s - al.start_station)
        fd = np.abs(np.gradient(k, s)).max()
        assert c.peak_rate_in == pytest.approx(fd, rel=2e-3)
    # Reversed spiral (exit) has the same peak magnitude.
    spiral = al.curves[0].entry.spirals[0]
    assert peak_curvature_rate(spiral.reversed().control_points)[0] == pytest.approx(
        peak_curvature_rate(spiral.control_points)[0], rel=1e-9
    )


def test_small_angle_peak_is_about_1_84_times_mean():
    al = Alignment.from_pis(PIS, 300.0, spiral_angles=0.02, shape="walton-meek")
    c = al.curves[0]
    assert al.shape == c.shape == "walton-meek"
    assert c.peak_rate_in * c.radius * c.spiral_in_length == pytest.approx(1.84, abs=0.02)


def test_near_linear_alignments_by_default_peak_at_their_mean():
    al = Alignment.from_pis(PIS, 300.0, spiral_angles=0.02)
    c = al.curves[0]
    assert al.shape == c.shape == c.entry.spirals[0].shape == "near-linear"
    assert c.peak_rate_in * c.radius * c.spiral_in_length == pytest.approx(1.0, abs=0.002)
    assert al.rows()[0]["spiral_shape"] == "near-linear"


# ------------------------------------------------------------ validation


def test_deflection_too_small_names_pi():
    with pytest.raises(NoSolutionError, match=r"PI 1: deflection 49\.\d+° is smaller than θ_in \+ θ_out"):
        Alignment.from_pis(PIS, [300.0, 400.0], spiral_angles=[(0.5, 0.5), 0.1])


def test_overlapping_curves_name_both_pis():
    with pytest.raises(NoSolutionError, match=r"curves at PI 1 and PI 2 overlap .* tangent length"):
        Alignment.from_pis(PIS, [900.0, 900.0], spiral_angles=0.2)


def test_curve_beyond_start_point():
    with pytest.raises(NoSolutionError, match="TS of PI 1 .* beyond the start point PI 0"):
        Alignment.from_pis([(900, 0), (1000, 0), (1600, 700), (2500, 600)], 300.0, spiral_angles=0.2)


@pytest.mark.parametrize(
    ("points", "radii", "pattern"),
    [
        (PIS, [300.0, -1.0], r"PI 2: radius must be positive; got -1\.0"),
        (PIS, [300.0, 0.0], r"PI 2: radius must be positive"),
        ([(0, 0), (1000, 0), (2000, 0), (2500, 600)], 300.0, r"PI 1 .* collinear"),
        ([(0, 0), (1000, 0), (1000, 0), (2500, 600)], 300.0, r"PI 1 and PI 2 coincide"),
        ([(0, 0), (1000, 0)], 300.0, "at least 3 PIs"),
    ],
)
def test_malformed_input_names_pi(points, radii, pattern):
    with pytest.raises(ValueError, match=pattern):
        Alignment.from_pis(points, radii, spiral_angles=0.1)


def test_spec_errors():
    with pytest.raises(ValueError, match="give spiral_angles or spiral_lengths, or design criteria"):
        Alignment.from_pis(PIS, 300.0)
    with pytest.raises(ValueError, match="at most one of spiral_angles and spiral_lengths"):
        Alignment.from_pis(PIS, 300.0, spiral_angles=0.1, spiral_lengths=50.0)
    with pytest.raises(ValueError, match=r"PI 2: exit spiral angle must lie in \(0, π/2\)"):
        Alignment.from_pis(PIS, 300.0, spiral_angles=[0.1, (0.1, 2.0)])
    with pytest.raises(ValueError, match="PI 1: entry spiral length must be positive"):
        Alignment.from_pis(PIS, 300.0, spiral_lengths=[(-5.0, 10.0), 10.0])


@pytest.mark.parametrize("shape", ["near-linear", "walton-meek"])
@pytest.mark.parametrize("origin", [np.zeros(2), ORIGIN])
def test_batch_built_curves_equal_the_scalar_solvers_bit_for_bit(shape, origin):
    """Every PI is solved in one batch call per side; each curve is the scalar solution, exactly."""
    from spiral_cad import line_to_circle

    al = Alignment.from_pis(PIS + origin, [300.0, 400.0], spiral_angles=[(0.15, 0.35), (0.3, 0.1)], shape=shape)
    for c in al.curves:
        pi, center = np.array(c.pi), np.array(c.center)
        t_in, t_out = (np.asarray(line.direction) for line in (c.entry.start_line, c.exit.end_line))
        entry = line_to_circle(pi, t_in, center, c.radius, shape=shape)
        exit_ = line_to_circle(pi, -t_out, center, c.radius, shape=shape).reversed()
        assert np.array_equal(c.entry.spirals[0].control_points, entry.spirals[0].control_points)
        assert np.array_equal(c.exit.spirals[0].control_points, exit_.spirals[0].control_points)
        assert (c.entry.theta, c.exit.theta, c.entry.end_circle, c.exit.start_circle) == (
            entry.theta,
            exit_.theta,
            entry.end_circle,
            exit_.start_circle,
        )
        assert c.entry.spirals[0] is al.chain[al.chain.segments.index(c.entry.spirals[0])]  # the chain's own segments


def test_curves_are_a_sequence_made_when_read():
    al = Alignment.from_pis(PIS, [300.0, 400.0], spiral_angles=0.2)
    curves = al.curves
    assert len(curves) == 2 and curves[-1].index == 2 and [c.index for c in curves[:1]] == [1]
    assert curves[0] is curves[0] and list(curves) == [curves[0], curves[1]] and curves == list(curves)
    assert curves.lengths.shape == curves.thetas.shape == curves.peak_rates.shape == (2, 2)
    with pytest.raises(IndexError):
        curves[2]


@pytest.mark.parametrize("shape", ["near-linear", "walton-meek"])
def test_many_lengths_to_angles_at_once(shape):
    from spiral_cad.design.alignment import thetas_for_lengths

    thetas = np.array([1e-6, 0.01, 0.2, 0.6, 0.85] + ([1.3] if shape == "walton-meek" else []))
    lengths = np.array([BezierSpiral((0, 0), (1, 0), t, 1 / 250.0, shape=shape).length for t in thetas])
    found = thetas_for_lengths(lengths, 250.0, shape)
    assert np.allclose(found, thetas, rtol=1e-12, atol=0)
    assert all(theta_for_length(length, 250.0, shape) == pytest.approx(t, rel=1e-12) for length, t in zip(lengths, thetas))
    assert np.isnan(thetas_for_lengths([1e-12, -1.0, np.inf], 250.0, shape)).all()


def test_the_first_failing_pi_is_named_whatever_the_check():
    """Checks run over all PIs at once; the error is the one the first failing PI raises."""
    pis = [(0, 0), (1000, 0), (1600, 700), (2200, 700.0), (2800, 700), (3400, 900)]
    with pytest.raises(ValueError, match=r"PI 3 at \[2200\.0, 700\.0\] .* collinear"):
        Alignment.from_pis(pis, 300.0, spiral_angles=[0.1, 0.1, 0.1, 3.0])  # PI 4's bad angle comes later
    with pytest.raises(ValueError, match=r"PI 2: exit spiral angle"):
        Alignment.from_pis(PIS, 300.0, spiral_angles=[(0.1, 0.1), (0.1, 2.0)])
    with pytest.raises(NoSolutionError, match=r"PI 1: deflection .* smaller than θ_in \+ θ_out"):
        Alignment.from_pis(PIS, 300.0, spiral_angles=[(0.9, 0.9), (0.1, 2.0)])
