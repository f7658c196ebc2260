"""G2 paths in space: 3-D corner rounding in batch, a G-code program end to end, a swept handrail.

Run: ``.venv/bin/python benchmarks/bench_paths3d.py [--repeat R] [--quick] [--out FILE]``.

Jobs, each with a peer measured in the same run:

* **3-D rounding of 1 M corners** (``corner_legs`` + ``round_corners_batch``,
  ``max_deviation``: every corner solved in its plane by the plane kernel,
  placed and verified in space), against the same polyline in the plane
  (the 2-D batch, same kernel) and against the per-corner route
  (``PlaneFrame.of_corner`` + ``line_to_line`` + ``placed``, timed on a
  sample and scaled). Goal: 1 M corners in about a second.
* **A 100 k-move G-code program end to end**: read (``read_gcode``), round
  (``round_toolpath``, max_deviation 0.01 mm), write STEP and samples at a
  0.005 mm chord tolerance (``spiral-cad build --from-gcode`` does these);
  peer: the raw polyline written as STEP.
* **Sweeping a 1 000-corner handrail** with a circle (build123d ``G2Polyline``
  + ``sweep``, a valid solid), against sweeping the raw polyline with round
  corner transitions (``Transition.ROUND``, G1 only).

``--quick`` runs small sizes once (checks that the script works).
"""

from __future__ import annotations

import math
import tempfile
import time
from pathlib import Path

import numpy as np
from timing import arguments, code_stamp, load, machine, median_time

#: The modules whose code these numbers measure (stamped into the results: ``timing.code_stamp``).
MEASURES = (
    "spiral_cad.design.rounding",
    "spiral_cad.design.rounded_paths",
    "spiral_cad.core.space",
    "spiral_cad.core._chain_kernels",
    "spiral_cad.io.gcode",
    "spiral_cad.io.toolpath_rounding",
    "spiral_cad.cad.export",
    "spiral_cad.build123d",
    "spiral_cad.build123d._lines",
    "spiral_cad.build123d._parts",
    "spiral_cad.build123d._sketches",
)

SIZES = {"corners": 1_000_000, "moves": 100_000, "handrail": 1_000, "scalar": 2_000}
QUICK = {"corners": 20_000, "moves": 2_000, "handrail": 30, "scalar": 200}


def random_polyline(corners: int, dim: int, rng: np.random.Generator) -> np.ndarray:
    """A walk with legs in [1, 10] and turns in [5°, 150°], each about a random axis in space (dim 3)."""
    legs = rng.uniform(1.0, 10.0, corners + 1)
    turns = rng.uniform(math.radians(5.0), math.radians(150.0), corners + 1)
    if dim == 2:
        heading = np.cumsum(turns * rng.choice([-1.0, 1.0], corners + 1))
        steps = np.stack([np.cos(heading), np.sin(heading)], axis=1)
    else:
        steps = np.empty((corners + 1, 3))
        d = np.array([1.0, 0.0, 0.0])
        for i, turn in enumerate(turns):  # rotate d by ``turn`` towards a random perpendicular
            other = rng.normal(size=3)
            other -= (other @ d) * d
            other /= np.linalg.norm(other)
            d = math.cos(turn) * d + math.sin(turn) * other
            steps[i] = d
    return np.vstack([np.zeros((1, dim)), np.cumsum(legs[:, None] * steps, axis=0)])


