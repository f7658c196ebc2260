"""One exact rational cubic B-spline per chain: structure, exactness, OCCT agreement."""

import math
import subprocess
import sys

import numpy as np
import pytest
from helpers import transition_chains
from scipy.interpolate import BSpline

from spiral_cad import Arc, Chain, Line
from spiral_cad.core.nurbs import Nurbs, chain_to_nurbs

CHAINS = transition_chains()


def span_deviation(seg, pts: np.ndarray, u: np.ndarray) -> float:
    """Largest distance of span points from ``seg`` (arcs: off the circle or outside the arc)."""
    if isinstance(seg, Arc):
        rel = pts - seg.center
        off_circle = np.abs(np.hypot(rel[:, 0], rel[:, 1]) - abs(seg.radius))
        travelled = (math.copysign(1.0, seg.radius) * (np.arctan2(rel[:, 1], rel[:, 0]) - seg.start_angle)) % (2 * math.pi)
        travelled[travelled > seg.sweep + 0.5 * (2 * math.pi - seg.sweep)] -= 2 * math.pi  # just before the start
        outside = np.maximum(0.0, np.maximum(-travelled, travelled - seg.sweep)) * abs(seg.radius)
        return float(np.max(off_circle + outside))
    # lines (control points at thirds) and spirals keep the segment's own parameter on their span
    return float(np.abs(pts - seg.point(u)).max())


@pytest.mark.parametrize("name", sorted(CHAINS))
def test_nurbs_reproduces_the_chain_exactly(name):
    chain = CHAINS[name]
    nurbs = chain.to_nurbs()
    tol = 1e-12 * chain.size
    assert nurbs.degree == 3
    assert len(nurbs.segment_index) == len(nurbs.knots) - 1
    u = np.linspace(0.0, 1.0, 201)
    for i, index in enumerate(nurbs.segment_index):
        t = nurbs.knots[i] + u * (nurbs.knots[i + 1] - nurbs.knots[i])
        assert span_deviation(chain[index], nurbs.point(t), u) <= tol
    # every segment is covered from its start to its end, in travel order
    for index, seg in enumerate(chain):
        spans = [i for i, owner in enumerate(nurbs.segment_index) if owner == index]
        assert spans == list(range(spans[0], spans[-1] + 1))
        ends = nurbs.point(np.array([nurbs.knots[spans[0]], nurbs.knots[spans[-1] + 1]]))
        assert np.abs(ends - [seg.start, seg.end]).max() <= tol


def test_structure_of_the_spline():
    chain = CHAINS["mixed"]
    nurbs = chain_to_nurbs(chain)
    arcs = [s for s in chain if isinstance(s, Arc)]
    expected_spans = len(chain) - len(arcs) + sum(math.ceil(a.sweep / (math.pi / 2)) for a in arcs)
    assert len(nurbs.knots) == expected_spans + 1
    assert nurbs.multiplicities.tolist() == [4] + [3] * (expected_spans - 1) + [4]
    assert len(nurbs.knot_vector) == len(nurbs.control_points) + nurbs.degree + 1
    assert np.all(np.diff(nurbs.knots) > 0) and np.all(nurbs.weights > 0)
    assert nurbs.knots[-1] == pytest.approx(chain.length, rel=1e-12)
    # piece weights: arcs carry cos-based interior weights, everything else is polynomial
    assert np.any(nurbs.weights < 1.0)
    assert nurbs.weights.min() >= (1 + 2 * math.cos(math.pi / 4)) / 3 - 1e-15


@pytest.mark.parametrize("name", ["mixed", "nested", "line-line"])
def test_point_matches_an_independent_b_spline_evaluation(name):
    nurbs = CHAINS[name].to_nurbs()
    w = nurbs.weights
    numerator = BSpline(nurbs.knot_vector, nurbs.control_points * w[:, None], 3)
    denominator = BSpline(nurbs.knot_vector, w, 3)
    t = np.linspace(*nurbs.domain, 1001)
    expected = numerator(t) / denominator(t)[:, None]
    assert np.abs(nurbs.point(t) - expected).max() <= 1e-12 * CHAINS[name].size


@pytest.mark.parametrize("name", sorted(CHAINS))
def test_occt_edge_evaluates_to_the_same_points(name):
    pytest.importorskip("OCP")
    from OCP.BRepAdaptor import BRepAdaptor_Curve
    from OCP.GeomAbs import GeomAbs_CurveType

    from spiral_cad.cad.occ import nurbs_edge

    chain = CHAINS[name]
    nurbs = chain.to_nurbs()
    curve = BRepAdaptor_Curve(nurbs_edge(nurbs))
    assert curve.GetType() == GeomAbs_CurveType.GeomAbs_BSplineCurve
    assert curve.Degree() == 3 and curve.IsRational() == bool(np.any(nurbs.weights != 1.0))
    t = np.linspace(*nurbs.domain, 997)
    got = np.array([[p.X(), p.Y(), p.Z()] for p in map(curve.Value, t)])
    assert np.abs(got[:, :2] - nurbs.point(t)).max() <= 1e-12 * chain.size
    assert np.abs(got[:, 2]).max() == 0.0


def test_scalar_and_array_parameters_and_range_check():
    nurbs = Chain([Line((0, 0), (3, 4))]).to_nurbs()
    assert nurbs.point(2.5).shape == (2,)
    assert np.allclose(nurbs.point(2.5), (1.5, 2.0), atol=1e-15)
    assert nurbs.point(np.zeros((2, 3))).shape == (2, 3, 2)
    with pytest.raises(ValueError, match=r"\[0.0, 5.0\]"):
        nurbs.point(5.5)


def test_invalid_nurbs_and_chains_are_rejected():
    with pytest.raises(ValueError, match="control points"):
        Nurbs(3, np.array([0.0, 1.0]), np.array([4, 4]), np.ones(3), np.zeros((3, 2)))
    with pytest.raises(ValueError, match="distinct"):
        Nurbs(3, np.array([0.0, 0.0]), np.array([4, 4]), np.ones(4), np.zeros((4, 2)))
    with pytest.raises(ValueError, match="sweep"):  # a zero-length piece cannot even be made
        chain_to_nurbs([Arc((0, 0), 1.0, 0.0, 0.0)])
    with pytest.raises(ValueError, match="at least one"):
        chain_to_nurbs([])


def test_module_is_pure_numpy():
    code = "import sys, spiral_cad.core.nurbs, spiral_cad; sys.exit('OCP' in sys.modules or 'build123d' in sys.modules)"
    assert subprocess.run([sys.executable, "-c", code]).returncode == 0
