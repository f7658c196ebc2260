"""make_g2 on joints of arcs that turn the same way with nearly equal radii, meeting tangent or nearly
(a spiral cut as arcs, as LinuxCNC's ``arcspiral.ngc``): the C pair between their circles (or the nested
spiral, or a tangent circle) makes each joint G2 within the bound, arcs kept; arcs of one circle are still
merged."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from test_make_g2 import arcs_kept, assert_g2

from spiral_cad import Arc, Line, NoSolutionError
from spiral_cad.design import make_g2


def same_sense_arcs(radii, kinks, sweeps, sense: float = 1.0, heading: float = 0.3) -> list:
    """Arcs of one sense (``sense``: +1 counterclockwise), radii ``radii``, each starting where the last ends
    with its start tangent turned by ``kinks[k - 1]`` (radians, counterclockwise) from the last one's end."""
    arcs = []
    point = np.zeros(2)
    for k, (radius, sweep) in enumerate(zip(radii, sweeps)):
        if k:
            heading += kinks[k - 1]
        centre = point + sense * radius * np.array([-math.sin(heading), math.cos(heading)])
        arc = Arc(tuple(centre), sense * radius, math.atan2(point[1] - centre[1], point[0] - centre[0]), sweep)
        arcs.append(arc)
        point = np.asarray(arc.end, dtype=float)
        heading += sense * sweep
    return arcs


def arcs_of_a_spiral(count: int, first: float, step: float, sweep: float = 0.1) -> list:
    """A spiral cut as ``count`` clockwise arcs by radius, as a CAM program writes it (``arcspiral.ngc``): arc k
    runs between points of r = first − step·k written to 6 decimals, with radius first − step·(k + 1)."""
    points = []
    for k in range(count + 1):
        r = first - step * k
        points.append(np.round([r * math.cos(-k * sweep), r * math.sin(-k * sweep)], 6))
    arcs = []
    for k in range(count):
        a, b, radius = points[k], points[k + 1], first - step * (k + 1)
        chord = b - a
        half = 0.5 * float(np.hypot(*chord))
        # The centre of the short clockwise arc from a to b lies right of the chord, then the arc turns about it.
        right = np.array([chord[1], -chord[0]]) / (2.0 * half)
        centre = a + 0.5 * chord + math.sqrt(radius * radius - half * half) * right
        start = math.atan2(a[1] - centre[1], a[0] - centre[0])
        end = math.atan2(b[1] - centre[1], b[0] - centre[0])
        arcs.append(Arc(tuple(centre), -radius, start, (start - end) % (2 * math.pi)))
    return arcs


@pytest.mark.parametrize("sense", [1.0, -1.0])
@pytest.mark.parametrize("eps", [1e-6, 1e-4, 1e-3, 1e-2, 0.1, 0.3])
@pytest.mark.parametrize("kink", [0.0, 1e-6, 1e-5, 1e-4, 1e-3])
def test_tangent_or_kinked_arcs_of_nearly_equal_radii_are_made_g2(sense, eps, kink):
    """Three arcs, radii r·(1 + ε)^k (growing and shrinking), kinked either way (with or against the arcs).

    Left: a kink of 1e-6 … 1e-5 rad between radii 1e-4 apart (relative), where the circles cross too flatly for
    a C pair float64 holds and made steeper they cross beyond the arcs, the nested spiral needs more of the arcs
    and a tangent circle's transitions are beyond float64: make_g2's named refusal with a bound that builds
    (as before), at some bounds."""
    for grow in (1.0, -1.0):
        radii = [2.0 * (1.0 + eps) ** (grow * k) for k in range(3)]
        for turn in {kink, -kink}:
            arcs = same_sense_arcs(radii, [turn, turn], [0.6] * 3, sense)
            for bound in (0.01, 0.001):
                if eps == 1e-4 and 0.0 < abs(turn) <= 1e-5:
                    try:
                        result = make_g2(arcs, bound)
                    except NoSolutionError as error:
                        assert "cannot be made G2 within max_deviation" in str(error) and "works (built and checked)" in str(error)
                        continue
                else:
                    result = make_g2(arcs, bound)
                assert len(result.chains) == 1 and not result.splits, result.describe_splits()
                assert all(j.kind != "split" for j in result.joints)
                assert_g2(arcs, result, bound, closed=False)
                if not any(j.kind == "g2" for j in result.joints):
                    arcs_kept(arcs, result)


@pytest.mark.parametrize("sense", [1.0, -1.0])
@pytest.mark.parametrize(("eps", "kink"), [(1e-3, 1e-4), (1e-2, 1e-3), (0.3, 1e-3), (1e-3, 3e-4)])
def test_a_kink_against_the_arcs_gets_a_c_pair_and_keeps_the_arcs_as_they_are(sense, eps, kink):
    """The path straightens at the joint: the C pair between the crossing circles joins them there, both arcs
    kept with their own radii (no shift), so the result lies far inside the bound."""
    radii = [2.0 * (1.0 + eps) ** k for k in range(3)]
    arcs = same_sense_arcs(radii, [-sense * kink] * 2, [0.6] * 3, sense)
    result = make_g2(arcs, 0.01)
    assert [j.kind for j in result.joints] == ["arc-arc-compound"] * 2
    assert all(j.moved.startswith("a C spiral pair") for j in result.joints), [j.moved for j in result.joints]
    assert_g2(arcs, result, 0.01, closed=False)
    kept = [s for s in result.chain if isinstance(s, Arc)]
    assert len(kept) == 3
    for arc, source in zip(kept, arcs):
        assert arc.radius == source.radius and np.array_equal(arc.center, source.center)
    assert result.deviation < 1e-3 * 0.01


