"""CAD layer: a long chain → OCCT wire → STEP → read back and checked, each against raw OCP in the same runs.

Run: ``.venv/bin/python benchmarks/bench_cad.py [--quick] [--segments N] [--rounds R] [--out FILE]``
(the harness and its conventions: ``timing.py``). The peer builds the very
same edges (Geom_Line, Geom_Circle, Geom_BezierCurve) from plain float lists
with direct OCP calls and writes them with OCCT's own STEP writer; OCCT then
reads both files. The growth of every job is fitted over a range of chain
lengths (exponent 1: linear).
"""

from __future__ import annotations

import os
import tempfile

from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeEdge, BRepBuilderAPI_MakeWire
from OCP.Geom import Geom_BezierCurve
from OCP.gp import gp_Ax2, gp_Circ, gp_Dir, gp_Pnt
from OCP.TColgp import TColgp_Array1OfPnt
from timing import Report, arguments, compare, growth_exponent, table

from spiral_cad import Arc, Chain, Line, circle_to_circle
from spiral_cad.cad.continuity import check_continuity
from spiral_cad.cad.export import export_step
from spiral_cad.cad.occ import chain_wire
from spiral_cad.cad.readers import read_shape

#: The modules whose code these numbers measure (stamped into the results: ``timing.code_stamp``).
MEASURES = ("spiral_cad.cad.occ", "spiral_cad.cad.export", "spiral_cad.cad.continuity", "spiral_cad.cad.readers", "spiral_cad.core.chain")


def snake(segments: int) -> Chain:
    """Circles of alternating sense joined by S transitions: arc, spiral, spiral, …"""
    circles = segments // 3 + 1
    parts = []
    for i in range(circles - 1):
        r0 = 40.0 if i % 2 == 0 else -40.0
        parts.append(circle_to_circle((100.0 * i, 0.0), r0, (100.0 * (i + 1), 0.0), -r0))
    return Chain.join(parts)


def plain_description(chain: Chain) -> list[tuple]:
    """What a user of raw OCP would start from: plain numbers per segment."""
    rows = []
    for seg in chain:
        if isinstance(seg, Line):
            rows.append(("line", *seg.start.tolist(), *seg.end.tolist()))
        elif isinstance(seg, Arc):
            rows.append(("arc", *seg.center.tolist(), seg.radius, seg.start_angle, seg.sweep))
        else:
            rows.append(("bezier", seg.control_points.tolist()))
    return rows


def raw_ocp_edges(rows: list[tuple]) -> list:
    """The same edges with direct OCP calls."""
    up, down, x = gp_Dir(0, 0, 1), gp_Dir(0, 0, -1), gp_Dir(1, 0, 0)
    edges = []
    for row in rows:
        if row[0] == "line":
            edge = BRepBuilderAPI_MakeEdge(gp_Pnt(row[1], row[2], 0), gp_Pnt(row[3], row[4], 0)).Edge()
        elif row[0] == "arc":
            _, cx, cy, r, a0, sweep = row
            axis, first = (up, a0) if r > 0 else (down, -a0)
            edge = BRepBuilderAPI_MakeEdge(gp_Circ(gp_Ax2(gp_Pnt(cx, cy, 0), axis, x), abs(r)), first, first + sweep).Edge()
        else:
            poles = TColgp_Array1OfPnt(1, 4)
            for i, (px, py) in enumerate(row[1], 1):
                poles.SetValue(i, gp_Pnt(px, py, 0))
            edge = BRepBuilderAPI_MakeEdge(Geom_BezierCurve(poles)).Edge()
        edges.append(edge)
    return edges


def raw_ocp_wire(rows: list[tuple]):
    """The usual way: those edges added one by one to BRepBuilderAPI_MakeWire."""
    wire = BRepBuilderAPI_MakeWire()
    for edge in raw_ocp_edges(rows):
        wire.Add(edge)
    return wire.Wire()


