"""STEP at scale: OCCT opening our one-wire file against OCCT's own file, the G2 checker on it, and ``to_wire``.

Run: ``.venv/bin/python benchmarks/bench_step.py [--pis N ...] [--repeat R] [--quick] [--out FILE]``.

For zigzag alignments of N PIs (near-linear spirals, 4 N + 1 edges, as
``bench_roads.py``) it times, alternating, medians of ``repeat`` runs (``pairs`` for ``to_wire``):

* **ours**: OCCT's STEP reader (``ReadFile`` + ``TransferRoots``, in this
  process, its defaults as in FreeCAD) on ``export_step``'s file: one wire;
* **OCCT's file**: the same reader on what OCCT's own writer makes of the
  same wire (``chain_wire`` → ``STEPControl_Writer``): loose edges, no wire;
* **wire check**: ``ShapeAnalysis_Wire::CheckOrder`` on the wire read from
  ours, the order check OCCT's reader runs on every wire it reads (its
  ``ShapeFix_Shape`` step), quadratic in the edge count. OCCT's file plus
  this check is the floor of any file that OCCT reads as one wire;
* **checker**: ``check_continuity`` on our file, split by its own
  ``report.timing``: the reader's part (the child's read, curve accounting
  and round trip) and ours (measuring every edge, classifying every joint),
  as joints per second;
* **to_wire**: ``chain_to_wire(chain)`` against the peer ``raw_ocp_edges`` of
  ``bench_cad.py`` (the same exact edges made with direct OCP calls from
  plain numbers, no wire), run back to back: the ratio is the median of the
  per-pair ratios (a shared machine's load hits both alike).

Growth exponents are least-squares slopes of log time against log edges.
"""

from __future__ import annotations

import argparse
import math
import statistics
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np
from bench_cad import plain_description, raw_ocp_edges
from timing import machine, write_markdown

from spiral_cad.build123d import chain_to_wire
from spiral_cad.cad.console import captured_messages
from spiral_cad.cad.continuity import check_continuity
from spiral_cad.cad.export import export_step
from spiral_cad.cad.occ import chain_wire
from spiral_cad.cad.step_occ import write_shape_step
from spiral_cad.continuity.joints import ContinuityReport
from spiral_cad.design import Alignment

#: The modules whose code these numbers measure (stamped into the results: ``timing.code_stamp``).
MEASURES = ("spiral_cad.cad.export", "spiral_cad.cad.step_occ", "spiral_cad.cad.occ", "spiral_cad.cad.continuity")


def zigzag(count: int) -> list[list[float]]:
    return [[1000.0 * k, 250.0 * (k % 2)] for k in range(count + 2)]


def occt_read(path: Path):
    """OCCT's STEP reader with its defaults, in this process; the shape read."""
    from OCP.STEPControl import STEPControl_Reader

    with captured_messages():
        reader = STEPControl_Reader()
        reader.ReadFile(str(path))
        reader.TransferRoots()
        return reader.OneShape()


def one_wire(shape):
    from OCP.TopAbs import TopAbs_WIRE
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopoDS import TopoDS

    explorer = TopExp_Explorer(shape, TopAbs_WIRE)
    wire = TopoDS.Wire_s(explorer.Current())
    explorer.Next()
    assert not explorer.More(), "our file must read as one wire"
    return wire


def check_order(wire) -> None:
    """The order check OCCT's reader runs on every wire (``ShapeFix_Wire::Perform`` → ``CheckOrder``)."""
    from OCP.ShapeAnalysis import ShapeAnalysis_Wire, ShapeAnalysis_WireOrder

    analysis = ShapeAnalysis_Wire()
    analysis.Load(wire)
    analysis.SetPrecision(1e-7)
    analysis.CheckOrder(ShapeAnalysis_WireOrder(), False, True, False)


def timed(runs: dict[str, Callable[[], object]], repeat: int) -> dict[str, list[float]]:
    """Times of ``repeat`` runs of each, interleaved, in alternating order (a shared machine: load
    hits every job alike). A run that returns a ``ContinuityReport`` also adds its timing's parts."""
    times: dict[str, list[float]] = {}
    for k in range(repeat):
        for name, run in list(runs.items())[:: 1 if k % 2 == 0 else -1]:
            started = time.perf_counter()
            result = run()
            times.setdefault(name, []).append(time.perf_counter() - started)
            if isinstance(result, ContinuityReport):
                times.setdefault("check reading", []).append(result.timing.reading)
                times.setdefault("check ours", []).append(result.timing.measuring + result.timing.classifying)
    return times


def medians(times: dict[str, list[float]]) -> dict[str, float]:
    return {name: statistics.median(values) for name, values in times.items()}


