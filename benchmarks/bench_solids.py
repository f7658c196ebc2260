"""ContinuousBox build time beside build123d's circular fillet of the same box.

Run: ``.venv/bin/python benchmarks/bench_solids.py [--quick] [--repeat R] [--out FILE]``.

Ours: ``ContinuousBox(40, 20, 8, 6, edge_radius=1.5)`` — plan corners G2 of radius 6, top and
bottom edges rolled G2 of radius 1.5 — built, sewn, checked by ``BRepCheck_Analyzer`` and by the
face checker (every edge G2) before it is returned. Peer: build123d's ``Box(40, 20, 8)`` with
its vertical edges filleted at 6 and then every other edge at 1.5 (OCCT's circular fillets,
G1, unchecked). Second pair: the sphere-octant box both ways — ``g2_slab`` of a circularly
rounded rectangle with a circular roll of 3 against ``fillet(Box.edges(), 3)``. Third pair (issue 30's):
``ContinuousBox(60, 40, 12, 8, edge_radius=3)`` against ``fillet(Box(60, 40, 12).edges(), 3)``, with what
each step of ours costs (median over the runs: fit checks, sweeps, faces, sewing, BRepCheck, face check).
Fourth pair (issue 41's): the gallery's plate with four holes and a pocket, every edge rounded by
``g2_fillet`` against build123d's ``fillet`` of the same edges (the sharp part made once, outside the
timing), with its steps too.
"""

from __future__ import annotations

import math
import time
from collections import defaultdict
from statistics import median

import build123d as bd
from timing import arguments, compare, machine, write_markdown

import spiral_cad.cad.slabs as slabs
import spiral_cad.cad.stack_fillet as stack_fillet
import spiral_cad.cad.stacks as stacks
from spiral_cad import Arc, Line
from spiral_cad.app.gallery import GALLERY
from spiral_cad.build123d import ContinuousBox, g2_fillet, g2_slab

#: The modules whose code these numbers measure (stamped into the results: ``timing.code_stamp``).
MEASURES = ("spiral_cad.build123d", "spiral_cad.build123d._lines", "spiral_cad.build123d._parts", "spiral_cad.build123d._sketches", "spiral_cad.cad.slabs", "spiral_cad.cad.roll_surfaces", "spiral_cad.cad.stacks",
            "spiral_cad.cad.stack_fillet", "spiral_cad.cad.prism_fillet")  # fmt: skip

#: The steps shared by slabs and 2.5-D parts, by the module and function doing each (timed there).
_BUILD = {
    "sweeps (s direction)": (stacks, "_along"),
    "surfaces and faces": (stacks, "_surface_face"),
    "STEP-note fingerprints": (stacks, "_record"),
    "plane faces": (stacks, "_level_faces"),
    "sewing and solid": (stacks, "_solid"),
}
#: The steps of a slab (``ContinuousBox``).
STEPS = {"fit checks": (slabs, "_roll_problem"), **_BUILD, "BRepCheck": (slabs, "verify_solid"), "face check": (slabs, "verify_faces")}
#: The steps of ``g2_fillet`` on a 2.5-D part.
PART_STEPS = {
    "reading the walls": (stack_fillet, "_walls"),
    "fit checks": (stack_fillet, "stack_problem"),
    **_BUILD,
    "BRepCheck": (stack_fillet, "verify_solid"),
    "face check": (stack_fillet, "verify_faces"),
}


def step_costs(make, rounds: int, steps: dict = STEPS) -> dict[str, float]:
    """Median seconds per step of ``make()`` over ``rounds`` runs (the steps' functions timed in place)."""
    spent: dict[str, list[float]] = defaultdict(list)
    originals = {step: getattr(module, name) for step, (module, name) in steps.items()}
    this_run: dict[str, float] = {}

    def timed(name, function):
        def run(*args, **kwargs):
            start = time.perf_counter()
            try:
                return function(*args, **kwargs)
            finally:
                this_run[name] = this_run.get(name, 0.0) + time.perf_counter() - start

        return run

    try:
        for step, function in originals.items():
            module, name = steps[step]
            setattr(module, name, timed(step, function))
        for _ in range(rounds):
            this_run.clear()
            start = time.perf_counter()
            make()
            this_run["total"] = time.perf_counter() - start
            for name, value in this_run.items():
                spent[name].append(value)
    finally:
        for step, function in originals.items():
            module, name = steps[step]
            setattr(module, name, function)
    return {name: median(values) for name, values in spent.items()}


