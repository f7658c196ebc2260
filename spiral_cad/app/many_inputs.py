"""The files of a many-file run: named, globbed or found in folders, each once, shown safely.

A file is taken once however it is named (``a.step``, ``./a.step``, a symbolic
link to it): inputs are told apart by their real path. Folders are walked
following symbolic links to folders, but never into a folder already walked,
so a link loop is walked once. File names are the operating system's bytes;
``shown`` makes any of them printable (bytes that are not UTF-8 as ``\\xe9``),
for the terminal and the summary alike.
"""

from __future__ import annotations

import codecs
import contextlib
import glob
import io
import os
import sys
from collections.abc import Iterator, Sequence

__all__ = ["ESCAPE", "escaping_streams", "expand_inputs", "output_collisions", "shown", "wants_many"]

#: The codec error handler that writes a name's undecodable byte as ``\xNN`` and any other character
#: the stream cannot encode as ``\uNNNN``.
ESCAPE = "spiral_cad.escape"


def _escape(error: UnicodeError) -> tuple[str, int]:
    if not isinstance(error, UnicodeEncodeError):
        raise error
    text = error.object[error.start : error.end]
    escaped = (f"\\x{ord(c) - 0xDC00:02x}" if 0xDC80 <= ord(c) <= 0xDCFF else c.encode("ascii", "backslashreplace").decode() for c in text)
    return "".join(escaped), error.end


codecs.register_error(ESCAPE, _escape)


def escaping_streams() -> None:
    """Have ``sys.stdout`` and ``sys.stderr`` escape what they cannot encode (a file name of any bytes)
    instead of failing on it."""
    for stream in (sys.stdout, sys.stderr):
        if isinstance(stream, io.TextIOWrapper):
            with contextlib.suppress(ValueError, OSError):
                stream.reconfigure(errors=ESCAPE)


_GLOB_CHARACTERS = frozenset("*?[")


def shown(name: str | os.PathLike) -> str:
    """``name`` as it can be printed and written as UTF-8: bytes that are not UTF-8 as backslash escapes."""
    return os.fsencode(name).decode("utf-8", "backslashreplace")


def _is_pattern(text: str) -> bool:
    return not os.path.lexists(text) and any(c in _GLOB_CHARACTERS for c in text)


def _walk(folder: str, suffixes: Sequence[str]) -> Iterator[str]:
    """The files with one of ``suffixes`` in ``folder`` at any depth, sorted per folder, each folder walked once."""
    wanted = {suffix.lower() for suffix in suffixes}
    walked: set[str] = set()
    for root, folders, names in os.walk(folder, followlinks=True):
        real = os.path.realpath(root)
        if real in walked:  # a link back to a folder already walked: a loop or a second name
            folders[:] = []
            continue
        walked.add(real)
        folders.sort()
        for name in sorted(names):
            path = os.path.join(root, name)
            if os.path.splitext(name)[1].lower() in wanted and os.path.isfile(path):
                yield path


def wants_many(inputs: Sequence[str], suffixes: Sequence[str]) -> bool:
    """True when ``inputs`` name more than one file: several, a glob pattern, or a folder that holds
    a file with one of ``suffixes`` (any other folder is refused as the one file it is not)."""
    return len(inputs) > 1 or any(
        _is_pattern(text) or (os.path.isdir(text) and next(_walk(text, suffixes), None) is not None) for text in inputs
    )


def expand_inputs(inputs: Sequence[str], suffixes: Sequence[str]) -> list[str]:
    """The files ``inputs`` name, in order, each once by its real path: a file as given, a glob
    pattern's files (``**`` reaches into subfolders), a folder's files with one of ``suffixes`` at any
    depth (symbolic links followed, loops not).

    Raises:
        ValueError: a pattern or folder that names no file.
    """
    files: dict[str, str] = {}  # real path → the name first given
    wanted = sorted({suffix.lower() for suffix in suffixes})
    for text in inputs:
        if os.path.isdir(text):
            found = sorted(_walk(text, suffixes))
            if not found:
                raise ValueError(f"folder {shown(text)!r} holds no {', '.join(wanted)} file")
        elif _is_pattern(text):
            found = sorted(p for p in glob.glob(text, recursive=True) if os.path.isfile(p))
            if not found:
                raise ValueError(f"no file matches {shown(text)!r}")
        else:
            found = [text]  # a missing file is that file's error, reported with the others
        for path in found:
            files.setdefault(os.path.realpath(path), path)
    return list(files.values())


def output_collisions(files: Sequence[str], outs: Sequence[str | os.PathLike]) -> None:
    """Refuse two inputs that would build into the same output folder (``pocket.nc`` and ``pocket.ngc``).

    Raises:
        ValueError: naming every such pair and the folder.
    """
    first: dict[str, str] = {}
    clashes = []
    for file, out in zip(files, outs):
        key = os.path.normcase(os.path.abspath(out))
        if key in first:
            clashes.append(f"{shown(first[key])} and {shown(file)} both build into {shown(out)}{os.sep}")
        else:
            first[key] = file
    if clashes:
        raise ValueError(f"{'; '.join(clashes)}: one would replace the other; build them separately or rename one")