def write_occt_step(shape, path: str) -> None:
    """OCCT's own STEP writer with its defaults."""
    from OCP.IFSelect import IFSelect_RetDone
    from OCP.STEPControl import STEPControl_AsIs, STEPControl_Writer

    writer = STEPControl_Writer()
    writer.Transfer(shape, STEPControl_AsIs)
    if writer.Write(path) != IFSelect_RetDone:
        raise RuntimeError(f"could not write {path}")


def measure(report: Report, segments: int, rounds: int, folder: str) -> dict[str, float]:
    """Every job at one chain length; returns the medians (seconds) for the growth fit."""
    chain = snake(segments)
    rows = plain_description(chain)
    ours_path, occt_path = os.path.join(folder, "ours.step"), os.path.join(folder, "occt.step")
    export_step(chain, ours_path)
    write_occt_step(raw_ocp_wire(rows), occt_path)
    wire = chain_wire(chain)
    t = compare({
        "wire": lambda: chain_wire(chain),
        "edges": lambda: raw_ocp_edges(rows),
        "step": lambda: export_step(chain, ours_path),
        "occt step": lambda: write_occt_step(wire, occt_path),
        "read ours": lambda: read_shape(ours_path),
        "read occt": lambda: read_shape(occt_path),
        "check wire": lambda: check_continuity(wire),
        "check file": lambda: check_continuity(ours_path),
    }, rounds)  # fmt: skip
    ms = {name: timing.median * 1e3 for name, timing in t.items()}
    n = f"{len(chain):,} segments"
    report.add(f"chain → OCCT wire ({n})", ms["wire"], "ms", t["wire"], f"raw OCP edges only {ms['edges']:,.0f} ms",
               t["edges"].median / t["wire"].median, "≤ 1.1× raw edges")  # fmt: skip
    report.add(f"chain → STEP file, written directly ({n})", ms["step"], "ms", t["step"],
               f"OCCT's writer, wire given {ms['occt step']:,.0f} ms", t["occt step"].median / t["step"].median)  # fmt: skip
    report.add(f"OCCT reads our STEP ({n})", ms["read ours"], "ms", t["read ours"],
               f"OCCT reads its own {ms['read occt']:,.0f} ms", t["read occt"].median / t["read ours"].median,
               "≤ 1.2× OCCT's own")  # fmt: skip
    joints = len(chain) - 1
    report.add(f"G2 checker on the wire ({joints:,} joints)", joints / t["check wire"].median, "joints/s", t["check wire"])
    report.add(f"G2 checker on our STEP file ({joints:,} joints)", joints / t["check file"].median, "joints/s",
               t["check file"], f"of it, OCCT's read {ms['read ours']:,.0f} ms",
               t["read ours"].median / t["check file"].median)  # fmt: skip
    return {name: timing.median for name, timing in t.items()}


def main() -> None:
    args = arguments(__doc__, segments=([1_000, 4_000, 10_000], [30, 60]), rounds=(3, 1))
    report = Report("CAD benchmark", f"Medians of {args.rounds} alternating rounds per chain length.")
    with tempfile.TemporaryDirectory() as folder:
        sizes = sorted(args.segments)
        medians = [measure(report, size, args.rounds, folder) for size in sizes]
    if len(sizes) > 1:
        names = {"wire": "chain → wire", "edges": "raw OCP edges", "step": "our STEP", "occt step": "OCCT's STEP writer",
                 "read ours": "OCCT reads ours", "read occt": "OCCT reads its own", "check file": "checker on our file"}  # fmt: skip
        rows = [(label, f"{growth_exponent(sizes, [m[name] for m in medians]):.2f}") for name, label in names.items()]
        report.section(f"Growth over {sizes[0]:,} … {sizes[-1]:,} segments (time ∝ N^k; 1 is linear)", table(("job", "k"), rows))
    report.finish(args)


if __name__ == "__main__":
    main()
