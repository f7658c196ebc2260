"""Core throughput: batch transitions, scalar latency, evaluation, vs a clothoid peer.

Run: ``.venv/bin/python benchmarks/bench_core.py [--rows N] [--repeat R] [--out FILE]``.
Prints a markdown table of medians over ``repeat`` runs; peers are measured in
the same run so the ratios hold on a noisy shared machine.
"""

from __future__ import annotations

import argparse
import timeit

import numpy as np
from scipy.special import fresnel
from timing import machine, median_time, write_markdown

import spiral_cad as sc
from spiral_cad import batch
from spiral_cad.core._kernels import WALTON_MEEK, nested_band_lower


def line_circle_problems(n: int, rng: np.random.Generator):
    """Lines along +x through the origin, circles above at d/r ∈ [1.01, 1.5]."""
    r = rng.uniform(0.5, 5.0, n)
    rho = rng.uniform(1.01, 1.5, n)
    centers = np.stack([rng.uniform(-10, 10, n), rho * r], axis=1)
    return np.zeros((n, 2)), np.tile([1.0, 0.0], (n, 1)), centers, r


def clothoid_line_to_circle(centers: np.ndarray, r: np.ndarray, tol: float = 1e-12):
    """Peer: the same job with clothoids, vectorised Newton on scipy.special.fresnel.

    The clothoid of turn τ and end radius R has length L = 2Rτ; its end circle
    lies at height y(τ) + R cos τ = R(√(2πτ)·S(√(2τ/π)) + cos τ).  Solve that
    for τ = d/R, then place the start on the line.
    """
    target = centers[:, 1] / r
    tau = np.minimum(np.sqrt(6.0 * (target - 1.0)), 1.5)
    for _ in range(50):
        z = np.sqrt(2.0 * tau / np.pi)
        s, c = fresnel(z)
        f = np.sqrt(2.0 * np.pi * tau) * s + np.cos(tau) - target
        step = f / (np.sqrt(np.pi / (2.0 * tau)) * s)
        tau = tau - step
        if np.max(np.abs(step)) < tol:
            break
    z = np.sqrt(2.0 * tau / np.pi)
    s, c = fresnel(z)
    x_end = r * np.sqrt(2.0 * np.pi * tau) * c
    start = centers[:, 0] - x_end + r * np.sin(tau)
    return start, tau


