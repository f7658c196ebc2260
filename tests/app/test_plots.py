"""Plots: artists, saved PNGs, and that plotted data is the chain's own."""

import math

import numpy as np
import pytest
from matplotlib.figure import Figure

from spiral_cad import BezierSpiral
from spiral_cad.app import plots
from spiral_cad.design import Alignment, round_corners

PNG = b"\x89PNG\r\n\x1a\n"


@pytest.fixture(scope="module")
def chain():
    pts = [(0.0, 0.0), (1000.0, 0.0), (1600.0, 700.0), (2500.0, 600.0)]
    return Alignment.from_pis(pts, [300.0, 400.0], spiral_angles=[(0.2, 0.3), 0.25]).chain


def saved(fig, tmp_path, name):
    path = tmp_path / name
    fig.savefig(path)
    return path.read_bytes()[:8] == PNG


def collections(ax, prefix):
    return [c for c in ax.collections if (c.get_gid() or "").startswith(prefix)]


def test_plan_with_comb(chain, tmp_path):
    fig = plots.plot_plan(chain)
    assert isinstance(fig, Figure)
    ax = fig.axes[0]
    kinds = {type(s).__name__ for s in chain}
    for prefix in ("plan-", "comb-", "envelope-"):
        assert {c.get_gid()[len(prefix) :] for c in collections(ax, prefix)} == kinds
    # every segment drawn once, on its own polyline, through the segment's points
    drawn = sum(len(c.get_segments()) for c in collections(ax, "plan-"))
    assert drawn == len(chain)
    (spirals,) = collections(ax, "plan-BezierSpiral")
    first = next(s for s in chain if isinstance(s, BezierSpiral))
    assert np.allclose(spirals.get_segments()[0][[0, -1]], [first.start, first.end])
    assert saved(fig, tmp_path, "plan.png")


def test_plan_without_comb_on_given_axes(chain):
    fig = Figure()
    ax = fig.add_subplot()
    assert plots.plot_plan(chain, comb=False, ax=ax) is fig
    assert not collections(ax, "comb-") and sum(len(c.get_segments()) for c in collections(ax, "plan-")) == len(chain)


def test_comb_matches_chain_curvature(chain):
    comb = plots.comb_samples(chain, per_segment=16)
    inside = (comb.stations > 0) & (comb.stations < chain.length)
    assert np.allclose(comb.curvature[inside], chain.curvature_at(comb.stations[inside]), rtol=1e-9, atol=1e-12)
    assert np.allclose(comb.points[inside], chain.point_at(comb.stations[inside]), atol=1e-6)
    teeth = np.hypot(*(comb.tips - comb.points).T)
    assert np.allclose(teeth, comb.scale * np.abs(comb.curvature), rtol=1e-12, atol=1e-9)
    # Teeth stand on the convex side: opposite the left normal for a left turn.
    left = comb.curvature > 0
    assert np.all(np.einsum("ij,ij->i", comb.tips[left] - comb.points[left], comb.normals[left]) < 0)


def test_curvature_plot_data(chain, tmp_path):
    fig = plots.plot_curvature(chain)
    profiles = [p for c in collections(fig.axes[0], "curvature-") for p in c.get_segments()]
    assert len(profiles) == len(chain)
    for profile in profiles:
        s, k = profile[:, 0], profile[:, 1]
        inner = (s > 0) & (s < chain.length)
        assert np.allclose(k[inner], chain.curvature_at(s[inner]), rtol=1e-9, atol=1e-12)
    assert saved(fig, tmp_path, "curvature.png")


def test_fig6(tmp_path):
    fig = plots.plot_fig6()
    lines = fig.axes[0].lines
    assert len(lines) == 9  # θ = 10°…80° and the clothoid
    ends = {(round(l.get_xdata()[-1], 12), round(l.get_ydata()[-1], 12)) for l in lines}
    assert len(ends) == 1  # all normalised to the same length and unit end curvature
    assert [l.get_ydata()[0] for l in lines] == [0.0] * 9
    assert saved(fig, tmp_path, "fig6.png")


def test_fig6_of_both_shapes(tmp_path):
    fig = plots.plot_fig6_shapes()
    left, right = fig.axes
    assert len(left.lines) == 9 and len(right.lines) == 6  # the near-linear family ends at 50°
    clothoid = right.lines[-1]
    for line in right.lines[:-1]:  # every near-linear profile stays close to the clothoid's straight line
        s, k = line.get_xdata(), line.get_ydata()
        assert np.max(np.abs(k - s / clothoid.get_xdata()[-1])) < 0.1
    assert saved(fig, tmp_path, "fig6_shapes.png")


