"""Every benchmark results file matches the code it measured.

Each ``benchmarks/bench_NAME.py`` names the modules its numbers measure (``MEASURES``) and writes
into ``results_NAME.md`` a stamp: a hash of the code of the script and of those modules
(``timing.code_stamp``; docstrings, comments and layout do not count). A results file whose stamp
differs from the code as it is now was measured on other code: rerun its benchmark
(``python benchmarks/run_all.py --only NAME``). Modification times cannot tell this (a fresh clone
gives every file the same one).
"""

import re
import sys
from pathlib import Path

import pytest

BENCH = Path(__file__).resolve().parents[2] / "benchmarks"
sys.path.insert(0, str(BENCH))

import timing  # noqa: E402  (the benchmarks folder is not a package)

SCRIPTS = sorted(BENCH.glob("bench_*.py"))
RESULTS = sorted(BENCH.glob("results_*.md"))

#: Results written before results were stamped, not regenerated since (their code is unknown).
#: A file leaves this set when its benchmark is rerun; none may join it.
NOT_YET_STAMPED = {
    "results_build.md",
    "results_cad.md",
    "results_chains.md",
    "results_checker.md",
    "results_fillets.md",
    "results_ifc.md",
    "results_landxml.md",
    "results_points.md",
    "results_roads.md",
    "results_roads3d.md",
    "results_shapes.md",
    "results_step.md",
}


def measures(script: Path) -> tuple[str, ...]:
    """A script's ``MEASURES``, read from its source (importing it would import what it measures)."""
    found = re.search(r"^MEASURES = \(([^)]*)\)", script.read_text(encoding="utf-8"), re.M)
    assert found, f"{script.name} must name the modules it measures: MEASURES = (...)"
    return tuple(re.findall(r'"([^"]+)"', found.group(1)))


@pytest.mark.parametrize("script", SCRIPTS, ids=lambda path: path.stem)
def test_every_benchmark_names_modules_that_exist(script):
    names = measures(script)
    assert names
    for name in names:
        assert Path(timing._source(name)).is_file(), f"{script.name}: no module {name}"


@pytest.mark.parametrize("results", RESULTS, ids=lambda path: path.stem)
def test_every_results_file_was_measured_on_the_code_as_it_is(results):
    script = BENCH / results.name.replace("results_", "bench_").replace(".md", ".py")
    assert script.exists(), f"{results.name} has no benchmark {script.name}"
    stated = [line for line in results.read_text(encoding="utf-8").splitlines() if line.startswith(timing.STAMP_PREFIX)]
    if results.name in NOT_YET_STAMPED:
        assert not stated, f"{results.name} is stamped now: take it out of NOT_YET_STAMPED"
        pytest.skip(f"{results.name} predates the stamps: rerun {script.name} to stamp it")
    assert len(stated) == 1, f"{results.name} states no code stamp: rerun {script.name}"
    now = timing.code_stamp(str(script), measures(script))
    assert stated[0] == now, (
        f"{results.name} was measured on other code than today's: rerun {script.name}\n  file: {stated[0]}\n  now:  {now}"
    )


def test_a_change_to_a_measured_module_changes_the_stamp_and_a_docstring_does_not(tmp_path):
    module = tmp_path / "bench_probe.py"
    module.write_text('"""Doc."""\n\nMEASURES = ()\n\n\ndef f():\n    """Doc."""\n    return 1  # note\n', encoding="utf-8")
    before = timing.code_stamp(str(module), ())
    module.write_text('"""Other doc."""\n\nMEASURES = ()\n\n\ndef f():\n    """Changed."""\n\n    return 1\n', encoding="utf-8")
    assert timing.code_stamp(str(module), ()) == before
    module.write_text('"""Doc."""\n\nMEASURES = ()\n\n\ndef f():\n    return 2\n', encoding="utf-8")
    assert timing.code_stamp(str(module), ()) != before
    assert timing.code_stamp(str(module), ("spiral_cad.core.space",)) != timing.code_stamp(str(module), ("spiral_cad.core.jit",))
