"""Signals during work that must finish or clean up: one helper for every command and writer.

Also the two ways a run of many files stops its helpers: a stop file that a
worker looks for before it commits anything (``stop_requested``), and child
processes that end with the process that started them (``die_with_parent``).
"""

from __future__ import annotations

import os
import signal
import sys
import threading
from collections.abc import Iterator
from contextlib import contextmanager

__all__ = ["die_with_parent", "raise_if_interrupted", "signals_handled", "stop_requested", "stopping_on"]

#: The records of the interrupting blocks now active. A signal stays in its record after its
#: KeyboardInterrupt was raised, also when the interpreter swallowed it ("Exception ignored in"
#: a ``__del__`` or a callback), so the command still stops.
_interrupting: list[list[int]] = []


@contextmanager
def signals_handled(names: tuple[str, ...], *, interrupt: bool) -> Iterator[list[int]]:
    """Within the block, the signals ``names`` (those this platform has) are recorded in the
    yielded list; with ``interrupt`` each also raises KeyboardInterrupt where it arrives, so
    cleanup runs, else the work goes on and the caller decides once it is done.

    The record also tells an interrupt that a library turned into another exception (OCP's
    "ImportError: initialization failed" during a long import). Outside the main thread signals
    cannot arrive, and nothing changes. A signal that reached an interrupting block is
    remembered until the block ends: ``stop_requested`` is True from then on, and
    ``raise_if_interrupted`` raises again an interrupt that was swallowed.
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
    if interrupt:
        _interrupting.append(received)
    try:
        yield received
    finally:
        for name, saved in previous.items():
            signal.signal(getattr(signal, name), saved)
        if interrupt:
            _interrupting.remove(received)


def raise_if_interrupted() -> None:
    """Raise KeyboardInterrupt when an interrupting ``signals_handled`` block got a signal.

    Called where a long wait loops, so that an interrupt raised where the interpreter
    ignores exceptions (a ``__del__`` run by the garbage collector) still stops the work.
    """
    if any(_interrupting):
        raise KeyboardInterrupt


_stop_file: str | None = None


@contextmanager
def stopping_on(path: str | None) -> Iterator[None]:
    """Within the block, ``stop_requested()`` is True once the file ``path`` exists (None: never).

    A command that runs files on worker processes creates the file when it is
    interrupted; a worker then commits nothing more.
    """
    global _stop_file
    saved, _stop_file = _stop_file, path
    try:
        yield
    finally:
        _stop_file = saved


def stop_requested() -> bool:
    """True when the command this process works for was interrupted (see ``stopping_on``), or
    this process got a signal in an interrupting ``signals_handled`` block."""
    return any(_interrupting) or (_stop_file is not None and os.path.exists(_stop_file))


def die_with_parent(parent: int) -> None:
    """Have this process killed when ``parent``, the process that started it, ends (Linux; elsewhere nothing).

    A reader child of a worker that is killed (Ctrl-C, a crash) then stops at
    once instead of running on with its memory until its own time limit. A
    parent that ended before this call ends this process now.
    """
    if not sys.platform.startswith("linux"):
        return
    try:
        import ctypes

        libc = ctypes.CDLL(None, use_errno=True)
        libc.prctl(1, int(signal.SIGKILL))  # PR_SET_PDEATHSIG
    except (OSError, AttributeError):
        return
    if os.getppid() != parent:  # the parent ended before the request was made
        os.kill(os.getpid(), signal.SIGKILL)
