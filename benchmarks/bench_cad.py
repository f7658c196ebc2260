"""CAD layer: a 10,000-segment chain → OCCT wire → STEP, against raw OCP calls.

Run: ``.venv/bin/python benchmarks/bench_cad.py [--segments N] [--repeat R] [--out FILE]``.
The peer builds the very same edges (Geom_Line, Geom_Circle, Geom_BezierCurve)
from plain float lists with direct OCP calls, in the same run; the ratio is
ours / raw (goal ≤ 1.2). Also reports the G2 checker's throughput.
"""

from __future__ import annotations

import argparse
import os
import tempfile
import time

from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeEdge, BRepBuilderAPI_MakeWire
from OCP.Geom import Geom_BezierCurve
from OCP.gp import gp_Ax2, gp_Circ, gp_Dir, gp_Pnt
from OCP.TColgp import TColgp_Array1OfPnt
from timing import machine, median_time, write_markdown

from spiral_cad import Arc, Chain, Line, circle_to_circle
from spiral_cad.continuity import check_continuity
from spiral_cad.export import export_step
from spiral_cad.occ import chain_wire


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


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--segments", type=int, default=10_000)
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--out", help="also write the table to this markdown file")
    args = parser.parse_args()
    t0 = time.perf_counter()
    chain = snake(args.segments)
    build_chain = time.perf_counter() - t0
    rows = plain_description(chain)
    print(f"chain of {len(chain):,} segments built and G2-checked in {build_chain:.2f} s", flush=True)
    with tempfile.TemporaryDirectory() as tmp:
        ours_path, raw_path = os.path.join(tmp, "ours.step"), os.path.join(tmp, "raw.step")
        t_ours_wire = median_time(lambda: chain_wire(chain), args.repeat)
        t_raw_edges = median_time(lambda: raw_ocp_edges(rows), args.repeat)
        t_raw_wire = median_time(lambda: raw_ocp_wire(rows), args.repeat)
        t_ours = median_time(lambda: export_step(chain, ours_path), args.repeat)
        t_raw = median_time(lambda: _write_step(raw_ocp_wire(rows), raw_path), args.repeat)
        wire = chain_wire(chain)
        t_check = median_time(lambda: check_continuity(wire), args.repeat)
        report = check_continuity(wire)
    joints = len(chain) - 1
    ms = lambda t: f"{t * 1e3:,.1f} ms"  # noqa: E731
    table = [
        ("segments", f"{len(chain):,}", "line, arc and spiral edges"),
        ("ours: chain → OCCT wire", ms(t_ours_wire), "edges share vertices, wire assembled directly"),
        ("raw OCP: the same edges only", ms(t_raw_edges), "MakeEdge per segment, no wire"),
        ("ratio ours (whole wire) / raw edges", f"{t_ours_wire / t_raw_edges:.2f}×", "goal ≤ 1.2"),
        ("raw OCP: edges + BRepBuilderAPI_MakeWire", ms(t_raw_wire), "the usual way; Add is linear in the wire size"),
        ("ours: chain → wire → STEP file", ms(t_ours), "17 significant digits"),
        ("raw OCP: edges → MakeWire → STEP file", ms(t_raw), "STEPControl_Writer defaults"),
        ("ratio ours / raw (wire + STEP)", f"{t_ours / t_raw:.2f}×", "goal ≤ 1.2"),
        ("G2 checker", f"{joints / t_check:,.0f} joints/s", f"{joints:,} joints, min level {report.min_level}"),
    ]
    for name, value, note in table:
        print(f"  {name:38} {value:>18}  {note}")
    print(f"machine: {machine()}")
    if args.out:
        write_markdown(args.out, "CAD benchmark", f"Median of {args.repeat} runs.", ("measurement", "value", "note"), table)


def _write_step(shape, path: str) -> None:
    from OCP.IFSelect import IFSelect_RetDone
    from OCP.STEPControl import STEPControl_AsIs, STEPControl_Writer

    writer = STEPControl_Writer()
    writer.Transfer(shape, STEPControl_AsIs)
    if writer.Write(path) != IFSelect_RetDone:
        raise RuntimeError(f"could not write {path}")


if __name__ == "__main__":
    main()