def peer_box() -> bd.Part:
    """build123d's box: vertical edges filleted at 6, then the top and bottom edges at 1.5."""
    box = bd.fillet(bd.Box(40, 20, 8).edges().filter_by(bd.Axis.Z), 6)
    return bd.fillet(box.edges().filter_by(bd.Axis.Z, reverse=True), 1.5)


def rounded_rectangle(length: float, width: float, r: float) -> list:
    a, b, h = length / 2, width / 2, math.pi / 2
    return [Line((-a + r, -b), (a - r, -b)), Arc((a - r, -b + r), r, -h, h), Line((a, -b + r), (a, b - r)),
            Arc((a - r, b - r), r, 0, h), Line((a - r, b), (-a + r, b)), Arc((-a + r, b - r), r, h, h),
            Line((-a, b - r), (-a, -b + r)), Arc((-a + r, -b + r), r, math.pi, h)]  # fmt: skip


def main() -> None:
    args = arguments(__doc__, repeat=(7, 2))
    make, plate_radius = GALLERY["plate_pocket_holes"]
    plate = make()  # the sharp part, made once
    jobs = {
        "ContinuousBox": lambda: ContinuousBox(40, 20, 8, 6, edge_radius=1.5),
        "build123d fillet": peer_box,
        "g2_slab circular": lambda: g2_slab(rounded_rectangle(40, 20, 3), 8, 3, profile="circular"),
        "build123d fillet all": lambda: bd.fillet(bd.Box(40, 20, 8).edges(), 3),
        "ContinuousBox 60×40×12": lambda: ContinuousBox(60, 40, 12, 8, edge_radius=3),
        "build123d fillet 60×40×12": lambda: bd.fillet(bd.Box(60, 40, 12).edges(), 3),
        "g2_fillet plate, 4 holes + pocket": lambda: g2_fillet(plate.edges(), plate_radius),
        "build123d fillet plate, 4 holes + pocket": lambda: bd.fillet(plate.edges(), plate_radius),
    }
    best = compare(jobs, args.repeat)
    ours, theirs = ContinuousBox(40, 20, 8, 6, edge_radius=1.5), peer_box()
    rows = []
    pairs = (("ContinuousBox", "build123d fillet"), ("g2_slab circular", "build123d fillet all"),
             ("ContinuousBox 60×40×12", "build123d fillet 60×40×12"),
             ("g2_fillet plate, 4 holes + pocket", "build123d fillet plate, 4 holes + pocket"))  # fmt: skip
    for name, peer in pairs:
        shape, other = jobs[name](), jobs[peer]()
        ratio = best[peer].median / best[name].median
        rows.append((name, f"{best[name].median * 1000:,.0f} ms", f"{len(shape.faces())} faces, valid {shape.is_valid}",
                     peer, f"{best[peer].median * 1000:,.0f} ms", f"{len(other.faces())} faces, valid {other.is_valid}",
                     f"{ratio:.2f}"))  # fmt: skip
    header = ("ours", "median", "result", "peer", "median", "result", "peer / ours")
    for row in rows:
        print("  ".join(row))
    note = (f"Medians of {args.repeat} interleaved runs (ratio > 1: ours is faster). Ours includes sewing, "
            f"BRepCheck and the face check; its sweeps over spirals deviate {ours.approximation:.2g} mm from exact. "
            f"Volumes: ours {ours.volume:.6g}, peer {theirs.volume:.6g} mm³ (different shapes: G2 vs circular).")  # fmt: skip
    costs = step_costs(jobs["ContinuousBox 60×40×12"], args.repeat)
    total = costs.pop("total")
    steps = ", ".join(f"{step} {costs.get(step, 0.0) * 1000:.0f} ms" for step in STEPS)
    note += f" ContinuousBox(60, 40, 12, 8, edge_radius=3) step by step (total {total * 1000:.0f} ms): {steps}."
    costs = step_costs(jobs["g2_fillet plate, 4 holes + pocket"], args.repeat, PART_STEPS)
    total = costs.pop("total")
    steps = ", ".join(f"{step} {costs.get(step, 0.0) * 1000:.0f} ms" for step in PART_STEPS)
    note += f" The plate with 4 holes and a pocket step by step (total {total * 1000:.0f} ms): {steps}."
    print(note)
    print(machine())
    if args.out:
        write_markdown(args.out, "G2 solids: ContinuousBox and 2.5-D parts beside build123d's fillet", note, header, rows)


if __name__ == "__main__":
    main()
