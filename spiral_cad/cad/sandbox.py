"""Run native code on untrusted input in a child process, so that its crash is an error, not ours.

OCCT's STEP and IGES readers can crash (a self-referencing entity, a damaged
pointer, deep nesting), loop or exhaust memory on a hostile or damaged file.
``run_isolated`` runs such a task in a forked child with a memory cap and a
time limit and hands back only plain data (``marshal``: numbers, strings,
bytes, tuples, lists, dicts — nothing that runs code when loaded). Whatever
happens in the child, the caller gets the result or a ``ValueError`` that
says what went wrong: the child's own ``ValueError`` message, a signal
("signal 11, SIGSEGV"), a timeout or running out of memory.

Forking keeps this cheap (no new interpreter, no re-import of OCCT: about a
millisecond plus the page tables). On systems without ``fork`` (Windows) the
task runs in the calling process.
"""

from __future__ import annotations

import faulthandler
import gc
import marshal
import math
import os
import select
import signal
import sys
import time
import warnings
from collections.abc import Callable
from typing import Any

from ..io.signals import die_with_parent

__all__ = ["MEMORY_LIMIT", "TIME_LIMIT", "Isolated", "run_isolated"]

#: Seconds a reader may take before it is stopped.
TIME_LIMIT = 120.0
#: Bytes of address space a reader may add to the calling process's (Linux
#: enforces it; elsewhere only the time limit applies). None: half the
#: physical memory, at least 1 GiB.
MEMORY_LIMIT: int | None = None


