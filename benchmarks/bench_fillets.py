"""G2 fillets at scale: every corner of an N-corner polygon rounded into a face, against build123d's fillet_2d.

Run: ``.venv/bin/python benchmarks/bench_fillets.py [--quick] [--corners N ...] [--peer-corners N ...] [--out FILE]``
(the harness and its conventions: ``timing.py``).

The polygon is a zigzag round a circle (alternating radii, every corner
turning about 77°), filleted with radius 5 % of its shortest side. Ours is
``spiral_cad.build123d.g2_fillet`` on the ``Face`` (spiral → arc → spiral at
every corner, exact edges, a valid face). The peer is build123d's
``Face.fillet_2d`` (OCCT's BRepFilletAPI_MakeFillet2d, circular arcs) on the
same face in the same run; it grows quadratically, so it is measured up to
``--peer-corners`` and the growth exponent fitted to those points is used to
estimate it at the larger sizes (marked "est."). Goal: no slower than
fillet_2d at 10 000 corners.
"""

from __future__ import annotations

import math
import time

import build123d as bd
import numpy as np
from timing import Report, arguments, table

from spiral_cad import NoSolutionError
from spiral_cad.build123d import g2_fillet

#: The modules whose code these numbers measure (stamped into the results: ``timing.code_stamp``).
MEASURES = (
    "spiral_cad.build123d",
    "spiral_cad.build123d._lines",
    "spiral_cad.build123d._parts",
    "spiral_cad.build123d._sketches",
    "spiral_cad.cad.fillet",
)


def zigzag_face(corners: int) -> tuple[bd.Face, float]:
    k = np.arange(corners)
    step = 2.0 * math.pi * 100.0 / corners
    radius = np.where(k % 2 == 0, 100.0, 100.0 - 0.8 * step)
    angle = 2.0 * math.pi * k / corners
    points = [(float(x), float(y)) for x, y in zip(radius * np.cos(angle), radius * np.sin(angle))]
    side = min(math.dist(points[i], points[(i + 1) % corners]) for i in range(corners))
    return bd.Face(bd.Polyline(*points, close=True)), 0.05 * side


def timed(fn) -> tuple[float, object]:
    started = time.perf_counter()
    result = fn()
    return time.perf_counter() - started, result


def main() -> None:
    args = arguments(__doc__, corners=([1000, 10_000], [40]), peer_corners=([100, 200, 400], [10, 20]))
    rows, peer = [], {}
    for n in sorted(set(args.peer_corners)):  # single runs: the peer takes minutes at these sizes
        face, radius = zigzag_face(n)
        seconds, theirs = timed(lambda: face.fillet_2d(radius, face.vertices()))
        assert theirs.is_valid
        peer[n] = seconds
        ours, mine = timed(lambda: g2_fillet(face, radius))
        assert mine.is_valid
        rows.append([f"{n:,}", f"{ours:.3f}", f"{seconds:.3f}", f"{seconds / ours:.1f}×"])
        print(" | ".join(rows[-1]), flush=True)
    sizes = np.array(sorted(peer))
    exponent, scale = np.polyfit(np.log(sizes), np.log([peer[n] for n in sizes]), 1)
    for n in args.corners:
        face, radius = zigzag_face(n)
        estimate = math.exp(scale) * n**exponent
        try:
            ours, mine = timed(lambda: g2_fillet(face, radius))
        except NoSolutionError as refusal:  # the one rule: a refusal is an answer, and the table says so
            rows.append([f"{n:,}", f"refused: {str(refusal).split(':', 2)[1].strip()}", f"est. {estimate:,.0f}", "—"])
        else:
            assert mine.is_valid and len(mine.edges()) == 4 * n
            rows.append([f"{n:,}", f"{ours:.3f}", f"est. {estimate:,.0f}", f"est. {estimate / ours:,.0f}×"])
        print(" | ".join(rows[-1]), flush=True)
    note = f"Single runs; fillet_2d grows as N^{exponent:.2f} (fitted to {', '.join(map(str, sizes))} corners)."
    report = Report("G2 fillets at scale", note)
    header = ["corners", "g2_fillet (ours), s", "fillet_2d (peer), s", "peer / ours"]
    report.section("g2_fillet against build123d's fillet_2d", table(header, rows))
    report.finish(args)


if __name__ == "__main__":
    main()
