"""The speed guard (``benchmarks/guard.py``): each guarded operation stays within its ratio of a
reference timed in the same process, and the guard fails when a kernel runs as plain Python.

The ratios are of the fastest of a few alternating runs, with limits about four times the ratio of
a quiet machine (see the guard's docstring): a loaded machine passes, a kernel that fell back to
plain Python (10× to 1000× slower) does not.
"""

import importlib
import sys
import time
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "benchmarks"))

import guard  # noqa: E402  (the benchmarks folder is not a package)

#: Guards that need build123d/OCCT (the CAD layer).
CAD = ("faces", "box")


@pytest.mark.parametrize("name", [n for n in guard.GUARDS if n not in CAD])
def test_the_numeric_operations_keep_their_speed(name):
    verdict = guard.judge(guard.GUARDS[name]())
    assert verdict.passed, " | ".join(verdict.row())


@pytest.mark.parametrize("name", CAD)
def test_the_cad_operations_keep_their_speed(name):
    pytest.importorskip("build123d")
    verdict = guard.judge(guard.GUARDS[name]())
    assert verdict.passed, " | ".join(verdict.row())


@pytest.mark.parametrize(
    ("name", "module", "scale"),
    [
        ("corners-plane", "spiral_cad.design.rounding", 0.5),
        ("corners-space", "spiral_cad.core.space", 0.5),
        ("chain", "spiral_cad.core._chain_kernels", 0.05),
        ("transitions", "spiral_cad.core._kernel_batches", 0.05),
    ],
)
def test_the_guard_fails_when_a_kernel_falls_back_to_plain_python(name, module, scale, monkeypatch):
    """The slip of the lazy-kernel change, made on purpose: the module that declares the kernels
    holds their plain-Python versions (``Kernels.python``) instead of their dispatchers. The guard
    that passes above must fail, by far."""
    owner = importlib.import_module(module)
    owner.KERNELS.compile()
    small = guard.GUARDS[name](scale)  # smaller inputs (plain Python takes seconds even so), large enough to pass compiled
    compiled = guard.judge(small)
    assert compiled.passed, " | ".join(compiled.row())
    for kernel in owner.KERNELS.functions:
        monkeypatch.setitem(vars(owner), kernel, getattr(owner.KERNELS.python, kernel))
    started = time.perf_counter()
    small.ours()  # one run tells (nothing left to warm up)
    verdict = guard.Verdict(small, time.perf_counter() - started, compiled.reference)  # the reference's fastest run above
    assert not verdict.passed, " | ".join(verdict.row())
    assert verdict.ratio > 2 * small.limit, " | ".join(verdict.row())  # not a near miss
