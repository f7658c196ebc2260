"""OCCT's console output, captured: its messenger prints straight to the process's stdout and stderr."""

from __future__ import annotations

import os
import re
import sys
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager

__all__ = ["captured_messages"]

_ANSI = re.compile(r"\x1b\[[0-9;]*m")


@contextmanager
def captured_messages() -> Iterator[list[str]]:
    """Capture everything OCCT prints (its messenger writes to the process's stdout and stderr).

    Yields a list that holds the printed lines, ANSI colour codes removed,
    once the block ends; nothing reaches the console.
    """
    lines: list[str] = []
    for stream in (sys.stdout, sys.stderr):
        stream.flush()
    saved = [os.dup(1), os.dup(2)]
    with tempfile.TemporaryFile() as sink:
        os.dup2(sink.fileno(), 1)
        os.dup2(sink.fileno(), 2)
        try:
            yield lines
        finally:
            os.dup2(saved[0], 1)
            os.dup2(saved[1], 2)
            for fd in saved:
                os.close(fd)
            sink.seek(0)
            text = _ANSI.sub("", sink.read().decode("utf-8", "replace"))
            lines.extend(line for line in text.splitlines() if line.strip())
