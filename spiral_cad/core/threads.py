"""Compiled row loops split over threads.

The kernels release the GIL and every row writes only its own slots, so
ranges of rows run side by side and give the same bits as one call over all
rows. Plain threads rather than numba's parallel loops: those start workers
that spin between loops, which on a machine whose cores are busy costs tens
of milliseconds per call.
"""

from __future__ import annotations

import threading
from typing import Any

import numpy as np

__all__ = ["ROWS_PER_THREAD", "run_split", "thread_count"]

#: Rows per thread from which a batch of transition rows is split (about a millisecond of work).
ROWS_PER_THREAD = 16_384


def thread_count(n: int, rows_per_thread: int = ROWS_PER_THREAD) -> int:
    """How many threads share n rows: one per ``rows_per_thread`` rows, at most
    ``NUMBA_NUM_THREADS`` (the cores, unless the environment says otherwise)."""
    from numba import config  # the batch that asks has compiled kernels: numba is loaded

    cores: int = config.NUMBA_NUM_THREADS  # type: ignore[attr-defined]  # set at import by numba's config, not in its stubs
    return max(1, min(cores, n // rows_per_thread))


def run_split(kernel: Any, args: list[Any], n: int, rows_per_thread: int = ROWS_PER_THREAD) -> None:
    """Call ``kernel(*args)`` over n rows, cut into ranges that run on threads.

    Every array argument of n rows is cut into the ranges; the others (shared
    rows, scalars) are passed whole to every range.
    """
    parts = thread_count(n, rows_per_thread)
    if parts == 1:
        kernel(*args)
        return
    bounds = [n * k // parts for k in range(parts + 1)]
    calls = [[a[lo:hi] if isinstance(a, np.ndarray) and a.ndim and len(a) == n else a for a in args] for lo, hi in zip(bounds, bounds[1:])]
    threads = [threading.Thread(target=kernel, args=call, daemon=True) for call in calls[1:]]
    for thread in threads:
        thread.start()
    kernel(*calls[0])
    for thread in threads:
        thread.join()