def _memory_limit() -> int:
    if MEMORY_LIMIT is not None:
        return MEMORY_LIMIT
    try:
        physical = os.sysconf("SC_PHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    except (ValueError, OSError, AttributeError):
        physical = 0
    return max(1 << 30, physical // 2)


def _gib(size: int) -> str:
    return f"{size / (1 << 30):.3g} GiB"


def run_isolated(task: Callable[..., Any], *args: Any, what: str, subject: str) -> Any:
    """``task(*args)`` run in a child process; its (marshal-able) result.

    Args:
        task: the work; it must return data ``marshal`` can carry.
        args: its arguments (the child inherits them; nothing is pickled).
        what: who does the work, for messages (``"the STEP reader"``).
        subject: what it works on (a file name), for messages.

    Raises:
        ValueError: the task raised ``ValueError`` (its message, unchanged),
            or it failed in any other way: ``"<what> failed on '<subject>'
            (signal 11, SIGSEGV: segmentation fault)"``, ``(no result within
            120 s; stopped)``, ``(out of memory: more than 4 GiB)`` or
            ``(<exception type>: <message>)``.
    """
    with Isolated(task, *args, what=what, subject=subject) as child:
        return child.result()


class Isolated:
    """``task(*args)`` started in a child process; ``result()`` waits for it (as ``run_isolated``).

    Between the start and ``result()`` the caller may do other work (the
    build writes its other files while OCCT reads the STEP). Used as a
    context manager, a child whose result was never asked for is stopped.
    """

    def __init__(self, task: Callable[..., Any], *args: Any, what: str, subject: str) -> None:
        self._failed = f"{what} failed on {subject!r}"
        self._pid: int | None = None
        self._outcome: tuple[bool, Any] | None = None
        if not hasattr(os, "fork"):  # the task runs here and now
            try:
                self._outcome = (True, task(*args))
            except ValueError as error:
                self._outcome = (False, error)
            return
        self._memory = _memory_limit()
        read_fd, write_fd = os.pipe()
        for stream in (sys.stdout, sys.stderr):  # else the child inherits unwritten output
            try:
                stream.flush()
            except (OSError, ValueError):
                pass
        parent = os.getpid()
        with warnings.catch_warnings():
            # Python ≥ 3.12 warns about forking with threads running (numpy's BLAS
            # pool): the child only runs ``task`` and leaves with os._exit.
            warnings.simplefilter("ignore", DeprecationWarning)
            try:
                pid = os.fork()
            except OSError as error:  # no process to spare
                os.close(read_fd)
                os.close(write_fd)
                self._outcome = (False, ValueError(f"{self._failed} (no process could be started for it: {error.strerror})"))
                return
        if pid == 0:  # the child: never returns
            os.close(read_fd)
            _child(task, args, write_fd, self._memory, parent)
        os.close(write_fd)
        self._pid, self._fd = pid, read_fd

    def __enter__(self) -> Isolated:
        return self

    def __exit__(self, *exc: object) -> None:
        self.stop()

    def stop(self) -> None:
        """Stop the child if it still runs (its result is not wanted)."""
        if self._pid is not None:
            os.close(self._fd)
            os.kill(self._pid, signal.SIGKILL)
            os.waitpid(self._pid, 0)
            self._pid = None

    def result(self) -> Any:
        """The task's result, once it is there (at most ``TIME_LIMIT`` s from now); raises as ``run_isolated``."""
        if self._pid is not None:
            pid, self._pid = self._pid, None
            status = None
            try:
                payload = _receive(self._fd, time.monotonic() + TIME_LIMIT)
                if payload is not None:
                    _, status = os.waitpid(pid, 0)
            finally:
                os.close(self._fd)
                if status is None:  # timed out or interrupted: the child goes too
                    os.kill(pid, signal.SIGKILL)
                    os.waitpid(pid, 0)
            self._outcome = _outcome(payload, status, self._failed, self._memory)
        if self._outcome is None:
            raise ValueError(f"{self._failed} (stopped before its result)")
        ok, value = self._outcome
        if ok:
            return value
        raise value


def _outcome(payload: bytes | None, status: int | None, failed: str, memory: int) -> tuple[bool, Any]:
    """(True, result) or (False, the ValueError to raise) from what a child sent and how it ended."""
    if payload is None:
        return False, ValueError(f"{failed} (no result within {TIME_LIMIT:g} s; stopped)")
    assert status is not None  # a payload arrived, so the child was waited for
    if os.WIFSIGNALED(status):
        number = os.WTERMSIG(status)
        try:
            name = f", {signal.Signals(number).name}: {signal.strsignal(number)}"
        except ValueError:
            name = ""
        killed = " (the system stops a process that runs out of memory this way)" if number == signal.SIGKILL else ""
        return False, ValueError(f"{failed} (signal {number}{name}){killed}")
    try:
        kind, value = marshal.loads(payload)
    except (EOFError, ValueError, TypeError):
        return False, ValueError(f"{failed} (it exited with status {os.waitstatus_to_exitcode(status)} and no result)")
    if kind == "ok":
        return True, value
    if kind == "ValueError":
        return False, ValueError(value)
    if kind == "MemoryError":
        return False, ValueError(f"{failed} (out of memory: more than {_gib(memory)})")
    return False, ValueError(f"{failed} ({value})")


def _receive(fd: int, deadline: float) -> bytes | None:
    """Everything written to ``fd`` until the child closes it, or None at ``deadline``."""
    chunks: list[bytes] = []
    poller = select.poll()  # not select(): it fails on descriptors above 1023
    poller.register(fd, select.POLLIN)
    while True:
        remaining = deadline - time.monotonic()
        if remaining <= 0.0:
            return None
        if poller.poll(max(1, math.ceil(remaining * 1000))):
            chunk = os.read(fd, 1 << 20)
            if not chunk:
                return b"".join(chunks)
            chunks.append(chunk)


def _child(task: Callable[..., Any], args: tuple, fd: int, memory: int, parent: int) -> None:
    """Run ``task`` under the limits, write ``(kind, value)`` to ``fd`` and leave at once."""
    try:
        signal.signal(signal.SIGINT, signal.SIG_IGN)  # Ctrl-C: the parent stops the child
        die_with_parent(parent)  # a parent killed (a worker stopped by Ctrl-C) takes the child with it
        faulthandler.disable()  # a crash here is reported by the parent, not dumped on the terminal
        _limit_resources(memory)
        devnull = os.open(os.devnull, os.O_WRONLY)  # nothing the child prints reaches the terminal
        os.dup2(devnull, 1)
        os.dup2(devnull, 2)
        sys.stdout = sys.stderr = open(devnull, "w", closefd=False)
        # what the parent made is never garbage here: the collector leaves it alone (no full passes over the
        # imported modules while a big part is read and measured, and their pages stay shared with the parent)
        gc.freeze()
        try:
            result: tuple[str, Any] = ("ok", task(*args))
        except ValueError as error:
            result = ("ValueError", str(error))
        except MemoryError:
            result = ("MemoryError", "")
        except BaseException as error:  # OCCT's Standard_Failure and the like
            text = str(error).strip()
            result = ("failure", f"{type(error).__name__}: {text}" if text else type(error).__name__)
            if "OutOfMemory" in result[1] or "bad_alloc" in result[1]:
                result = ("MemoryError", "")
        payload = marshal.dumps(result)
        view = memoryview(payload)
        while view:
            view = view[os.write(fd, view) :]
    except BaseException:
        os._exit(70)
    os._exit(0)


def _limit_resources(memory: int) -> None:
    """No core file; at most ``memory`` more bytes of address space (Linux)."""
    try:
        import resource
    except ImportError:  # not POSIX
        return
    resource.setrlimit(resource.RLIMIT_CORE, (0, 0))
    try:
        with open("/proc/self/statm") as statm:
            in_use = int(statm.read().split()[0]) * os.sysconf("SC_PAGE_SIZE")
    except OSError:
        return
    soft, hard = resource.getrlimit(resource.RLIMIT_AS)
    cap = in_use + memory
    if hard != resource.RLIM_INFINITY:
        cap = min(cap, hard)
    if soft == resource.RLIM_INFINITY or cap < soft:
        resource.setrlimit(resource.RLIMIT_AS, (cap, hard))
