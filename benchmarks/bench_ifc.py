"""IFC 4.3 alignments at scale: writing, reading and evaluating the alignment of N PIs.

Run: ``.venv/bin/python benchmarks/bench_ifc.py [--quick] [--pis N ...] [--rounds R] [--out FILE]``
(the harness and its conventions: ``timing.py``). The alignment is a zigzag of 1 km tangents
(R = 800 m, 80 km/h, spirals chosen by the criteria: 4 segments per PI) with a profile of a
grade change every 3 km. Jobs: ``write_ifc`` (plan and profile, the file on disk), its peer
``export_opendrive`` of the same road; ``ifcopenshell.open`` + ``read_ifc_alignments`` (the
layouts back); ifcopenshell's evaluator at every segment end of the composite curve (one
``function_item_evaluator``), with the largest distance from our chain. Goal: 10 000 PIs
written in ≤ 60 s and read back in ≤ 30 s.
"""

from __future__ import annotations

import tempfile
import time
from pathlib import Path

import numpy as np
from timing import Report, arguments, compare

from spiral_cad.cad.export import export_opendrive
from spiral_cad.design import Alignment, Profile
from spiral_cad.io.ifc import read_ifc_alignments, write_ifc

#: The modules whose code these numbers measure (stamped into the results: ``timing.code_stamp``).
MEASURES = ("spiral_cad.io.ifc",)


def road(count: int) -> tuple[Alignment, Profile]:
    pis = [[1000.0 * k, 250.0 * (k % 2)] for k in range(count + 2)]
    alignment = Alignment.from_pis(pis, 800.0, units="m", design_speed=80, max_jerk=0.6)
    start, end = alignment.start_station, alignment.end_station
    stations = np.arange(start, end, 3000.0)
    pvis = np.column_stack([stations, 100.0 + 5.0 * (np.arange(len(stations)) % 2)])
    pvis = np.vstack([pvis, [end, 100.0]]) if end - pvis[-1, 0] > 500.0 else np.vstack([pvis[:-1], [end, 100.0]])
    profile = Profile.from_pvis(pvis, curve_lengths=200.0, units="m", alignment=alignment)
    return alignment, profile


def main() -> None:
    args = arguments(__doc__, pis=([10_000], [20]), rounds=(3, 1))
    report = Report("IFC 4.3 alignments at scale", f"Medians of {args.rounds} runs; plan and profile in one IfcAlignment.")
    import ifcopenshell
    import ifcopenshell.geom
    import ifcopenshell.ifcopenshell_wrapper as wrapper

    folder = Path(tempfile.mkdtemp())
    for count in args.pis:
        alignment, profile = road(count)
        chain = alignment.chain
        ifc, xodr = folder / "road.ifc", folder / "road.xodr"
        times = compare({
            "ifc": lambda: write_ifc(alignment, ifc, profile=profile),
            "xodr": lambda: export_opendrive(alignment, xodr, profile=profile),
        }, args.rounds)  # fmt: skip
        per_k = 1000.0 / count
        report.add(f"write_ifc, {count:,} PIs ({len(chain):,} segments)", times["ifc"].median, "s", times["ifc"],
                   peer="export_opendrive", ratio=times["xodr"].median / times["ifc"].median, goal="≤ 60 s at 10 000 PIs")  # fmt: skip
        report.add("write_ifc per 1 000 PIs", times["ifc"].median * per_k, "s")
        report.add("file size", ifc.stat().st_size / 1e6, "MB")
        read = compare({"read": lambda: read_ifc_alignments(ifcopenshell.open(str(ifc)))}, args.rounds)["read"]
        report.add("ifcopenshell.open + read_ifc_alignments", read.median, "s", read, goal="≤ 30 s at 10 000 PIs")
        (layout,) = read_ifc_alignments(ifcopenshell.open(str(ifc)))
        assert len(layout.horizontal) == len(chain) + 1
        model = ifcopenshell.open(str(ifc))
        (plan,) = model.by_type("IfcCompositeCurve", include_subtypes=False)
        settings = ifcopenshell.geom.settings()
        started = time.perf_counter()
        evaluate = wrapper.function_item_evaluator(settings, wrapper.map_shape(settings, plan)).evaluate
        ends = np.array([np.array(evaluate(float(s)))[:2, 3] for s in chain.stations])
        evaluated = time.perf_counter() - started
        deviation = float(np.hypot(*(ends - chain.point_at(chain.stations)).T).max())
        report.add(f"ifcopenshell evaluates {len(chain) + 1:,} segment ends", evaluated, "s")
        report.add("largest distance of those ends from our chain", deviation * 1e6, "µm", goal="≤ 1 µm")
    report.finish(args)


if __name__ == "__main__":
    main()
