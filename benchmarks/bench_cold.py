"""Cold and warm first calls: ``import spiral_cad`` plus one scalar transition, in fresh processes.

Run: ``.venv/bin/python benchmarks/bench_cold.py [--quick] [--rounds N] [--out FILE]`` (conventions: ``timing.py``).

Each measurement is a new Python process (so nothing is imported yet):

* **cold**: an empty kernel cache (``NUMBA_CACHE_DIR`` a new empty folder):
  the scalar API runs the kernels as plain Python and never waits for a compiler;
* **warm**: the same, after the kernels were compiled into that cache by a
  process that made enough scalar calls to compile them;
* **compiled first call**: the time a process that does compile its kernels
  pays (a batch call with an empty cache) — what the first call cost before;
* **first g2_fillet** and **first curve**: what a newcomer who installed with pip waits for, with an
  empty cache: ``g2_fillet`` of a 40 × 20 × 8 box's edges (the call alone, build123d already imported),
  and the README's first curve written as STEP (import included);
* peers in the same runs: ``import numpy`` alone (the floor any numpy package
  pays) and ``import numba`` alone.

Goals: import plus the first scalar call in ≤ 2 s with an empty cache; the first ``g2_fillet`` in ≤ 5 s.
"""

from __future__ import annotations

import statistics
import subprocess
import sys
import tempfile
import time

from timing import Report, Timing, arguments

#: The modules whose code these numbers measure (stamped into the results: ``timing.code_stamp``).
MEASURES = ("spiral_cad", "spiral_cad.core.jit", "spiral_cad.core.transitions", "spiral_cad.core.batch")

FIRST_CALL = "import spiral_cad; spiral_cad.line_to_circle((0, 0), (1, 0), (10, 5), 3)"
COMPILE_ALL = (
    "import spiral_cad; from spiral_cad.core.jit import SCALAR_CALLS_BEFORE_COMPILING as n\n"
    "for _ in range(n + 2): spiral_cad.line_to_circle((0, 0), (1, 0), (10, 5), 3)"
)
BATCH_CALL = "import numpy as np, spiral_cad; spiral_cad.batch.line_to_circle(np.zeros((4, 2)), [[1, 0]] * 4, [[10, 5]] * 4, [3] * 4)"
FIRST_FILLET = (
    "import time; from build123d import Box; from spiral_cad.build123d import g2_fillet\n"
    "box = Box(40, 20, 8); started = time.perf_counter(); g2_fillet(box.edges(), 2); print(time.perf_counter() - started)"
)
FIRST_CURVE = (
    "import os, tempfile, spiral_cad as sc\n"
    "enter = sc.line_to_circle((0, 0), (1, 0), (100, 60), 50.0)\n"
    "leave = sc.line_to_circle((-20, 120), (1, 0), (100, 60), 50.0).reversed()\n"
    "chain = sc.Chain.join([enter, leave], start=(-20, 0), end=(-20, 120), units='mm')\n"
    "sc.export(chain, os.path.join(tempfile.mkdtemp(), 'first.step'))"
)


def process_time(code: str, cache: str, printed: bool = False) -> float:
    """Wall time of a new interpreter running ``code`` with numba's cache in ``cache`` (``printed``: the
    seconds the code prints instead)."""
    env = {"NUMBA_CACHE_DIR": cache, "PATH": "/usr/bin:/bin"}
    started = time.perf_counter()
    done = subprocess.run([sys.executable, "-c", code], check=True, env=env, capture_output=True, text=True)
    return float(done.stdout.split()[-1]) if printed else time.perf_counter() - started


def main() -> None:
    args = arguments(__doc__, rounds=(7, 1))
    runs: dict[str, list[float]] = {name: [] for name in ("cold", "warm", "compiled", "fillet", "fillet warm", "curve", "numpy", "numba")}
    for _ in range(args.rounds):
        with tempfile.TemporaryDirectory() as cold, tempfile.TemporaryDirectory() as warm, tempfile.TemporaryDirectory() as fresh:
            runs["cold"].append(process_time(FIRST_CALL, cold))
            if not args.quick:  # compiling takes tens of seconds: not for a smoke test
                process_time(COMPILE_ALL, warm)
                runs["warm"].append(process_time(FIRST_CALL, warm))
                runs["compiled"].append(process_time(BATCH_CALL, fresh))
                with tempfile.TemporaryDirectory() as first, tempfile.TemporaryDirectory() as curve:
                    runs["fillet"].append(process_time(FIRST_FILLET, first, printed=True))
                    runs["fillet warm"].append(process_time(FIRST_FILLET, first, printed=True))
                    runs["curve"].append(process_time(FIRST_CURVE, curve))
            runs["numpy"].append(process_time("import numpy", cold))
            runs["numba"].append(process_time("import numba", cold))
    runs = {name: values for name, values in runs.items() if values}
    timings = {name: Timing(tuple(values)) for name, values in runs.items()}
    report = Report("Cold start", note=f"{args.rounds} fresh processes per row, taken in turn; medians.")
    floor = timings["numpy"].median
    compiled = timings.get("compiled")
    report.add("import + first scalar call, empty kernel cache", timings["cold"].median, "s", timings["cold"],
               "a first call that compiles" if compiled else "", compiled.median / timings["cold"].median if compiled else None, "≤ 2 s")  # fmt: skip
    if compiled:
        report.add("import + first scalar call, warm kernel cache", timings["warm"].median, "s", timings["warm"])
        report.add("import + first batch call, empty cache (compiles)", compiled.median, "s", compiled)
        report.add("first g2_fillet of a box, empty cache (the call)", timings["fillet"].median, "s", timings["fillet"], goal="≤ 5 s")
        report.add("the same, warm cache", timings["fillet warm"].median, "s", timings["fillet warm"])
        report.add("import + the README's first curve to STEP, empty cache", timings["curve"].median, "s", timings["curve"])
    report.add("import numba alone", timings["numba"].median, "s", timings["numba"])
    report.add("import numpy alone", floor, "s", timings["numpy"])
    report.section("Every run (s)", "\n".join(f"- {name}: {', '.join(f'{v:.2f}' for v in values)} (median {statistics.median(values):.2f})"
                                              for name, values in runs.items()))  # fmt: skip
    report.finish(args)


if __name__ == "__main__":
    main()
