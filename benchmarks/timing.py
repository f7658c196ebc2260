"""The benchmark harness: every job against its peer in one process, alternating; medians, spreads, ratios.

The convention every ``benchmarks/bench_NAME.py`` follows (``run_all.py`` finds
and runs them all; ``make bench``; the test suite runs them with ``--quick``):

* It runs as ``python benchmarks/bench_NAME.py [--quick] [--out FILE]``; take
  the arguments with ``arguments(__doc__)``. ``run_all.py`` runs each script in
  its own process and writes ``benchmarks/results_NAME.md``.
* Jobs are timed with ``compare``: a job and its peers (the same work done
  another way: a clothoid, raw OCP calls, the memory floor) run in turn,
  round-robin, after one warm-up each, so the load of a shared machine falls
  on all of them alike; a ratio is always taken between medians of one
  ``compare`` call.
* Results go into a ``Report`` (measurement, median, unit, spread of the runs,
  the peer and the ratio, the goal), printed as they come and written as
  markdown by ``--out``; tables that do not fit its columns go into
  ``Report.section``.
* ``--quick`` shrinks every size and round to the least that exercises the
  code (a smoke test: the test suite checks that every script runs and writes
  its table, never its numbers).
* It names the modules whose code its numbers measure in ``MEASURES``
  (module names); every results file it writes states the ``code_stamp`` of
  them and of the script, and ``tests/app/test_benchmark_results.py`` fails
  when a results file no longer matches the code it measured.
"""

from __future__ import annotations

import argparse
import ast
import hashlib
import math
import os
import platform
import statistics
import sys
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np

#: The repository (the folder above ``benchmarks/``).
ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
#: How a results file states the code it measured.
STAMP_PREFIX = "Code measured: "


@dataclass(frozen=True)
class Timing:
    """Wall times of one job in a ``compare`` call (seconds)."""

    runs: tuple[float, ...]

    @property
    def median(self) -> float:
        return statistics.median(self.runs)

    @property
    def spread(self) -> float:
        """(slowest − fastest) / median: how much the machine moved during the runs."""
        return (max(self.runs) - min(self.runs)) / self.median if self.median > 0 else 0.0


def compare(jobs: dict[str, Callable[[], object]], rounds: int, warm_up: bool = True) -> dict[str, Timing]:
    """Time every job ``rounds`` times, taking them in turn (one round = each job once)."""
    if warm_up:
        for job in jobs.values():
            job()  # compilation, caches, first-touch allocations
    runs: dict[str, list[float]] = {name: [] for name in jobs}
    for _ in range(rounds):
        for name, job in jobs.items():
            started = time.perf_counter()
            job()
            runs[name].append(time.perf_counter() - started)
    return {name: Timing(tuple(values)) for name, values in runs.items()}


def latencies(calls: dict[str, Callable[[], object]], rounds: int, number: int) -> dict[str, Timing]:
    """``latency`` of several calls, taken in turn round by round (like ``compare``)."""
    for call in calls.values():
        call()
    runs: dict[str, list[float]] = {name: [] for name in calls}
    for _ in range(rounds):
        for name, call in calls.items():
            started = time.perf_counter()
            for _ in range(number):
                call()
            runs[name].append((time.perf_counter() - started) / number)
    return {name: Timing(tuple(values)) for name, values in runs.items()}


def growth_exponent(sizes: Sequence[float], seconds: Sequence[float]) -> float:
    """k in time ∝ size^k, fitted by least squares on logs (1: linear)."""
    return float(np.polyfit(np.log(np.asarray(sizes, dtype=float)), np.log(np.asarray(seconds, dtype=float)), 1)[0])


def _source(module: str) -> str:
    """The file of a module of this repository by its dotted name (``spiral_cad.core.space``)."""
    base = os.path.join(ROOT, *module.split("."))
    return os.path.join(base, "__init__.py") if os.path.isdir(base) else base + ".py"


def _code(path: str) -> str:
    """A file's code without its docstrings, comments or layout (``ast.dump``): what changes its speed."""
    with open(path, encoding="utf-8") as handle:
        tree = ast.parse(handle.read())
    for node in ast.walk(tree):
        body = getattr(node, "body", None)
        if isinstance(body, list) and body and isinstance(body[0], ast.Expr) and isinstance(getattr(body[0], "value", None), ast.Constant):
            if isinstance(body[0].value.value, str):
                node.body = body[1:] or [ast.Pass()]  # type: ignore[attr-defined]
    return ast.dump(tree)


def code_stamp(script: str, measures: Sequence[str]) -> str:
    """The stamp line of a results file: a hash of the code of ``script`` (a path) and of the
    ``measures`` modules, then what was hashed. Docstrings, comments and layout do not count."""
    digest = hashlib.sha256()
    name = os.path.relpath(os.path.abspath(script), ROOT)
    for label, path in [(name, script), *((m, _source(m)) for m in measures)]:
        digest.update(label.encode() + b"\0" + _code(path).encode() + b"\0")
    return f"{STAMP_PREFIX}{digest.hexdigest()[:16]} ({', '.join([name, *measures])})."


