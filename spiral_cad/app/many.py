"""``spiral-cad check`` and ``build`` on many files at once, on dask.distributed.

The command line hands over the files (named, globbed or found in folders) and
the one-file function it runs for a single file; each file becomes one task on
a ``LocalCluster`` of this machine or on an existing cluster (``--scheduler``).
A task takes a path and returns a ``FileResult``: the exit status, the text the
one-file run prints and the worst joint it reported — plain strings and
numbers, so no OCCT object is ever pickled. The results come back in the
order of the files, whatever order the workers finish in, so the output is the
one of running the files one by one.

Nothing is lost and nothing hangs: a file whose worker died is run again
alone in a fresh process (however often workers die, and also when no
worker is left); a lost scheduler ends the run with every finished file
reported and the others named "not run"; the ``--summary`` file is opened
before anything runs and gets each row as its result arrives; Ctrl-C or
SIGTERM commit nothing more, stop the workers and their children and remove
their staging folders. The workers' own output (dask's log, tracebacks of a
dying worker) never reaches the terminal.

dask is imported only here and only when a run starts: a single file never
starts a cluster and the command's cold start does not pay for dask.
"""

from __future__ import annotations

import contextlib
import csv
import logging
import os
import queue
import shutil
import signal
import sys
import tempfile
import time
from collections.abc import Callable, Iterator, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any, TextIO

from ..io.signals import raise_if_interrupted
from ..io.staging import remove_stale, wait_ended
from .many_inputs import expand_inputs, shown, wants_many
from .many_task import NOT_RUN, FileResult, note_worst, run_alone, run_one

if TYPE_CHECKING:
    import argparse

__all__ = ["PIP_MANY", "FileResult", "expand_inputs", "note_worst", "run_many", "run_one", "wants_many"]

PIP_MANY = 'pip install "spiral_cad[many]"'
#: Seconds with no worker on the cluster after which the files left run here, each alone in a fresh process.
NO_WORKERS = 20.0
#: Seconds a file may take when it runs alone in a fresh process (its worker died).
ALONE_LIMIT = 600.0


def _client(workers: int | None, scheduler: str | None, files: int) -> Any:
    """A dask client: of the cluster at ``scheduler``, else of a new LocalCluster on loopback."""
    try:
        import dask
        from distributed import Client, LocalCluster
    except ImportError:
        raise ValueError(f"many files run on dask.distributed, which is not installed: {PIP_MANY}") from None

    # a task whose worker dies is not retried by dask: the command runs it again alone, in a fresh process of its own,
    # so only a file that stops a process by itself is its error, and no worker's death can hold the run
    dask.config.set({"distributed.scheduler.allowed-failures": 0, "distributed.admin.tick.limit": "1h"})
    # dask's own log (a lost connection, a worker that died) is not the command's to print: every file's fate is reported
    for name in ("distributed", "tornado", "asyncio"):
        logging.getLogger(name).setLevel(logging.CRITICAL + 1)
    if scheduler is not None:
        try:
            return Client(scheduler, timeout="10s")
        except (OSError, TimeoutError) as error:
            raise ValueError(f"--scheduler {scheduler!r}: no dask scheduler answered ({error})") from None
    count = workers if workers is not None else max(1, min(os.cpu_count() or 1, files))
    try:
        cluster = LocalCluster(n_workers=count, threads_per_worker=1, processes=True, host="127.0.0.1",
                               dashboard_address="127.0.0.1:0", silence_logs=logging.CRITICAL + 1)  # fmt: skip
    except (OSError, RuntimeError, TimeoutError) as error:  # a worker killed while it started, no process to spare
        raise ValueError(f"the local dask cluster could not start ({type(error).__name__}: {error}); nothing was run") from None
    return Client(cluster)


_INTERRUPTS = {signal.SIGINT}
#: Seconds the command waits for the workers it killed to end before it removes their staging folders.
KILLED_WAIT = 10.0


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


def _on_descriptor(stream: TextIO, fd: int) -> bool:
    try:
        return stream.fileno() == fd
    except (AttributeError, OSError, ValueError):
        return False


@contextlib.contextmanager
def _children_quiet() -> Iterator[None]:
    """Within the block, descriptors 1 and 2 lead to the null device — so the workers and the
    processes they start, and dask's log, write nothing on the terminal — while this process's
    ``sys.stdout`` and ``sys.stderr`` write where they did."""
    try:
        null = os.open(os.devnull, os.O_WRONLY)
    except OSError:
        yield
        return
    saved: dict[int, int] = {}
    replaced: dict[str, TextIO] = {}
    try:
        for fd, name in ((1, "stdout"), (2, "stderr")):
            stream = getattr(sys, name)
            with contextlib.suppress(OSError, ValueError, AttributeError):
                stream.flush()
            saved[fd] = os.dup(fd)
            if _on_descriptor(stream, fd):
                mine = open(os.dup(saved[fd]), "w", encoding=stream.encoding, errors=stream.errors or "strict")  # noqa: SIM115
                mine.reconfigure(line_buffering=getattr(stream, "line_buffering", False))
                replaced[name] = stream
                setattr(sys, name, mine)
            os.dup2(null, fd)
        yield
    finally:
        for name, stream in replaced.items():
            mine = getattr(sys, name)
            with contextlib.suppress(OSError, ValueError):
                mine.flush()
            setattr(sys, name, stream)
            with contextlib.suppress(OSError, ValueError):
                mine.close()
        for fd, copy in saved.items():
            os.dup2(copy, fd)
            os.close(copy)
        os.close(null)


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