def slope(sizes: list[int], values: list[float]) -> float:
    """Least-squares exponent b of values ≈ a · sizes^b."""
    if len(sizes) < 2:
        return math.nan
    return float(np.polyfit(np.log(sizes), np.log(values), 1)[0])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--pis", type=int, nargs="+", default=[1000, 2000, 5000, 10000])
    parser.add_argument("--repeat", type=int, default=3, help="runs of each read and check")
    parser.add_argument("--pairs", type=int, default=15, help="back-to-back pairs of to_wire and raw edges")
    parser.add_argument("--quick", action="store_true", help="small sizes, one run each (a smoke test)")
    parser.add_argument("--out", help="also write the tables to this markdown file")
    args = parser.parse_args()
    if args.quick:
        args.pis, args.repeat, args.pairs = [50, 100, 200], 1, 3
    folder = Path(tempfile.mkdtemp(prefix="bench_step_"))
    chains = [Alignment.from_pis(zigzag(count), 800.0, spiral_angles=0.08, units="m").chain for count in args.pis]
    sizes = [len(chain) for chain in chains]
    results = []
    for chain in chains:  # first, in a process that has read no large file (OCCT's reads leave its heap fragmented)
        rows = plain_description(chain)
        pairs = timed({"to_wire": lambda: chain_to_wire(chain), "raw edges": lambda: raw_ocp_edges(rows)}, args.pairs)
        results.append(medians(pairs))
        results[-1]["to_wire / raw"] = statistics.median(a / b for a, b in zip(pairs["to_wire"], pairs["raw edges"]))
    for count, chain, t in zip(args.pis, chains, results):
        ours, theirs = folder / f"ours_{count}.step", folder / f"occt_{count}.step"
        export_step(chain, ours)
        write_shape_step(chain_wire(chain), theirs, "occt", "m", "bench_step", occt_wires=True)
        wire = one_wire(occt_read(ours))
        t |= medians(timed({
            "ours": lambda: occt_read(ours),
            "occt": lambda: occt_read(theirs),
            "order": lambda: check_order(wire),
            "check": lambda: check_continuity(ours),
        }, args.repeat))  # fmt: skip
        report = check_continuity(ours)
        assert report.describe() == f"1 wire of {len(chain)} edges" and report.passes("G2"), report.describe()
        print(f"{count:,} PIs, {len(chain):,} edges: " + ", ".join(f"{k} {v:.3f} s" for k, v in t.items()), flush=True)
    read_rows, check_rows, wire_rows = [], [], []
    for count, edges, t in zip(args.pis, sizes, results):
        floor = t["occt"] + t["order"]
        ours_part = t["check ours"]
        read_rows.append([
            f"{count:,}", f"{edges:,}", f"{t['ours']:.3f}", f"{t['occt']:.3f}", f"{t['ours'] / t['occt']:.2f}×",
            f"{t['order']:.3f}", f"{floor:.3f}", f"{t['ours'] / floor:.2f}×",
        ])  # fmt: skip
        check_rows.append([
            f"{count:,}", f"{edges - 1:,}", f"{t['check']:.3f}", f"{t['check reading']:.3f}", f"{ours_part:.3f}",
            f"{(edges - 1) / ours_part:,.0f}", f"{t['check reading'] / (t['check reading'] + ours_part):.0%}",
        ])  # fmt: skip
        wire_rows.append([f"{count:,}", f"{edges:,}", f"{t['to_wire'] * 1e3:,.1f}", f"{t['raw edges'] * 1e3:,.1f}",
                          f"{t['to_wire / raw']:.2f}×"])  # fmt: skip
    exponent = {k: slope(sizes, [t[k] for t in results]) for k in results[0]}
    read_rows.append(["growth exponent", "", f"{exponent['ours']:.2f}", f"{exponent['occt']:.2f}", "",
                      f"{exponent['order']:.2f}", "", ""])  # fmt: skip
    check_rows.append(["growth exponent", "", f"{exponent['check']:.2f}", f"{exponent['check reading']:.2f}",
                       f"{exponent['check ours']:.2f}", "", ""])  # fmt: skip
    wire_rows.append(["growth exponent", "", f"{exponent['to_wire']:.2f}", f"{exponent['raw edges']:.2f}", ""])
    read_head = ["PIs", "edges", "OCCT reads ours (1 wire), s", "OCCT reads OCCT's (loose edges), s", "ours / OCCT's",
                 "wire order check, s", "floor: OCCT's + check, s", "ours / floor"]  # fmt: skip
    check_head = ["PIs", "joints", "check_continuity, s", "reader (child: read, accounting, round trip), s",
                  "ours (measure + classify), s", "ours, joints/s", "reader's share"]  # fmt: skip
    wire_head = ["PIs", "edges", "chain.to_wire(), ms", "raw OCP edges, ms", "to_wire / raw (median of pairs)"]
    tables = ((read_head, read_rows), (check_head, check_rows), (wire_head, wire_rows))
    for head, rows in tables:
        print("| " + " | ".join(head) + " |")
        for row in rows:
            print("| " + " | ".join(row) + " |")
    print(f"machine: {machine()}")
    if args.out:
        note = (f"Zigzag alignments, near-linear spirals; medians of {args.repeat} interleaved runs "
                f"({args.pairs} pairs for to_wire); growth exponents fitted over the sizes shown.")  # fmt: skip
        write_markdown(args.out, "STEP at scale: OCCT reading our wire, and the checker", note, read_head, read_rows)
        with open(args.out, "a", encoding="utf-8") as fh:
            for head, rows in tables[1:]:
                fh.write("\n| " + " | ".join(head) + " |\n|" + "---|" * len(head) + "\n")
                fh.writelines("| " + " | ".join(row) + " |\n" for row in rows)


if __name__ == "__main__":
    main()
