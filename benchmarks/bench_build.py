"""`spiral-cad build` of long road alignments: wall time and peak memory of the command.

Run: ``.venv/bin/python benchmarks/bench_build.py [--quick] [--pis N ...] [--repeat R] [--out FILE]``.

A design file of N PIs (a zigzag of 1 km tangents, R = 800 m, spirals chosen
from the criteria at 80 km/h, as in ``bench_roads.py``) is built by the
command as a user runs it, in a fresh process each time: with ``--no-plots``
and with plots, the two taking turns run by run. The floor beside them is the
same command's start (``spiral-cad build --help``: Python and the package
imported). Peak memory is the child's maximum resident set.
Goals: 10 000 PIs in ≤ 5 s without plots and ≤ 8 s with, ≤ 400 MB; growth
linear (the exponent over the sizes is printed).
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from bench_roads import zigzag
from timing import Report, Timing, arguments, growth_exponent

#: The modules whose code these numbers measure (stamped into the results: ``timing.code_stamp``).
MEASURES = ("spiral_cad.app.cli", "spiral_cad.app.designfile", "spiral_cad.cad.export")

COMMAND = [str(Path(sys.executable).parent / "spiral-cad")]  # the installed command, as a user runs it


def run(args: list[str], cwd: Path) -> tuple[float, float]:
    """Wall seconds and peak resident MB of one command run to completion (it must succeed)."""
    started = time.perf_counter()
    child = subprocess.Popen(COMMAND + args, cwd=cwd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    _, status, usage = os.wait4(child.pid, 0)
    seconds = time.perf_counter() - started
    child.returncode = os.waitstatus_to_exitcode(status)
    error = child.stderr.read().decode(errors="replace")
    child.stderr.close()
    if child.returncode != 0:
        raise SystemExit(f"spiral-cad {' '.join(args)} failed ({child.returncode}): {error[-2000:]}")
    return seconds, usage.ru_maxrss / 1024.0  # kB on Linux


def design(count: int) -> dict:
    pis = zigzag(count)
    road = {"name": "road", "type": "alignment", "pis": pis, "radii": 800, "design_speed": 80}
    return {"units": "m", "designs": [road]}


def main() -> None:
    args = arguments(__doc__, pis=([1_000, 3_000, 10_000], [20]), repeat=(3, 1))
    report = Report("`spiral-cad build` of long alignments",
                    f"Medians of {args.repeat} runs, each a fresh process; with and without plots taking turns.")  # fmt: skip
    with tempfile.TemporaryDirectory() as scratch:
        folder = Path(scratch)
        floor = Timing(tuple(run(["build", "--help"], folder)[0] for _ in range(args.repeat if args.quick else max(3, args.repeat))))
        report.add("command start (`spiral-cad build --help`)", floor.median, "s", floor)
        medians: dict[str, list[float]] = {"no plots": [], "plots": []}
        for count in args.pis:
            path = folder / f"road_{count}.json"
            path.write_text(json.dumps(design(count)), encoding="utf-8")
            runs: dict[str, list[tuple[float, float]]] = {"no plots": [], "plots": []}
            for _ in range(args.repeat):
                runs["no plots"].append(run(["build", str(path), "--out", str(folder / "a"), "--no-plots"], folder))
                runs["plots"].append(run(["build", str(path), "--out", str(folder / "b")], folder))
            goals = {"no plots": 5.0, "plots": 8.0} if count == 10_000 else {}
            for label, values in runs.items():
                timing = Timing(tuple(seconds for seconds, _ in values))
                memory = max(mb for _, mb in values)
                medians[label].append(timing.median)
                goal = goals.get(label)
                verdict = "" if goal is None else f"≤ {goal:g} s, ≤ 400 MB: " + (
                    "met" if timing.median <= goal and memory <= 400 else "missed")  # fmt: skip
                report.add(f"build {count:,} PIs, {label}", timing.median, "s", timing,
                           peer=f"peak memory {memory:,.0f} MB; start {floor.median:.2f} s",
                           ratio=None, goal=verdict)  # fmt: skip
        if len(args.pis) >= 2:
            lines = [f"- {label}: growth exponent {growth_exponent(args.pis, values):.2f} over "
                     f"{args.pis[0]:,} … {args.pis[-1]:,} PIs" for label, values in medians.items()]  # fmt: skip
            report.section("Growth", "\n".join(lines))
    report.finish(args)


if __name__ == "__main__":
    main()
