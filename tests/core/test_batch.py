"""Batch solvers: same kernels as the scalar API, one status per row."""

import math

import numpy as np
import pytest

import spiral_cad as sc
from spiral_cad import Status
from spiral_cad.core import batch
from spiral_cad.core.errors import MALFORMED

rng = np.random.default_rng(7)
N = 400


def scalar_rows(solve, rows):
    """Scalar result per row: control points, or the error message."""
    out = []
    for args in rows:
        try:
            t = solve(*args)
            out.append(np.stack([s.control_points for s in t.spirals]))
        except ValueError as e:
            out.append(e)
    return out


def check_same(result, expected):
    for i, exp in enumerate(expected):
        if isinstance(exp, ValueError):
            assert result.status[i] != Status.OK
            if isinstance(exp, sc.NoSolutionError):
                assert result.reason(i) == str(exp)
            else:  # malformed: the scalar API names the argument itself
                assert Status(result.status[i]) in MALFORMED
            assert all(np.isnan(s[i]).all() for s in result.spirals)
        else:
            assert result.status[i] == Status.OK, result.reason(i)
            got = np.stack([s[i] for s in result.spirals])
            assert np.array_equal(got, exp)  # same kernel: bit for bit


def test_line_to_circle_batch_equals_scalar():
    p = rng.normal(size=(N, 2))
    d = rng.normal(size=(N, 2))
    c = rng.normal(size=(N, 2)) * 4
    r = rng.uniform(0.2, 3, N)
    r[5] = 0.0
    d[6] = 0.0
    c[7, 0] = np.nan
    res = batch.line_to_circle(p, d, c, r)
    assert res.spirals[0].shape == (N, 4, 2) and len(res.spirals) == 1
    expected = scalar_rows(sc.line_to_circle, zip(p.tolist(), d.tolist(), c.tolist(), r.tolist()))
    check_same(res, expected)
    assert 0 < res.ok.sum() < N  # both feasible and infeasible rows present
    assert res.status[5] == Status.BAD_RADIUS and res.status[6] == Status.ZERO_DIRECTION
    assert res.status[7] == Status.NOT_FINITE


def test_circle_to_circle_batch_equals_scalar_for_c_and_s():
    c0 = rng.normal(size=(N, 2)) * 5
    c1 = rng.normal(size=(N, 2)) * 5
    r0 = rng.uniform(0.2, 3, N) * rng.choice([-1, 1], N)
    r1 = rng.uniform(0.2, 3, N) * rng.choice([-1, 1], N)
    res = batch.circle_to_circle(c0, r0, c1, r1)
    assert len(res.spirals) == 2
    expected = scalar_rows(sc.circle_to_circle, zip(c0.tolist(), r0.tolist(), c1.tolist(), r1.tolist()))
    check_same(res, expected)
    assert {Status.CIRCLES_OVERLAP, Status.OK} <= set(res.status.tolist())


def test_line_to_line_batch_equals_scalar_with_auto_and_given_curvature():
    p = rng.normal(size=(N, 2)) * 3
    p0 = p + rng.normal(size=(N, 2)) * 5
    p1 = p + rng.normal(size=(N, 2)) * 5
    k = np.where(rng.random(N) < 0.5, np.nan, rng.uniform(0.05, 3, N))
    res = batch.line_to_line(p0, p, p1, k)
    rows = [(a, b, c, None if math.isnan(kk) else kk) for a, b, c, kk in zip(p0.tolist(), p.tolist(), p1.tolist(), k.tolist())]
    check_same(res, scalar_rows(sc.line_to_line, rows))
    assert {Status.LEGS_TOO_SHORT, Status.OK} <= set(res.status.tolist())


