"""All-or-nothing output into a folder: files are written into a staging folder, then moved into place together.

``Staging(out)`` makes a staging folder inside ``out`` (so that moving a file
into place is an atomic rename on the same file system) and writes a marker
file into it first. ``commit()`` checks every destination before anything is
replaced (not a folder or another non-file, writable), then moves each
existing destination into a backup folder inside the staging folder and the
new file into place; if any move fails, or an interrupt (Ctrl-C, SIGTERM,
SIGHUP) arrives, every destination is restored from its backup and the
error is raised. Leaving the ``with`` block removes the staging folder (and
the backups) — unless a restore itself failed, in which case the folder is
kept and the error names it — and, after a failure, the output folder too
if it was created for this output and is still empty.

A build killed outright (SIGKILL) leaves its staging folder behind; the next
``Staging`` in the same ``out`` removes it, but only when it carries our
marker (written by this module, naming a process that no longer runs) and
holds no backups. No other folder is ever removed.
"""

from __future__ import annotations

import os
import re
import shutil
import stat
import tempfile
from pathlib import Path
from types import TracebackType

from .signals import signals_handled, stop_requested

PREFIX = ".spiral-cad-build-"
MARKER = ".spiral-cad-staging"
BACKUP = ".backup"
_FOLDER = re.compile(re.escape(PREFIX) + r"(\d+)-[A-Za-z0-9_]+")


def temporary_beside(target: str | os.PathLike, suffix: str) -> str:
    """A new empty file beside ``target`` (in its folder: one file system, so a rename replaces ``target``
    whole), hidden and named after it; the name is cut to 64 characters, so that a target whose name is
    near the file system's 255 still has one."""
    place = Path(target)
    handle, temporary = tempfile.mkstemp(prefix=f".{place.name[:64]}.", suffix=suffix, dir=place.parent)
    os.close(handle)
    return temporary


class OutputError(ValueError):
    """The output folder or a destination in it cannot take the new files; nothing was changed."""


def _marker_text(pid: int) -> str:
    return f"spiral_cad staging folder of process {pid}; removed when that process has ended\n"


def prepare_folder(out: Path) -> list[Path]:
    """Create ``out`` if needed; refuse a file, or a folder we may not write to. Returns the
    folders it created, outermost first.

    Raises:
        OutputError: ``out`` is not a folder, cannot be created or is not writable.
    """
    if out.exists() and not out.is_dir():
        raise OutputError(f"--out {str(out)!r} is a file, not a folder")
    created = [folder for folder in (out, *out.parents) if not folder.exists()][::-1]
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as e:
        raise OutputError(f"cannot create the output folder {str(out)!r}: {e.strerror}") from None
    if not os.access(out, os.W_OK | os.X_OK):
        raise OutputError(f"the output folder {str(out)!r} is not writable")
    return created


def destination_problem(target: Path) -> str | None:
    """Why ``target`` cannot be replaced by a new file, or None when it can."""
    try:
        info = os.stat(target)  # follows a symbolic link to what it names
    except FileNotFoundError:
        return None  # free, or a dangling link that the new file replaces
    except OSError as e:
        return f"{target.name} cannot be inspected ({e.strerror})"
    if stat.S_ISDIR(info.st_mode):
        return f"{target.name} is a folder"
    if not stat.S_ISREG(info.st_mode):
        return f"{target.name} is not a regular file"
    if not os.access(target, os.W_OK):
        return f"{target.name} is read-only"
    return None


def remove_stale(out: Path) -> list[Path]:
    """Remove staging folders of builds that were killed (see the module docstring); returns them."""
    removed = []
    for folder in out.iterdir():
        if _is_stale(folder):
            shutil.rmtree(folder, ignore_errors=True)
            removed.append(folder)
    return removed


def _is_stale(folder: Path) -> bool:
    """True for our staging folder (named and marked by us) of a process that has ended, without backups."""
    found = _FOLDER.fullmatch(folder.name)
    if not found:
        return False
    pid = int(found.group(1))
    marker, backups = folder / MARKER, folder / BACKUP
    expected = _marker_text(pid).encode()
    try:
        if folder.is_symlink() or not folder.is_dir() or marker.is_symlink() or not marker.is_file():
            return False
        with open(marker, "rb") as handle:
            if handle.read(len(expected) + 1) != expected:
                return False
        if backups.exists() and (not backups.is_dir() or any(backups.iterdir())):
            return False
    except OSError:  # unreadable: not ours to judge
        return False
    return not _alive(pid)


