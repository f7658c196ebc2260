"""One file of a many-file run: what a worker runs for it, or a fresh process when its worker died.

A task takes a path and returns a ``FileResult``: the exit status, the text the
one-file run prints and the worst joint it reported — plain strings and
numbers, so no OCCT object is ever pickled. What the task prints is caught per
thread, so a worker's own threads (and helper threads of a task) never write
into a file's output.
"""

from __future__ import annotations

import contextlib
import copy
import io
import multiprocessing
import os
import signal
import sys
import threading
import time
import warnings
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, TextIO

from ..io.signals import die_with_parent, stopping_on

if TYPE_CHECKING:
    import argparse

__all__ = ["NOT_RUN", "FileResult", "note_worst", "run_alone", "run_one"]

#: The rank of every level a checker reports, worst first (joints: unmeasurable < none < G0 < G1 < G2;
#: faces: a gap is no G0 and a crease is G0 only).
_RANK = {"unmeasurable": -1, "none": 0, "gap": 0, "crease": 1, "G0": 1, "G1": 2, "G2": 3}
#: The status of a file that was never run (the scheduler was lost, the command interrupted).
NOT_RUN = -1


@dataclass(frozen=True)
class FileResult:
    """What one file's run gave back from a worker: plain data only.

    Attributes:
        file: the file as the command line shows it.
        status: the one-file exit status (0 ok, 1 below ``--require``, 2 error; ``NOT_RUN``).
        worst: the worst joint or edge the run reported (``"G2"``, ``"G1"``, ``"gap"`` …; ``""`` when
            nothing was judged).
        seconds: wall time of the run on its worker.
        output: what the one-file run printed on stdout.
        errors: its ``error: …`` lines (an exception's message, or what it printed on stderr).
    """

    file: str
    status: int
    worst: str
    seconds: float
    output: str
    errors: tuple[str, ...]

    @property
    def verdict(self) -> str:
        """``ok``, ``fail`` (below ``--require``), ``error`` (not read, not built) or ``not run``."""
        return {0: "ok", 1: "fail", NOT_RUN: "not run"}.get(self.status, "error")

    def reason(self) -> str:
        """Why the file did not pass, in one line (its error, else its ``FAIL:`` line)."""
        if self.errors:
            return "; ".join(line.removeprefix("error: ") for line in self.errors)
        fails = [line.removeprefix("FAIL: ") for line in self.output.splitlines() if line.startswith("FAIL: ")]
        return "; ".join(fails) or f"exit status {self.status}"

    @classmethod
    def failed(cls, file: str, why: str, status: int = 2) -> FileResult:
        """A file with no output: an error (``status`` 2) or never run (``NOT_RUN``), for the reason ``why``."""
        return cls(file, status, "", 0.0, "", (f"error: {why}",))


class _Capture(threading.local):
    """The streams and worst joint of the task running on this thread (None: not in a task)."""

    out: io.StringIO | None = None
    err: io.StringIO | None = None
    worst: str = ""


_capture = _Capture()


class _ThreadStream(io.TextIOBase):
    """A process's stdout or stderr that sends what a task prints to that task's buffer."""

    def __init__(self, stream: TextIO, which: str) -> None:
        self.stream, self.which = stream, which

    def write(self, text: str) -> int:
        buffer = getattr(_capture, self.which)
        return (buffer if buffer is not None else self.stream).write(text)

    def flush(self) -> None:
        if getattr(_capture, self.which) is None:
            self.stream.flush()

    def fileno(self) -> int:
        return self.stream.fileno()

    def isatty(self) -> bool:
        return getattr(_capture, self.which) is None and self.stream.isatty()

    @property
    def encoding(self) -> str:  # type: ignore[override]
        return getattr(self.stream, "encoding", None) or "utf-8"


_install_lock = threading.Lock()


@contextlib.contextmanager
def _captured() -> Iterator[_Capture]:
    """What this thread prints goes to ``_capture.out``/``err`` (other threads print as before)."""
    with _install_lock:
        if not isinstance(sys.stdout, _ThreadStream):
            sys.stdout = _ThreadStream(sys.stdout, "out")
        if not isinstance(sys.stderr, _ThreadStream):
            sys.stderr = _ThreadStream(sys.stderr, "err")
    _capture.out, _capture.err, _capture.worst = io.StringIO(), io.StringIO(), ""
    try:
        yield _capture
    finally:
        _capture.out = _capture.err = None


