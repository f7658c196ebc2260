"""Roads in 3-D at scale: profile design, corridor solids, OpenDRIVE with elevation and superelevation.

Run: ``.venv/bin/python benchmarks/bench_roads3d.py [--repeat R] [--quick] [--out FILE]``.
Prints a markdown table of medians over ``repeat`` runs, each beside a peer
measured in the same run:

* profile design of 1 000 PVIs (the shortest vertical curves from the
  stopping sight distance at 100 km/h), and evaluating it at 1 M stations
  against ``numpy.interp`` of the same PVIs (a floor: straight grades only);
* the corridor solid of a 10 km road (lanes, crown, superelevation, crest
  and sag curves): time, faces, validity, against build123d's ``sweep`` of
  the same cross-section along the plan wire (flat: no profile, no banking);
* OpenDRIVE with elevation and superelevation for 100 … 10 000 PIs (up to
  40 001 segments): write and read against ``ElementTree.parse`` of the same
  file (as called, and with the garbage collector off: the parse's floor),
  with the growth exponent of each (fitted over the sizes). Goal for 40 k
  segments: write and read ≤ 1 s each.
"""

from __future__ import annotations

import gc
import tempfile
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
from timing import arguments, machine, median_time, write_markdown

from spiral_cad.cad.export import export_opendrive
from spiral_cad.design import Alignment, Profile
from spiral_cad.io.opendrive import read_opendrive

#: The modules whose code these numbers measure (stamped into the results: ``timing.code_stamp``).
MEASURES = (
    "spiral_cad.design.alignment",
    "spiral_cad.design.profile",
    "spiral_cad.build123d",
    "spiral_cad.build123d._lines",
    "spiral_cad.build123d._parts",
    "spiral_cad.build123d._sketches",
    "spiral_cad.io.opendrive",
)


def zigzag_alignment(count: int, spacing: float = 1000.0, offset: float = 250.0, speed: float = 80.0) -> Alignment:
    """``count`` curves on a zigzag of PIs ``spacing`` apart."""
    pis = [[spacing * k, offset * (k % 2)] for k in range(count + 2)]
    return Alignment.from_pis(pis, 800.0, units="m", design_speed=speed)


def rolling_profile(alignment: Alignment, spacing: float, speed: float | None = 80.0, seed: int = 1) -> Profile:
    """PVIs every ``spacing`` along the alignment, grades within ±3 %."""
    rng = np.random.default_rng(seed)
    stations = np.linspace(alignment.start_station, alignment.end_station, max(2, round(alignment.chain.length / spacing)) + 1)
    grades = rng.uniform(0.005, 0.03, len(stations) - 1) * np.where(np.arange(len(stations) - 1) % 2, -1.0, 1.0)
    elevations = 100.0 + np.concatenate([[0.0], np.cumsum(grades * np.diff(stations))])
    return Profile.from_pvis(np.column_stack([stations, elevations]), units="m", design_speed=speed, alignment=alignment)


def profile_rows(repeat: int) -> list[list[str]]:
    rng = np.random.default_rng(7)
    stations = np.cumsum(rng.uniform(400.0, 600.0, 1000))
    grades = rng.uniform(0.005, 0.04, 999) * np.where(np.arange(999) % 2, -1.0, 1.0)
    pvis = np.column_stack([stations, 100.0 + np.concatenate([[0.0], np.cumsum(grades * np.diff(stations))])])
    design = median_time(lambda: Profile.from_pvis(pvis, units="m", design_speed=100), repeat)
    profile = Profile.from_pvis(pvis, units="m", design_speed=100)
    samples = np.random.default_rng(3).uniform(stations[0], stations[-1], 1_000_000)
    ours = median_time(lambda: profile.elevation(samples), repeat)
    peer = median_time(lambda: np.interp(samples, pvis[:, 0], pvis[:, 1]), repeat)
    return [
        ["profile design, 1 000 PVIs (curves chosen at 100 km/h)", f"{design * 1e3:.1f} ms", "", ""],
        ["profile z at 1 M stations / numpy.interp of the PVIs", f"{ours * 1e3:.1f} ms", f"{peer * 1e3:.1f} ms",
         f"{ours / peer:.2f}×"],
    ]  # fmt: skip


