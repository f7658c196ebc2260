"""Many files at once: ``spiral-cad check FOLDER`` on dask.distributed against one process checking them in turn.

Run: ``.venv/bin/python benchmarks/bench_many.py [--files N] [--workers N ...] [--rounds R] [--quick] [--out FILE]``.

It writes N small STEP files (one wire of a line-to-line transition each, our
own writer; every tenth holds a second, loose piece, so it fails ``--require G2``)
and checks them with ``--require G2``:

* **one process** (the peer): ``main(["check", file, "--require", "G2"])`` for
  every file in turn, in this process — the files one by one, no cluster;
* **dask, W workers**: ``main(["check", folder, "--require", "G2", "--workers", W,
  "--summary", csv])`` — a new ``LocalCluster`` of W worker processes, each
  importing spiral_cad and OCCT, started and stopped inside the timed run;
* **dask, a run of 2 files**: the fixed cost of a dask run (the cluster's
  start and stop), to tell it from the rate per file once started (N − 2
  files over the difference of the medians);
* **one command per file** (a shell loop's ``spiral-cad check FILE``), timed on
  a sample of the files: every file pays the command's start.

The same verdicts are asserted for every file in every run. Files per second
are N over the median wall time; the ratio is against the one-process run of
the same rounds. The machine's cores bound the ratio (its load is in the
machine line).
"""

from __future__ import annotations

import contextlib
import csv
import io
import os
import random
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from timing import Report, Timing, arguments, compare

from spiral_cad import Chain, Line, line_to_line
from spiral_cad.app.cli import main
from spiral_cad.io.step import write_step

#: The modules whose code these numbers measure (stamped into the results: ``timing.code_stamp``).
MEASURES = ("spiral_cad.app.many",)


def write_files(folder: Path, count: int) -> dict[str, str]:
    """``count`` STEP files in ``folder``; the verdict each should get (``ok``, or ``fail``: two pieces)."""
    rng = random.Random(7)
    expected = {}
    for k in range(count):
        corner = (rng.uniform(20.0, 80.0), rng.uniform(5.0, 60.0))
        end = (corner[0] + rng.uniform(10.0, 60.0), corner[1] + rng.uniform(10.0, 60.0))
        chains = [Chain(line_to_line((0.0, 0.0), corner, end).spirals)]
        if k % 10 == 9:
            chains.append(Chain([Line((500.0, 0.0), (600.0, 10.0))]))
        name = f"part_{k:05d}.step"
        write_step(chains, folder / name, f"part {k}", "mm", "bench_many")
        expected[str(folder / name)] = "fail" if k % 10 == 9 else "ok"
    return expected


def one_process(files: list[str]) -> dict[str, str]:
    """Every file checked in turn in this process; its verdict."""
    verdicts = {}
    with contextlib.redirect_stdout(io.StringIO()):
        for file in files:
            verdicts[file] = {0: "ok", 1: "fail"}.get(main(["check", file, "--require", "G2"]), "error")
    return verdicts


def on_dask(folder: Path, workers: int, summary: Path) -> dict[str, str]:
    """The folder checked on a new LocalCluster of ``workers`` processes; the verdicts of its summary."""
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
        main(["check", str(folder), "--require", "G2", "--workers", str(workers), "--summary", str(summary)])
    with summary.open(encoding="utf-8") as handle:
        return {row["file"]: row["verdict"] for row in csv.DictReader(handle)}


def one_command_each(files: list[str]) -> float:
    """Seconds per file of ``python -m spiral_cad.app.cli check FILE`` run once per file."""
    started = time.perf_counter()
    for file in files:
        subprocess.run([sys.executable, "-m", "spiral_cad.app.cli", "check", file, "--require", "G2"], capture_output=True, check=False)
    return (time.perf_counter() - started) / len(files)


def main_bench() -> None:
    args = arguments(__doc__, files=(1000, 20), workers=([1, 2], [2]), rounds=(2, 1), sample=(20, 2))
    report = Report("Many files: check on dask.distributed", note=f"{args.files} small STEP files, --require G2.")
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp) / "parts"
        folder.mkdir()
        started = time.perf_counter()
        expected = write_files(folder, args.files)
        report.add("writing the files", args.files / (time.perf_counter() - started), "files/s")
        files = sorted(expected)
        one_process(files[:3])  # OCCT loaded, the kernels compiled: the peer's warm-up
        verdicts: dict[str, dict[str, str]] = {}
        jobs = {"one process": lambda: verdicts.__setitem__("one process", one_process(files))}
        for w in args.workers:
            jobs[f"dask, {w} workers"] = lambda w=w: verdicts.__setitem__(f"dask, {w} workers", on_dask(folder, w, Path(tmp) / f"s{w}.csv"))
        timings: dict[str, Timing] = compare(jobs, args.rounds, warm_up=False)
        peer = timings["one process"]
        for name, timing in timings.items():
            same = verdicts[name] == expected
            ratio = peer.median / timing.median if name != "one process" else None
            report.add(f"{name}: files checked per second (identical verdicts {same})", args.files / timing.median, "files/s",
                       timing, "one process" if ratio else "", ratio, "")  # fmt: skip
            if not same:
                raise SystemExit(f"{name}: verdicts differ from the files' own")
        pair = Path(tmp) / "pair"
        pair.mkdir()
        for file in files[:2]:
            (pair / Path(file).name).write_bytes(Path(file).read_bytes())
        for w in args.workers:  # the fixed cost of a run: its cluster's start and stop
            start = compare({"pair": lambda w=w: on_dask(pair, w, Path(tmp) / "pair.csv")}, args.rounds, warm_up=False)["pair"]
            report.add(f"dask, {w} workers: a run of 2 files (the cluster's start and stop)", start.median, "s", start)
            rest = timings[f"dask, {w} workers"].median - start.median
            if rest > 0:
                rate = (args.files - 2) / rest
                report.add(f"dask, {w} workers: files per second once started (the difference of the medians)", rate, "files/s",
                           None, "one process", rate * peer.median / args.files)  # fmt: skip
        each = one_command_each(files[: args.sample])
        report.add(
            f"one command per file ({args.sample} files)", 1.0 / each, "files/s", None, "one process", peer.median / args.files / each
        )
    report.section(
        "Reading the table",
        f"Each dask run starts its cluster (worker processes importing spiral_cad and OCCT) inside the timed run; "
        f"{os.cpu_count()} cores here, shared. On a cluster the same command takes `--scheduler tcp://HOST:8786`.",
    )
    report.finish(args)


if __name__ == "__main__":
    main_bench()
