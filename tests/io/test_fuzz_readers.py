"""Single-byte mutations of the demo's STEP and IGES files: `spiral-cad check` reports or refuses, never crashes.

Each mutated file is checked by ``spiral-cad check --require G2`` in a forked
process of its own (one per core at a time), so a crash is counted rather than fatal. The outcome must
be exit 0/1 with a complete report, or exit 2 with one ``error: …`` line —
never a signal, a traceback or an "internal error".

A bigger campaign (not part of the suite) runs the same way:
``python tests/test_fuzz_readers.py --mutations 5000 --seed 7``.
"""

from __future__ import annotations

import argparse
import io
import os
import random
import re
import signal
import sys
import tempfile
import time
from collections import Counter
from pathlib import Path

SEED = 20261201
#: Bytes that make a mutation meaningful to a parser more often than chance would.
SYNTAX = b"0123456789.,;()#'=-+E* \n"
#: Longest a single check may take before it counts as a hang.
HANG = 120.0


def demo_files(folder: Path) -> list[Path]:
    """The demo's circle chain written as STEP and IGES (the demo's writers, its smallest design)."""
    from spiral_cad.cad.export import export_iges, export_step
    from spiral_cad.design import circle_chain

    chain = circle_chain([((0, 0), 60), ((29.85, 0), 30), ((150, -10), 40), ((150, 120), -35)], units="m").chain
    paths = [folder / "circles.step", folder / "circles.igs"]
    export_step(chain, paths[0], name="circles")
    export_iges(chain, paths[1], name="circles")
    return paths


def mutations(data: bytes, count: int, seed: int) -> list[bytes]:
    """``count`` copies of ``data``, each with one byte replaced (seeded)."""
    rng = random.Random(seed)
    out = []
    while len(out) < count:
        position = rng.randrange(len(data))
        byte = rng.choice(SYNTAX) if rng.random() < 0.75 else rng.randrange(256)
        if data[position] != byte:
            out.append(data[:position] + bytes([byte]) + data[position + 1 :])
    return out


def start_check(path: Path) -> int:
    """Fork a child running ``spiral-cad check PATH --require G2`` (its output into PATH.out, PATH.err); its pid."""
    import spiral_cad.cad.continuity  # noqa: F401  (what `check` imports for STEP/IGES)
    from spiral_cad.app.cli import main  # imported here once, not in every child

    out_file, err_file = path.with_suffix(".out"), path.with_suffix(".err")
    pid = os.fork()
    if pid == 0:
        status = 70
        try:
            for fd, name in ((1, out_file), (2, err_file)):
                os.dup2(os.open(name, os.O_WRONLY | os.O_CREAT | os.O_TRUNC), fd)
            sys.stdout, sys.stderr = io.TextIOWrapper(open(1, "wb", closefd=False)), io.TextIOWrapper(open(2, "wb", closefd=False))
            status = main(["check", str(path), "--require", "G2"])
            sys.stdout.flush()
            sys.stderr.flush()
        finally:
            os._exit(status)
    return pid


def finished(pid: int, path: Path, started: float) -> tuple[str, str, str] | None:
    """(outcome, stdout, stderr) of the check ``start_check`` forked, or None while it runs.

    outcome is ``"exit N"``, ``"signal N"`` or ``"hang"`` (killed after ``HANG`` seconds).
    """
    done, status = os.waitpid(pid, os.WNOHANG)
    if not done:
        if time.monotonic() - started <= HANG:
            return None
        os.kill(pid, signal.SIGKILL)
        os.waitpid(pid, 0)
        return "hang", "", ""
    outcome = f"signal {os.WTERMSIG(status)}" if os.WIFSIGNALED(status) else f"exit {os.WEXITSTATUS(status)}"
    return outcome, path.with_suffix(".out").read_text(errors="replace"), path.with_suffix(".err").read_text(errors="replace")


