"""Progress on stderr for long jobs: counted steps, or a tick for one long call."""

from __future__ import annotations

import sys
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager

__all__ = ["Progress", "ticking"]


class Progress:
    """Progress lines on stderr for a job that has run longer than ``after`` seconds, at most one every ``every``."""

    def __init__(self, what: str, total: int | None = None, after: float = 3.0, every: float = 2.0):
        self.what, self.total, self.every = what, total, every
        self.started = time.monotonic()
        self.next = self.started + after
        self.shown = False

    def __call__(self, done: int) -> None:
        now = time.monotonic()
        if now < self.next:
            return
        self.next = now + self.every
        self.shown = True
        of = f" of {self.total:,}" if self.total else ""
        print(f"{self.what}: {done:,}{of} ({now - self.started:.0f} s)", file=sys.stderr, flush=True)

    def done(self, count: int) -> None:
        if self.shown:
            print(f"{self.what}: {count:,} done in {time.monotonic() - self.started:.1f} s", file=sys.stderr, flush=True)


@contextmanager
def ticking(what: str, after: float = 3.0, every: float = 5.0) -> Iterator[None]:
    """While the block runs longer than ``after`` seconds, a line on stderr every ``every`` seconds
    saying it still runs (for one long call that cannot count its own progress), and its time at the end."""
    stop = threading.Event()
    started = time.monotonic()

    def tick() -> None:
        wait = after
        while not stop.wait(wait):
            print(f"{what}: still running ({time.monotonic() - started:.0f} s)", file=sys.stderr, flush=True)
            wait = every

    thread = threading.Thread(target=tick, daemon=True)
    thread.start()
    try:
        yield
    finally:
        stop.set()
        thread.join()
        if time.monotonic() - started > after:
            print(f"{what}: done in {time.monotonic() - started:.1f} s", file=sys.stderr, flush=True)
