"""make_g2: paths of lines and tangent arcs made G2 within a Hausdorff bound, arcs kept true arcs.

Every built result is judged independently of the code under test: the joints by the chain's own
check and by finite differences of dense samples (tangent turn and curvature from three points),
the deviation by exact distances to the input's lines and arcs (dense samples of the result) and
by the input's samples against the result's dense polyline.
"""

import math

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from spiral_cad import Arc, BezierSpiral, Chain, Line, NoSolutionError
from spiral_cad.core.chain import g2_mismatch
from spiral_cad.design import G2Path, make_g2
from spiral_cad.design._g2_pieces import CHORD_SHARE

# ---------------------------------------------------------------- independent measures


def _distance_to_input(points: np.ndarray, segments) -> np.ndarray:
    """Exact distance of points to the nearest input line segment or arc."""
    best = np.full(len(points), np.inf)
    for s in segments:
        if isinstance(s, Line):
            a, b = s.start, s.end
            d = b - a
            t = np.clip(((points - a) @ d) / float(d @ d), 0.0, 1.0)
            dist = np.linalg.norm(points - a - t[:, None] * d, axis=1)
        else:
            rel = points - s.center
            angle = np.arctan2(rel[:, 1], rel[:, 0])
            inside = (math.copysign(1.0, s.radius) * (angle - s.start_angle)) % (2 * math.pi) <= s.sweep + 1e-12
            radial = np.abs(np.linalg.norm(rel, axis=1) - abs(s.radius))
            ends = np.minimum(np.linalg.norm(points - s.start, axis=1), np.linalg.norm(points - s.end, axis=1))
            dist = np.where(inside, radial, ends)
        best = np.minimum(best, dist)
    return best


def _dense(chain: Chain, per: int = 400) -> np.ndarray:
    u = np.linspace(0.0, 1.0, per)
    return np.vstack([s.point(u) for s in chain])


def _distance_to_polyline(points: np.ndarray, poly: np.ndarray) -> np.ndarray:
    best = np.full(len(points), np.inf)
    a, d = poly[:-1], np.diff(poly, axis=0)
    dd = np.einsum("ij,ij->i", d, d)
    keep = dd > 0
    a, d, dd = a[keep], d[keep], dd[keep]
    for start in range(0, len(points), 256):
        p = points[start : start + 256]
        rel = p[:, None] - a[None]
        t = np.clip(np.einsum("mkj,kj->mk", rel, d) / dd, 0.0, 1.0)
        near = rel - t[..., None] * d[None]
        best[start : start + 256] = np.sqrt(np.einsum("mkj,mkj->mk", near, near)).min(axis=1)
    return best


def hausdorff(segments, result: G2Path) -> float:
    """Output → input exactly (dense samples of the output, exact distance to the input's primitives);
    input → output exactly to the output's lines and arcs, and to each spiral's dense polyline
    (its sag, under 1e-9 of the bound in these tests, is negligible)."""
    out = np.vstack([_dense(c) for c in result.chains])
    there = float(_distance_to_input(out, segments).max())
    u = np.linspace(0.0, 1.0, 120)
    inputs = np.vstack([s.point(u) for s in segments])
    pieces = [s for c in result.chains for s in c]
    back = _distance_to_input(inputs, [s for s in pieces if not isinstance(s, BezierSpiral)])
    fine = np.linspace(0.0, 1.0, 3000)
    for s in pieces:
        if isinstance(s, BezierSpiral):
            # the spiral lies within its length of its start: only points it could bring nearer
            near = np.linalg.norm(inputs - s.start, axis=1) - s.length < back
            if near.any():
                back[near] = np.minimum(back[near], _distance_to_polyline(inputs[near], s.point(fine)))
    return max(there, float(back.max()))


