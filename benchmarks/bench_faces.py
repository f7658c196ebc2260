"""Face checker on STEP files of ~100, ~300 and ~1 000 faces: time per face, linear in the faces.

Run: ``.venv/bin/python benchmarks/bench_faces.py [--quick] [--repeat R] [--boxes N N N] [--g2-boxes N N]
[--picture-boxes N N] [--out FILE]``.

Each file is an array of build123d boxes (40 × 20 × 8) with their vertical edges filleted
(10 faces, 8 G1 and 16 sharp edges each: planes and cylinders bounded by lines and circles), written as
one STEP compound; ``--g2-boxes`` adds arrays of ``ContinuousBox(40, 20, 8, 3)`` (B-spline faces and
edges, every edge G2). ``check_faces(path)``
reads it in a child process and measures there (a floor of 16 samples and both ends per edge,
more only at knots and where the geometry turns); the peer is the same
measuring and classifying on the shape already in memory (no reader): the difference is the
reader's share. The growth exponent of the time in the faces should be 1 (linear).

Pictures: ``spiral-cad check FILE --zebra Z.png`` draws the zebra stripes of ~100 and ~1 000 faces
(``--picture-boxes``) in a fresh Python process; the time to mesh, draw and write the PNG, and the
peak resident memory of that process and its reader child (``ru_maxrss``), are reported.
"""

from __future__ import annotations

import json
import subprocess
import sys
import tempfile
from pathlib import Path

import build123d as bd
from timing import arguments, compare, growth_exponent, machine, table, write_markdown

from spiral_cad.build123d import ContinuousBox
from spiral_cad.cad.faces import check_faces

#: The modules whose code these numbers measure (stamped into the results: ``timing.code_stamp``).
MEASURES = (
    "spiral_cad.cad.faces",
    "spiral_cad.cad.face_sampling",
    "spiral_cad.cad.face_projection",
    "spiral_cad.cad.batch_geometry",
    "spiral_cad.cad.batch_bspline",
    "spiral_cad.cad.readers",
    "spiral_cad.cad.mesh",
    "spiral_cad.app.zebra",
)


def boxes(count: int, g2: bool = False) -> bd.Compound:
    """``count`` filleted boxes on a grid, one compound: build123d's circular fillets (planes and cylinders
    bounded by lines and circles), or with ``g2`` ContinuousBoxes (mostly B-spline faces and edges)."""
    box = ContinuousBox(40, 20, 8, 3) if g2 else bd.fillet(bd.Box(40, 20, 8).edges().filter_by(bd.Axis.Z), 2)
    return bd.Compound([box.moved(bd.Location((50 * (i % 10), 30 * (i // 10), 0))) for i in range(count)])


#: Run in a fresh process: mesh a file, draw its zebra stripes, write the PNG; time and peak memory as JSON.
_PICTURE = """
import json, resource, sys, time
from spiral_cad.app.zebra import plot_zebra
from spiral_cad.cad.mesh import face_mesh
started = time.perf_counter()
mesh = face_mesh(sys.argv[1])
plot_zebra(mesh).savefig(sys.argv[2], dpi=120, bbox_inches="tight")
peak = max(resource.getrusage(who).ru_maxrss for who in (resource.RUSAGE_SELF, resource.RUSAGE_CHILDREN))
print(json.dumps({"seconds": time.perf_counter() - started, "peak_kb": peak, "triangles": len(mesh.triangles)}))
"""


def picture(path: Path) -> dict[str, float]:
    """Time, peak memory (kB) and triangles of the zebra picture of ``path``, in a fresh process."""
    done = subprocess.run([sys.executable, "-c", _PICTURE, str(path), str(path.with_suffix(".png"))], check=True,
                          capture_output=True, text=True, cwd=Path(__file__).resolve().parent.parent)  # fmt: skip
    return json.loads(done.stdout.splitlines()[-1])


def main() -> None:
    args = arguments(__doc__, repeat=(5, 1), boxes=([10, 30, 100], [2, 6]), picture_boxes=([10, 100], [2]),
                     g2_boxes=([4, 12], [1]))  # fmt: skip
    rows, faces, seconds = [], [], []
    with tempfile.TemporaryDirectory() as folder:
        for count, g2 in [(count, False) for count in args.boxes] + [(count, True) for count in args.g2_boxes]:
            part = boxes(count, g2)
            path = Path(folder) / f"boxes_{count}{'_g2' if g2 else ''}.step"
            bd.export_step(part, str(path))
            report = check_faces(path)
            if g2:
                assert report.passes("G2"), report.describe()
            else:
                assert report.counts["G1"] == 8 * count and report.counts["sharp"] == 16 * count, report.describe()
            best = compare({"file": lambda: check_faces(path), "shape": lambda: check_faces(part)}, args.repeat)
            ours, shape = best["file"].median, best["shape"].median
            if not g2:  # the growth exponent is of one kind of part
                faces.append(report.faces)
                seconds.append(ours)
            kind = "ContinuousBox" if g2 else "filleted box"
            rows.append((f"{count} × {kind}: {report.faces:,} faces, {len(report.edges):,} edges", f"{ours * 1000:,.0f} ms",
                         f"{ours / report.faces * 1e6:,.0f} µs", f"{shape * 1000:,.0f} ms",
                         f"{shape / report.faces * 1e6:,.0f} µs", f"{1 - shape / ours:.0%}"))  # fmt: skip
        pictures = []
        for count in args.picture_boxes:
            path = Path(folder) / f"picture_{count}.step"
            bd.export_step(boxes(count), str(path))
            got = picture(path)
            pictures.append((f"{10 * count:,} faces", f"{got['triangles']:,}", f"{got['seconds']:,.1f} s",
                             f"{got['peak_kb'] / 1024:,.0f} MB"))  # fmt: skip
    exponent = growth_exponent(faces, seconds) if len(faces) > 1 else float("nan")
    header = ("file", "check_faces(file)", "per face", "check_faces(shape)", "per face", "reader's share")
    width = max(len(r[0]) for r in rows)
    for row in rows:
        print(f"{row[0]:{width}}  " + "  ".join(f"{cell:>12}" for cell in row[1:]))
    print(f"growth exponent of the file check in the faces: {exponent:.2f} (1: linear)")
    picture_header = ("file", "triangles", "zebra picture (mesh, draw, write)", "peak memory")
    for row in pictures:
        print("zebra " + "  ".join(f"{cell:>12}" for cell in row))
    print(machine())
    if args.out:
        write_markdown(args.out, "Face checker: time per face",
                       f"Medians of {args.repeat} interleaved runs; a floor of 16 samples per edge, adapted. Growth exponent of the file "
                       f"check in the faces: {exponent:.2f} (1: linear).", header, rows)  # fmt: skip
        with open(args.out, "a", encoding="utf-8") as fh:
            fh.write(
                f"\n## Zebra pictures\n\nOne fresh process per file: mesh, draw and write the PNG (dpi 120); "
                f"peak resident memory of the process and its reader child.\n\n{table(picture_header, pictures)}\n"
            )


if __name__ == "__main__":
    main()
