"""Circle chains: C, S and nested transitions joined by arcs, and the overlap check."""

import math

import numpy as np
import pytest

from spiral_cad import Arc, Circle, NoSolutionError
from spiral_cad.design import circle_chain
from spiral_cad.design.circles import belt_contacts

R1, R2 = 4.0, 1.6
C1 = np.array([12.0, 0.0])
C2 = C1 + 0.993 * (R1 - R2) * np.array([math.cos(0.524), math.sin(0.524)])  # inside circle 1
CIRCLES = [((0.0, 0.0), 3.0), (tuple(C1), R1), (tuple(C2), R2), (tuple(C2 + (8.0, 2.4)), -2.0)]


def test_c_nested_and_s_in_one_chain():
    result = circle_chain(CIRCLES)
    assert [t.kind for t in result.transitions] == ["C", "circle-circle-nested", "S"]
    chain = result.chain
    for j in chain.joins():
        assert j.gap <= 1e-9 * chain.size and j.angle <= 1e-9 and j.curvature_jump * chain.size <= 1e-9
    # Each intermediate circle contributes one arc on that circle with the reported sweep.
    arcs = [s for s in chain.segments if isinstance(s, Arc)]
    assert len(arcs) == 2
    for arc, circle, sweep in zip(arcs, result.circles[1:3], result.sweeps):
        assert np.allclose(arc.center, circle.center) and arc.radius == circle.radius
        assert arc.sweep == pytest.approx(sweep, abs=1e-12)
    # The path starts on circle 0 and ends on circle 3.
    assert np.hypot(*(chain.start - (0, 0))) == pytest.approx(3.0)
    assert np.hypot(*(chain.end - CIRCLES[3][0])) == pytest.approx(2.0)


def test_input_forms_agree():
    as_tuples = circle_chain(CIRCLES)
    as_circles = circle_chain([Circle(c, r) for c, r in CIRCLES])
    as_triples = circle_chain([(c[0], c[1], r) for c, r in CIRCLES])
    for other in (as_circles, as_triples):
        assert other.chain.length == as_tuples.chain.length


def test_overlap_on_middle_circle_is_reported():
    # Three equal circles in a row, all counterclockwise: the C from circle 0
    # reaches circle 1 past where the C to circle 2 leaves it.
    with pytest.raises(NoSolutionError, match=r"circle 1: the transition from circle 0 reaches it .* Move circle 0 or circle 2"):
        circle_chain([((0, 0), 1.0), ((5, 0), 1.0), ((10, 0), 1.0)])


def test_overlap_index_is_the_offending_circle():
    # Circle 2 (the nested one) overlaps when circle 3 sits behind the arrival point.
    bad = [*CIRCLES[:3], (tuple(C2 + 8.0 * np.array([math.cos(2.094), math.sin(2.094)])), -2.0)]
    with pytest.raises(NoSolutionError, match=r"^circle 2: .* circle 1 or circle 3"):
        circle_chain(bad)


def test_no_transition_names_both_circles():
    with pytest.raises(NoSolutionError, match=r"^circles 1 and 2: circle_to_circle \(S\)"):
        circle_chain([((0, 0), 1.0), ((5, 0), 1.0), ((6, 0), -1.0)])


def test_malformed():
    with pytest.raises(ValueError, match="at least 2 circles"):
        circle_chain([((0, 0), 1.0)])
    with pytest.raises(ValueError, match="circle 1: radius must be non-zero"):
        circle_chain([((0, 0), 1.0), ((5, 0), 0.0)])


@pytest.mark.parametrize("signs", [(1, 1), (1, -1), (-1, 1), (-1, -1)])
def test_belt_line_is_tangent_in_travel_sense(signs):
    a, b = Circle((0.0, 0.0), signs[0] * 1.5), Circle((6.0, 2.0), signs[1] * 1.0)
    p, q = belt_contacts(a, b)
    t = (q - p) / np.hypot(*(q - p))
    for point, circle in ((p, a), (q, b)):
        radial = point - circle.center
        assert np.hypot(*radial) == pytest.approx(abs(circle.radius))
        assert np.dot(radial, t) == pytest.approx(0.0, abs=1e-12)
        # Centre on the left of travel for a positive radius.
        side = t[0] * (circle.center[1] - point[1]) - t[1] * (circle.center[0] - point[0])
        assert math.copysign(1, side) == math.copysign(1, circle.radius)