def problem(name: str, outcome: str, out: str, err: str) -> str | None:
    """What is wrong with one check's outcome, or None."""
    if outcome in ("exit 0", "exit 1"):
        lines = out.splitlines()
        if err or not lines or not lines[0].startswith(f"{name}: ") or not re.match(r"(OK|FAIL): ", lines[-1]):
            return "incomplete report"
        declared = sum(int(n) for n in re.findall(r", (\d+) joint\(s\), worst ", out))
        rows = sum(1 for line in lines if re.match(r"\s+\d+\s+\S+\s+\S+", line))
        return None if declared == rows else f"{rows} joint rows for {declared} joints"
    if outcome == "exit 2":
        if out or not err.startswith("error: ") or err.count("\n") != 1 or "Traceback" in err or "internal error" in err:
            return "not one clean error line"
        return None
    return outcome


def campaign(files: list[Path], count: int, seed: int, folder: Path, jobs: int | None = None) -> tuple[Counter, list[str]]:
    """Check ``count`` mutations of each file, ``jobs`` children at a time (default: one per core);
    (outcomes, problems found)."""
    jobs = jobs or len(os.sched_getaffinity(0))
    pending = [
        (folder / f"m{n}-{k}{source.suffix}", data)
        for n, source in enumerate(files)
        for k, data in enumerate(mutations(source.read_bytes(), count, seed + n))
    ]
    pending.reverse()  # taken from the end, in order
    running: dict[int, tuple[Path, bytes, float]] = {}
    outcomes: Counter = Counter()
    problems = []
    while pending or running:
        while pending and len(running) < jobs:
            path, data = pending.pop()
            path.write_bytes(data)
            running[start_check(path)] = (path, data, time.monotonic())
        for pid, (path, data, started) in list(running.items()):
            if (result := finished(pid, path, started)) is None:
                continue
            del running[pid]
            outcome, out, err = result
            outcomes[outcome] += 1
            found = problem(path.name, outcome, out, err)
            if found:
                kept = folder / f"problem-{len(problems)}{path.suffix}"
                kept.write_bytes(data)
                problems.append(f"{kept}: {found}: {outcome} {err.strip()[:200]!r}")
        time.sleep(0.002)
    return outcomes, problems


def test_mutated_demo_files_are_reported_or_refused_never_a_crash(tmp_path):
    import pytest

    pytest.importorskip("OCP")
    from conftest import NIGHTLY_FACTOR
    from hypothesis import settings

    files = demo_files(tmp_path)
    count = 60 * (NIGHTLY_FACTOR if settings.get_current_profile_name() == "nightly" else 1)  # `make nightly`: 600 a file
    outcomes, problems = campaign(files, count, SEED, tmp_path)
    assert sum(outcomes.values()) == 2 * count
    assert problems == [], "\n".join(problems[:10])
    assert outcomes["exit 2"] > 0 and outcomes["exit 0"] + outcomes["exit 1"] > 0  # both kinds of mutation occur


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description="mutation campaign for `spiral-cad check` (see the module docstring)")
    parser.add_argument("--mutations", type=int, default=2500, help="per file (STEP and IGES)")
    parser.add_argument("--seed", type=int, default=SEED)
    parser.add_argument("--jobs", type=int, help="checks at a time (default: one per core)")
    parser.add_argument("--keep", help="folder to keep the files that showed a problem (default: a temporary one)")
    options = parser.parse_args()
    with tempfile.TemporaryDirectory() as scratch:
        folder = Path(options.keep or scratch)
        folder.mkdir(parents=True, exist_ok=True)
        started = time.perf_counter()
        outcomes, problems = campaign(demo_files(folder), options.mutations, options.seed, folder, options.jobs)
        print(f"{sum(outcomes.values())} mutations in {time.perf_counter() - started:.0f} s: {dict(sorted(outcomes.items()))}")
        print(f"{len(problems)} problems")
        for line in problems[:20]:
            print("  " + line)
