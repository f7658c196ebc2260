"""The speed guard: a few seconds of timing that fail when an operation falls far behind a reference.

Run: ``.venv/bin/python benchmarks/guard.py [--rounds R] [--only NAME ...] [--out FILE]`` (exit 1 when a
guard fails); ``tests/app/test_speed_guard.py`` runs it as part of the test suite.

Each guarded operation is timed against a reference computed in the same process on the same
input, alternating (``timing.compare``), and judged on the ratio of their fastest runs: the fastest of
R runs is what the code costs when the shared machine lets it run, and both sides of a ratio see the
same machine. A guard fails when ours / reference exceeds its ``limit``. The references never call
this package's kernels (a kernel that fell back to plain Python would slow both sides alike): they
are numpy doing comparable arithmetic on the same arrays, a plain-Python pass over the same objects,
ElementTree writing as many elements, scipy fitting the same points, or build123d/OCCT's own
operation on the same solid. Each ``limit`` is about three times the ratio measured when it was set
(``typical``, stated beside it: on the shared 2-core machine at a load of about 7, where threads
help ours little and the references are single-threaded), and below ten times it: room for a
loaded machine, while an operation ten times slower, as a kernel running as plain Python is
(10× to 1000×), fails.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import xml.etree.ElementTree as ET
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from bench_core import numpy_closed_form_line_to_circle as numpy_line_to_circle
from timing import compare, machine, table

#: Runs of each side per guard (the fastest counts).
ROUNDS = 5


@dataclass(frozen=True)
class Guard:
    """One guarded operation and its reference, both ready to run (inputs built)."""

    name: str
    ours: Callable[[], object]
    reference_name: str
    reference: Callable[[], object]
    #: Largest ours / reference (fastest runs) that passes.
    limit: float
    #: The ratio measured when the limit was set (for the reader of a failure).
    typical: float


@dataclass(frozen=True)
class Verdict:
    guard: Guard
    ours: float
    reference: float

    @property
    def ratio(self) -> float:
        return self.ours / self.reference

    @property
    def passed(self) -> bool:
        return self.ratio <= self.guard.limit

    def row(self) -> list[str]:
        g = self.guard
        return [g.name, f"{self.ours * 1e3:,.2f} ms", f"{g.reference_name}: {self.reference * 1e3:,.2f} ms",
                f"{self.ratio:.2f}×", f"≤ {g.limit:g}× (typical {g.typical:g}×)", "pass" if self.passed else "FAIL"]  # fmt: skip


def random_polyline(corners: int, dim: int, rng: np.random.Generator) -> np.ndarray:
    """A walk with legs in [1, 10] and turns in ±[5°, 150°] (climbing and falling in z when ``dim`` is 3)."""
    legs = rng.uniform(1.0, 10.0, corners + 1)
    turns = rng.uniform(np.radians(5.0), np.radians(150.0), corners + 1) * rng.choice([-1.0, 1.0], corners + 1)
    heading = np.cumsum(turns)
    steps = legs[:, None] * np.stack([np.cos(heading), np.sin(heading)], axis=1)
    points = np.vstack([np.zeros((1, 2)), np.cumsum(steps, axis=0)])
    if dim == 3:
        points = np.column_stack([points, np.cumsum(rng.uniform(-1.0, 1.0, len(points)))])
    return points


def numpy_corners(p0: np.ndarray, corners: np.ndarray, p1: np.ndarray) -> np.ndarray:
    """Reference: what every corner needs in numpy (legs, unit directions, the turn, a corner
    distance and four control points per spiral), unverified."""
    vin, vout = corners - p0, p1 - corners
    lin, lout = np.linalg.norm(vin, axis=1), np.linalg.norm(vout, axis=1)
    tin, tout = vin / lin[:, None], vout / lout[:, None]
    cos_t = np.einsum("ij,ij->i", tin, tout)
    half = 0.5 * np.arccos(np.clip(cos_t, -1.0, 1.0))
    d = np.minimum(lin, lout) * np.cos(half)
    legs = np.stack([corners - d[:, None] * tin, corners - 0.6 * d[:, None] * tin, corners, corners + 0.6 * d[:, None] * tout])
    return np.stack([legs, legs[::-1]], axis=1)


def transitions(scale: float = 1.0) -> Guard:
    from spiral_cad.core import batch

    n = int(200_000 * scale)
    rng = np.random.default_rng(5)
    r = rng.uniform(0.5, 5.0, n)
    p, d = np.zeros((n, 2)), np.tile([1.0, 0.0], (n, 1))
    centers = np.column_stack([rng.uniform(-3.0, 3.0, n), r * rng.uniform(1.01, 1.5, n)])
    return Guard(f"batch line → circle, {n:,} rows", lambda: batch.line_to_circle(p, d, centers, r),
                 "the closed form in numpy", lambda: numpy_line_to_circle(p, d, centers, r), 2.0, 0.23)  # fmt: skip


def corners(dim: int, scale: float = 1.0) -> Guard:
    from spiral_cad.design import corner_legs, round_corners_batch

    n = int(100_000 * scale)
    p0, c, p1, _ = corner_legs(random_polyline(n, dim, np.random.default_rng(dim)))
    where = "in the plane" if dim == 2 else "in space"
    return Guard(f"round_corners_batch {where}, {n:,} corners, max_deviation", lambda: round_corners_batch(p0, c, p1, max_deviation=0.05),
                 "legs, turns and pairs in numpy", lambda: numpy_corners(p0, c, p1), 15.0 if dim == 2 else 20.0, 4.2 if dim == 2 else 6.4)  # fmt: skip


def chain_building(scale: float = 1.0) -> Guard:
    from spiral_cad import Chain
    from spiral_cad.design import Alignment

    pis = [[1000.0 * k, 250.0 * (k % 2)] for k in range(int(1000 * scale) + 2)]
    segments = list(Alignment.from_pis(pis, 800.0, spiral_angles=0.08, units="m").chain)

    def ours() -> object:
        return Chain(segments, units="m")

    def reference() -> object:  # the floor of any chain of these objects: visit each and read its ends
        return [(s.start, s.end, s.start_tangent) for s in segments]

    return Guard(
        f"Chain of {len(segments):,} segments (joints measured)", ours, "reading each segment's ends in Python", reference, 5.0, 0.73
    )


def opendrive_write(scale: float = 1.0) -> Guard:
    from spiral_cad.cad.export import export_opendrive
    from spiral_cad.design import Alignment

    alignment = Alignment.from_pis(
        [[1000.0 * k, 250.0 * (k % 2)] for k in range(int(500 * scale) + 2)], 800.0, spiral_angles=0.08, units="m"
    )
    count = len(alignment.chain)
    folder = Path(tempfile.mkdtemp())

    def reference() -> object:  # ElementTree writing as many geometries, each with its paramPoly3's attributes
        root = ET.Element("OpenDRIVE")
        plan = ET.SubElement(ET.SubElement(root, "road"), "planView")
        for i in range(count):
            g = ET.SubElement(plan, "geometry", s=repr(i * 1.5), x=repr(i * 0.1), y=repr(i * 0.2), hdg="0.5", length="12.25")
            ET.SubElement(g, "paramPoly3", **{k: repr(0.1 * i + j) for j, k in enumerate(("aU", "bU", "cU", "dU", "aV", "bV", "cV", "dV"))})
        ET.ElementTree(root).write(folder / "floor.xml")

    return Guard(f"export_opendrive, {count:,} segments", lambda: export_opendrive(alignment, folder / "road.xodr"),
                 "ElementTree writing as many geometries", reference, 4.0, 0.5)  # fmt: skip


def fitting(scale: float = 1.0) -> Guard:
    from scipy.interpolate import make_splprep

    from spiral_cad import fit_points
    from spiral_cad.design import Alignment

    alignment = Alignment.from_pis([[0, 0], [300, 0], [600, 200], [900, 150]], 200.0, spiral_angles=0.1, units="m")
    truth, n = alignment.chain, int(2_000 * scale)
    points = truth.point_at(np.linspace(0.0, truth.length, n)) + np.random.default_rng(2).normal(0.0, 0.0025, (n, 2))
    return Guard(f"fit_points, {n:,} noisy points, tolerance 0.05", lambda: fit_points(points, 0.05, units="m"),
                 "scipy make_splprep smoothing spline", lambda: make_splprep(points.T, s=len(points) * 0.0025**2), 40.0, 11.0)  # fmt: skip


def face_checker(scale: float = 1.0) -> Guard:
    import build123d as bd

    from spiral_cad.cad.faces import check_faces

    box = bd.fillet(bd.Box(40, 20, 8).edges().filter_by(bd.Axis.Z), 2)
    shape = bd.Compound([box.moved(bd.Location((50 * (i % 5), 30 * (i // 5), 0))) for i in range(max(1, int(10 * scale)))])
    return Guard(f"check_faces, {10 * len(shape.solids())} faces in memory", lambda: check_faces(shape),
                 "OCCT's BRepCheck of the same shape", lambda: shape.is_valid, 15.0, 3.0)  # fmt: skip


def continuous_box(scale: float = 1.0) -> Guard:
    del scale  # one box
    import build123d as bd

    from spiral_cad.build123d import ContinuousBox

    return Guard("ContinuousBox(60, 40, 12, 8, edge_radius=3)", lambda: ContinuousBox(60, 40, 12, 8, edge_radius=3),
                 "build123d fillet(Box(60, 40, 12).edges(), 3)", lambda: bd.fillet(bd.Box(60, 40, 12).edges(), 3), 60.0, 14.0)  # fmt: skip


#: Every guard by name, built on demand with its inputs at ``scale`` × their size (the CAD ones import build123d).
GUARDS: dict[str, Callable[..., Guard]] = {
    "transitions": transitions,
    "corners-plane": lambda scale=1.0: corners(2, scale),
    "corners-space": lambda scale=1.0: corners(3, scale),
    "chain": chain_building,
    "opendrive": opendrive_write,
    "fit": fitting,
    "faces": face_checker,
    "box": continuous_box,
}


def judge(guard: Guard, rounds: int = ROUNDS, warm_up: bool = True) -> Verdict:
    """Time ``guard`` against its reference (alternating, after a warm-up each unless told): fastest runs."""
    t = compare({"ours": guard.ours, "reference": guard.reference}, rounds, warm_up)
    return Verdict(guard, min(t["ours"].runs), min(t["reference"].runs))


def run(names: list[str] | None = None, rounds: int = ROUNDS) -> list[Verdict]:
    """Judge the named guards (default: all), printing each verdict as it comes."""
    verdicts = []
    for name in names or list(GUARDS):
        verdict = judge(GUARDS[name](), rounds)
        print("  " + " | ".join(verdict.row()), flush=True)
        verdicts.append(verdict)
    return verdicts


def main() -> int:
    parser = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    parser.add_argument("--rounds", type=int, default=ROUNDS)
    parser.add_argument("--only", nargs="+", choices=list(GUARDS))
    parser.add_argument("--out", help="also write the verdicts to this markdown file")
    args = parser.parse_args()
    verdicts = run(args.only, args.rounds)
    header = ["operation", "ours (fastest)", "reference (fastest)", "ratio", "limit", "verdict"]
    text = f"# Speed guard\n\nMachine: {machine()}. Fastest of {args.rounds} alternating runs each.\n\n{table(header, [v.row() for v in verdicts])}\n"
    if args.out:
        Path(args.out).write_text(text, encoding="utf-8")
    failed = [v.guard.name for v in verdicts if not v.passed]
    if failed:
        print(f"speed guard failed: {', '.join(failed)}", file=sys.stderr)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
