"""Chains and alignments at scale, against another version of the package in the same run.

Run: ``.venv/bin/python benchmarks/bench_chains.py [--baseline REF] [--repeat R] [--quick] [--out FILE]``.

Jobs (a zigzag of 1 km tangents, R = 800 m, as in ``bench_roads.py``):

* ``Chain(segments)``: a chain of 1 k / 10 k / 40 k fresh segments (lines, spirals,
  arcs of an alignment; fresh objects each run, so spiral lengths are measured);
* ``Chain.join(parts)``: the same chains from their transitions (fresh each run);
* ``Alignment.from_pis``: 100 … 10 000 PIs with given spiral angles and with
  criteria (80 km/h), with the growth exponent of each fitted over the sizes.

Each job runs in two worker processes, ours and the baseline (the package as
it is at git ``REF``, exported with ``git archive`` into a temporary folder;
by default the package before its chains were array-backed, when git can
find it; none in ``--quick``), alternating run by run; the table gives
medians, the baseline/ours ratio and the goals (``Alignment.from_pis`` ≥ 100 k segments/s:
10 000 PIs in ≤ 0.4 s with given angles, ≤ 0.6 s with criteria).
"""

from __future__ import annotations

import argparse
import json
import math
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from timing import growth_exponent, machine, write_markdown

#: The modules whose code these numbers measure (stamped into the results: ``timing.code_stamp``).
MEASURES = (
    "spiral_cad.core.chain",
    "spiral_cad.core.segments",
    "spiral_cad.core.rows",
    "spiral_cad.core._chain_kernels",
    "spiral_cad.design.alignment",
)

ROOT = Path(__file__).resolve().parent.parent
CHAIN_SIZES = (1_000, 10_000, 40_000)
PI_SIZES = (100, 300, 1_000, 3_000, 10_000)
GOALS = {"from_pis": 0.4, "from_pis_criteria": 0.6}  # seconds at 10 000 PIs


def zigzag(count: int) -> list[list[float]]:
    return [[1000.0 * k, 250.0 * (k % 2)] for k in range(count + 2)]


# ------------------------------------------------------------------ worker


class Jobs:
    """What a worker times; built with whichever ``spiral_cad`` is on its path."""

    def __init__(self) -> None:
        import spiral_cad as sc
        from spiral_cad.design import Alignment

        self.sc, self.Alignment = sc, Alignment
        self.cache: dict[tuple[str, int], object] = {}

    def _alignment(self, pis: int):
        key = ("alignment", pis)
        if key not in self.cache:
            self.cache[key] = self.Alignment.from_pis(zigzag(pis), 800.0, spiral_angles=0.08, units="m")
        return self.cache[key]

    def prepare(self, job: str, size: int):
        """The timed call for ``job`` at ``size`` (its inputs made fresh, untimed)."""
        if job in ("chain", "join"):
            alignment = self._alignment(math.ceil((size - 1) / 4))
            if job == "chain":
                segments = [s.reversed().reversed() for s in list(alignment.chain.segments)[:size]]  # fresh objects
                return lambda: self.sc.Chain(segments, units="m")
            parts = [t.reversed().reversed() for c in alignment.curves for t in (c.entry, c.exit)]
            return lambda: self.sc.Chain.join(parts, start=(0.0, 0.0), end=zigzag(len(alignment.curves))[-1], units="m")
        pis = zigzag(size)
        if job == "from_pis":
            return lambda: self.Alignment.from_pis(pis, 800.0, spiral_angles=0.08, units="m")
        return lambda: self.Alignment.from_pis(pis, 800.0, units="m", design_speed=80, max_jerk=0.6)

    def run(self, job: str, size: int) -> tuple[float, int]:
        call = self.prepare(job, size)
        t0 = time.perf_counter()
        result = call()
        seconds = time.perf_counter() - t0
        chain = getattr(result, "chain", result)
        return seconds, len(chain)


def worker() -> None:
    """Answer one JSON request per line: {"job", "size"} → {"seconds", "segments"}."""
    jobs = Jobs()
    for line in sys.stdin:
        request = json.loads(line)
        try:
            seconds, segments = jobs.run(request["job"], request["size"])
            print(json.dumps({"seconds": seconds, "segments": segments}), flush=True)
        except Exception as error:  # the baseline may lack a job: report, do not die
            print(json.dumps({"error": f"{type(error).__name__}: {error}"}), flush=True)


# ------------------------------------------------------------------ driver


class Worker:
    def __init__(self, pythonpath: str | None, cwd: str):
        env = None
        if pythonpath is not None:
            import os

            env = {**os.environ, "PYTHONPATH": pythonpath}
        self.process = subprocess.Popen([sys.executable, str(Path(__file__).resolve()), "--worker"], stdin=subprocess.PIPE,
                                        stdout=subprocess.PIPE, text=True, env=env, cwd=cwd)  # fmt: skip

    def ask(self, job: str, size: int) -> dict:
        self.process.stdin.write(json.dumps({"job": job, "size": size}) + "\n")
        self.process.stdin.flush()
        return json.loads(self.process.stdout.readline())

    def close(self) -> None:
        self.process.stdin.close()
        self.process.wait()


def baseline_source(ref: str, folder: Path) -> Path:
    """``spiral_cad`` as it is at git ``ref``, exported into ``folder`` (no checkout touched)."""
    archive = subprocess.run(["git", "-C", str(ROOT), "archive", ref, "spiral_cad"], check=True, capture_output=True).stdout
    subprocess.run(["tar", "-x", "-C", str(folder)], input=archive, check=True)
    return folder


