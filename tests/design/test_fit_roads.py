"""Roads from points: Alignment.fit recovers a designed alignment's curves from its sampled centre
line (noise-free and GPS-like noise), Profile.fit keeps every elevation within its tolerance with
parabolic curves, and a 3-D survey gives plan and profile on shared stations."""

from __future__ import annotations

import numpy as np
import pytest

from spiral_cad import NoSolutionError
from spiral_cad.core.fit import chain_distances
from spiral_cad.design import Alignment, Profile, fit_survey

PIS = [(0.0, 0.0), (400.0, 0.0), (700.0, 300.0), (1100.0, 250.0)]


@pytest.fixture(scope="module")
def designed() -> Alignment:
    return Alignment.from_pis(PIS, radii=[300.0, 250.0], spiral_lengths=60.0, units="m")


@pytest.mark.parametrize("noise", [0.0, 0.0025])
def test_alignment_fit_recovers_the_curves(designed, noise):
    points = designed.chain.point_at(np.linspace(0.0, designed.chain.length, 1500))
    points = points + np.random.default_rng(5).normal(0.0, noise, points.shape)
    fitted = Alignment.fit(points, 0.05, design_speed=80, units="m")
    assert len(fitted.chain) == len(designed.chain) == 9
    assert [c.radius for c in fitted.curves] == pytest.approx([300.0, 250.0], rel=2e-3)
    assert chain_distances(fitted.chain, points)[0].max() <= 0.05
    # The road criteria judge every fitted curve (a verdict per curve).
    assert len(fitted.checks) == 2 and "80 km/h" in fitted.criteria_table()
    # The PointFit it was read from: the point-wise curvature estimate, 1/300 in the first arc's middle.
    estimate = fitted.point_fit.curvature_estimate
    assert estimate.shape == (1500,)
    middle = designed.chain.stations[2] + designed.chain[2].length / 2
    assert estimate[np.argmin(np.abs(fitted.point_fit.stations - middle))] == pytest.approx(1 / 300, rel=0.05)


def test_alignment_fit_refuses_points_without_curves():
    x = np.linspace(0.0, 100.0, 50)
    with pytest.raises(NoSolutionError, match="one straight line"):
        Alignment.fit(np.c_[x, 0.2 * x], 0.01, units="m")


@pytest.mark.parametrize("noise", [0.0, 0.002])
def test_profile_fit_stays_within_tolerance(noise):
    designed = Profile.from_pvis([(0, 100), (400, 110), (900, 95), (1200, 100)], curve_lengths=[200, 250], units="m")
    stations = np.linspace(0.0, 1200.0, 1200)
    elevations = designed.elevation(stations) + np.random.default_rng(6).normal(0.0, noise, stations.shape)
    fitted = Profile.fit(stations, elevations, 0.05, units="m")
    assert np.abs(fitted.elevation(stations) - elevations).max() <= 0.05
    assert fitted.pvis[0, 0] == 0.0 and fitted.pvis[-1, 0] == 1200.0
    # C1 by its own pieces: the grade is continuous at every piece boundary.
    inner = fitted.stations[1:-1]
    assert np.allclose(fitted.grade(inner - 1e-7), fitted.grade(inner + 1e-7), atol=1e-6)


def test_profile_fit_refuses_malformed_input():
    with pytest.raises(ValueError, match="same length"):
        Profile.fit([0, 1, 2], [1, 2], 0.1)
    with pytest.raises(ValueError, match="not finite"):
        Profile.fit([0, 1, 2], [1, np.nan, 2], 0.1)
    with pytest.raises(ValueError, match="tolerance"):
        Profile.fit([0, 1, 2], [1, 2, 3], 0.0)


def test_a_survey_gives_plan_and_profile_on_shared_stations(designed):
    stations = np.linspace(0.0, designed.chain.length, 1500)
    profile = Profile.from_pvis([(0, 50), (600, 56), (designed.chain.length, 52)], curve_lengths=[300], units="m")
    xyz = np.c_[designed.chain.point_at(stations), profile.elevation(stations)]
    survey = fit_survey(xyz, 0.05, units="m")
    assert survey.plan_residuals.max() <= 0.05 and survey.vertical_residuals.max() <= 0.05
    assert np.allclose(survey.stations, stations, atol=1e-3)
    assert len(survey.alignment.chain) == 9
    with pytest.raises(ValueError, match=r"\(N, 3\)"):
        fit_survey(xyz[:, :2], 0.05)


@pytest.mark.parametrize(
    "pvis, lengths",
    [
        ([(0, 100), (300, 112), (600, 100)], [250]),  # one crest
        ([(0, 100), (400, 110), (900, 95), (1200, 100)], [200, 250]),
        ([(0, 50), (200, 56), (500, 50), (800, 62), (1000, 60)], [150, 200, 180]),
        ([(0, 50), (200, 56), (500, 50), (800, 62), (1000, 60)], [200, 400, 180]),  # two curves meet with no grade between
    ],
)
def test_profile_fit_returns_the_designed_pvis(pvis, lengths):
    """Noise-free samples of a designed profile: its grade change rate is zero on grades and constant on
    curves, so the fit returns the designed PVIs and curves, not a polyline's corners."""
    designed = Profile.from_pvis(pvis, curve_lengths=lengths, units="m")
    stations = np.linspace(0.0, pvis[-1][0], 801)
    fitted = Profile.fit(stations, designed.elevation(stations), 0.01, units="m")
    assert len(fitted.pvis) == len(pvis)
    np.testing.assert_allclose(fitted.pvis, np.array(pvis, dtype=float), atol=1e-6)
    dense = np.linspace(0.0, pvis[-1][0], 5001)
    assert np.abs(fitted.elevation(dense) - designed.elevation(dense)).max() <= 1e-6
