"""``spiral-cad check`` and ``build`` on many files at once, on dask.distributed.

The command line hands over the files (named, globbed or found in folders) and
the one-file function it runs for a single file; each file becomes one task on
a ``LocalCluster`` of this machine or on an existing cluster (``--scheduler``).
A task takes a path and returns a ``FileResult``: the exit status, the text the
one-file run prints and the worst joint it reported — plain strings and
numbers, so no OCCT object is ever pickled. The results come back in the
order of the files, whatever order the workers finish in, so the output is the
one of running the files one by one.

dask is imported only here and only when a run starts: a single file never
starts a cluster and the command's cold start does not pay for dask.
"""

from __future__ import annotations

import contextlib
import copy
import csv
import glob
import io
import os
import signal
import sys
import threading
import time
import warnings
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, TextIO

if TYPE_CHECKING:
    import argparse

__all__ = ["PIP_MANY", "FileResult", "expand_inputs", "note_worst", "run_many", "run_one", "wants_many"]

PIP_MANY = 'pip install "spiral_cad[many]"'

#: The rank of every level a checker reports, worst first (joints: unmeasurable < none < G0 < G1 < G2;
#: faces: a gap is no G0 and a crease is G0 only).
_RANK = {"unmeasurable": -1, "none": 0, "gap": 0, "crease": 1, "G0": 1, "G1": 2, "G2": 3}
_GLOB_CHARACTERS = frozenset("*?[")


