"""Fitting points: fit_points against pyclothoids' G2 clothoid spline and build123d's Spline through the same points.

Run: ``.venv/bin/python benchmarks/bench_fit.py [--quick] [--points N] [--sizes N ...] [--out FILE]``
(the harness: ``timing.py``). A road centre line (tangent–spiral–arc–spiral–tangent twice, from
``Alignment.from_pis``) is sampled and given GPS-like noise (σ = 5 % of the tolerance). Ours
fits it within the tolerance; the peers pass through every point: pyclothoids (Bertolazzi–Frego
``SolveG2``, three clothoids per gap between the points' estimated tangent angles and
curvatures) and build123d's C2 B-spline ``Edge.make_spline``. Every curve is sampled at the same
fine spacing and judged alike: its worst deviation from the true (noise-free) centre line,
its pieces, the curvature sign changes (the true line has one) and the worst step of the
sampled curvature between neighbouring samples (a kink shows as a step). Then fit_points'
time at growing sizes (goal: 1 M points ≤ 10 s, linear).
"""

from __future__ import annotations

import time

import numpy as np
from timing import Report, arguments, compare, growth_exponent

from spiral_cad import fit_points
from spiral_cad.core.fit import chain_distances
from spiral_cad.design import Alignment

#: The modules whose code these numbers measure (stamped into the results: ``timing.code_stamp``).
MEASURES = ("spiral_cad.core.fit", "spiral_cad.core._fit_runs", "spiral_cad.core._fit_joins")

TOLERANCE = 0.05  # m


def road() -> Alignment:
    return Alignment.from_pis([(0, 0), (400, 0), (700, 300), (1100, 250)], radii=[300, 250], spiral_lengths=60, units="m")


def menger(points: np.ndarray) -> np.ndarray:
    """Signed three-point curvature of consecutive samples."""
    a, b, c = points[:-2], points[1:-1], points[2:]
    u, v, w = b - a, c - b, c - a
    cross = u[:, 0] * v[:, 1] - u[:, 1] * v[:, 0]
    return 2 * cross / (np.hypot(*u.T) * np.hypot(*v.T) * np.hypot(*w.T))


def judged(samples: np.ndarray, truth) -> dict[str, float]:
    kappa = menger(samples)
    signs = np.sign(kappa[np.abs(kappa) > 1e-5])
    return {
        "deviation": float(chain_distances(truth, samples)[0].max()),
        "sign changes": int(np.count_nonzero(np.diff(signs))),
        "curvature step": float(np.abs(np.diff(kappa)).max()),
    }


def even(points: np.ndarray, spacing: float) -> np.ndarray:
    """Resample a dense polyline at (about) even arc length."""
    s = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(points, axis=0).T))])
    t = np.arange(0.0, s[-1], spacing)
    return np.c_[np.interp(t, s, points[:, 0]), np.interp(t, s, points[:, 1])]


def clothoid_spline(points: np.ndarray):
    """pyclothoids: SolveG2 between consecutive points with angles and curvatures of the circle through each point's neighbours."""
    from pyclothoids import SolveG2

    previous, following = np.r_[points[:1], points[:-1]], np.r_[points[1:], points[-1:]]
    heading = np.arctan2(*(following - previous).T[::-1])
    kappa = np.r_[0.0, menger(points), 0.0]
    pieces = []
    for i in range(len(points) - 1):
        pieces += SolveG2(*points[i], heading[i], kappa[i], *points[i + 1], heading[i + 1], kappa[i + 1])
    return pieces


def clothoid_samples(pieces, spacing: float) -> np.ndarray:
    out = []
    for piece in pieces:
        count = max(2, int(piece.length / spacing) + 1)
        x, y = piece.SampleXY(count)
        out.append(np.c_[x, y][:-1])
    return np.vstack(out)


def readme_curve():
    """The README's first curve: line, Walton–Meek spiral, arc, spiral, line (5 pieces, 826 mm)."""
    from spiral_cad import Chain, line_to_circle

    enter = line_to_circle((0, 0), (1, 0), (100, 60), 50.0)
    leave = line_to_circle((300, 150), (-1, -1), (100, 60), 50.0).reversed()
    return Chain.join([enter, leave], start=(-20, 0), end=(400, 250), units="mm")


