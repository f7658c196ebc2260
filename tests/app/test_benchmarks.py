"""The benchmarks run: every ``benchmarks/bench_*.py`` in quick mode writes its table.

A smoke test only: the numbers of a quick run mean nothing and are never
checked (speed goals live in the benchmarks' own tables). The quick runs are
made in the test's own process, as ``python bench_NAME.py --quick --out FILE``
would run them, so they share its imports and compiled kernels instead of
starting twenty interpreters; ``run_all.py`` is run as a program.
"""

import runpy
import subprocess
import sys
from pathlib import Path

import pytest

BENCH = Path(__file__).resolve().parents[2] / "benchmarks"
SCRIPTS = sorted(BENCH.glob("bench_*.py"))
#: What a script's quick table must say beside its numbers (every job ran; the solids it built are valid).
EXPECTED = {
    "bench_gcode": ("spiral-cad build --from-gcode", "spiral-cad g2 (in place)"),
    "bench_paths3d": ("3-D batch", "G-code", "valid True", "per-corner"),
    "bench_roads3d": ("corridor", "valid", "growth exponent"),
    "bench_solids": ("ContinuousBox", "valid True", "build123d fillet"),
}


#: Smaller still than --quick where a script's quick run would take over 10 s (the test asks only that it runs).
SMALLEST = {
    "bench_many": ["--files", "6", "--sample", "1"],
    "bench_faces": ["--boxes", "2", "--picture-boxes", "2"],
    "bench_fit": ["--points", "40", "--sizes", "500"],
}


def run_quick(script: Path, out: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """``script --quick --out OUT`` run as ``__main__`` in this process, from the benchmarks folder."""
    monkeypatch.setattr(sys, "argv", [str(script), "--quick", "--out", str(out), *SMALLEST.get(script.stem, [])])
    monkeypatch.syspath_prepend(str(BENCH))  # the scripts import timing.py and each other
    monkeypatch.chdir(BENCH)
    try:
        runpy.run_path(str(script), run_name="__main__")
    except SystemExit as exit:
        assert exit.code in (0, None), f"{script.name} exited with {exit.code}"


@pytest.mark.parametrize("script", SCRIPTS, ids=lambda path: path.stem)
def test_benchmark_runs_quick_and_writes_its_table(script, tmp_path, monkeypatch):
    out = tmp_path / "results.md"
    run_quick(script, out, monkeypatch)
    text = out.read_text(encoding="utf-8")
    assert text.startswith("# ") and "Machine:" in text
    assert "\n| " in text and "|---|" in text  # at least one table
    assert all(words in text for words in EXPECTED.get(script.stem, ())) and "INVALID" not in text


def test_run_all_runs_the_named_scripts_and_counts_failures(tmp_path):
    done = subprocess.run([sys.executable, str(BENCH / "run_all.py"), "--quick", "--only", "shapes", "--out-dir", str(tmp_path)],
                          cwd=BENCH, capture_output=True, text=True, timeout=600)  # fmt: skip
    assert done.returncode == 0, done.stdout[-3000:] + done.stderr[-3000:]
    assert [path.name for path in tmp_path.iterdir()] == ["results_shapes.md"]
    unknown = subprocess.run([sys.executable, str(BENCH / "run_all.py"), "--quick", "--only", "nonexistent"],
                             cwd=BENCH, capture_output=True, text=True, timeout=60)  # fmt: skip
    assert unknown.returncode != 0 and "no benchmark named nonexistent" in unknown.stderr