def note_worst(level: str) -> None:
    """Record a level a run reported; a task keeps the worst (nothing happens outside a task)."""
    if _capture.out is None or level not in _RANK:
        return
    if not _capture.worst or _RANK[level] < _RANK[_capture.worst]:
        _capture.worst = level


def run_one(task: Callable[[argparse.Namespace], int], shown: str, args: argparse.Namespace, changes: dict[str, Any],
            stop: str | None = None) -> FileResult:  # fmt: skip
    """Run the one-file command ``task`` on a copy of ``args`` with ``changes`` (the file, its output
    folder): what a worker runs for the file ``shown``. Once the file ``stop`` exists (the command was
    interrupted) nothing more is committed.

    Errors are caught as the command line catches them: a ``ValueError``/``OSError`` is an
    ``error: …`` line, anything else an internal error; none escapes as a traceback.
    """
    warnings.simplefilter("ignore")  # as the command line: what matters is in the report
    mine = copy.copy(args)
    for name, value in changes.items():
        setattr(mine, name, value)
    started = time.perf_counter()
    errors: list[str] = []
    with _captured() as captured, stopping_on(stop):
        try:
            status = task(mine)
        except (ValueError, OSError) as error:
            status, errors = 2, [f"error: {error}"]
        except KeyboardInterrupt:
            if stop is None:  # the command's own Ctrl-C
                raise
            status, errors = 2, ["error: interrupted"]  # the command was interrupted: this worker committed nothing
        except Exception as error:
            status, errors = 2, [f"error: internal error ({type(error).__name__}: {error}); please report it"]
        assert captured.out is not None and captured.err is not None
        output, printed, worst = captured.out.getvalue(), captured.err.getvalue(), captured.worst
    errors = [line for line in printed.splitlines() if line.strip()] + errors
    return FileResult(shown, status, worst, time.perf_counter() - started, output, tuple(errors))


def _alone(send: Any, task: Callable[[argparse.Namespace], int], shown: str, args: argparse.Namespace, changes: dict[str, Any],
           stop: str | None, parent: int) -> None:  # fmt: skip
    """The fresh process of ``run_alone``: Ctrl-C is the command's to answer; the result goes back on ``send``."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    if hasattr(signal, "pthread_sigmask"):
        signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})
    die_with_parent(parent)
    send.send(run_one(task, shown, args, changes, stop))
    send.close()


def run_alone(task: Callable[[argparse.Namespace], int], shown: str, args: argparse.Namespace, changes: dict[str, Any],
              *, limit: float, stop: str | None = None) -> FileResult:  # fmt: skip
    """``run_one`` in a fresh process of its own, stopped after ``limit`` seconds: a file whose worker died.

    Whatever the file does to that process (a crash of native code, exhausted memory), the
    result is the file's error and the command lives on.
    """
    context = multiprocessing.get_context("spawn")
    receive, send = context.Pipe(duplex=False)
    process = context.Process(target=_alone, args=(send, task, shown, args, changes, stop, os.getpid()), daemon=True)
    masked = hasattr(signal, "pthread_sigmask")
    if masked:  # started with Ctrl-C blocked (it ignores Ctrl-C once running): the command stops it
        signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    try:
        process.start()
    finally:
        if masked:
            signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})
    send.close()
    started = time.perf_counter()
    try:
        if receive.poll(limit):
            result: FileResult = receive.recv()
            return result
        return FileResult.failed(shown, f"stopped after {limit:g} s (the time limit of a file)")
    except EOFError:
        process.join(5.0)
        code = process.exitcode
        how = f"signal {-code}" if code is not None and code < 0 else f"exit status {code}"
        return FileResult(shown, 2, "", time.perf_counter() - started, "",
                          (f"error: its process stopped ({how}), also when run alone in a fresh process",))  # fmt: skip
    finally:
        receive.close()
        if process.is_alive():
            process.kill()
        process.join()