def test_vs_clothoid(tmp_path):
    theta, k = math.radians(30.0), 0.01
    fig = plots.plot_vs_clothoid(theta, k)
    left, right = fig.axes
    bez, clo = left.lines
    assert clo.get_xdata()[-1] == pytest.approx(2 * theta / k)
    assert np.allclose(np.diff(clo.get_ydata(), 2), 0.0, atol=1e-15)  # linear
    assert bez.get_xdata()[-1] == pytest.approx(BezierSpiral((0, 0), (1, 0), theta, k).length)
    assert len(right.lines) == 5  # two curves, two end circles, the axis line
    assert saved(fig, tmp_path, "vs_clothoid.png")


def test_clothoid_points_turn_and_length():
    theta, k = 0.5, 0.2
    length = 2 * theta / k
    s = np.linspace(0, length, 20001)
    xy = plots.clothoid_points(theta, k, s)
    step = np.diff(xy, axis=0)
    assert np.hypot(*step.T).sum() == pytest.approx(length, rel=1e-6)
    end = step[-1] / np.hypot(*step[-1])
    assert math.atan2(end[1], end[0]) == pytest.approx(theta, abs=1e-3)
    assert np.allclose(plots.clothoid_points(-theta, -k, s)[:, 1], -xy[:, 1])


def test_rounded_path_plots(tmp_path):
    path = round_corners([(0, 0), (2, 0), (3, 1), (5, 1)], shape="g2cbs")
    fig = plots.plot_plan(path.chain)
    assert saved(fig, tmp_path, "rounded.png")


def test_jerk_length_plot_compares_both_shapes_with_the_clothoid(tmp_path):
    fig = plots.plot_jerk_length(shapes=("walton-meek", "near-linear"))
    left, right = fig.axes
    walton_meek, near_linear = (line.get_ydata() for line in left.lines[:2])
    assert walton_meek[0] == pytest.approx(1.84, abs=0.01) and near_linear[0] == pytest.approx(1.0, abs=0.001)
    wm_length, nl_length, clothoid = (line.get_ydata() for line in right.lines)
    highway = right.lines[0].get_xdata() >= 300.0  # radii of an 80 km/h road (R_min = 229 m): small spiral angles
    assert np.all(nl_length < wm_length) and np.all(np.abs(nl_length / clothoid - 1)[highway] < 0.02)
    assert saved(fig, tmp_path, "jerk_shapes.png")


def test_jerk_length_plot_shows_the_bezier_needs_more_length(tmp_path):
    fig = plots.plot_jerk_length()
    left, right = fig.axes
    ratio = left.lines[0].get_ydata()
    assert ratio[0] == pytest.approx(1.84, abs=0.01) and ratio.min() > 1.2  # always longer than the clothoid rule
    bezier, clothoid = right.lines
    assert np.all(bezier.get_ydata() > clothoid.get_ydata())
    assert saved(fig, tmp_path, "jerk.png")


def test_chains_in_space_plot_as_a_plan_projection_and_a_curvature_magnitude(tmp_path):
    path = round_corners([(0, 0, 0), (1, 0, 0), (1, 1, 1), (2, 1, 2)], max_curvature=5.0)
    chain = path.chain
    assert chain.dim == 3
    comb = plots.comb_samples(chain, per_segment=16)
    inside = (comb.stations > 0) & (comb.stations < chain.length)
    assert np.allclose(comb.curvature[inside], chain.curvature_at(comb.stations[inside]), rtol=1e-9, atol=1e-12)
    vectors = chain.curvature_vector_at(comb.stations[inside])
    teeth = (comb.tips - comb.points)[inside]
    bent = comb.curvature[inside] > 1e-9
    assert np.all(np.einsum("ij,ij->i", teeth[bent], vectors[bent]) < 0)  # against κN: on the convex side
    assert np.allclose(np.linalg.norm(teeth, axis=1), comb.scale * comb.curvature[inside], rtol=1e-9, atol=1e-12)
    fig = plots.plot_plan(chain)
    assert "projected onto XY" in fig.axes[0].get_title() and saved(fig, tmp_path, "plan3d.png")
    fig = plots.plot_curvature(chain)
    assert "|κ|" in fig.axes[0].get_ylabel() and saved(fig, tmp_path, "curvature3d.png")


def test_axes_in_a_subfigure_give_back_the_savable_root_figure(chain, tmp_path):
    root = Figure()
    left, right = root.subfigures(1, 2)
    fig = plots.plot_plan(chain, comb=False, ax=left.add_subplot())
    assert fig is root and saved(fig, tmp_path, "plan.png")
    pair = plots.plot_vs_clothoid(0.3, 0.01, ax=right.subplots(1, 2))
    assert pair is root and saved(pair, tmp_path, "pair.png")


def test_the_old_name_of_comb_samples_works_for_one_release_with_a_warning():
    with pytest.warns(
        DeprecationWarning, match="spiral_cad.app.plots.curvature_comb is now comb_samples; the old name goes in the next release"
    ):
        old = plots.curvature_comb
    assert old is plots.comb_samples
    with pytest.raises(AttributeError, match="has no attribute 'nothing'"):
        plots.nothing  # noqa: B018
