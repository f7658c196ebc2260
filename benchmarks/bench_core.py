"""Core throughput: batch transitions, scalar calls and evaluation, each against its peer in the same runs.

Run: ``.venv/bin/python benchmarks/bench_core.py [--quick] [--rows N] [--rounds R] [--out FILE]``
(the harness and its conventions: ``timing.py``). Peers: a clothoid solving the
same line → circle rows (vectorised Newton on ``scipy.special.fresnel``), the
same closed form in plain numpy, the memory floor (reading every input and
writing every output once), the row kernel called directly (for the scalar
API), numpy Bernstein sums and scipy's Fresnel integrals (for evaluation).
"""

from __future__ import annotations

import numpy as np
from scipy.special import fresnel
from timing import Report, arguments, compare, growth_exponent, latencies, per_second, table

import spiral_cad as sc
from spiral_cad.core import _kernel_batches as KB
from spiral_cad.core import _kernel_circles as KC
from spiral_cad.core import _kernel_line_circle as KLC
from spiral_cad.core import _kernel_line_line as KLL
from spiral_cad.core import _kernels as K
from spiral_cad.core import batch

#: The modules whose code these numbers measure (stamped into the results: ``timing.code_stamp``).
MEASURES = (
    "spiral_cad.core._kernels",
    "spiral_cad.core._kernel_spiral",
    "spiral_cad.core._kernel_line_circle",
    "spiral_cad.core._kernel_circles",
    "spiral_cad.core._kernel_line_line",
    "spiral_cad.core._kernel_batches",
    "spiral_cad.core.jit",
    "spiral_cad.core.threads",
    "spiral_cad.core.batch",
    "spiral_cad.core.transitions",
    "spiral_cad.core.bezier",
)


def line_circle_problems(n: int, rng: np.random.Generator, near: bool = False):
    """Lines along +x through the origin, circles above at d/r ∈ [1.01, 1.5] (``near``:
    road shifts d/r ∈ [1.0005, 1.11], which near-linear spirals reach)."""
    r = rng.uniform(0.5, 5.0, n)
    rho = rng.uniform(1.0005, 1.11, n) if near else rng.uniform(1.01, 1.5, n)
    centers = np.stack([rng.uniform(-10, 10, n), rho * r], axis=1)
    return np.zeros((n, 2)), np.tile([1.0, 0.0], (n, 1)), centers, r


def circle_problems(n: int, rng: np.random.Generator):
    """Circle pairs: centres, radii, and circle-1 centres for a C and for an S."""
    c0 = rng.uniform(-5, 5, (n, 2))
    r0, r1 = rng.uniform(0.5, 2.0, n), rng.uniform(0.5, 2.0, n)
    angle = rng.uniform(-np.pi, np.pi, n)
    unit = np.stack([np.cos(angle), np.sin(angle)], 1)
    c1_s = c0 + ((r0 + r1) * rng.uniform(1.05, 3.0, n))[:, None] * unit
    c1_c = c0 + (np.abs(r1 - r0) + rng.uniform(0.1, 3.0, n))[:, None] * unit
    return c0, r0, r1, c1_c, c1_s, unit, angle


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
    """Peer: MATH.md's closed form written in plain numpy (no verification)."""
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


def memory_floor(p, d, c, r):
    """Peer: what any line → circle batch must move: read every input once, write every output once."""
    n = len(r)
    out = np.empty((n, 1, 4, 2))
    out[:, 0, 0], out[:, 0, 1], out[:, 0, 2] = p, d, c
    out[:, 0, 3, 0] = r
    out[:, 0, 3, 1] = r
    return out, np.zeros(n, dtype=np.int8), r.copy(), r.copy()


def bernstein_points(cp: np.ndarray, u: np.ndarray) -> np.ndarray:
    """Peer: points of a cubic as a Bernstein sum in plain numpy."""
    v = 1.0 - u
    weights = (v * v * v, 3.0 * u * v * v, 3.0 * u * u * v, u * u * u)
    return np.stack([sum(w * p for w, p in zip(weights, cp[:, j])) for j in range(2)], axis=-1)


def bernstein_curvature(cp: np.ndarray, u: np.ndarray) -> np.ndarray:
    """Peer: curvature from the Bernstein sums of Q' and Q'' in plain numpy."""
    v = 1.0 - u
    d, dd = 3.0 * np.diff(cp, axis=0), 6.0 * np.diff(cp, 2, axis=0)
    dx, dy = (v * v * d[0, j] + 2.0 * u * v * d[1, j] + u * u * d[2, j] for j in range(2))
    ddx, ddy = (v * dd[0, j] + u * dd[1, j] for j in range(2))
    return (dx * ddy - dy * ddx) / np.hypot(dx, dy) ** 3


def clothoid_points(u: np.ndarray, theta: float = 0.7) -> np.ndarray:
    """Peer: points of a clothoid turning by θ at parameters u (scipy's Fresnel integrals)."""
    s, c = fresnel(np.sqrt(2.0 * theta / np.pi) * u)
    return np.stack([c, s], axis=-1)