def _stamp() -> str:
    """The stamp of the running script (``__main__``), from its ``MEASURES``; empty without them."""
    main = sys.modules.get("__main__")
    measures = getattr(main, "MEASURES", None)
    script = getattr(main, "__file__", None)
    return code_stamp(script, measures) if measures is not None and script else ""


def machine() -> str:
    """One line naming the machine and the runtime."""
    cpu = platform.processor() or platform.machine()
    return f"{cpu}, {os.cpu_count()} cores, Python {platform.python_version()}, numpy {np.__version__}"


def load() -> str:
    """The 1-minute load average (how busy the shared machine was), if the system tells it."""
    try:
        return f"{os.getloadavg()[0]:.1f}"
    except OSError:
        return "unknown"


def arguments(doc: str | None, **sizes: tuple[object, object]) -> argparse.Namespace:
    """The common command line: ``--quick`` and ``--out FILE``, plus each script's sizes.

    ``sizes`` maps an option name to (full value, quick value); the parsed
    namespace holds the quick value under ``--quick`` unless the option was given.
    """
    parser = argparse.ArgumentParser(description=(doc or "").splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="smallest sizes: a smoke test, not a measurement")
    parser.add_argument("--out", help="also write the results to this markdown file")
    for name, (full, _) in sizes.items():
        kind = type(full[0]) if isinstance(full, list) else type(full)
        parser.add_argument(f"--{name.replace('_', '-')}", type=kind, nargs="+" if isinstance(full, list) else None,
                            default=None, help=f"default {full}")  # fmt: skip
    args = parser.parse_args()
    for name, (full, quick) in sizes.items():
        if getattr(args, name) is None:
            setattr(args, name, quick if args.quick else full)
    return args


def per_second(count: float, timing: Timing, scale: float = 1e6) -> float:
    """Throughput of ``count`` items per run at the median time (in units of ``scale``)."""
    return count / timing.median / scale


@dataclass
class Report:
    """A benchmark's results: one table of measurements and any further sections."""

    title: str
    note: str = ""
    rows: list[tuple[str, ...]] = field(default_factory=list)
    sections: list[str] = field(default_factory=list)

    HEADER = ("measurement", "median", "unit", "spread", "peer (same runs)", "ratio", "goal")

    def add(self, measurement: str, value: float | str, unit: str = "", timing: Timing | None = None,
            peer: str = "", ratio: float | None = None, goal: str = "") -> None:  # fmt: skip
        """One row; ``ratio`` is how many times better ours is than the peer (> 1: ours wins)."""
        shown = value if isinstance(value, str) else _number(value)
        spread = f"{timing.spread:.0%}" if timing is not None and len(timing.runs) > 1 else ""
        row = (measurement, shown, unit, spread, peer, "" if ratio is None else f"{ratio:.2f}×", goal)
        self.rows.append(row)
        print("  " + " | ".join(cell for cell in row if cell), flush=True)

    def section(self, title: str, text: str) -> None:
        """A further markdown section (a table of its own, a note)."""
        self.sections.append(f"## {title}\n\n{text.rstrip()}\n")
        print(f"\n## {title}\n{text}", flush=True)

    def markdown(self) -> str:
        lines = [f"# {self.title}", "", f"Machine: {machine()}; load {load()} when written. {self.note}".rstrip(), ""]
        if _stamp():
            lines[4:4] = [_stamp(), ""]
        if self.rows:
            lines += ["| " + " | ".join(self.HEADER) + " |", "|" + "---|" * len(self.HEADER)]
            lines += ["| " + " | ".join(row) + " |" for row in self.rows]
            lines.append("")
        return "\n".join(lines + self.sections)

    def finish(self, args: argparse.Namespace) -> None:
        """Print the machine line and write ``--out`` if asked."""
        print(f"machine: {machine()}, load {load()}")
        if args.out:
            with open(args.out, "w", encoding="utf-8") as handle:
                handle.write(self.markdown())


def median_time(fn: Callable[[], object], repeat: int, warm_up: bool = True) -> float:
    """Median wall time of ``repeat`` calls of one job (after one warm-up call). For a job
    with a peer use ``compare``, which alternates them."""
    return compare({"job": fn}, repeat, warm_up)["job"].median


def write_markdown(path: str, title: str, note: str, header: Sequence[str], rows: Sequence[Sequence[str]]) -> None:
    """A markdown file: title, machine line and note, then one table (scripts with a ``Report`` use ``finish``)."""
    with open(path, "w", encoding="utf-8") as fh:
        stamp = f"{_stamp()}\n\n" if _stamp() else ""
        fh.write(f"# {title}\n\nMachine: {machine()}; load {load()} when written. {note}\n\n{stamp}{table(header, rows)}\n")


def table(header: Sequence[str], rows: Sequence[Sequence[str]]) -> str:
    """A markdown table."""
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    return "\n".join(lines + ["| " + " | ".join(row) + " |" for row in rows])


def _number(value: float) -> str:
    if not math.isfinite(value):
        return str(value)
    if abs(value) >= 100:
        return f"{value:,.0f}"
    if abs(value) >= 10:
        return f"{value:,.1f}"
    return f"{value:,.2f}" if abs(value) >= 0.1 else f"{value:.3g}"
