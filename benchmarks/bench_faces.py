"""Face checker on STEP files of ~100, ~300 and ~1 000 faces: time per face, linear in the faces.

Run: ``.venv/bin/python benchmarks/bench_faces.py [--quick] [--repeat R] [--boxes N N N] [--out FILE]``.

Each file is an array of build123d boxes (40 × 20 × 8) with their vertical edges filleted
(10 faces, 8 G1 and 16 sharp edges each), written as one STEP compound. ``check_faces(path)``
reads it in a child process and measures there (16 samples per edge); the peer is the same
measuring and classifying on the shape already in memory (no reader): the difference is the
reader's share. The growth exponent of the time in the faces should be 1 (linear).
"""

from __future__ import annotations

import tempfile
from pathlib import Path

import build123d as bd
from timing import arguments, compare, growth_exponent, machine, write_markdown

from spiral_cad.cad.faces import check_faces


def boxes(count: int) -> bd.Compound:
    """``count`` filleted boxes on a grid, one compound."""
    box = bd.fillet(bd.Box(40, 20, 8).edges().filter_by(bd.Axis.Z), 2)
    return bd.Compound([box.moved(bd.Location((50 * (i % 10), 30 * (i // 10), 0))) for i in range(count)])


def main() -> None:
    args = arguments(__doc__, repeat=(5, 1), boxes=([10, 30, 100], [2, 6]))
    rows, faces, seconds = [], [], []
    with tempfile.TemporaryDirectory() as folder:
        for count in args.boxes:
            part = boxes(count)
            path = Path(folder) / f"boxes_{count}.step"
            bd.export_step(part, str(path))
            report = check_faces(path)
            assert report.counts["G1"] == 8 * count and report.counts["sharp"] == 16 * count, report.describe()
            best = compare({"file": lambda: check_faces(path), "shape": lambda: check_faces(part)}, args.repeat)
            ours, shape = best["file"].median, best["shape"].median
            faces.append(report.faces)
            seconds.append(ours)
            rows.append((f"{report.faces:,} faces, {len(report.edges):,} edges", f"{ours * 1000:,.0f} ms",
                         f"{ours / report.faces * 1e6:,.0f} µs", f"{shape * 1000:,.0f} ms",
                         f"{shape / report.faces * 1e6:,.0f} µs", f"{1 - shape / ours:.0%}"))  # fmt: skip
    exponent = growth_exponent(faces, seconds) if len(faces) > 1 else float("nan")
    header = ("file", "check_faces(file)", "per face", "check_faces(shape)", "per face", "reader's share")
    width = max(len(r[0]) for r in rows)
    for row in rows:
        print(f"{row[0]:{width}}  " + "  ".join(f"{cell:>12}" for cell in row[1:]))
    print(f"growth exponent of the file check in the faces: {exponent:.2f} (1: linear)")
    print(machine())
    if args.out:
        write_markdown(args.out, "Face checker: time per face",
                       f"Medians of {args.repeat} interleaved runs; 16 samples per edge. Growth exponent of the file "
                       f"check in the faces: {exponent:.2f} (1: linear).", header, rows)  # fmt: skip


if __name__ == "__main__":
    main()
