"""Shared benchmark helpers: medians, the machine line, markdown tables."""

from __future__ import annotations

import os
import platform
import statistics
import time
from collections.abc import Callable, Sequence

import numpy as np


def median_time(fn: Callable[[], object], repeat: int, warm_up: bool = True) -> float:
    """Median wall time of ``repeat`` calls (after one warm-up call: compilation, caches)."""
    if warm_up:
        fn()
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def machine() -> str:
    """One line naming the machine and the runtime."""
    cpu = platform.processor() or platform.machine()
    return f"{cpu}, {os.cpu_count()} cores, Python {platform.python_version()}, numpy {np.__version__}"


def write_markdown(path: str, title: str, note: str, header: Sequence[str], rows: Sequence[Sequence[str]]) -> None:
    """A markdown file: title, machine line and note, then the table."""
    with open(path, "w", encoding="utf-8") as fh:
        fh.write(f"# {title}\n\nMachine: {machine()}. {note}\n\n")
        fh.write("| " + " | ".join(header) + " |\n|" + "---|" * len(header) + "\n")
        for row in rows:
            fh.write("| " + " | ".join(row) + " |\n")
