"""STEP at scale: OCCT opening our one-wire file against OCCT's own file, and the G2 checker on it.

Run: ``.venv/bin/python benchmarks/bench_step.py [--pis N ...] [--repeat R] [--quick] [--out FILE]``.

For zigzag alignments of N PIs (near-linear spirals, 4 N + 1 edges, as
``bench_roads.py``) it times, alternating, medians of ``repeat`` runs:

* **ours**: OCCT's STEP reader (``ReadFile`` + ``TransferRoots``, in this
  process, its defaults as in FreeCAD) on ``export_step``'s file: one wire;
* **OCCT's file**: the same reader on what OCCT's own writer makes of the
  same wire (``chain_wire`` → ``STEPControl_Writer``): loose edges, no wire;
* **wire check**: ``ShapeAnalysis_Wire::CheckOrder`` on the wire read from
  ours, the order check OCCT's reader runs on every wire it reads (its
  ``ShapeFix_Shape`` step), quadratic in the edge count. OCCT's file plus
  this check is the floor of any file that OCCT reads as one wire;
* **checker**: ``check_continuity`` on our file; the reader's part
  (``read_file`` with nothing to extract: the child's read and curve
  accounting) and ours (the rest: measuring and classifying every joint),
  as joints per second.

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
from timing import machine, write_markdown

from spiral_cad.cad.continuity import check_continuity
from spiral_cad.cad.occ import chain_wire, captured_messages
from spiral_cad.cad.readers import read_file
from spiral_cad.design import Alignment
from spiral_cad.export import export_step
from spiral_cad.formats.step_occ import write_shape_step


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


def medians(runs: dict[str, Callable[[], object]], repeat: int) -> dict[str, float]:
    """Median of ``repeat`` runs of each, interleaved (a shared machine: load hits every job alike)."""
    times: dict[str, list[float]] = {name: [] for name in runs}
    for _ in range(repeat):
        for name, run in runs.items():
            started = time.perf_counter()
            run()
            times[name].append(time.perf_counter() - started)
    return {name: statistics.median(values) for name, values in times.items()}


def slope(sizes: list[int], values: list[float]) -> float:
    """Least-squares exponent b of values ≈ a · sizes^b."""
    if len(sizes) < 2:
        return math.nan
    return float(np.polyfit(np.log(sizes), np.log(values), 1)[0])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--pis", type=int, nargs="+", default=[1000, 2000, 5000, 10000])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--quick", action="store_true", help="small sizes, one run each (a smoke test)")
    parser.add_argument("--out", help="also write the tables to this markdown file")
    args = parser.parse_args()
    if args.quick:
        args.pis, args.repeat = [50, 100, 200], 1
    folder = Path(tempfile.mkdtemp(prefix="bench_step_"))
    sizes, results = [], []
    for count in args.pis:
        chain = Alignment.from_pis(zigzag(count), 800.0, spiral_angles=0.08, units="m").chain
        ours, theirs = folder / f"ours_{count}.step", folder / f"occt_{count}.step"
        export_step(chain, ours)
        write_shape_step(chain_wire(chain), theirs, "occt", "m", "bench_step")
        wire = one_wire(occt_read(ours))
        t = medians({
            "ours": lambda: occt_read(ours),
            "occt": lambda: occt_read(theirs),
            "order": lambda: check_order(wire),
            "check": lambda: check_continuity(ours),
            "reader": lambda: read_file(ours, None, lambda shape: None),
        }, args.repeat)  # fmt: skip
        report = check_continuity(ours)
        assert report.describe() == f"1 wire of {len(chain)} edges" and report.passes("G2"), report.describe()
        sizes.append(len(chain))
        results.append(t)
        print(f"{count:,} PIs, {len(chain):,} edges: " + ", ".join(f"{k} {v:.3f} s" for k, v in t.items()), flush=True)
    read_rows, check_rows = [], []
    for count, edges, t in zip(args.pis, sizes, results):
        floor = t["occt"] + t["order"]
        ours_part = max(t["check"] - t["reader"], 1e-9)
        read_rows.append([
            f"{count:,}", f"{edges:,}", f"{t['ours']:.3f}", f"{t['occt']:.3f}", f"{t['ours'] / t['occt']:.2f}×",
            f"{t['order']:.3f}", f"{floor:.3f}", f"{t['ours'] / floor:.2f}×",
        ])  # fmt: skip
        check_rows.append([
            f"{count:,}", f"{edges - 1:,}", f"{t['check']:.3f}", f"{t['reader']:.3f}", f"{ours_part:.3f}",
            f"{(edges - 1) / ours_part:,.0f}", f"{t['reader'] / t['check']:.0%}",
        ])  # fmt: skip
    exponent = {k: slope(sizes, [t[k] for t in results]) for k in results[0]}
    ours_exp = slope(sizes, [max(t["check"] - t["reader"], 1e-9) for t in results])
    read_rows.append(["growth exponent", "", f"{exponent['ours']:.2f}", f"{exponent['occt']:.2f}", "",
                      f"{exponent['order']:.2f}", "", ""])  # fmt: skip
    check_rows.append(["growth exponent", "", f"{exponent['check']:.2f}", f"{exponent['reader']:.2f}", f"{ours_exp:.2f}", "", ""])
    read_head = ["PIs", "edges", "OCCT reads ours (1 wire), s", "OCCT reads OCCT's (loose edges), s", "ours / OCCT's",
                 "wire order check, s", "floor: OCCT's + check, s", "ours / floor"]  # fmt: skip
    check_head = ["PIs", "joints", "check_continuity, s", "reader in child (read + accounting), s",
                  "ours (measure + classify), s", "ours, joints/s", "reader's share"]  # fmt: skip
    for head, rows in ((read_head, read_rows), (check_head, check_rows)):
        print("| " + " | ".join(head) + " |")
        for row in rows:
            print("| " + " | ".join(row) + " |")
    print(f"machine: {machine()}")
    if args.out:
        note = (f"Zigzag alignments, near-linear spirals; medians of {args.repeat} interleaved runs; "
                "growth exponents fitted over the sizes shown.")  # fmt: skip
        write_markdown(args.out, "STEP at scale: OCCT reading our wire, and the checker", note, read_head, read_rows)
        with open(args.out, "a", encoding="utf-8") as fh:
            fh.write("\n| " + " | ".join(check_head) + " |\n|" + "---|" * len(check_head) + "\n")
            fh.writelines("| " + " | ".join(row) + " |\n" for row in check_rows)


if __name__ == "__main__":
    main()