def fd_curvature_continuous(chain: Chain, tol: float) -> None:
    """At every joint: curvature from finite differences just before and just after agree with the
    curvatures the segments report, and those agree across the joint."""
    segs = list(chain)
    size = float(np.abs(chain.segment_ends).max())
    for i, (a, b) in enumerate(zip(segs[:-1], segs[1:])):
        # The stencil is wide enough that float64's rounding of the points (δ ≈ 4 eps·size) moves the
        # curvature by under 1e-3 of its scale (δ/(hL)²); the curvature's own change across it is
        # allowed for (≈ 4h of its scale).
        own = [abs(float(s.curvature(u))) for s in (a, b) for u in (0.0, 1.0)]  # a spiral's peak: its own scale
        length = min(a.length, b.length)
        kappa = max(*own, 1.0 / max(a.length, b.length))
        h = min(max(1e-4, math.sqrt(4 * 2.2e-16 * size / (1e-3 * kappa)) / length), 0.05)
        ka = _fd_kappa(a, 1.0, h)
        kb = _fd_kappa(b, 0.0, h)
        scale = max(abs(ka), abs(kb), kappa)
        assert abs(ka - kb) <= (tol + 4 * h) * scale, f"joint {i}: κ {ka} before, {kb} after ({type(a).__name__} → {type(b).__name__})"
        # a tangent from control points a piece's length apart, far from the origin, holds its direction
        # only to about eps·size/length: float64's resolution, not a turn
        ta, tb = a.tangent(1.0), b.tangent(0.0)
        turn_tol = max(1e-7, 16 * 2.2e-16 * size / length)
        assert abs(ta[0] * tb[1] - ta[1] * tb[0]) <= turn_tol and float(ta @ tb) > 0, f"joint {i}: tangent turns"


def _fd_kappa(segment, u0: float, h: float) -> float:
    """Signed curvature from three points h of the segment's parameter apart at its end (a circle through them)."""
    us = np.array([0.0, h, 2 * h]) if u0 == 0.0 else np.array([1.0 - 2 * h, 1.0 - h, 1.0])
    p = segment.point(us)
    a, b, c = p - p[0]
    cross = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
    return 2.0 * cross / (np.linalg.norm(b - a) * np.linalg.norm(c - b) * np.linalg.norm(c - a))


def assert_g2(segments, result: G2Path, bound: float, closed: bool) -> None:
    for chain in result.chains:
        Chain(list(chain), units=result.units)  # the chain's own check, again
        fd_curvature_continuous(chain, 2e-2)
    if closed and len(result.chains) == 1:
        chain = result.chain
        assert g2_mismatch(chain[-1], chain[0], 1e-9) is None
    measured = hausdorff(segments, result)
    assert measured <= bound * (1 + 1e-6) + 1e-9 * _size(segments), (measured, bound)
    assert result.deviation <= bound
    # The reported deviation is the measured one (within what sampling sees).
    assert result.deviation >= 0.95 * measured - 1e-9 * _size(segments)


def _size(segments) -> float:
    return float(max(np.abs(np.vstack([s.point(np.linspace(0, 1, 5)) for s in segments])).max(), 1e-300))


def arcs_kept(segments, result: G2Path) -> None:
    """Every input arc's circle appears in the result as an Arc, concentric, radius within the bound, but
    for an arc within ``CHORD_SHARE`` of the bound of its chord (make_g2 may cut such a short arc as its
    chord where a kinked joint beside it cannot be absorbed)."""
    out_arcs = [s for c in result.chains for s in c if isinstance(s, Arc)]
    for s in segments:
        sagitta = abs(s.radius) * (1.0 - math.cos(abs(s.sweep) / 2.0)) if isinstance(s, Arc) and abs(s.sweep) <= math.pi else math.inf
        if isinstance(s, Arc) and sagitta > CHORD_SHARE * result.max_deviation:
            same = [a for a in out_arcs if np.allclose(a.center, s.center, rtol=0, atol=1e-9 * _size(segments))
                    and abs(abs(a.radius) - abs(s.radius)) <= result.max_deviation]  # fmt: skip
            assert same, f"arc {s} has no true arc in the result"


# ---------------------------------------------------------------- paths


def filleted_rectangle(w=10.0, h=6.0, r=1.0, x=0.0, y=0.0):
    return [
        Line((x + r, y), (x + w - r, y)),
        Arc((x + w - r, y + r), r, -math.pi / 2, math.pi / 2),
        Line((x + w, y + r), (x + w, y + h - r)),
        Arc((x + w - r, y + h - r), r, 0.0, math.pi / 2),
        Line((x + w - r, y + h), (x + r, y + h)),
        Arc((x + r, y + h - r), r, math.pi / 2, math.pi / 2),
        Line((x, y + h - r), (x, y + r)),
        Arc((x + r, y + r), r, math.pi, math.pi / 2),
    ]