class _Summary:
    """The ``--summary`` CSV (file, verdict, worst joint, seconds): opened before the run, a row
    written as each result arrives, so a run that ends early leaves every row it had."""

    def __init__(self, path: str | None) -> None:
        self.path, self.problem = path, ""
        self.handle: TextIO | None = None
        if path is None:
            return
        if Path(path).suffix.lower() != ".csv":
            raise ValueError(f"--summary {shown(path)!r}: the summary is CSV; give a .csv file")
        try:
            self.handle = open(path, "w", newline="", encoding="utf-8")  # noqa: SIM115
        except OSError as error:
            raise ValueError(f"--summary {shown(path)!r}: cannot write it ({error.strerror or error}); nothing was run") from None
        self.writer = csv.writer(self.handle)
        self.row(["file", "verdict", "worst_joint", "seconds"])

    def row(self, cells: Sequence[str]) -> None:
        """Write one row now (a failure is kept for the end: the run goes on)."""
        if self.handle is None or self.problem:
            return
        try:
            self.writer.writerow(cells)
            self.handle.flush()
        except OSError as error:
            self.problem = f"--summary {shown(self.path or '')!r}: cannot write it ({error.strerror or error}); its rows end early"

    def close(self) -> None:
        if self.handle is not None:
            with contextlib.suppress(OSError):
                self.handle.close()
            self.handle = None


class _Results:
    """Results as they arrive, printed in the order of the files; progress on stderr; summary rows."""

    def __init__(self, files: Sequence[str], verb: str, summary: _Summary) -> None:
        self.shown = [shown(f) for f in files]
        self.results: list[FileResult | None] = [None] * len(files)
        self.printed = self.failed = self.done = 0
        self.progress = _Progress(len(files), verb)
        self.summary = summary

    def add(self, index: int, result: FileResult, *, show: bool = True) -> None:
        if self.results[index] is not None:
            return
        self.results[index] = result
        self.summary.row([result.file, result.verdict, result.worst, f"{result.seconds:.4f}"])
        if not show:
            return
        self.done += result.status != NOT_RUN
        self.failed += result.status not in (0, NOT_RUN)
        while self.printed < len(self.results) and (ready := self.results[self.printed]) is not None:
            if ready.status != NOT_RUN:
                ending = "" if ready.output.endswith("\n") else "\n"
                print(f"== {ready.file}\n{ready.output}", end=ending, flush=True)
            self.printed += 1
        self.progress(self.done, self.failed)

    def not_run(self, why: str, *, show: bool = True) -> None:
        """Every file without a result is named "not run", for the reason ``why``."""
        for index, result in enumerate(self.results):
            if result is None:
                self.add(index, FileResult.failed(self.shown[index], f"not run: {why}", NOT_RUN), show=show)

    def finish(self) -> int:
        """The last progress line, an ``error:`` line per file that did not pass; the exit status."""
        final = [r for r in self.results if r is not None]
        self.progress(self.done, self.failed, final=True)
        for r in final:
            if r.status != 0:
                print(f"error: {r.file}: {r.reason()}", file=sys.stderr)
        if self.summary.problem:
            print(f"error: {self.summary.problem}", file=sys.stderr)
        return 0 if all(r.status == 0 for r in final) and not self.summary.problem else 2


def run_many(task: Callable[[argparse.Namespace], int], files: Sequence[str], changes: Sequence[dict[str, Any]], args: argparse.Namespace,
             *, verb: str, workers: int | None = None, scheduler: str | None = None, summary: str | None = None) -> int:  # fmt: skip
    """Run the one-file command ``task`` on every file, one dask task each (``changes[i]``: what file
    ``i`` changes in ``args``); print each file's output in the order of ``files``, progress on
    stderr, and ``error: FILE: …`` for every file that did not pass. A single file with no
    ``scheduler`` runs here, without a cluster.

    Returns:
        0 when every file passed, else 2.

    Raises:
        ValueError: a bad option, or a ``summary`` that cannot be written (before anything runs).
        KeyboardInterrupt: Ctrl-C or SIGTERM; the workers were stopped, nothing committed since.
    """
    if workers is not None and workers < 1:
        raise ValueError(f"--workers must be at least 1; got {workers}")
    sink = _Summary(summary)
    try:
        results = _Results(files, verb, sink)
        if len(files) == 1 and scheduler is None:
            streams = sys.stdout, sys.stderr
            try:
                result = run_one(task, results.shown[0], args, changes[0])
            finally:
                sys.stdout, sys.stderr = streams  # this process's own again
            results.add(0, result)
            return results.finish()
        stop_folder = tempfile.mkdtemp(prefix="spiral-cad-stop-")
        try:
            with _children_quiet():
                _on_cluster(task, files, changes, args, results, workers, scheduler, os.path.join(stop_folder, "stop"))
        except BaseException:
            results.not_run("interrupted", show=False)
            raise
        finally:
            shutil.rmtree(stop_folder, ignore_errors=True)
        return results.finish()
    finally:
        sink.close()


