"""Corner rounding throughput: 1,000,000 corners of a random polyline.

Run: ``.venv/bin/python benchmarks/bench_rounding.py [--corners N] [--repeat R]``.
Times ``corner_legs`` (leg sharing along the polyline) plus
``round_corners_batch`` for both spiral pairs and prints a markdown table of
medians over ``repeat`` runs. Goal: 1 M corners in ≤ 1 s.
"""

from __future__ import annotations

import argparse

import numpy as np
from timing import machine, median_time

from spiral_cad.design import corner_legs, round_corners_batch


def random_polyline(corners: int, rng: np.random.Generator) -> np.ndarray:
    """A walk with legs in [1, 10] and turns in ±[5°, 150°]."""
    legs = rng.uniform(1.0, 10.0, corners + 1)
    turns = rng.uniform(np.radians(5.0), np.radians(150.0), corners + 1) * rng.choice([-1.0, 1.0], corners + 1)
    turns[0] = 0.0
    heading = np.cumsum(turns)
    steps = legs[:, None] * np.stack([np.cos(heading), np.sin(heading)], axis=1)
    return np.vstack([np.zeros((1, 2)), np.cumsum(steps, axis=0)])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--corners", type=int, default=1_000_000)
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--out", help="also write the table to this markdown file")
    args = parser.parse_args()
    lines: list[str] = []

    def emit(line: str = "") -> None:
        print(line, flush=True)
        lines.append(line)

    points = random_polyline(args.corners, np.random.default_rng(1))
    emit(f"machine: {machine()}")
    emit(f"{args.corners:,} corners, median of {args.repeat} runs\n")
    emit("| case | time (s) | corners/s | 1 M corners ≤ 1 s |")
    emit("|---|---:|---:|:---:|")
    legs_time = median_time(lambda: corner_legs(points), args.repeat)
    p0, corners, p1, _ = corner_legs(points)
    cases = [
        ("corner_legs (leg sharing) only", lambda: corner_legs(points), None),
        ("walton-meek, largest fit", lambda: round_corners_batch(p0, corners, p1), "walton-meek"),
        ("walton-meek, κmax = 2", lambda: round_corners_batch(p0, corners, p1, max_curvature=2.0), "walton-meek"),
        ("g2cbs, largest fit", lambda: round_corners_batch(p0, corners, p1, method="g2cbs"), "g2cbs"),
        ("g2cbs, κmax = 2", lambda: round_corners_batch(p0, corners, p1, max_curvature=2.0, method="g2cbs"), "g2cbs"),
    ]
    for name, fn, method in cases:
        t = legs_time if method is None else median_time(fn, args.repeat)
        total = t if method is None else t + legs_time  # polyline → spirals, end to end
        label = name if method is None else f"{name} (+ legs)"
        per_million = total * 1e6 / args.corners
        goal = "yes" if per_million <= 1.0 else "no"
        emit(f"| {label} | {total:.3f} | {args.corners / total:,.0f} | {goal} |")
    result = round_corners_batch(p0, corners, p1, max_curvature=2.0)
    emit(f"\nκmax = 2: {result.ok.sum():,} corners rounded, {(~result.ok).sum():,} report legs too short")

    if args.out:
        with open(args.out, "w", encoding="utf-8") as fh:
            fh.write("# Corner rounding benchmark\n\n" + "\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