def slot(length=8.0, r=1.5):
    return [
        Line((0.0, -r), (length, -r)),
        Arc((length, 0.0), r, -math.pi / 2, math.pi),
        Line((length, r), (0.0, r)),
        Arc((0.0, 0.0), r, math.pi / 2, math.pi),
    ]


@pytest.mark.parametrize("shape", ["near-linear", "walton-meek"])
@pytest.mark.parametrize("bound", [1e-1, 1e-3, 1e-6])
def test_filleted_rectangle_becomes_g2_with_true_arcs(shape, bound):
    segments = filleted_rectangle()
    result = make_g2(segments, bound, shape=shape)
    assert result.closed and len(result.chains) == 1
    assert_g2(segments, result, bound, closed=True)
    arcs_kept(segments, result)
    assert [j.kind for j in result.joints] == ["line-arc"] * 8
    assert all(0 < j.shift <= bound for j in result.joints)
    assert sum(isinstance(s, BezierSpiral) for s in result.chain) == 8


def test_slot_closed_and_deviation_is_the_shift():
    segments = slot()
    result = make_g2(segments, 0.01)
    assert_g2(segments, result, 0.01, closed=True)
    arcs_kept(segments, result)
    # The shift is the bound (less its margin): the gentlest transitions the bound allows.
    assert result.deviation == pytest.approx(0.01, rel=1e-5)


def test_reverse_and_compound_curves():
    reverse = [Line((0, 0), (5, 0)), Arc((5, 2), 2, -math.pi / 2, math.pi), Arc((5, 6), -2, -math.pi / 2, math.pi / 2)]
    result = make_g2(reverse, 0.01)
    assert [j.kind for j in result.joints] == ["line-arc", "arc-arc-reverse"]
    assert_g2(reverse, result, 0.01, closed=False)
    compound = [Line((0, 0), (5, 0)), Arc((5, 3), 3, -math.pi / 2, math.pi / 2), Arc((7, 3), 1, 0.0, math.pi / 2)]
    result = make_g2(compound, 0.01)
    assert [j.kind for j in result.joints] == ["line-arc", "arc-arc-compound"]
    assert_g2(compound, result, 0.01, closed=False)
    arcs_kept(compound, result)


def test_corners_of_a_polyline_and_a_reversal_split():
    square = make_g2([(0, 0), (1, 0), (1, 1), (0, 1)], 0.01)
    assert [j.kind for j in square.joints] == ["corner", "corner"]
    assert_g2([Line((0, 0), (1, 0)), Line((1, 0), (1, 1)), Line((1, 1), (0, 1))], square, 0.01, closed=False)
    folded = make_g2([(0, 0), (1, 0), (0, 0), (0, 1)], 0.01)
    assert folded.splits == [0] and len(folded.chains) == 2
    with pytest.raises(ValueError, match=r"split into 2 parts at joint 0 at \(1, 0\)"):
        _ = folded.chain


def test_g2_joints_are_left_alone_and_a_circle_is_already_g2():
    halves = [Arc((0, 0), 1.0, 0.0, math.pi), Arc((0, 0), 1.0, math.pi, math.pi)]
    result = make_g2(halves, 0.01)
    assert result.closed and result.deviation == 0.0
    assert [j.kind for j in result.joints] == ["g2", "g2"]


def test_refusal_names_the_joint_and_a_bound_that_works(monkeypatch):
    # A bound below what float64 resolves at these coordinates.
    segments = filleted_rectangle(x=1e6, y=1e6)
    with pytest.raises(NoSolutionError) as error:
        make_g2(segments, 1e-12)
    message = str(error.value)
    assert "joint" in message and "works (built and checked)" in message
    works = float(message.split("max_deviation ")[-1].split(" ")[0])
    result = make_g2(segments, works)
    assert_g2(segments, result, works, closed=True)
    # A path whose one build takes a good share of the search's time gets no search (it would overrun it).
    import spiral_cad.design.g2 as g2

    monkeypatch.setattr(g2, "ADVICE_SECONDS", 1e-9)
    with pytest.raises(NoSolutionError, match="a larger max_deviation may help$"):
        make_g2(segments, 1e-12)
    monkeypatch.undo()
    # A caller that splits where make_g2 refuses and goes on (a program made G2 in place) asks for no advice.
    with pytest.raises(NoSolutionError) as error:
        make_g2(segments, 1e-12, advise=False)
    assert str(error.value) == message.split("; max_deviation")[0] + "; a larger max_deviation may help"


