"""make_g2 throughput: a long random G1 path of lines and tangent arcs made G2, against its parts.

Run: ``.venv/bin/python benchmarks/bench_make_g2.py [--quick] [--joints N] [--rounds R] [--out FILE]``
(the harness and its conventions: ``timing.py``). Times ``make_g2`` end to end on a
path of N joints (line → arc → line …, radii 1–10, sweeps 0.3–1.5 rad, lines 1–3
long, arcs turning either way) and, in the same alternating rounds, its parts as
peers: the batch transition solve alone (``batch.line_to_circle`` of the same N
joints: what the formulas cost) and a ``Chain`` of the same number of segments
(what building the result costs). Goal of the issue: 1 M joints/s for 1 000 000
joints in a batch path; the table says what bounds ``make_g2``.
"""

from __future__ import annotations

import math

import numpy as np
from timing import Report, arguments, compare, per_second

from spiral_cad import Arc, Chain, Line, batch
from spiral_cad.design import make_g2

#: The modules whose code these numbers measure (stamped into the results: ``timing.code_stamp``).
MEASURES = ("spiral_cad.design.g2", "spiral_cad.design._g2_measure", "spiral_cad.design._g2_pieces", "spiral_cad.design._g2_solve")


def random_g1_path(joints: int, rng: np.random.Generator) -> list:
    """Lines and tangent arcs alternating (``joints`` + 1 segments)."""
    x = y = heading = 0.0
    segments = []
    for k in range(joints + 1):
        if k % 2 == 0:
            length = rng.uniform(1.0, 3.0)
            end = (x + length * math.cos(heading), y + length * math.sin(heading))
            segments.append(Line((x, y), end))
            x, y = end
        else:
            radius = rng.uniform(1.0, 10.0) * rng.choice([-1.0, 1.0])
            sweep = rng.uniform(0.3, 1.5)
            cx, cy = x - radius * math.sin(heading), y + radius * math.cos(heading)
            arc = Arc((cx, cy), radius, math.atan2(y - cy, x - cx), sweep)
            segments.append(arc)
            x, y = arc.end.tolist()
            heading += math.copysign(sweep, radius)
    return segments


def main() -> None:
    args = arguments(__doc__, joints=(20_000, 2_000), rounds=(3, 1))
    n = args.joints
    segments = random_g1_path(n, np.random.default_rng(1))
    # The same joints as one batch of Theorem 4.1 problems (each line onto the next arc, shrunk by 0.01).
    lines = [s for s in segments if isinstance(s, Line)]
    arcs = [s for s in segments if isinstance(s, Arc)]
    points = np.array([line.end for line in lines[: len(arcs)]])
    directions = np.array([line.end - line.start for line in lines[: len(arcs)]])
    centres = np.array([arc.center for arc in arcs])
    radii = np.array([abs(arc.radius) - 0.01 for arc in arcs])
    result = make_g2(segments, 0.01)
    pieces = list(result.chain)
    jobs = {
        "make_g2": lambda: make_g2(segments, 0.01),
        "batch.line_to_circle": lambda: batch.line_to_circle(points, directions, centres, radii, shape="near-linear"),
        "Chain of the result's segments": lambda: Chain(pieces),
    }
    t = compare(jobs, args.rounds)
    report = Report(
        "make_g2 benchmark",
        f"{n:,} joints of a random G1 path of lines and arcs (bound 0.01, near-linear); medians of {args.rounds} alternating rounds.",
    )
    ours = t["make_g2"]
    rate = per_second(n, ours)
    report.add("make_g2, end to end", rate, "M joints/s", ours, "", None,
               "1 M joints/s" + ("" if rate >= 1.0 else f": missed ({1.0 / rate:,.0f}× short)"))  # fmt: skip
    solve = t["batch.line_to_circle"]
    report.add("batch.line_to_circle of the same joints (its formulas alone)", per_second(len(arcs), solve), "M joints/s", solve,
               f"make_g2 takes {ours.median / solve.median:,.0f}× as long")  # fmt: skip
    chain = t["Chain of the result's segments"]
    report.add(f"Chain of its {len(pieces):,} segments (building the result alone)", per_second(n, chain), "M joints/s", chain,
               f"make_g2 takes {ours.median / chain.median:,.1f}× as long")  # fmt: skip
    report.section(
        "What bounds it",
        "make_g2 solves every joint of a kind in one batch call and measures the deviation of all joints at once in "
        "arrays (sampled spirals against exact distances to the lines and arcs, Newton-polished nearest points on the "
        "spirals), with Python's cycle collector paused. What is left is per-joint Python: a piece record per input "
        "segment and the classification of each joint, a result record per transition, a Line, Arc or BezierSpiral "
        "object per piece of the result and the Chain's check of every joint, and a G2Joint record (with its "
        "description) per joint. Timed by parts on 20,000 joints the measure takes about 40 %, the solve around the "
        "batch call about 13 %, the segment objects and the Chain about 15 %, pieces and classification about 12 %, "
        "the joint records and grouping the rest: the transition formulas are not the limit (the ratio above). 1 M "
        "joints/s needs the result held as arrays until a Chain is asked for, and the measure in compiled code.",
    )
    report.finish(args)


if __name__ == "__main__":
    main()
