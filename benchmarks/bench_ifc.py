"""IFC 4.3 alignments at scale: writing, reading and evaluating the alignment of N PIs.

Run: ``.venv/bin/python benchmarks/bench_ifc.py [--quick] [--pis N ...] [--rounds R] [--out FILE]``
(the harness and its conventions: ``timing.py``). The alignment is a zigzag of 1 km tangents
(R = 800 m, 80 km/h, spirals chosen by the criteria: 4 segments per PI) with a profile of a
grade change every 3 km. Jobs: ``write_ifc`` (plan and profile, the file on disk), its peer
``export_opendrive`` of the same road; ``ifcopenshell.open`` + ``read_ifc_alignments`` (the
layouts back); ifcopenshell's evaluator on up to 2 000 segments (each on its own) at its end and at
a quarter, half and three quarters of its length, against our chain's point at the same station
(stations must agree, inside spirals too). Goals: 10 000 PIs written in ≤ 10 s and read back in ≤ 30 s.
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
                   peer="export_opendrive", ratio=times["xodr"].median / times["ifc"].median, goal="≤ 10 s at 10 000 PIs")  # fmt: skip
        report.add("write_ifc per 1 000 PIs", times["ifc"].median * per_k, "s")
        report.add("file size", ifc.stat().st_size / 1e6, "MB")
        read = compare({"read": lambda: read_ifc_alignments(ifcopenshell.open(str(ifc)))}, args.rounds)["read"]
        report.add("ifcopenshell.open + read_ifc_alignments", read.median, "s", read, goal="≤ 30 s at 10 000 PIs")
        (layout,) = read_ifc_alignments(ifcopenshell.open(str(ifc)))
        assert len(layout.horizontal) == len(chain) + 1
        model = ifcopenshell.open(str(ifc))
        (plan,) = model.by_type("IfcCompositeCurve", include_subtypes=False)
        settings = ifcopenshell.geom.settings()
        segments = plan.Segments[:-1]
        starts = np.concatenate([[0.0], np.cumsum([abs(s.SegmentLength.wrappedValue) for s in segments])])
        chosen = np.unique(np.linspace(0, len(segments) - 1, min(len(segments), 2000)).astype(int))
        started = time.perf_counter()
        ends, inside = [], []
        for k in chosen:  # each segment on its own: the composite curve's evaluator costs more per call as it grows
            function = wrapper.map_shape(settings, segments[k])
            evaluate = wrapper.function_item_evaluator(settings, function).evaluate
            length = function.length()
            ends.append((np.array(evaluate(length))[:2, 3], starts[k + 1]))
            inside += [(np.array(evaluate(f * length))[:2, 3], starts[k] + f * length) for f in (0.25, 0.5, 0.75)]
        evaluated = time.perf_counter() - started
        end_gap = max(float(np.hypot(*(p - chain.point_at(min(s, chain.length))))) for p, s in ends)
        station_gap = max(float(np.hypot(*(p - chain.point_at(s)))) for p, s in inside)
        report.add(f"ifcopenshell evaluates {len(chosen):,} segments on their own (end, ¼, ½, ¾)", evaluated, "s")
        report.add("largest distance of those segment ends from our chain", end_gap * 1e6, "µm", goal="≤ 1 µm")
        report.add("largest distance, at ¼, ½, ¾ of each segment, from our chain's point at that station", station_gap * 1e6, "µm",
                   goal="≤ 1 mm")  # fmt: skip
    report.finish(args)


if __name__ == "__main__":
    main()
