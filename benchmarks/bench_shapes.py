"""Spiral shapes side by side: the jerk-limited design table and peak/mean dκ/ds by spiral angle.

Run: ``.venv/bin/python benchmarks/bench_shapes.py [--quick] [--samples N] [--out FILE]`` (conventions: ``timing.py``).

1. Design speed V, radius R and jerk limit C → the spiral length L and the
   circle's shift p of the clothoid rule (L = v³/(R·C), p ≈ L²/(24R)), of the
   1996 spiral and of the near-linear spiral, each the shortest whose *peak*
   jerk v³·max dκ/ds meets C (``RoadCriteria.choose`` with the shift limits
   lifted), and whether the road criteria (0.2 m ≤ p ≤ 1.0 m) can be met.
2. Peak over mean dκ/ds by spiral angle θ for each shape, measured on the
   spirals by dense sampling (4·10⁵ points) — the extended Fig. 6 table.
"""

from __future__ import annotations

import math

import numpy as np
from timing import Report, arguments, table

from spiral_cad import BezierSpiral
from spiral_cad.core.factors import length_factor, shift_factor
from spiral_cad.design import RoadCriteria

#: The modules whose code these numbers measure (stamped into the results: ``timing.code_stamp``).
MEASURES = ("spiral_cad.core.spiral", "spiral_cad.core.factors", "spiral_cad.design.criteria")

SHAPES = ("walton-meek", "near-linear")
DESIGNS = ((60, 120, 0.9), (80, 250, 0.6), (100, 500, 0.5), (100, 700, 0.5), (120, 1000, 0.3))
ANGLES = (2, 5, 8, 15, 30, 45, 60)


def design_rows(designs=DESIGNS) -> list[list[str]]:
    rows = []
    for speed, radius, jerk in designs:
        v = speed / 3.6
        clothoid = v**3 / (radius * jerk)
        row = [f"{speed}", f"{radius}", f"{jerk}", f"{clothoid:.2f}, {clothoid**2 / (24 * radius):.3f}"]
        relaxed = RoadCriteria(speed, jerk, shift_min=0.0, shift_max=1e9)
        for shape in SHAPES:
            theta = relaxed.choose([float(radius)], "m", shape)[0]
            length = float(length_factor(theta, shape)[0]) * radius
            shift = float(shift_factor(theta, shape)[0]) * radius
            meets = 0.2 <= shift <= 1.0
            row.append(f"{length:.2f}, {shift:.3f} ({length / clothoid:.3f}×){'' if meets else ' — p > 1 m: refused'}")
        rows.append(row)
    return rows


def ratio(theta: float, shape: str, samples: int) -> float:
    """max dκ/ds · L / κ_end, sampled densely along the spiral."""
    spiral = BezierSpiral((0.0, 0.0), (1.0, 0.0), theta, 1.0, shape=shape)
    u = np.linspace(0.0, 1.0, samples)
    points = spiral.point(u)
    s = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(points, axis=0).T))])
    kappa = spiral.curvature(u)
    return float(np.max(np.diff(kappa) / np.diff(s)) * s[-1] / kappa[-1])


def angle_rows(samples: int, angles=ANGLES) -> list[list[str]]:
    rows = []
    for degrees in angles:
        cells = [f"{degrees}°"]
        for shape in SHAPES:
            fits = shape != "near-linear" or degrees <= 50
            cells.append(f"{ratio(math.radians(degrees), shape, samples):.4f}" if fits else "— (near-linear ends at 50°)")
        rows.append(cells)
    return rows


def main() -> None:
    args = arguments(__doc__, samples=(400_001, 2_001))
    designs, angles = (DESIGNS[2:3], ANGLES[:2]) if args.quick else (DESIGNS, ANGLES)
    report = Report("Spiral shapes")
    header = ["V km/h", "R m", "C m/s³", "clothoid L, p (m)", "1996 spiral L, p (m)", "near-linear L, p (m)"]
    report.section(
        "Spiral length at a jerk limit",
        "The shortest spiral whose peak lateral jerk v³·max dκ/ds equals C "
        "(the clothoid's is constant). Road criteria also ask 0.2 m ≤ p ≤ 1.0 m.\n\n" + table(header, design_rows(designs)),
    )
    report.section("Peak over mean dκ/ds by spiral angle", f"Measured on the spirals ({args.samples:,} samples): the clothoid's is 1.\n\n"
                   + table(["θ", "1996 spiral", "near-linear"], angle_rows(args.samples, angles)))  # fmt: skip
    report.finish(args)


if __name__ == "__main__":
    main()
