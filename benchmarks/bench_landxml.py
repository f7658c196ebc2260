"""LandXML 1.2 out and in for long alignments.

Run: ``.venv/bin/python benchmarks/bench_landxml.py [--pis N ...] [--repeat R] [--out FILE]``.
Prints a markdown table of medians over ``repeat`` runs for alignments of N
PIs (a zigzag of 1 km tangents, R = 800 m, spiral angle 0.08 rad: five
segments per PI), with a profile of a vertical curve every 2 km. "write"
is ``write_landxml`` (the spirals' offsets from their clothoids measured
too); "read" is ``read_landxml`` rebuilding the G2 chain and measuring every
element's offset. The peer is OpenDRIVE out and in of the same alignment,
measured in the same run. Goal: 10 000 PIs written and read in seconds.
"""

from __future__ import annotations

import tempfile
from pathlib import Path

from timing import arguments, machine, median_time, write_markdown

from spiral_cad.cad.export import export_opendrive
from spiral_cad.design import Alignment, Profile
from spiral_cad.io import read_landxml
from spiral_cad.io.landxml import write_landxml
from spiral_cad.io.opendrive import read_opendrive

#: The modules whose code these numbers measure (stamped into the results: ``timing.code_stamp``).
MEASURES = ("spiral_cad.io.landxml", "spiral_cad.io.landxml_read")


def zigzag(count: int) -> list[list[float]]:
    return [[1000.0 * k, 250.0 * (k % 2)] for k in range(count + 2)]


def main() -> None:
    args = arguments(__doc__, pis=([1000, 10000], [50]), repeat=(3, 1))
    rows = []
    folder = Path(tempfile.mkdtemp())
    for count in args.pis:
        alignment = Alignment.from_pis(zigzag(count), 800.0, spiral_angles=0.08, units="m", shape="near-linear")
        end = alignment.end_station
        stations = [*range(0, int(end) - 1000, 2000), end]
        pvis = [[float(s), 100.0 + 5.0 * (k % 2)] for k, s in enumerate(stations)]
        profile = Profile.from_pvis(pvis, curve_lengths=200.0, units="m", alignment=alignment)
        path = folder / "road.xml"
        write = median_time(lambda: write_landxml(alignment, path, name="road", profile=profile), args.repeat)
        read = median_time(lambda: read_landxml(path), args.repeat)
        (back,) = read_landxml(path)
        xodr = folder / "road.xodr"
        write_xodr = median_time(lambda: export_opendrive(alignment, xodr), args.repeat)
        read_xodr = median_time(lambda: read_opendrive(xodr)[0].chain(), args.repeat)
        rows.append([
            f"{count:,}", f"{len(alignment.chain):,}", f"{path.stat().st_size / 1e6:.1f}", f"{write:.2f}", f"{read:.2f}",
            f"{write_xodr:.2f}", f"{read_xodr:.2f}", f"{back.offset:.2g}",
        ])  # fmt: skip
        print(" | ".join(rows[-1]), flush=True)
    header = ["PIs", "segments", "file MB", "write .xml, s", "read .xml → Chain, s", "write .xodr, s", "read .xodr → Chain, s",
              "largest offset read back, m"]  # fmt: skip
    print("| " + " | ".join(header) + " |")
    for row in rows:
        print("| " + " | ".join(row) + " |")
    print(f"machine: {machine()}")
    if args.out:
        note = (f"Medians of {args.repeat} runs. The offset read back is the near-linear cubics' own distance from the "
                "clothoids the file states (the chain read back is ours to rounding).")  # fmt: skip
        write_markdown(args.out, "LandXML out and in at scale", note, header, rows)


if __name__ == "__main__":
    main()
