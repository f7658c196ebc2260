"""Corner rounding throughput: every corner of a long random polyline, against leg sharing alone.

Run: ``.venv/bin/python benchmarks/bench_rounding.py [--quick] [--corners N] [--rounds R] [--out FILE]``
(the harness and its conventions: ``timing.py``). Times ``corner_legs`` (leg
sharing along the polyline) and ``round_corners_batch`` for each spiral pair,
all in the same alternating rounds; the peer is ``corner_legs`` alone (the
work any rounding must do first). Goal: 1 M corners in ≤ 1 s, legs included.
"""

from __future__ import annotations

import numpy as np
from timing import Report, arguments, compare, per_second

from spiral_cad.design import corner_legs, round_corners_batch

#: The modules whose code these numbers measure (stamped into the results: ``timing.code_stamp``).
MEASURES = (
    "spiral_cad.design.rounding",
    "spiral_cad.design.rounded_paths",
    "spiral_cad.core.space",
    "spiral_cad.core._chain_kernels",
    "spiral_cad.core._kernels",
    "spiral_cad.core._kernel_spiral",
    "spiral_cad.core._kernel_line_line",
    "spiral_cad.core.batch",
)


def random_polyline(corners: int, rng: np.random.Generator) -> np.ndarray:
    """A walk with legs in [1, 10] and turns in ±[5°, 150°]."""
    legs = rng.uniform(1.0, 10.0, corners + 1)
    turns = rng.uniform(np.radians(5.0), np.radians(150.0), corners + 1) * rng.choice([-1.0, 1.0], corners + 1)
    turns[0] = 0.0
    heading = np.cumsum(turns)
    steps = legs[:, None] * np.stack([np.cos(heading), np.sin(heading)], axis=1)
    return np.vstack([np.zeros((1, 2)), np.cumsum(steps, axis=0)])


def main() -> None:
    args = arguments(__doc__, corners=(1_000_000, 2_000), rounds=(5, 1))
    n = args.corners
    points = random_polyline(n, np.random.default_rng(1))
    p0, corners, p1, _ = corner_legs(points)
    jobs = {
        "legs": lambda: corner_legs(points),
        "walton-meek, largest fit": lambda: round_corners_batch(p0, corners, p1),
        "walton-meek, κmax = 2": lambda: round_corners_batch(p0, corners, p1, max_curvature=2.0),
        "near-linear, largest fit": lambda: round_corners_batch(p0, corners, p1, shape="near-linear"),
        "g2cbs, largest fit": lambda: round_corners_batch(p0, corners, p1, shape="g2cbs"),
        "g2cbs, κmax = 2": lambda: round_corners_batch(p0, corners, p1, max_curvature=2.0, shape="g2cbs"),
    }
    t = compare(jobs, args.rounds)
    report = Report("Corner rounding benchmark", f"{n:,} corners of a random polyline; medians of {args.rounds} alternating rounds.")
    legs = t.pop("legs")
    report.add("corner_legs (leg sharing) alone", per_second(n, legs), "M corners/s", legs)
    for name, timing in t.items():
        total = timing.median + legs.median  # polyline → spirals, end to end
        report.add(f"{name} (+ legs)", n / total / 1e6, "M corners/s", timing, f"legs alone {legs.median * 1e3:,.1f} ms",
                   legs.median / total, "1 M corners ≤ 1 s" if total * 1e6 / n <= 1.0 else "1 M corners ≤ 1 s: missed")  # fmt: skip
    result = round_corners_batch(p0, corners, p1, max_curvature=2.0)
    report.section("κmax = 2", f"{int(result.ok.sum()):,} corners rounded, {int((~result.ok).sum()):,} report legs too short.")
    report.finish(args)


if __name__ == "__main__":
    main()
