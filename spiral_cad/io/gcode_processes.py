"""A long G-code program's runs made G2 in one forked process per core (``spiral-cad g2``, ``gcode_inplace``):
the processes share what was read before the fork and give back each run's result, in order."""

from __future__ import annotations

import multiprocessing
import os
import signal
from collections.abc import Callable
from typing import Any

from .progress import Progress

__all__ = ["MAX_PROCESSES", "PARALLEL_MOVES", "in_processes", "processes"]

#: A program of at least this many cutting moves has its runs made G2 in several processes at once (one per
#: core, forked; the output is the same as made in one).
PARALLEL_MOVES = 20_000
#: ... in at most this many.
MAX_PROCESSES = 8

#: What a forked process makes (``in_processes``).
_MAKE: Callable[[int], Any] | None = None


def processes() -> int:
    """How many processes may share the runs: one per core, at most ``MAX_PROCESSES``; 1 where the system cannot
    fork or this process may start none (a pool's own)."""
    if "fork" not in multiprocessing.get_all_start_methods() or multiprocessing.current_process().daemon:
        return 1
    cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1
    return min(cores, MAX_PROCESSES)


def in_processes(make: Callable[[int], Any], count: int, what: str) -> dict[int, Any]:
    """``make(k)`` for every k below ``count``, in ``processes()`` forked processes, by k; progress on stderr as
    ``what``. The processes leave Ctrl-C and SIGTERM to this one, which ends them with it."""
    global _MAKE
    made: dict[int, Any] = {}
    progress = Progress(what, count)
    _MAKE = make
    try:
        with multiprocessing.get_context("fork").Pool(processes(), _quiet) as pool:
            for k, result in enumerate(pool.imap(_made, range(count), chunksize=8)):
                made[k] = result
                progress(k + 1)
    finally:
        _MAKE = None
    progress.done(len(made))
    return made


def _quiet() -> None:
    """A forked process leaves Ctrl-C and SIGTERM to the command: it is ended with the pool, saying nothing."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)


def _made(index: int) -> Any:
    assert _MAKE is not None
    return _MAKE(index)
