"""Road design at scale: choosing spirals from criteria, OpenDRIVE out and in, plots, for long alignments.

Run: ``.venv/bin/python benchmarks/bench_roads.py [--pis N ...] [--repeat R] [--out FILE]``.
Prints a markdown table of medians over ``repeat`` runs for alignments of
N PIs (a zigzag of 1 km tangents, R = 800 m, 80 km/h). Goals: choosing the
spirals of 1 000 PIs and writing/reading their OpenDRIVE each well under a
second; plots linear in the chain length. The peer is the same alignment
built from given spiral angles (no criteria), measured in the same run.
"read clothoid .xodr" reads a file of as many roads of three ``<spiral>``
geometries each (in, nearly circular, out: what exported maps hold), every
clothoid evaluated to rounding accuracy.
"""

from __future__ import annotations

import tempfile
from pathlib import Path

from timing import arguments, machine, median_time, write_markdown

from spiral_cad.cad.export import export_opendrive
from spiral_cad.design import Alignment
from spiral_cad.io.opendrive import check_opendrive, read_network, read_opendrive

#: The modules whose code these numbers measure (stamped into the results: ``timing.code_stamp``).
MEASURES = (
    "spiral_cad.design.alignment",
    "spiral_cad.io.opendrive",
    "spiral_cad.io.opendrive_read",
    "spiral_cad.io.opendrive_check",
    "spiral_cad.app.plots",
)


def zigzag(count: int) -> list[list[float]]:
    return [[1000.0 * k, 250.0 * (k % 2)] for k in range(count + 2)]


def clothoid_roads(count: int) -> str:
    """An OpenDRIVE text of ``count`` roads, each a spiral in, a nearly circular spiral and a spiral out."""
    k = 1.0 / 800.0
    roads = []
    for i in range(count):
        spirals = ((0.0, k, 60.0), (k, k + 1e-13 * (i % 7), 120.0), (k, 0.0, 60.0))
        geometries, s = [], 0.0
        for k0, k1, length in spirals:
            geometries.append(f'<geometry s="{s!r}" x="{1000.0 * i!r}" y="{s!r}" hdg="0.5" length="{length!r}">'
                              f'<spiral curvStart="{k0!r}" curvEnd="{k1!r}"/></geometry>')  # fmt: skip
            s += length
        roads.append(f'<road id="{i}" junction="-1" length="{s!r}"><planView>{"".join(geometries)}</planView></road>')
    return f'<?xml version="1.0"?><OpenDRIVE><header revMajor="1" revMinor="8"/>{"".join(roads)}</OpenDRIVE>'


def main() -> None:
    args = arguments(__doc__, pis=([250, 1000, 4000], [4]), repeat=(3, 1))
    rows = []
    folder = Path(tempfile.mkdtemp())
    for count in args.pis:
        pis = zigzag(count)
        given = median_time(lambda: Alignment.from_pis(pis, 800.0, spiral_angles=0.08, units="m"), args.repeat)
        chosen = median_time(lambda: Alignment.from_pis(pis, 800.0, units="m", design_speed=80, max_jerk=0.6), args.repeat)
        alignment = Alignment.from_pis(pis, 800.0, units="m", design_speed=80, max_jerk=0.6)
        path = folder / "road.xodr"
        write = median_time(lambda: export_opendrive(alignment, path), args.repeat)
        read = median_time(lambda: read_opendrive(path)[0].chain(), args.repeat)
        check = median_time(lambda: check_opendrive(path), args.repeat)
        spirals = folder / "spirals.xodr"
        spirals.write_text(clothoid_roads(count))
        clothoids = median_time(lambda: read_network(spirals), args.repeat)
        import matplotlib

        matplotlib.use("Agg")
        from spiral_cad.app.plots import plot_plan

        plot = median_time(lambda: plot_plan(alignment.chain).savefig(folder / "plan.png", dpi=110), 1)
        per_k = 1000.0 / count
        rows.append([
            f"{count:,}", f"{len(alignment.chain):,}", f"{given * per_k:.3f}", f"{chosen * per_k:.3f}",
            f"{chosen / given:.2f}×", f"{write * per_k:.3f}", f"{read * per_k:.3f}", f"{check * per_k:.3f}", f"{clothoids * per_k:.3f}",
            f"{plot:.2f}",
        ])  # fmt: skip
        print(" | ".join(rows[-1]), flush=True)
    header = ["PIs", "segments", "given spirals, s/1000 PIs", "chosen by criteria, s/1000 PIs", "ratio",
              "write .xodr, s/1000 PIs", "read .xodr → Chain, s/1000 PIs", "check .xodr, s/1000 PIs", "read clothoid .xodr, s/1000 roads", "plot_plan + PNG, s"]  # fmt: skip
    print("| " + " | ".join(header) + " |")
    for row in rows:
        print("| " + " | ".join(row) + " |")
    print(f"machine: {machine()}")
    if args.out:
        write_markdown(args.out, "Road design at scale", f"Medians of {args.repeat} runs.", header, rows)


if __name__ == "__main__":
    main()