def wait_ended(pids: list[int], seconds: float) -> None:
    """Wait (at most ``seconds``) until every process of ``pids`` has ended (or is a zombie): a process killed a
    moment ago still holds its folder while the system ends it."""
    import time

    deadline = time.monotonic() + seconds
    while any(_alive(pid) for pid in pids) and time.monotonic() < deadline:
        time.sleep(0.02)


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # it exists, owned by another user
        pass
    except OverflowError:  # not a pid this system can have
        return False
    return not _zombie(pid)


def _zombie(pid: int) -> bool:
    """True for a process that has ended but is not yet reaped by its parent (Linux; elsewhere False):
    a worker the command has just killed is one until its cluster is closed."""
    try:
        with open(f"/proc/{pid}/stat", "rb") as handle:
            state = handle.read().rpartition(b")")[2].split()[:1]  # the name in parentheses may hold spaces
    except OSError:
        return False
    return state == [b"Z"]


class Staging:
    """A staging folder in ``out`` whose files ``commit`` moves into ``out`` all together (see the module)."""

    def __init__(self, out: str | os.PathLike) -> None:
        self.out = Path(out)
        self._folder: Path | None = None  # made on entry
        self._keep = False
        self._created: list[Path] = []

    @property
    def folder(self) -> Path:
        """The staging folder (inside ``out``) to write the files into."""
        if self._folder is None:
            raise RuntimeError("the staging folder exists only inside the with block")
        return self._folder

    def __enter__(self) -> Staging:
        self._created = prepare_folder(self.out)
        remove_stale(self.out)
        try:
            self._folder = Path(tempfile.mkdtemp(prefix=f"{PREFIX}{os.getpid()}-", dir=self.out))
            (self._folder / MARKER).write_text(_marker_text(os.getpid()), encoding="utf-8")
        except OSError as e:
            self._remove(failed=True)
            raise OutputError(f"cannot write into the output folder {str(self.out)!r}: {e.strerror}") from None
        return self

    def __exit__(self, kind: type[BaseException] | None, error: BaseException | None, trace: TracebackType | None) -> None:
        if not self._keep:
            self._remove(failed=error is not None)

    def _remove(self, failed: bool) -> None:
        """Remove the staging folder and, after a failure, the output folders made for it (if empty)."""
        if self._folder is not None:
            shutil.rmtree(self._folder, ignore_errors=True)
            self._folder = None
        if failed:
            for folder in reversed(self._created):
                try:
                    folder.rmdir()
                except OSError:
                    break

    def files(self) -> list[Path]:
        """The staged files, by name."""
        return sorted(p for p in self.folder.iterdir() if p.name not in (MARKER, BACKUP))

    def commit(self) -> list[Path]:
        """Move every staged file into ``out``, replacing files of the same name; returns the destinations.

        Raises:
            OutputError: a destination is a folder, not a regular file, or
                read-only (checked before anything is replaced).
            OSError: a move failed; every destination was restored.
            KeyboardInterrupt: an interrupt arrived (or the command this worker
                runs for was interrupted, ``stop_requested``); every destination was
                restored (or, if it came after the last move, every file is in
                place and the exception says so).
        """
        if stop_requested():  # the command was interrupted: nothing more is committed
            raise KeyboardInterrupt
        staged = self.files()
        targets = [self.out / p.name for p in staged]
        problems = [p for p in map(destination_problem, targets) if p]
        if problems:
            raise OutputError(f"cannot replace files in {str(self.out)!r}: {'; '.join(problems)}; nothing there was changed")
        backups = self.folder / BACKUP
        backups.mkdir()
        moved: list[tuple[Path, bool, bool]] = []  # (destination, backed up, new file in place)
        with signals_handled(("SIGINT", "SIGTERM", "SIGHUP"), interrupt=False) as received:
            try:
                for source, target in zip(staged, targets):
                    if received or stop_requested():
                        raise KeyboardInterrupt
                    saved = os.path.lexists(target)
                    if saved:
                        os.replace(target, backups / target.name)
                    moved.append((target, saved, False))
                    os.replace(source, target)
                    moved[-1] = (target, saved, True)
                if received:
                    raise KeyboardInterrupt
            except BaseException:
                self._restore(moved, backups)
                raise
        if received:  # arrived after the last check: every file is in place
            raise KeyboardInterrupt(f"every file had been written to {str(self.out)!r}")
        return targets

    def _restore(self, moved: list[tuple[Path, bool, bool]], backups: Path) -> None:
        failed = []
        for target, saved, placed in reversed(moved):
            try:
                if saved:
                    os.replace(backups / target.name, target)
                elif placed:
                    os.unlink(target)
            except OSError as e:
                failed.append(f"{target.name} ({e.strerror})")
        if failed:
            self._keep = True
            raise OSError(f"could not restore {', '.join(failed)} in {str(self.out)!r}; the previous files are in {str(backups)!r}")