def corridor_rows(repeat: int, length_km: float) -> list[list[str]]:
    from build123d import Plane, Polygon, sweep

    from spiral_cad.build123d import chain_to_wire, corridor
    from spiral_cad.cad.export import CrossSection

    count = max(1, round(length_km))  # a curve every kilometre
    alignment = zigzag_alignment(count, offset=150.0, speed=100.0)
    profile = rolling_profile(alignment, 400.0, speed=100.0)
    section = CrossSection(driving_lanes=2)
    road = corridor(alignment, profile, section)
    ours = median_time(lambda: corridor(alignment, profile, section), repeat, warm_up=False)
    faces = len(road.solid.faces())
    wire = chain_to_wire(alignment.chain)
    start, tangent = wire @ 0, wire % 0
    half = 2 * 3.5 + 2.5

    def flat_sweep():
        plane = Plane(origin=start, x_dir=(0, 0, 1), z_dir=tangent)
        outline = Polygon((0, -half), (0.0, half), (-0.5, half), (-0.5, -half), align=None).moved(plane.location)
        return sweep(outline.faces()[0], path=wire)

    peer = median_time(flat_sweep, repeat, warm_up=False)
    swept = flat_sweep()
    return [
        [f"corridor, {alignment.chain.length / 1000:.1f} km ({len(alignment.chain)} segments): faces, valid",
         f"{ours:.2f} s, {faces} faces, {'valid' if road.solid.is_valid else 'INVALID'}",
         f"{peer:.2f} s, {len(swept.faces())} faces, {'valid' if swept.is_valid else 'INVALID'}", f"{ours / peer:.2f}×"],
        ["corridor: edges within (measured) / tolerance", f"{road.roadway.deviation:.2g} / {road.roadway.tolerance:.2g} m", "", ""],
    ]  # fmt: skip


def opendrive_rows(repeat: int, sizes: list[int]) -> list[list[str]]:
    folder = Path(tempfile.mkdtemp())
    rows, segments, writes, reads = [], [], [], []
    for count in sizes:
        alignment = zigzag_alignment(count)
        profile = rolling_profile(alignment, 500.0)
        path = folder / f"road{count}.xodr"
        write = median_time(lambda: export_opendrive(alignment, path, profile=profile), repeat)
        read = median_time(lambda: read_opendrive(path), repeat)
        parse = median_time(lambda: ET.parse(path), repeat)
        floor = median_time(lambda: _without_gc(lambda: ET.parse(path)), repeat)
        segments.append(len(alignment.chain))
        writes.append(write)
        reads.append(read)
        rows.append([f"OpenDRIVE with elevation, {count:,} PIs ({len(alignment.chain):,} segments): write / read",
                     f"{write:.3f} / {read:.3f} s", f"ET.parse {parse:.3f} s (without gc {floor:.3f} s)",
                     f"read {read / parse:.2f}× ({read / floor:.2f}×) the parse"])  # fmt: skip
    if len(sizes) > 1:
        fit = lambda t: np.polyfit(np.log(segments), np.log(t), 1)[0]  # noqa: E731
        rows.append(["growth exponent over the sizes: write / read", f"{fit(writes):.2f} / {fit(reads):.2f}", "", ""])
    return rows


def _without_gc(job):
    """``job()`` with the cyclic garbage collector off (what the reader does): the parse's floor."""
    gc.disable()
    try:
        return job()
    finally:
        gc.enable()


def main() -> None:
    args = arguments(__doc__, repeat=(3, 1))
    repeat = args.repeat
    rows = profile_rows(repeat)
    rows += corridor_rows(repeat, 1.0 if args.quick else 10.0)
    rows += opendrive_rows(repeat, [10, 100] if args.quick else [100, 1000, 10000])
    header = ["job", "ours", "peer (same run)", "ratio"]
    print("| " + " | ".join(header) + " |")
    print("|" + "---|" * len(header))
    for row in rows:
        print("| " + " | ".join(row) + " |", flush=True)
    print(f"machine: {machine()}")
    if args.out:
        write_markdown(args.out, "Roads in 3-D at scale", f"Medians of {repeat} runs.", header, rows)


if __name__ == "__main__":
    main()
