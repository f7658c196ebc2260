"""Run every benchmark script, each in its own process, and write its results file.

Run: ``.venv/bin/python benchmarks/run_all.py [--quick] [--only NAME ...] [--out-dir DIR]``
(``make bench`` runs it without options). Every ``benchmarks/bench_NAME.py``
is found and run as ``bench_NAME.py [--quick] --out DIR/results_NAME.md``
(the convention: ``timing.py``), so a new script takes part by its name
alone. A full run writes into ``benchmarks/``; ``--quick`` (the test suite's
smoke run) writes into a temporary folder unless ``--out-dir`` is given, so
quick numbers never replace measured ones. Exits with the number of scripts
that failed.
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent


def scripts(only: list[str] | None = None) -> list[Path]:
    """The benchmark scripts, by name (``bench_NAME.py``), optionally only the NAMEs given."""
    found = sorted(HERE.glob("bench_*.py"))
    if only:
        unknown = set(only) - {path.stem.removeprefix("bench_") for path in found}
        if unknown:
            names = ", ".join(path.stem for path in found)
            raise SystemExit(f"no benchmark named {', '.join(sorted(unknown))}; have {names}")
        found = [path for path in found if path.stem.removeprefix("bench_") in only]
    return found


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="every script at its smallest sizes (a smoke test)")
    parser.add_argument("--only", nargs="+", metavar="NAME", help="run only bench_NAME.py for these NAMEs")
    parser.add_argument("--out-dir", type=Path, help="for results_NAME.md (default benchmarks/; --quick: a temporary folder)")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as scratch:
        out_dir = args.out_dir or (Path(scratch) if args.quick else HERE)
        out_dir.mkdir(parents=True, exist_ok=True)
        summary = []
        for script in scripts(args.only):
            name = script.stem.removeprefix("bench_")
            out = out_dir / f"results_{name}.md"
            command = [sys.executable, str(script), *(["--quick"] if args.quick else []), "--out", str(out)]
            print(f"\n=== {script.name} ===", flush=True)
            started = time.perf_counter()
            code = subprocess.run(command, cwd=HERE).returncode
            summary.append((script.name, code, time.perf_counter() - started))
    for name, code, seconds in summary:
        print(f"{name:24} {'ok' if code == 0 else f'FAILED ({code})':12} {seconds:8.1f} s")
    return sum(code != 0 for _, code, _ in summary)


if __name__ == "__main__":
    sys.exit(main())
