"""What the commands of ``spiral-cad`` share: the CAD extra's install line, and the options and the runner of
many files at once (``spiral_cad.app.many``)."""

from __future__ import annotations

import argparse
from collections.abc import Callable

from .many import PIP_MANY

__all__ = ["MANY_OPTIONS", "PIP_CAD", "add_many_options", "run_on_many", "summary_only"]


#: How to install the CAD extra, for the commands that need OCCT.
PIP_CAD = 'pip install "spiral_cad[cad]"'


#: The options of ``many.py``: none of them changes what a file gives.
MANY_OPTIONS = ("workers", "scheduler", "summary")


def add_many_options(command: argparse.ArgumentParser) -> None:
    """The options of a command that runs many files at once (``--workers``, ``--scheduler``, ``--summary``)."""
    many = command.add_argument_group(
        "many files", "several files, folders or glob patterns ('**' reaches into subfolders) run in parallel on dask.distributed,\n"
        "one task per file, each file's output in the order given; exit 0 only when every file passes, else 2 with an\n"
        f"'error: FILE: …' line per file (needs {PIP_MANY})")  # fmt: skip
    many.add_argument("--workers", type=int, metavar="N", help="worker processes of the local cluster (default: one per core)")
    many.add_argument("--scheduler", metavar="ADDRESS",
                      help="run on the dask cluster of this scheduler (tcp://host:8786) instead of a local one; every worker "
                           "must see the files at the same paths")  # fmt: skip
    many.add_argument("--summary", metavar="FILE.csv", help="also write one row per file: file, verdict, worst joint, seconds")


def run_on_many(
    args: argparse.Namespace, task: Callable[[argparse.Namespace], int], files: list[str], changes: list[dict], verb: str
) -> int:
    """``task`` on every file of ``files`` on dask (``many.run_many``), each with its ``changes`` to ``args``."""
    from .many import run_many

    return run_many(task, files, changes, args, verb=verb, workers=args.workers, scheduler=args.scheduler, summary=args.summary)


def summary_only(table: str, quiet: bool) -> str:
    """A check's table, or with ``quiet`` its first line: the summary (``check --quiet``)."""
    return table.split("\n", 1)[0] if quiet else table