def test_malformed_input_is_refused_by_name():
    with pytest.raises(ValueError, match="do not meet"):
        make_g2([Line((0, 0), (1, 0)), Line((2, 0), (3, 0))], 0.01)
    with pytest.raises(ValueError, match="max_deviation"):
        make_g2([(0, 0), (1, 0)], -1.0)
    with pytest.raises(ValueError, match="shape"):
        make_g2([(0, 0), (1, 0)], 0.1, shape="g2cbs")


# ---------------------------------------------------------------- properties


def _walk(moves, scale: float, origin) -> list:
    """A G1 path from ``origin`` heading +x: each move a line (length) or a tangent arc (radius, sweep)."""
    x, y = origin
    heading = 0.0
    segments = []
    for kind, a, b in moves:
        if kind == "turn":  # a sharp corner (or, at ±π, a reversal) before the next move
            heading += a
            continue
        if kind == "line":
            length = a * scale
            end = (x + length * math.cos(heading), y + length * math.sin(heading))
            segments.append(Line((x, y), end))
            x, y = end
        else:
            radius, sweep = a * scale, b
            # centre on the left for a positive radius
            cx, cy = x - radius * math.sin(heading), y + radius * math.cos(heading)
            start = math.atan2(y - cy, x - cx)
            arc = Arc((cx, cy), radius, start, sweep)
            segments.append(arc)
            x, y = arc.end.tolist()
            heading += math.copysign(sweep, radius)
    return segments


_line = st.tuples(st.just("line"), st.floats(0.2, 3.0), st.just(0.0))
_arc = st.tuples(
    st.just("arc"),
    st.one_of(st.floats(0.01, 100.0), st.floats(-100.0, -0.01)),
    st.floats(0.05, 2.5),
)


@settings(max_examples=100)
@given(
    moves=st.lists(st.one_of(_line, _arc), min_size=2, max_size=6),
    scale_exp=st.floats(-3.0, 6.0),
    offset_exp=st.floats(-3.0, 6.0),
    bound_exp=st.floats(-6.0, -1.0),
    shape=st.sampled_from(["near-linear", "walton-meek"]),
)
def test_random_g1_paths_become_g2_within_the_bound(outcome, moves, scale_exp, offset_exp, bound_exp, shape):
    scale = 10.0**scale_exp
    segments = _walk(moves, scale, (10.0**offset_exp, -(10.0**offset_exp)))
    size = max(s.length for s in segments)
    bound = 10.0**bound_exp * size
    result = outcome(lambda: make_g2(segments, bound, shape=shape))
    if result is None:
        _suggested_bound_works(segments, bound, shape, closed=False)
        return
    assert_g2(segments, result, bound, closed=False)
    arcs_kept(segments, result)


def _suggested_bound_works(segments, bound, shape, closed) -> None:
    """A refusal that names a bound: that bound then builds, G2 and within it."""
    try:
        make_g2(segments, bound, shape=shape)
    except NoSolutionError as error:
        message = str(error)
        assert "joint" in message
        if "works (built and checked)" in message:
            works = float(message.split("max_deviation ")[-1].split(" ")[0])
            assert works > bound
            again = make_g2(segments, works, shape=shape)
            assert_g2(segments, again, works, closed)