def _on_cluster(task: Callable[[argparse.Namespace], int], files: Sequence[str], changes: Sequence[dict[str, Any]],
                args: argparse.Namespace, results: _Results, workers: int | None, scheduler: str | None, stop: str) -> None:  # fmt: skip
    """The files on the cluster; those whose worker died each alone in a fresh process after."""
    with _interrupts_held():  # the workers start with Ctrl-C blocked: the command alone answers it
        client = _client(workers, scheduler, len(files))
    cluster = client.cluster if scheduler is None else None
    alone: list[int] = []
    killed: list[int] = []
    try:
        try:
            _interrupts_released()  # a Ctrl-C during the start arrives here, where the cluster is closed
            lost = _dispatch(client, task, files, changes, args, results, stop, alone)
        except BaseException:
            killed = _stop_workers(stop, cluster)
            raise
        finally:
            _close(client, cluster)
        if lost:
            results.not_run("the dask scheduler was lost")
            return
        for index in alone:  # each alone: only a file that stops its process by itself is its error
            results.add(index, run_alone(task, results.shown[index], args, changes[index], limit=ALONE_LIMIT, stop=stop))
    except BaseException:
        with contextlib.suppress(OSError):  # nothing more is committed (a process run alone was killed)
            Path(stop).touch()
        raise
    finally:
        wait_ended(killed, KILLED_WAIT)  # a killed worker may still be ending: its folder is removed once it has
        for index, result in enumerate(results.results):  # staging folders of workers that were stopped
            out = changes[index].get("out")
            if result is None and out is not None and os.path.isdir(out):
                remove_stale(Path(out))


def _dispatch(client: Any, task: Callable[[argparse.Namespace], int], files: Sequence[str], changes: Sequence[dict[str, Any]],
              args: argparse.Namespace, results: _Results, stop: str, alone: list[int]) -> bool:  # fmt: skip
    """Run the files on the cluster, a bounded number in flight; the files whose worker died (or
    all those left once no worker has been there for ``NO_WORKERS`` s) go into ``alone``.

    Returns:
        True when the scheduler was lost (its futures cancelled).
    """
    arrived: queue.Queue = queue.Queue()
    window = max(64, 8 * _threads(client))
    waiting = iter(range(len(files)))
    in_flight: dict[Any, int] = {}  # task key → file index

    def submit(index: int) -> None:
        future = client.submit(run_one, task, results.shown[index], args, changes[index], stop, pure=False)
        in_flight[future.key] = index
        future.add_done_callback(arrived.put)

    for _, index in zip(range(window), waiting):
        submit(index)
    idle_since: float | None = None
    while in_flight:
        raise_if_interrupted()  # a Ctrl-C whose KeyboardInterrupt dask's callbacks swallowed
        try:
            future = arrived.get(timeout=0.5)
        except queue.Empty:
            if _threads(client) > 0:
                idle_since = None
            elif idle_since is None:
                idle_since = time.monotonic()
            elif time.monotonic() - idle_since > NO_WORKERS:  # no worker comes back: the rest run here
                alone.extend(sorted(in_flight.values()))
                alone.extend(waiting)
                return False
            continue
        index = in_flight.pop(future.key, -1)
        if index < 0:
            continue
        if future.status == "cancelled":  # we cancel nothing: the scheduler is gone
            return True
        try:
            results.add(index, future.result())
        except Exception:  # its worker died (KilledWorker), or dask could not run it
            alone.append(index)
        for following in waiting:
            submit(following)
            break
    return False


def _threads(client: Any) -> int:
    """The worker threads the cluster has now (1 when the scheduler cannot tell)."""
    try:
        return sum(client.nthreads().values())
    except Exception:
        return 1


def _stop_workers(stop: str, cluster: Any) -> list[int]:
    """Interrupted: workers commit nothing more (the stop file), and a local cluster's are killed now; their pids."""
    with contextlib.suppress(OSError):
        Path(stop).touch()
    killed = []
    for nanny in list(getattr(cluster, "workers", {}).values()):
        pid = getattr(getattr(getattr(nanny, "process", None), "process", None), "pid", None)
        if pid:
            with contextlib.suppress(OSError):
                os.kill(pid, signal.SIGKILL)  # its reader children end with it (die_with_parent)
                killed.append(pid)
    return killed


def _close(client: Any, cluster: Any) -> None:
    """Close the client (and the local cluster), whatever state they are in, without a word."""
    masked = hasattr(signal, "pthread_sigmask")
    if masked:  # a second Ctrl-C does not cut the closing short (it arrives after)
        signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT, signal.SIGTERM})
    try:
        with contextlib.suppress(Exception):
            client.close(timeout=10)
        if cluster is not None:
            with contextlib.suppress(Exception):
                cluster.close(timeout=20)
    finally:
        if masked:
            signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT, signal.SIGTERM})