def test_circle_in_circle_batch_equals_scalar():
    n = 60
    big = rng.uniform(1, 5, n)
    q = rng.uniform(0.1, 0.9, n)
    frac = rng.uniform(0.97, 1.0, n)
    ang = rng.uniform(-np.pi, np.pi, n)
    c0 = rng.normal(size=(n, 2))
    c1 = c0 + (big * (1 - q) * frac)[:, None] * np.stack([np.cos(ang), np.sin(ang)], 1)
    r0, r1 = big, big * q
    swap = rng.random(n) < 0.5  # outward rows
    c0[swap], c1[swap] = c1[swap].copy(), c0[swap].copy()
    r0, r1 = np.where(swap, r1, r0), np.where(swap, r0, r1)
    res = batch.circle_in_circle(c0, r0, c1, r1)
    expected = scalar_rows(sc.circle_in_circle, zip(c0.tolist(), r0.tolist(), c1.tolist(), r1.tolist()))
    check_same(res, expected)
    ok = res.ok
    assert ok.any() and (~ok).any()
    assert np.all((res.parameter[ok] > 0) & (res.parameter[ok] < 1))


def test_broadcasting_a_shared_radius_and_direction():
    centers = np.array([[0, 2.0], [0, 3.0], [0, 0.5]])
    res = batch.line_to_circle((0, 0), (1, 0), centers, 1.0)
    assert res.status.tolist() == [Status.OK, Status.OK, Status.CIRCLE_MEETS_LINE]
    assert res.measure[2] == pytest.approx(0.5)
    assert "d/r = 0.50000" in res.reason(2)
    assert res.reason(0) == "ok"


def test_bad_shapes_are_rejected():
    with pytest.raises(ValueError, match="point must have shape"):
        batch.line_to_circle(np.zeros((3, 3)), (1, 0), (0, 2), 1.0)
    with pytest.raises(ValueError):
        batch.line_to_circle(np.zeros((3, 2)), (1, 0), np.zeros((4, 2)), 1.0)


def test_out_buffer_is_filled_in_place_and_checked():
    centers = np.array([[0, 2.0], [0, 3.0]])
    buf = np.zeros((2, 1, 4, 2))
    res = batch.line_to_circle((0, 0), (1, 0), centers, 1.0, out=buf)
    assert np.shares_memory(res.spirals[0], buf)
    assert np.array_equal(buf[:, 0], batch.line_to_circle((0, 0), (1, 0), centers, 1.0).spirals[0])
    with pytest.raises(ValueError, match="out must be"):
        batch.line_to_circle((0, 0), (1, 0), centers, 1.0, out=np.zeros((2, 2, 4, 2)))


def test_an_out_buffer_that_overlaps_an_input_is_refused_by_name():
    buf = np.zeros((300, 1, 4, 2))
    centers = buf.reshape(-1, 2)[:300]  # the rows would be overwritten while they are read
    centers[:] = np.c_[np.linspace(-1, 1, 300), np.full(300, 1.5)]
    with pytest.raises(ValueError, match="overlaps center"):
        batch.line_to_circle((0, 0), (1, 0), centers, 1.0, out=buf)


def test_batch_theta_matches_the_scalar_theta():
    centers = np.stack([np.linspace(-3, 3, 50), np.linspace(1.2, 40, 50)], axis=1)
    res = batch.line_to_circle((0, 0), (1, 0), centers, 1.0)
    scalar = [sc.line_to_circle((0, 0), (1, 0), c, 1.0).theta for c in centers.tolist()]
    np.testing.assert_allclose(res.theta, scalar, rtol=4e-16, atol=0)


# ------------------------------------------------ the vectorised rows and threads


