"""Signals during work that must finish or clean up: one helper for every command and writer."""

from __future__ import annotations

import signal
import threading
from collections.abc import Iterator
from contextlib import contextmanager

__all__ = ["signals_handled"]


@contextmanager
def signals_handled(names: tuple[str, ...], *, interrupt: bool) -> Iterator[list[int]]:
    """Within the block, the signals ``names`` (those this platform has) are recorded in the
    yielded list; with ``interrupt`` each also raises KeyboardInterrupt where it arrives, so
    cleanup runs, else the work goes on and the caller decides once it is done.

    The record also tells an interrupt that a library turned into another exception (OCP's
    "ImportError: initialization failed" during a long import). Outside the main thread signals
    cannot arrive, and nothing changes.
    """
    received: list[int] = []
    if threading.current_thread() is not threading.main_thread():
        yield received
        return

    def handler(signum: int, frame: object) -> None:
        received.append(signum)
        if interrupt:
            raise KeyboardInterrupt

    previous = {name: signal.signal(getattr(signal, name), handler) for name in names if hasattr(signal, name)}
    try:
        yield received
    finally:
        for name, saved in previous.items():
            signal.signal(getattr(signal, name), saved)