def batches(report: Report, n: int, rounds: int, rng: np.random.Generator) -> None:
    p, d, c, r = line_circle_problems(n, rng)
    buffer = np.empty((n, 1, 4, 2))
    out, status, theta, measure = np.empty((n, 1, 4, 2)), np.empty(n, np.int8), np.empty(n), np.empty(n)
    t = compare({
        "ours": lambda: batch.line_to_circle(p, d, c, r),
        "out=": lambda: batch.line_to_circle(p, d, c, r, out=buffer),
        "one thread": lambda: KB.line_to_circle_batch(p, d, c, r, K.WALTON_MEEK, out, status, theta, measure),
        "clothoid": lambda: clothoid_line_to_circle(c, r),
        "numpy": lambda: numpy_closed_form_line_to_circle(p, d, c, r),
        "floor": lambda: memory_floor(p, d, c, r),
    }, rounds)  # fmt: skip
    assert batch.line_to_circle(p, d, c, r).ok.all()
    rate = {name: per_second(n, timing) for name, timing in t.items()}
    ratio = {name: t["clothoid"].median / t[name].median for name in t}
    report.add("batch line → circle, verified (new output arrays)", rate["ours"], "M rows/s", t["ours"],
               f"clothoid {rate['clothoid']:.2f} M/s", ratio["ours"], "≥ 20 M/s and ≥ 3× the clothoid")  # fmt: skip
    report.add("batch line → circle, `out=` buffer reused", rate["out="], "M rows/s", t["out="],
               f"clothoid {rate['clothoid']:.2f} M/s", ratio["out="])  # fmt: skip
    report.add("batch line → circle, the row kernel on one thread", rate["one thread"], "M rows/s", t["one thread"],
               f"clothoid {rate['clothoid']:.2f} M/s", ratio["one thread"])  # fmt: skip
    report.add("peer: clothoid, Newton on scipy.special.fresnel to 1e-12", rate["clothoid"], "M rows/s", t["clothoid"])
    report.add("peer: the same closed form in plain numpy (unverified)", rate["numpy"], "M rows/s", t["numpy"],
               "ours (new arrays)", t["numpy"].median / t["ours"].median)  # fmt: skip
    report.add("peer: memory floor (read the inputs, write the outputs)", rate["floor"], "M rows/s", t["floor"],
               "ours (new arrays)", t["floor"].median / t["ours"].median)  # fmt: skip

    pn, dn, cn, rn = line_circle_problems(n, rng, near=True)
    t = compare({
        "near-linear": lambda: batch.line_to_circle(pn, dn, cn, rn, shape="near-linear"),
        "walton-meek": lambda: batch.line_to_circle(pn, dn, cn, rn),
    }, rounds)  # fmt: skip
    assert batch.line_to_circle(pn, dn, cn, rn, shape="near-linear").ok.all()
    report.add("batch line → circle, near-linear (road shifts: equal legs and beyond)",
               per_second(n, t["near-linear"]), "M rows/s", t["near-linear"],
               f"walton-meek on the same rows {per_second(n, t['walton-meek']):.2f} M/s",
               t["walton-meek"].median / t["near-linear"].median)  # fmt: skip

    c0, r0, r1, c1_c, c1_s, unit, angle = circle_problems(n, rng)
    corner = rng.uniform(-5, 5, (n, 2))
    p0 = corner - rng.uniform(1, 5, n)[:, None] * unit
    turn = angle + rng.uniform(0.2, 2.8, n) * rng.choice([-1, 1], n)
    p1 = corner + rng.uniform(1, 5, n)[:, None] * np.stack([np.cos(turn), np.sin(turn)], 1)
    m = max(n // 20, 1)
    q = rng.uniform(0.1, 0.9, m)
    low = np.array([KC.nested_band_lower(x, K.WALTON_MEEK) for x in q])
    dist = (1 - q) * (low + rng.uniform(0.05, 0.95, m) * (1 - low))
    nested = (c0[:m], 1.0, c0[:m] + dist[:, None] * unit[:m], q)
    t = compare({
        "C": lambda: batch.circle_to_circle(c0, r0, c1_c, r1),
        "S": lambda: batch.circle_to_circle(c0, -r0, c1_s, r1),
        "line-line": lambda: batch.line_to_line(p0, corner, p1),
        "nested": lambda: batch.circle_in_circle(*nested),
        "clothoid": lambda: clothoid_line_to_circle(c, r),
    }, rounds)  # fmt: skip
    clothoid = f"clothoid line → circle {per_second(n, t['clothoid']):.2f} M/s"
    for name, label, goal in (("C", "batch circle → circle, broken-back C", "≥ 12 M/s"),
                              ("S", "batch circle → circle, S", "≥ 12 M/s"),
                              ("line-line", "batch line → line (Corollary 4.5)", "")):  # fmt: skip
        report.add(label, per_second(n, t[name]), "M rows/s", t[name], clothoid, t["clothoid"].median / t[name].median, goal)
    report.add(f"batch circle in circle ({m:,} rows; an iterative solve)", per_second(m, t["nested"]), "M rows/s", t["nested"])

    sizes = sorted({max(n // 100, 10), max(n // 10, 10), n})
    t = compare({size: (lambda k=size: batch.line_to_circle(p[:k], d[:k], c[:k], r[:k])) for size in sizes}, rounds)
    seconds = [t[size].median for size in sizes]
    report.add(f"growth of batch line → circle over {sizes[0]:,} … {sizes[-1]:,} rows", growth_exponent(sizes, seconds),
               "exponent", goal="1 (linear)")  # fmt: skip


def scalar_calls(report: Report, rounds: int, number: int) -> None:
    out1, out2 = np.empty((1, 1, 4, 2)), np.empty((1, 2, 4, 2))
    code = K.WALTON_MEEK
    t = latencies({
        "line_to_circle": lambda: sc.line_to_circle((0, 0), (1, 0), (0, 1.3), 1.0),
        "line_to_circle row": lambda: KLC.line_to_circle_row(0.0, 0.0, 1.0, 0.0, 0.0, 1.3, 1.0, code, out1, 0),
        "circle_to_circle": lambda: sc.circle_to_circle((0, 0), -1.0, (4, 0), 1.5),
        "circle_to_circle row": lambda: KC.circle_to_circle_row(0.0, 0.0, -1.0, 4.0, 0.0, 1.5, code, out2, 0),
        "line_to_line": lambda: sc.line_to_line((0, 0), (10, 0), (15, 8)),
        "line_to_line row": lambda: KLL.line_to_line_row(0.0, 0.0, 10.0, 0.0, 15.0, 8.0, np.nan, code, out2, 0),
        "circle_in_circle": lambda: sc.circle_in_circle((0, 0), 1.0, (0, 0.595), 0.4),
        "circle_in_circle row": lambda: KC.circle_in_circle_row(0.0, 0.0, 1.0, 0.0, 0.595, 0.4, code, out1, 0),
        "BezierSpiral": lambda: sc.BezierSpiral((0, 0), (1, 0), 0.5, 1.0),
    }, rounds, number)  # fmt: skip
    for name in ("line_to_circle", "circle_to_circle", "line_to_line", "circle_in_circle"):
        row = t[f"{name} row"].median * 1e6
        report.add(f"scalar `{name}`" + (" (an S)" if name == "circle_to_circle" else ""), t[name].median * 1e6, "µs/call",
                   t[name], f"its row kernel alone {row:.2f} µs", row / (t[name].median * 1e6),
                   "≤ 3 µs" if name == "line_to_circle" else "")  # fmt: skip
    report.add("scalar `BezierSpiral(...)`", t["BezierSpiral"].median * 1e6, "µs/call", t["BezierSpiral"])


def evaluation(report: Report, n: int, rounds: int, rng: np.random.Generator) -> None:
    spiral = sc.BezierSpiral((0, 0), (1, 0), 0.7, 1.0)
    cp = spiral.control_points
    u = rng.random(n)
    t = compare({
        "point": lambda: spiral.point(u),
        "curvature": lambda: spiral.curvature(u),
        "tangent": lambda: spiral.tangent(u),
        "bernstein points": lambda: bernstein_points(cp, u),
        "bernstein curvature": lambda: bernstein_curvature(cp, u),
        "fresnel": lambda: clothoid_points(u),
    }, rounds)  # fmt: skip
    for name, peer in (("point", "bernstein points"), ("curvature", "bernstein curvature"), ("tangent", "bernstein points")):
        report.add(f"evaluation `{name}(u)`", per_second(n, t[name]), "M points/s", t[name],
                   f"numpy Bernstein {per_second(n, t[peer]):.0f} M/s", t[peer].median / t[name].median,
                   "≥ 100" if name != "tangent" else "")  # fmt: skip
    report.add("peer: clothoid points, scipy.special.fresnel", per_second(n, t["fresnel"]), "M points/s", t["fresnel"],
               "ours `point(u)`", t["fresnel"].median / t["point"].median)  # fmt: skip


def main() -> None:
    args = arguments(__doc__, rows=(1_000_000, 2_000), rounds=(9, 2), calls=(20_000, 200))
    rng = np.random.default_rng(1)
    report = Report("Core benchmark", f"{args.rows:,} rows per batch and points per evaluation; "
                    f"medians of {args.rounds} alternating rounds (scalar calls: of {args.calls:,} calls each).")  # fmt: skip
    batches(report, args.rows, args.rounds, rng)
    scalar_calls(report, args.rounds, args.calls)
    evaluation(report, args.rows, args.rounds, rng)
    report.section("How to read it", table(("column", "meaning"), [
        ("median", "the median of the rounds; every row of one block ran in the same rounds, alternating"),
        ("spread", "(slowest − fastest) / median of the rounds: how much the shared machine moved"),
        ("ratio", "the peer's median time over ours: > 1 means ours is faster (for a floor: the fraction of it we reach)"),
    ]))  # fmt: skip
    report.finish(args)


if __name__ == "__main__":
    main()