def test_arcs_of_one_circle_are_still_merged():
    """Same centre, same radius, same sense: one arc, as before."""
    arcs = [Arc((1.0, 2.0), 3.0, 0.2, 0.7), Arc((1.0, 2.0), 3.0, 0.9, 0.5), Arc((1.0, 2.0), 3.0, 1.4, 0.4)]
    result = make_g2(arcs, 0.01)
    assert [j.kind for j in result.joints] == ["g2", "g2"]
    assert len(result.chain) == 1 and isinstance(result.chain[0], Arc)
    assert result.chain[0].sweep == pytest.approx(1.6) and result.deviation == 0.0


@pytest.mark.parametrize("bound", [0.01, 0.001])
def test_a_spiral_cut_as_arcs_by_radius_is_made_g2_whole(bound):
    """``arcspiral.ngc``'s outer turns, as the program writes them: each joint a same-sense joint of radii 0.1 %
    apart with the program's rounding as kink (1e-6 … 1e-4 rad, both ways)."""
    arcs = arcs_of_a_spiral(60, 2.0, 0.002)
    result = make_g2(arcs, bound)
    assert len(result.chains) == 1 and not result.splits
    assert all(j.kind == "arc-arc-compound" for j in result.joints)
    assert sum(j.moved.startswith("a C spiral pair") for j in result.joints) > 40
    assert_g2(arcs, result, bound, closed=False)


@settings(max_examples=30, deadline=None, derandomize=True)
@given(
    count=st.integers(2, 5),
    radius=st.floats(1.0, 20.0),
    ratio=st.sampled_from([1e-3, 1e-2, 0.1, 0.3, -1e-3, -1e-2, -0.1, -0.2]),
    kinks=st.lists(st.sampled_from([0.0, 1e-4, 3e-4, 1e-3]), min_size=4, max_size=4),
    sweeps=st.lists(st.floats(0.2, 1.5), min_size=5, max_size=5),
    sense=st.sampled_from([1.0, -1.0]),
    bound_exp=st.floats(-3.0, -1.0),
)
def test_random_spirals_cut_as_arcs_are_made_g2(count, radius, ratio, kinks, sweeps, sense, bound_exp):
    """Arcs of one sense, radii changing by one ratio, each kinked against the arcs (or tangent)."""
    arcs = same_sense_arcs([radius * (1.0 + ratio) ** k for k in range(count)], [-sense * k for k in kinks], sweeps[:count], sense)
    bound = 10.0**bound_exp
    result = make_g2(arcs, bound)
    assert len(result.chains) == 1 and not result.splits
    assert_g2(arcs, result, bound, closed=False)


@settings(max_examples=30, deadline=None, derandomize=True)
@given(
    radii=st.lists(st.floats(1.0, 20.0), min_size=2, max_size=5),
    nearly=st.booleans(),
    kinks=st.lists(st.sampled_from([0.0, 1e-6, -1e-6, 1e-5, -1e-5, 1e-4, -1e-4, 1e-3, -1e-3]), min_size=4, max_size=4),
    sense=st.sampled_from([1.0, -1.0]),
    bound_exp=st.floats(-3.0, -1.0),
)
def test_random_same_sense_arcs_are_made_g2_or_refused_by_joint(radii, nearly, kinks, sense, bound_exp):
    """Any chain of same-sense arcs (radii near each other or not, kinked either way): G2 within the bound, or
    make_g2's named refusal (the joint, its point and the reason), never another error."""
    if nearly:
        radii = [radii[0] * (1.0 + 1e-3 * (r - 10.0) / 10.0) for r in radii]
    arcs = same_sense_arcs(radii, kinks[: len(radii) - 1], [0.8] * len(radii), sense)
    bound = 10.0**bound_exp
    try:
        result = make_g2(arcs, bound)
    except NoSolutionError as error:
        assert "cannot be made G2 within max_deviation" in str(error) and "between segments" in str(error)
        return
    assert_g2(arcs, result, bound, closed=False)


@pytest.mark.parametrize("bound", [0.01, 0.03, 0.1])
def test_arcs_of_nearly_one_circle_before_a_short_line_stay_g2_when_the_bound_grows(bound):
    """Two arcs of radius 19 kinked by 1.4e-4 rad (their circles 2.6e-3 apart), then a 0.5 line: within 0.01 a
    C pair joins them; a larger bound would merge them as arcs of one circle, which moves the line's start off
    the arc, so they are joined as within 0.01 (a bound that works keeps working)."""
    first = Arc((0.0, 0.0), -19.0, 0.5, 1.0)
    heading = 0.5 - math.pi / 2 - 1.0 + 1.38e-4  # the end tangent of the clockwise arc, kinked
    end = np.asarray(first.end, dtype=float)
    centre = end - 19.0 * np.array([-math.sin(heading), math.cos(heading)])
    second = Arc(tuple(centre), -19.0, math.atan2(end[1] - centre[1], end[0] - centre[0]), 1.0)
    tail = np.asarray(second.end, dtype=float)
    out = heading - 1.0
    arcs = [first, second, Line(tuple(tail), tuple(tail + 0.5 * np.array([math.cos(out), math.sin(out)])))]
    result = make_g2(arcs, bound)
    assert [j.kind for j in result.joints] == ["arc-arc-compound", "line-arc"]
    assert_g2(arcs, result, bound, closed=False)