def own_design_table(quick: bool, with_build123d: bool) -> str:
    """Pieces of 400 noise-free points (100 with ``quick``) of the README curve fitted in each spiral shape at
    tolerances from 1e-9 to 1e-2 of its length; the interpolating peers pass through every point at any tolerance."""
    curve = readme_curve()
    points = curve.point_at(np.linspace(0.0, curve.length, 100 if quick else 400))
    interpolated = len(clothoid_spline(points))
    relatives = (1e-4,) if quick else (1e-9, 1e-7, 1e-6, 1e-5, 1e-4, 1e-3, 1e-2)
    shapes = ("walton-meek", "near-linear", "auto")
    lines = [
        f"{len(points)} points of the README's first curve ({len(curve)} pieces, Walton–Meek spirals, {curve.length:.0f} mm), no noise; "
        "pieces of each fit (its time in s), and of the peers, which interpolate every point at any tolerance.",
        "",
        "| tolerance (of the length) | "
        + " | ".join(f"fit_points `{shape}`" for shape in shapes)
        + " | pyclothoids SolveG2 spline |"
        + (" build123d Spline |" if with_build123d else ""),
        "|---" * (len(shapes) + 2 + with_build123d) + "|",
    ]
    for relative in relatives:
        cells = []
        for shape in shapes:
            started = time.perf_counter()
            try:
                fit = fit_points(points, relative * curve.length, shape=shape)
                cells.append(f"{fit.pieces:,} ({time.perf_counter() - started:.1f})")
            except ValueError:
                cells.append(f"refused ({time.perf_counter() - started:.1f})")
        peers = [f"{interpolated:,}"] + (["1"] if with_build123d else [])
        lines.append(f"| {relative:g} | " + " | ".join(cells + peers) + " |")
    return "\n".join(lines)


def main() -> None:
    args = arguments(__doc__, points=(400, 80), sizes=([10_000, 100_000, 1_000_000], [2_000]))
    truth = road().chain
    rng = np.random.default_rng(3)
    points = truth.point_at(np.linspace(0.0, truth.length, args.points)) + rng.normal(0.0, 0.05 * TOLERANCE, (args.points, 2))
    spacing = 0.05  # m: every curve judged on samples this far apart

    def b123d():
        from build123d import Edge, Vector

        return Edge.make_spline([Vector(x, y, 0.0) for x, y in points])

    jobs = {"fit_points": lambda: fit_points(points, TOLERANCE, units="m"), "pyclothoids SolveG2 spline": lambda: clothoid_spline(points)}
    try:
        b123d()
        jobs["build123d Spline"] = b123d
    except ImportError:  # the cad extra is not installed
        pass
    timings = compare(jobs, 1 if args.quick else 3)
    ours = fit_points(points, TOLERANCE, units="m")
    dense = ours.chain.point_at(np.arange(0.0, ours.chain.length, spacing))
    rows = {"fit_points": (judged(dense, truth), ours.pieces, ours.max_residual)}
    pieces = clothoid_spline(points)
    rows["pyclothoids SolveG2 spline"] = (judged(clothoid_samples(pieces, spacing), truth), len(pieces), 0.0)
    if "build123d Spline" in jobs:
        edge = b123d()
        u = np.linspace(0.0, 1.0, int(edge.length / spacing) + 1)
        samples = np.array([(p.X, p.Y) for p in edge.positions(u.tolist())])
        rows["build123d Spline"] = (judged(even(samples, spacing), truth), 1, 0.0)
    report = Report("Fitting points", f"{args.points:,} noisy points (σ = {0.05 * TOLERANCE:g} m) along a road; tolerance {TOLERANCE} m.")
    true = judged(truth.point_at(np.arange(0.0, truth.length, spacing)), truth)
    lines = ["| method | pieces | worst point residual [m] | worst deviation from the true line [m] | curvature sign changes | worst curvature step [1/m] | time [ms] |",
             "|---|---|---|---|---|---|---|",
             f"| true centre line | {len(truth)} | 0 | 0 | {true['sign changes']} | {true['curvature step']:.3g} | |"]  # fmt: skip
    for name, (measures, count, residual) in rows.items():
        lines.append(f"| {name} | {count:,} | {residual:.3g} | {measures['deviation']:.3g} | {measures['sign changes']} | "
                     f"{measures['curvature step']:.3g} | {timings[name].median * 1e3:,.1f} |")  # fmt: skip
    report.section("Against interpolation through the same points", "\n".join(lines))
    report.section("Our own design back, in each spiral shape", own_design_table(args.quick, "build123d Spline" in jobs))
    seconds = []
    for n in args.sizes:
        many = truth.point_at(np.linspace(0.0, truth.length, n)) + rng.normal(0.0, 0.05 * TOLERANCE, (n, 2))
        runs = []
        for _ in range(1 if args.quick else 3):  # the median of three runs: the machine is shared
            started = time.perf_counter()
            fit = fit_points(many, TOLERANCE, units="m")
            runs.append(time.perf_counter() - started)
        seconds.append(float(np.median(runs)))
        goal = "" if n < 1_000_000 else ("1 M points ≤ 10 s" if seconds[-1] <= 10 else "1 M points ≤ 10 s: missed")
        report.add(f"fit_points, {n:,} points ({fit.pieces} pieces, worst residual {fit.max_residual:.3g} m)", seconds[-1], "s", goal=goal)
    if len(seconds) > 1:
        report.add("growth exponent (time ∝ points^k)", growth_exponent(args.sizes, seconds), "k")
    report.finish(args)


if __name__ == "__main__":
    main()