def _filleted_polygon(points, radii) -> list:
    """A closed G1 path: the polygon's corners replaced by tangent circular arcs (radii scaled down to fit)."""
    pts = np.asarray(points, dtype=float)
    n = len(pts)
    t_in = [(pts[i] - pts[i - 1]) / np.linalg.norm(pts[i] - pts[i - 1]) for i in range(n)]
    t_out = [(pts[(i + 1) % n] - pts[i]) / np.linalg.norm(pts[(i + 1) % n] - pts[i]) for i in range(n)]
    turns = [math.atan2(a[0] * b[1] - a[1] * b[0], float(a @ b)) for a, b in zip(t_in, t_out)]
    tangents = [r * math.tan(abs(d) / 2) for r, d in zip(radii, turns)]
    edges = [np.linalg.norm(pts[(i + 1) % n] - pts[i]) for i in range(n)]
    fit = min(0.9 * e / (tangents[i] + tangents[(i + 1) % n]) for i, e in enumerate(edges))
    radii = [r * min(fit, 1.0) for r in radii]
    segments = []
    for i in range(n):
        r, d = radii[i], turns[i]
        t = r * math.tan(abs(d) / 2)
        start, end = pts[i] - t * t_in[i], pts[i] + t * t_out[i]
        normal = np.array([-t_in[i][1], t_in[i][0]]) * math.copysign(1.0, d)
        centre = start + r * normal
        arc = Arc(centre, math.copysign(r, d), math.atan2(*(start - centre)[::-1]), abs(d))
        segments.append(arc)
        nxt = pts[(i + 1) % n]
        t_next = radii[(i + 1) % n] * math.tan(abs(turns[(i + 1) % n]) / 2)
        segments.append(Line(end, nxt - t_next * t_out[i]))
    return segments


@settings(max_examples=50)
@given(
    count=st.integers(3, 7),
    jitter=st.lists(st.floats(-0.3, 0.3), min_size=7, max_size=7),
    spread=st.lists(st.floats(0.4, 1.0), min_size=7, max_size=7),
    radii=st.lists(st.floats(0.01, 1.0), min_size=7, max_size=7),
    scale_exp=st.floats(-3.0, 6.0),
    bound_exp=st.floats(-6.0, -1.0),
    shape=st.sampled_from(["near-linear", "walton-meek"]),
)
def test_random_closed_filleted_polygons_become_g2(outcome, count, jitter, spread, radii, scale_exp, bound_exp, shape):
    """Star-shaped polygons (convex and concave corners: reverse curves between fillets of opposite sense)."""
    angles = [2 * math.pi * (k + jitter[k]) / count for k in range(count)]
    scale = 10.0**scale_exp
    points = [(scale * spread[i] * math.cos(a), scale * spread[i] * math.sin(a)) for i, a in enumerate(angles)]
    segments = _filleted_polygon(points, [r * scale for r in radii[:count]])
    size = max(s.length for s in segments)
    bound = 10.0**bound_exp * size
    result = outcome(lambda: make_g2(segments, bound, shape=shape))
    if result is None:
        _suggested_bound_works(segments, bound, shape, closed=True)
        return
    assert result.closed
    assert_g2(segments, result, bound, closed=True)
    arcs_kept(segments, result)


def test_a_planar_path_in_space_is_made_g2_in_its_plane():
    from spiral_cad import PlaneFrame

    frame = PlaneFrame((1.0, 2.0, 3.0), (1.0, 0.0, 1.0), (-1.0, 0.5, 1.0))
    flat = filleted_rectangle()
    tilted = make_g2([s.placed(frame) for s in flat], 0.01)
    plane = make_g2(flat, 0.01)
    assert tilted.chain.dim == 3 and tilted.closed
    assert tilted.chain.length == pytest.approx(plane.chain.length, rel=1e-9)
    assert tilted.deviation == pytest.approx(plane.deviation, rel=1e-6)
    points = tilted.chain.sample(50)
    off_plane = (points - np.array(frame.origin)) @ (np.asarray(frame.normal) / np.linalg.norm(frame.normal))
    assert np.abs(off_plane).max() <= 1e-9
    corner = make_g2([(0, 0, 0), (1, 0, 1), (1, 1, 1)], 0.01)
    assert corner.chain.dim == 3 and [j.kind for j in corner.joints] == ["corner"]