@dataclass(frozen=True)
class FileResult:
    """What one file's run gave back from a worker: plain data only.

    Attributes:
        file: the file as the command line shows it.
        status: the one-file exit status (0 ok, 1 below ``--require``, 2 error).
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
        """``ok``, ``fail`` (below ``--require``) or ``error`` (not read, not built)."""
        return {0: "ok", 1: "fail"}.get(self.status, "error")

    def reason(self) -> str:
        """Why the file did not pass, in one line (its error, else its ``FAIL:`` line)."""
        if self.errors:
            return "; ".join(line.removeprefix("error: ") for line in self.errors)
        fails = [line.removeprefix("FAIL: ") for line in self.output.splitlines() if line.startswith("FAIL: ")]
        return "; ".join(fails) or f"exit status {self.status}"


def _is_pattern(text: str) -> bool:
    return not Path(text).exists() and any(c in _GLOB_CHARACTERS for c in text)


def _holds(folder: Path, suffixes: Sequence[str]) -> bool:
    wanted = {suffix.lower() for suffix in suffixes}
    return any(p.suffix.lower() in wanted and p.is_file() for p in folder.rglob("*"))


def wants_many(inputs: Sequence[str], suffixes: Sequence[str]) -> bool:
    """True when ``inputs`` name more than one file: several, a glob pattern, or a folder that holds
    a file with one of ``suffixes`` (any other folder is refused as the one file it is not)."""
    return len(inputs) > 1 or any(_is_pattern(text) or (Path(text).is_dir() and _holds(Path(text), suffixes)) for text in inputs)


def expand_inputs(inputs: Sequence[str], suffixes: Sequence[str]) -> list[str]:
    """The files ``inputs`` name, in order, each once: a file as given, a glob pattern's files
    (``**`` reaches into subfolders), a folder's files with one of ``suffixes`` at any depth.

    Raises:
        ValueError: a pattern or folder that names no file.
    """
    files: dict[str, None] = {}
    wanted = {suffix.lower() for suffix in suffixes}
    for text in inputs:
        path = Path(text)
        if path.is_dir():
            found = sorted(str(p) for p in path.rglob("*") if p.is_file() and p.suffix.lower() in wanted)
            if not found:
                raise ValueError(f"folder {text!r} holds no {', '.join(sorted(wanted))} file")
        elif _is_pattern(text):
            found = sorted(p for p in glob.glob(text, recursive=True) if Path(p).is_file())
            if not found:
                raise ValueError(f"no file matches {text!r}")
        else:
            found = [text]  # a missing file is that file's error, reported with the others
        files.update(dict.fromkeys(found))
    return list(files)


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


def run_one(task: Callable[[argparse.Namespace], int], shown: str, args: argparse.Namespace, changes: dict[str, Any]) -> FileResult:
    """Run the one-file command ``task`` on a copy of ``args`` with ``changes`` (the file, its output
    folder): what a worker runs for the file ``shown``.

    Errors are caught as the command line catches them: a ``ValueError``/``OSError`` is an
    ``error: …`` line, anything else an internal error; none escapes as a traceback.
    """
    warnings.simplefilter("ignore")  # as the command line: what matters is in the report
    mine = copy.copy(args)
    for name, value in changes.items():
        setattr(mine, name, value)
    started = time.perf_counter()
    errors: list[str] = []
    with _captured() as captured:
        try:
            status = task(mine)
        except (ValueError, OSError) as error:
            status, errors = 2, [f"error: {error}"]
        except Exception as error:
            status, errors = 2, [f"error: internal error ({type(error).__name__}: {error}); please report it"]
        assert captured.out is not None and captured.err is not None
        output, printed, worst = captured.out.getvalue(), captured.err.getvalue(), captured.worst
    errors = [line for line in printed.splitlines() if line.strip()] + errors
    return FileResult(shown, status, worst, time.perf_counter() - started, output, tuple(errors))


def _client(workers: int | None, scheduler: str | None, files: int) -> Any:
    """A dask client: of the cluster at ``scheduler``, else of a new LocalCluster on loopback."""
    try:
        import dask
        from distributed import Client, LocalCluster
    except ImportError:
        raise ValueError(f"many files run on dask.distributed, which is not installed: {PIP_MANY}") from None
    import logging

    # a file that kills its worker (OCCT crashing outside the reader's sandbox) is that file's error after one retry (the
    # retry spares a file that was only queued on the same worker), not after dask's default three
    dask.config.set({"distributed.scheduler.allowed-failures": 1, "distributed.admin.tick.limit": "1h"})
    if scheduler is not None:
        try:
            return Client(scheduler, timeout="10s")
        except (OSError, TimeoutError) as error:
            raise ValueError(f"--scheduler {scheduler!r}: no dask scheduler answered ({error})") from None
    count = workers if workers is not None else max(1, min(os.cpu_count() or 1, files))
    cluster = LocalCluster(n_workers=count, threads_per_worker=1, processes=True, host="127.0.0.1",
                           dashboard_address="127.0.0.1:0", silence_logs=logging.ERROR)  # fmt: skip
    return Client(cluster)


_INTERRUPTS = {signal.SIGINT}


@contextlib.contextmanager
def _interrupts_held() -> Iterator[None]:
    """Ctrl-C held back while the block runs (it arrives at ``_interrupts_released``).

    Processes and threads started meanwhile inherit the blocked signal, so a Ctrl-C in the
    terminal reaches the command alone (not every worker, which would each print a
    traceback); the command stops the cluster itself.
    """
    if not hasattr(signal, "pthread_sigmask"):  # Windows: no signal masks
        yield
        return
    from multiprocessing import resource_tracker

    resource_tracker.ensure_running()  # now: starting it later would unblock Ctrl-C in the thread that starts the workers
    signal.pthread_sigmask(signal.SIG_BLOCK, _INTERRUPTS)
    try:
        yield
    except BaseException:
        _interrupts_released()
        raise


def _interrupts_released() -> None:
    if hasattr(signal, "pthread_sigmask"):
        signal.pthread_sigmask(signal.SIG_UNBLOCK, _INTERRUPTS)


class _Progress:
    """``done/total files, failed, files/s`` on stderr, at most about once a second (and at the end)."""

    def __init__(self, total: int, verb: str) -> None:
        self.total, self.verb = total, verb
        self.started = self.shown = time.perf_counter()

    def __call__(self, done: int, failed: int, final: bool = False) -> None:
        now = time.perf_counter()
        if not final and now - self.shown < 1.0:
            return
        self.shown = now
        rate = done / (now - self.started) if now > self.started else 0.0
        ending = f" in {now - self.started:.1f} s" if final else ""
        print(f"{self.verb} {done}/{self.total} files, {failed} not passed, {rate:.1f} files/s{ending}", file=sys.stderr, flush=True)


def _summary(path: str, results: Sequence[FileResult]) -> None:
    """The CSV summary: one row per file (file, verdict, worst joint, seconds)."""
    try:
        with open(path, "w", newline="", encoding="utf-8") as handle:
            writer = csv.writer(handle)
            writer.writerow(["file", "verdict", "worst_joint", "seconds"])
            for r in results:
                writer.writerow([r.file, r.verdict, r.worst, f"{r.seconds:.4f}"])
    except OSError as error:
        raise ValueError(f"--summary {path!r}: cannot write it ({error.strerror or error})") from None


class _Results:
    """Results as they arrive, printed in the order of the files; progress on stderr."""

    def __init__(self, files: Sequence[str], verb: str) -> None:
        self.files = list(files)
        self.results: list[FileResult | None] = [None] * len(files)
        self.printed = self.failed = self.done = 0
        self.progress = _Progress(len(files), verb)

    def add(self, index: int, result: FileResult) -> None:
        self.results[index] = result
        self.done += 1
        self.failed += result.status != 0
        while self.printed < len(self.results) and (ready := self.results[self.printed]) is not None:
            ending = "" if ready.output.endswith("\n") else "\n"
            print(f"== {ready.file}\n{ready.output}", end=ending, flush=True)
            self.printed += 1
        self.progress(self.done, self.failed)

    def finish(self, summary: str | None) -> int:
        """The last progress line, the summary, an ``error:`` line per file that did not pass; the exit status."""
        final = [r for r in self.results if r is not None]
        self.progress(self.done, self.failed, final=True)
        if summary is not None:
            _summary(summary, final)
        for r in final:
            if r.status != 0:
                print(f"error: {r.file}: {r.reason()}", file=sys.stderr)
        return 0 if self.failed == 0 else 2


def run_many(task: Callable[[argparse.Namespace], int], files: Sequence[str], changes: Sequence[dict[str, Any]], args: argparse.Namespace,
             *, verb: str, workers: int | None = None, scheduler: str | None = None, summary: str | None = None) -> int:  # fmt: skip
    """Run the one-file command ``task`` on every file, one dask task each (``changes[i]``: what file
    ``i`` changes in ``args``); print each file's output in the order of ``files``, progress on
    stderr, and ``error: FILE: …`` for every file that did not pass. A single file with no
    ``scheduler`` runs here, without a cluster.

    Returns:
        0 when every file passed, else 2.
    """
    if workers is not None and workers < 1:
        raise ValueError(f"--workers must be at least 1; got {workers}")
    if summary is not None and Path(summary).suffix.lower() != ".csv":
        raise ValueError(f"--summary {summary!r}: the summary is CSV; give a .csv file")
    results = _Results(files, verb)
    if len(files) == 1 and scheduler is None:
        streams = sys.stdout, sys.stderr
        try:
            result = run_one(task, files[0], args, changes[0])
        finally:
            sys.stdout, sys.stderr = streams  # this process's own again
        results.add(0, result)
        return results.finish(summary)
    with _interrupts_held():  # the workers start with Ctrl-C blocked: the command alone answers it
        client = _client(workers, scheduler, len(files))
    try:
        _interrupts_released()  # a Ctrl-C during the start arrives here, where the cluster is closed
        from distributed import as_completed

        window = max(64, 8 * sum(client.nthreads().values()))  # a bounded number of tasks in flight
        waiting = iter(range(len(files)))
        where: dict[str, int] = {}  # task key → file index

        def submit(index: int) -> Any:
            future = client.submit(run_one, task, files[index], args, changes[index], pure=False)
            where[future.key] = index
            return future

        pending = as_completed([submit(index) for _, index in zip(range(window), waiting)])
        died: list[int] = []  # files whose worker stopped: the file's doing, or another's on the same worker
        for future in pending:
            index = where.pop(future.key)
            try:
                results.add(index, future.result())
            except Exception:
                died.append(index)
            for following in waiting:
                pending.add(submit(following))
                break
        for index in died:  # each alone on the cluster: only a file that stops its worker by itself is its error
            future = submit(index)
            where.pop(future.key)
            try:
                result = future.result()
            except Exception as error:
                result = FileResult(files[index], 2, "", 0.0, "", (f"error: its worker stopped ({type(error).__name__}: {error})",))
            results.add(index, result)
    finally:
        cluster = client.cluster
        client.close()
        if cluster is not None and scheduler is None:
            cluster.close()
    return results.finish(summary)