def gcode_program(moves: int, rng: np.random.Generator) -> str:
    """A 3-D finishing toolpath: a zigzag over a wavy surface, 3 decimals, as a CAM post writes it."""
    lines = ["%", "(zigzag finishing pass)", "G21 G17 G90 G94", "T1 M6", "S12000 M3", "G0 X0. Y0. Z5.", "G1 Z0. F600."]
    row = 200
    k = np.arange(moves)
    x = (k % row) * 0.5
    x = np.where((k // row) % 2 == 0, x, (row - 1) * 0.5 - x)
    y = (k // row) * 0.4 + 0.05 * np.sin(k * 0.37)
    z = 2.0 * np.sin(x / 9.0) * np.cos(y / 7.0) + rng.uniform(-0.002, 0.002, moves)
    lines += [f"G1 X{a:.3f} Y{b:.3f} Z{c:.3f}" for a, b, c in zip(x, y, z)]
    return "\n".join(lines + ["G0 Z5.", "M5", "M30", "%", ""])


def handrail_points(corners: int, rng: np.random.Generator) -> list[tuple[float, float, float]]:
    """A stair handrail: legs of 300–600 mm turning 17°–52° left or right, climbing or falling."""
    pts, heading = [np.zeros(3)], 0.0
    for _ in range(corners + 1):
        heading += rng.choice([-1.0, 1.0]) * rng.uniform(0.3, 0.9)
        step = rng.uniform(300.0, 600.0)
        pts.append(pts[-1] + (step * math.cos(heading), step * math.sin(heading), rng.uniform(-80.0, 200.0)))
    return [tuple(p.tolist()) for p in pts]


def rounding_rows(sizes: dict, repeat: int) -> list[list[str]]:
    import spiral_cad as sc
    from spiral_cad.design import corner_legs, round_corners_batch

    rng = np.random.default_rng(1)
    rows = []
    space, plane = random_polyline(sizes["corners"], 3, rng), random_polyline(sizes["corners"], 2, rng)
    legs3, legs2 = corner_legs(space), corner_legs(plane)
    n = len(legs3[1])
    for shape in ("walton-meek", "g2cbs", "near-linear"):
        t3 = median_time(lambda: round_corners_batch(*legs3[:3], max_deviation=0.05, shape=shape), repeat)
        t2 = median_time(lambda: round_corners_batch(*legs2[:3], max_deviation=0.05, shape=shape), repeat)
        ok = int(round_corners_batch(*legs3[:3], max_deviation=0.05, shape=shape).ok.sum())
        rows.append([f"3-D batch, max_deviation 0.05, {shape}", f"{n:,}", f"{t3:.3f}", f"{n / t3 / 1e6:.2f} M/s",
                     f"2-D batch {t2:.3f} s: {t3 / t2:.2f}×", f"{ok:,} rounded"])  # fmt: skip
    legs_time = median_time(lambda: corner_legs(space), repeat)
    rows.append(["corner_legs (3-D leg sharing)", f"{n:,}", f"{legs_time:.3f}", f"{n / legs_time / 1e6:.2f} M/s", "", ""])
    # the per-corner route: one PlaneFrame, one scalar solve and two placed spirals per corner (at the
    # curvature the batch found for max_deviation, so both do the same work)
    m = sizes["scalar"]
    found = round_corners_batch(*legs3[:3], max_deviation=0.05)
    sample = np.flatnonzero(found.ok)[:m]
    p0, c, p1, k = (a[sample] for a in (*legs3[:3], found.curvature))

    def per_corner():
        for a, b, d, kappa in zip(p0, c, p1, k.tolist()):
            frame = sc.PlaneFrame.of_corner(a, b, d)
            pair = sc.line_to_line(frame.local(a), (0.0, 0.0), frame.local(d), curvature=kappa)
            [s.placed(frame) for s in pair.spirals]

    scalar = median_time(per_corner, max(1, repeat // 2)) * n / len(sample)
    batch = median_time(lambda: round_corners_batch(*legs3[:3], max_deviation=0.05), repeat)
    rows.append(["peer: per-corner PlaneFrame route (scaled from a sample)", f"{n:,}", f"{scalar:.1f}",
                 f"{n / scalar / 1e6:.3f} M/s", f"batch {batch:.3f} s: {scalar / batch:.0f}× faster", ""])  # fmt: skip
    return rows


def gcode_rows(sizes: dict, folder: Path) -> list[list[str]]:
    from build123d import Polyline

    from spiral_cad.cad.export import export_samples, export_step
    from spiral_cad.io.gcode import read_gcode
    from spiral_cad.io.toolpath_rounding import round_toolpath

    program = folder / "finish.nc"
    program.write_text(gcode_program(sizes["moves"], np.random.default_rng(2)))
    stages = {}
    t0 = time.perf_counter()
    path = read_gcode(program)
    stages["read"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    rounded = round_toolpath(path, max_deviation=0.01)
    stages["round"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    export_step(rounded.chain, folder / "finish.step")
    stages["STEP"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    count = export_samples(rounded.chain, folder / "finish.csv", chord_tolerance=0.005)
    stages["samples"] = time.perf_counter() - t0
    total = sum(stages.values())
    t0 = time.perf_counter()
    export_step(Polyline(*[tuple(p) for p in path.points.tolist()]), folder / "raw.step")
    raw = time.perf_counter() - t0
    detail = ", ".join(f"{k} {v:.2f}" for k, v in stages.items())
    return [[f"G-code {len(path):,} moves → {len(rounded.corners):,} corners, STEP + {count:,} samples", f"{len(path):,}",
             f"{total:.2f}", detail, f"raw polyline → STEP {raw:.2f} s", f"{rounded.chain.size:.0f} mm path"]]  # fmt: skip


def sweep_rows(sizes: dict) -> list[list[str]]:
    from build123d import Circle, Plane, Polyline, Transition, sweep

    from spiral_cad.build123d import G2Polyline

    pts = handrail_points(sizes["handrail"], np.random.default_rng(3))
    t0 = time.perf_counter()
    path = G2Polyline(*pts, radius=100)
    build = time.perf_counter() - t0
    t0 = time.perf_counter()
    solid = sweep(Plane(origin=path @ 0, z_dir=path % 0) * Circle(20), path=path)
    swept = time.perf_counter() - t0
    raw = Polyline(*pts)
    t0 = time.perf_counter()
    peer = sweep(Plane(origin=raw @ 0, z_dir=raw % 0) * Circle(20), path=raw, transition=Transition.ROUND)
    raw_time = time.perf_counter() - t0
    return [[f"handrail: G2Polyline + sweep of a Ø40 circle, {sizes['handrail']:,} corners", f"{len(path.edges()):,} edges",
             f"{build + swept:.2f}", f"path {build:.2f}, sweep {swept:.2f}; valid {solid.is_valid}",
             f"raw polyline, Transition.ROUND {raw_time:.2f} s (valid {peer.is_valid}): {(build + swept) / raw_time:.2f}×", ""]]  # fmt: skip


def main() -> None:
    args = arguments(__doc__, repeat=(5, 1))
    sizes, repeat = (QUICK if args.quick else SIZES), args.repeat
    head = ["job", "size", "time (s)", "rate / detail", "peer in the same run", "note"]
    with tempfile.TemporaryDirectory() as folder:
        rows = rounding_rows(sizes, repeat) + gcode_rows(sizes, Path(folder)) + sweep_rows(sizes)
    lines = [f"Machine: {machine()}; load {load()} when written; medians of {repeat} runs (G-code and sweep: one run each)", "",
             code_stamp(__file__, MEASURES), "", "| " + " | ".join(head) + " |", "|" + "---|" * len(head)]  # fmt: skip
    lines += ["| " + " | ".join(row) + " |" for row in rows]
    print("\n".join(lines))
    if args.out:
        Path(args.out).write_text("# G2 paths in space benchmark\n\n" + "\n".join(lines) + "\n", encoding="utf-8")


if __name__ == "__main__":
    main()