def _ordinary_rows(n):
    """Random rows of each case, most of them within the near-linear spirals' reach too."""
    r = np.random.default_rng(11)
    p, angle = r.normal(size=(n, 2)) * 3, r.uniform(-np.pi, np.pi, n)
    t = np.stack([np.cos(angle), np.sin(angle)], 1)
    radii, side = r.uniform(0.2, 3, n), r.choice([-1.0, 1.0], n)
    c = p + r.normal(size=n)[:, None] * t + (side * radii * r.uniform(1.0005, 1.12, n))[:, None] * t[:, ::-1] * [-1, 1]
    c0, r0, r1 = r.normal(size=(n, 2)) * 5, r.uniform(0.2, 3, n), r.uniform(0.2, 3, n)
    s_shape = r.random(n) < 0.5
    reach = np.where(s_shape, (r0 + r1) * r.uniform(1.01, 1.4, n), np.abs(r1 - r0) + (r0 + r1) * r.uniform(0.05, 0.8, n))
    c1 = c0 + reach[:, None] * t
    r1 = np.where(s_shape, -r1, r1)
    corner = r.normal(size=(n, 2)) * 3
    p0, p1 = corner + r.normal(size=(n, 2)) * 5, corner + r.normal(size=(n, 2)) * 5
    k = np.where(r.random(n) < 0.5, np.nan, r.uniform(0.05, 3, n))
    return (p, t * r.uniform(0.1, 10, n)[:, None], c, radii), (c0, r0, c1, r1), (p0, corner, p1, k)


@pytest.mark.parametrize("shape", ["walton-meek", "near-linear"])
def test_vectorised_rows_are_the_general_rows_bit_for_bit(shape):
    """Rows the blocks solve on vectors of rows (``*_fast``) get exactly what the general
    row function (checks, scaled frames, exact residuals) gives them."""
    from spiral_cad.core import _kernel_circles as KC
    from spiral_cad.core import _kernel_line_circle as KLC
    from spiral_cad.core import _kernel_line_line as KLL
    from spiral_cad.core import _kernels as K

    code = {"walton-meek": K.WALTON_MEEK, "near-linear": K.NEAR_LINEAR}[shape]
    lc, cc, ll = _ordinary_rows(300)
    cases = [(batch.line_to_circle(*lc, shape=shape), KLC.line_to_circle_general, np.column_stack([lc[0], lc[1], lc[2], lc[3]])),
             (batch.circle_to_circle(*cc, shape=shape), KC.circle_to_circle_general,
              np.column_stack([cc[0], cc[1], cc[2], cc[3]])),
             (batch.line_to_line(*ll, shape=shape), KLL.line_to_line_general, np.column_stack(ll[:3] + (ll[3],)))]  # fmt: skip
    for result, general, rows in cases:
        assert result.ok.sum() > 100
        for i, row in enumerate(rows.tolist()):
            out = np.empty((1, len(result.spirals), 4, 2))
            status, theta, _, _ = general(*row, code, out, 0)
            assert status == result.status[i]
            if status == Status.OK:
                assert theta == result.theta[i]
                assert np.array_equal(out[0], np.stack([s[i] for s in result.spirals]))


def test_batches_split_over_threads_give_the_bits_of_one_call():
    from spiral_cad.core import _kernel_batches as KB
    from spiral_cad.core import _kernels as K
    from spiral_cad.core.threads import ROWS_PER_THREAD

    n = 2 * ROWS_PER_THREAD + 17
    r = np.random.default_rng(5)
    p, d, c, radii = r.normal(size=(n, 2)), r.normal(size=(n, 2)), r.normal(size=(n, 2)) * 4, r.uniform(0.2, 3, n)
    split = batch.line_to_circle(p, d, c, radii)
    out, status, theta, measure = np.empty((n, 1, 4, 2)), np.empty(n, np.int8), np.empty(n), np.empty(n)
    KB.line_to_circle_batch(p, d, c, radii, K.WALTON_MEEK, out, status, theta, measure)
    assert np.array_equal(split.spirals[0], out[:, 0], equal_nan=True)
    assert np.array_equal(split.status, status) and np.array_equal(split.theta, theta, equal_nan=True)


def test_shared_input_rows_are_read_in_place_not_copied():
    centers = np.tile([0.0, 105.0], (5, 1))
    res = batch.line_to_circle([0.0, 0.0], [1.0, 0.0], centers, 100.0)
    assert res.ok.all() and res.inputs["point"].shape == (5, 2) and res.inputs["radius"].shape == (5,)
    assert res.inputs["point"].strides[0] == 0  # one stored row, shown as five
    assert np.array_equal(res.spirals[0][0], res.spirals[0][4])