def numpy_closed_form_line_to_circle(p, d, centers, r):
    """Peer: MATH.md's closed form written in plain numpy (no compiled loop)."""
    t = d / np.linalg.norm(d, axis=1, keepdims=True)
    v = centers - p
    dist = t[:, 0] * v[:, 1] - t[:, 1] * v[:, 0]
    rho = np.abs(dist) / r
    cos_t = 10.0 / (9.0 * rho + np.sqrt(81.0 * rho * rho - 80.0))
    sin_t = np.sqrt(1.0 - cos_t * cos_t)
    g = 25.0 * sin_t * r / (54.0 * cos_t**2)
    h = 5.0 * sin_t * r / (9.0 * cos_t)
    a = np.einsum("ij,ij->i", v, t) - r * sin_t * (25.0 - 12.0 * cos_t**2) / (27.0 * cos_t**2)
    side = np.sign(dist)
    n = np.stack([-t[:, 1], t[:, 0]], 1) * side[:, None]
    b0 = p + a[:, None] * t
    end_dir = cos_t[:, None] * t + sin_t[:, None] * n
    return np.stack([b0, b0 + g[:, None] * t, b0 + 2 * g[:, None] * t, b0 + 2 * g[:, None] * t + h[:, None] * end_dir], 1)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rows", type=int, default=1_000_000)
    parser.add_argument("--repeat", type=int, default=7)
    parser.add_argument("--out", help="also write the table to this markdown file")
    args = parser.parse_args()
    n, rep = args.rows, args.repeat
    rng = np.random.default_rng(1)
    rows: list[tuple[str, str, str, str]] = []

    def add(name, value, unit, note=""):
        rows.append((name, f"{value:,.2f}", unit, note))
        print(f"  {name:45} {value:12,.2f} {unit:14} {note}", flush=True)

    print(f"{n:,} rows per batch, median of {rep} runs")
    p, d, c, r = line_circle_problems(n, rng)
    ours = median_time(lambda: batch.line_to_circle(p, d, c, r), rep)
    buffer = np.empty((n, 1, 4, 2))
    ours_reused = median_time(lambda: batch.line_to_circle(p, d, c, r, out=buffer), rep)
    numpy_cf = median_time(lambda: numpy_closed_form_line_to_circle(p, d, c, r), rep)
    clothoid = median_time(lambda: clothoid_line_to_circle(c, r), rep)
    add("batch line→circle (new output arrays)", n / ours / 1e6, "M/s", "goal ≥ 20")
    add("batch line→circle (out= reused buffer)", n / ours_reused / 1e6, "M/s", "goal ≥ 20")
    # near-linear spirals reach shifts q = d/r − 1 < 0.115; the equal-leg closed form covers q < 1/27
    near = np.stack([c[:, 0], r * rng.uniform(1.0005, 1.11, n)], axis=1)
    t_nl = median_time(lambda: batch.line_to_circle(p, d, near, r, shape="near-linear"), rep)
    t_wm_same = median_time(lambda: batch.line_to_circle(p, d, near, r), rep)
    add("batch line→circle near-linear (new arrays)", n / t_nl / 1e6, "M/s", f"walton-meek on the same rows {n / t_wm_same / 1e6:,.2f}")
    assert batch.line_to_circle(p, d, near, r, shape="near-linear").ok.all()
    add("  peer: same closed form, plain numpy", n / numpy_cf / 1e6, "M/s")
    add("  peer: clothoid, Newton on fresnel (1e-12)", n / clothoid / 1e6, "M/s")
    add("  ratio ours (new arrays) / clothoid", clothoid / ours, "×", "goal ≥ 3")
    add("  ratio ours / numpy closed form", numpy_cf / ours, "×")
    # sanity: both solve the same problems (clothoid offsets differ, curvature ends agree)
    res = batch.line_to_circle(p, d, c, r)
    assert res.ok.all()

    c0 = rng.uniform(-5, 5, (n, 2))
    r0 = rng.uniform(0.5, 2.0, n)
    r1 = rng.uniform(0.5, 2.0, n)
    ang = rng.uniform(-np.pi, np.pi, n)
    unit = np.stack([np.cos(ang), np.sin(ang)], 1)
    c1_s = c0 + ((r0 + r1) * rng.uniform(1.05, 3.0, n))[:, None] * unit
    c1_c = c0 + (np.abs(r1 - r0) + rng.uniform(0.1, 3.0, n))[:, None] * unit
    t_c = median_time(lambda: batch.circle_to_circle(c0, r0, c1_c, r1), rep)
    t_s = median_time(lambda: batch.circle_to_circle(c0, -r0, c1_s, r1), rep)
    pair = np.empty((n, 2, 4, 2))
    t_c_reused = median_time(lambda: batch.circle_to_circle(c0, r0, c1_c, r1, out=pair), rep)
    t_s_reused = median_time(lambda: batch.circle_to_circle(c0, -r0, c1_s, r1, out=pair), rep)
    add("batch circle→circle C (new output arrays)", n / t_c / 1e6, "M/s", "goal ≥ 10")
    add("batch circle→circle C (out= reused buffer)", n / t_c_reused / 1e6, "M/s", "goal ≥ 10")
    add("batch circle→circle S (new output arrays)", n / t_s / 1e6, "M/s", "goal ≥ 10")
    add("batch circle→circle S (out= reused buffer)", n / t_s_reused / 1e6, "M/s", "goal ≥ 10")

    corner = rng.uniform(-5, 5, (n, 2))
    p0 = corner - rng.uniform(1, 5, n)[:, None] * unit
    turn = ang + rng.uniform(0.2, 2.8, n) * rng.choice([-1, 1], n)
    p1 = corner + rng.uniform(1, 5, n)[:, None] * np.stack([np.cos(turn), np.sin(turn)], 1)
    t_ll = median_time(lambda: batch.line_to_line(p0, corner, p1), rep)
    add("batch line→line (Cor 4.5)", n / t_ll / 1e6, "M/s")

    m = n // 20
    q = rng.uniform(0.1, 0.9, m)
    low = np.array([nested_band_lower(x, WALTON_MEEK) for x in q])
    dist = (1 - q) * (low + rng.uniform(0.05, 0.95, m) * (1 - low))
    t_n = median_time(lambda: batch.circle_in_circle(c0[:m], 1.0, c0[:m] + dist[:, None] * unit[:m], q), rep)
    add("batch circle in circle (iterative)", m / t_n / 1e6, "M/s")

    number = 20000
    lat = {
        "line_to_circle": lambda: sc.line_to_circle((0, 0), (1, 0), (0, 1.3), 1.0),
        "circle_to_circle (S)": lambda: sc.circle_to_circle((0, 0), -1.0, (4, 0), 1.5),
        "line_to_line": lambda: sc.line_to_line((0, 0), (10, 0), (15, 8)),
        "circle_in_circle": lambda: sc.circle_in_circle((0, 0), 1.0, (0, 0.595), 0.4),
    }
    for name, fn in lat.items():
        fn()
        per_call = min(timeit.repeat(fn, number=number, repeat=5)) / number * 1e6
        add(f"scalar {name} latency", per_call, "µs/call", "goal ≤ 10" if name == "line_to_circle" else "")

    spiral = sc.BezierSpiral((0, 0), (1, 0), 0.7, 1.0)
    u = rng.random(n)
    t_pt = median_time(lambda: spiral.point(u), rep)
    t_k = median_time(lambda: spiral.curvature(u), rep)
    add("evaluation point(u)", n / t_pt / 1e6, "M points/s", "goal ≥ 30")
    add("evaluation curvature(u)", n / t_k / 1e6, "M points/s", "goal ≥ 30")

    print(f"machine: {machine()}")
    if args.out:
        note = f"{n:,} rows per batch, median of {rep} runs."
        write_markdown(args.out, "Core benchmark", note, ("measurement", "value", "unit", "goal"), rows)


if __name__ == "__main__":
    main()