#: The package before array-backed chains (the first parent of their merge).
BEFORE_CHAINS = "0a2f552^1"


def resolvable(ref: str) -> bool:
    """Whether git knows ``ref`` here (a clone may be shallow, or no clone at all)."""
    return subprocess.run(["git", "-C", str(ROOT), "rev-parse", "--verify", "--quiet", ref + "^{commit}"],
                          capture_output=True).returncode == 0  # fmt: skip


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--baseline", help=f"git ref of the version to compare with ('' for none; default {BEFORE_CHAINS})")
    parser.add_argument("--repeat", type=int, default=7)
    parser.add_argument("--quick", action="store_true", help="small sizes, one run (checks that the script works)")
    parser.add_argument("--out", help="also write the table to this markdown file")
    parser.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.worker:
        worker()
        return
    if args.baseline is None:
        args.baseline = "" if args.quick else BEFORE_CHAINS
    if args.baseline and not resolvable(args.baseline):
        print(f"note: git cannot find {args.baseline!r} here; measuring without a baseline")
        args.baseline = ""
    chain_sizes, pi_sizes, repeat = ((200, 1_000), (20, 60, 200), 1) if args.quick else (CHAIN_SIZES, PI_SIZES, args.repeat)
    with tempfile.TemporaryDirectory() as scratch:
        ours = Worker(None, str(ROOT))
        theirs = Worker(str(baseline_source(args.baseline, Path(scratch))), scratch) if args.baseline else None
        workers = [("ours", ours)] + ([("baseline", theirs)] if theirs else [])
        plan = [("chain", n) for n in chain_sizes] + [("join", n) for n in chain_sizes]
        plan += [(job, n) for job in ("from_pis", "from_pis_criteria") for n in pi_sizes]
        results: dict[tuple[str, int, str], list[float]] = {}
        segments: dict[tuple[str, int], int] = {}
        for job, size in plan:
            for _, w in workers:  # warm-up: compilation, caches
                w.ask(job, size)
            for _ in range(repeat):  # alternate ours and the baseline, run by run
                for name, w in workers:
                    answer = w.ask(job, size)
                    if "error" in answer:
                        print(f"{name} {job} {size}: {answer['error']}", file=sys.stderr)
                        continue
                    results.setdefault((job, size, name), []).append(answer["seconds"])
                    segments[(job, size)] = answer["segments"]
            print(
                f"{job} {size}: "
                + ", ".join(f"{name} {statistics.median(results.get((job, size, name), [math.nan])):.4f} s" for name, _ in workers),
                flush=True,
            )
        for _, w in workers:
            w.close()
    header = ["job", "size", "segments", "ours: median s", "ours: segments/s"]
    if theirs:
        header += [f"{args.baseline}: median s", f"{args.baseline} / ours"]
    rows = []
    labels = {"chain": "Chain(segments)", "join": "Chain.join(parts)", "from_pis": "Alignment.from_pis, given angles",
              "from_pis_criteria": "Alignment.from_pis, criteria (80 km/h)"}  # fmt: skip
    for job, size in plan:
        ours_t = statistics.median(results[(job, size, "ours")])
        row = [labels[job], f"{size:,}" + (" PIs" if job.startswith("from") else ""), f"{segments[(job, size)]:,}", f"{ours_t:.4f}",
               f"{segments[(job, size)] / ours_t:,.0f}"]  # fmt: skip
        if theirs:
            base = results.get((job, size, "baseline"))
            base_t = statistics.median(base) if base else math.nan
            row += [f"{base_t:.4f}", f"{base_t / ours_t:.1f}×"]
        rows.append(row)
    notes = []
    for job in ("chain", "join", "from_pis", "from_pis_criteria"):
        sizes = chain_sizes if job in ("chain", "join") else pi_sizes
        for name, _ in workers:
            times = [statistics.median(results[(job, n, name)]) for n in sizes if (job, n, name) in results]
            if len(times) == len(sizes) >= 3:
                # Over every size, and over the largest three (where a fixed cost no longer hides the growth).
                notes.append(f"{labels[job]} ({name}): growth exponent {growth_exponent(list(sizes), times):.2f} over "
                             f"{sizes[0]:,}…{sizes[-1]:,}, {growth_exponent(list(sizes[-3:]), times[-3:]):.2f} over {sizes[-3]:,}…{sizes[-1]:,}")  # fmt: skip
    for job, goal in GOALS.items():
        if (job, 10_000, "ours") in results:
            t = statistics.median(results[(job, 10_000, "ours")])
            verdict = "met" if t <= goal else "missed"
            notes.append(
                f"{labels[job]}, 10 000 PIs: {t:.3f} s (goal ≤ {goal} s: {verdict}; {segments[(job, 10_000)] / t:,.0f} segments/s)"
            )
    print("| " + " | ".join(header) + " |")
    print("|" + "---|" * len(header))
    for row in rows:
        print("| " + " | ".join(row) + " |")
    for note in notes:
        print(note)
    print(f"machine: {machine()}")
    if args.out:
        note = (
            f"Medians of {repeat} runs per job, ours and {args.baseline or 'no baseline'} alternating in two worker processes.\n\n"
            + "\n".join(f"- {n}" for n in notes)
        )
        write_markdown(args.out, "Chains and alignments at scale", note, header, rows)


if __name__ == "__main__":
    main()