@pytest.mark.parametrize("path", [[Line((0, 0, 1), (1, 0, 1))], [(0.0, 0.0, 1.0), (1.0, 0.0, 1.0)]])
def test_a_single_line_in_space_is_already_g2(path):
    # two outline points span no plane: any plane through the line will do
    result = make_g2(path, 0.1)
    assert result.deviation == 0.0 and result.chain.dim == 3
    points = result.chain.sample(5)
    assert np.allclose(points[:, 1:], 0.0 * points[:, 1:] + [0.0, 1.0]) and np.ptp(points[:, 0]) == pytest.approx(1.0)


@pytest.mark.parametrize("length", [1e-2, 1e-3])
@pytest.mark.parametrize("sense", [1.0, -1.0])
def test_a_short_line_between_arcs_is_bridged_by_a_pair(length, sense):
    """A line too short for a transition at each end (here 1e-2 and 1e-3 between arcs of radius 100)
    is joined across by a C (same sense) or S pair: the arcs still shift by the whole bound."""
    segments = _walk([("arc", 100.0, 0.3), ("line", length, 0.0), ("arc", sense * 100.0, 0.3)], 1.0, (0.0, 0.0))
    result = make_g2(segments, 0.01)
    assert_g2(segments, result, 0.01, closed=False)
    arcs_kept(segments, result)
    assert [j.kind for j in result.joints] == ["line-arc", "line-arc"]
    assert "joined across" in result.joints[0].moved
    assert result.joints[0].shift == pytest.approx(0.01, rel=1e-5)


_turn = st.tuples(st.just("turn"), st.one_of(st.floats(-2.8, -0.05), st.floats(0.05, 2.8), st.just(math.pi)), st.just(0.0))


@settings(max_examples=60)
@example(moves=[("arc", 0.015625, 0.125), ("turn", -2.0, 0.0), ("arc", 2.0, 1.0)], scale_exp=1.0, bound_exp=-4.0,
         shape="near-linear")  # a newcomer's run: the short arc beside the kink cut as its chord  # fmt: skip
@given(
    moves=st.lists(st.one_of(_line, _arc, _turn), min_size=2, max_size=7),
    scale_exp=st.floats(-3.0, 6.0),
    bound_exp=st.floats(-6.0, -1.0),
    shape=st.sampled_from(["near-linear", "walton-meek"]),
)
def test_random_paths_with_corners_and_reversals(outcome, moves, scale_exp, bound_exp, shape):
    """Sharp corners between lines and arcs in any order, and reversals: rounded or split, G2 within the bound."""
    moves = [m for i, m in enumerate(moves) if m[0] != "turn" or (i > 0 and moves[i - 1][0] != "turn")]
    if not any(m[0] != "turn" for m in moves) or moves[0][0] == "turn" or moves[-1][0] == "turn":
        return
    scale = 10.0**scale_exp
    segments = _walk(moves, scale, (scale, scale))
    size = max(s.length for s in segments)
    bound = 10.0**bound_exp * size
    result = outcome(lambda: make_g2(segments, bound, shape=shape))
    if result is None:
        _suggested_bound_works(segments, bound, shape, closed=False)
        return
    assert_g2(segments, result, bound, closed=False)
    arcs_kept(segments, result)
    reversals = sum(1 for m in moves if m[0] == "turn" and m[1] == math.pi)
    assert len(result.chains) >= 1 + reversals


def test_small_gaps_are_closed_within_the_bound_and_larger_ones_refused():
    """Arcs whose ends miss their neighbours by a rounding (as a CNC program's arcs do) and lines that
    miss at a corner: closed, still within the bound; a gap over half the bound is refused by name."""
    off = [s if isinstance(s, Line) else Arc(s.center, s.radius * (1 + 2e-4), s.start_angle, s.sweep) for s in filleted_rectangle()]
    result = make_g2(off, 0.01)
    assert_g2(off, result, 0.01, closed=True)
    square = [Line((0, 0), (1, 0)), Line((1, 0.0005), (1, 1)), Line((1, 1), (0, 1))]
    result = make_g2(square, 0.01)
    assert_g2(square, result, 0.01, closed=False)
    result = make_g2(square, 0.001)  # a gap of half the bound is closed too
    assert_g2(square, result, 0.001, closed=False)
    with pytest.raises(ValueError, match=r"segments 0 and 1 do not meet.*0\.0005 apart"):
        make_g2(square, 0.0009)
