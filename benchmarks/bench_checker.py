"""G2 checker on files: the price of reading in a child process, against OCCT reading in-process.

Run: ``.venv/bin/python benchmarks/bench_checker.py [--quick] [--repeat R] [--edges N] [--out FILE]``.

The peer reads the same file with OCCT's reader in the calling process
(``ReadFile`` + ``TransferRoots``) and measures it with the same code, as
the checker did before its readers moved into a child process. Ours reads it
in a forked child (time and memory limits), counts the file's curves against
the edges transferred, measures there and sends back only the numbers. The
ratio is ours / peer; the goal is an overhead of a few tens of milliseconds
per file (one fork) and about 1.2× on a 10 000-edge file.
"""

from __future__ import annotations

import tempfile
from collections.abc import Callable
from pathlib import Path

from bench_cad import snake
from timing import arguments, compare, machine, write_markdown

from spiral_cad.cad.console import captured_messages
from spiral_cad.cad.continuity import _measure, _report, check_continuity
from spiral_cad.cad.export import export_iges, export_step
from spiral_cad.cad.readers import read_shape
from spiral_cad.cad.sandbox import run_isolated
from spiral_cad.design import Alignment

#: The modules whose code these numbers measure (stamped into the results: ``timing.code_stamp``).
MEASURES = ("spiral_cad.cad.continuity", "spiral_cad.cad.readers", "spiral_cad.cad.sandbox", "spiral_cad.cad.export")


def in_process_check(path: Path) -> None:
    """The peer: OCCT reads in this process, the same measures follow."""
    from OCP.IGESControl import IGESControl_Controller, IGESControl_Reader
    from OCP.STEPControl import STEPControl_Reader

    with captured_messages():  # as ours: OCCT's console chatter captured
        if path.suffix == ".step":
            reader = STEPControl_Reader()
        else:
            IGESControl_Controller.Init_s()
            reader = IGESControl_Reader()
        reader.ReadFile(str(path))
        reader.TransferRoots()
    _report(_measure(reader.OneShape()), "", path.name, 1e-7, 1e-7, 1e-6, None)


def medians(runs: dict[str, Callable[[], object]], repeat: int) -> dict[str, float]:
    """The median of ``repeat`` runs of each, taking them in turn (``timing.compare``)."""
    return {name: timing.median for name, timing in compare(runs, repeat).items()}


def main() -> None:
    args = arguments(__doc__, repeat=(6, 1), edges=(10_000, 200))
    rows = []
    with tempfile.TemporaryDirectory() as folder:
        files = []
        highway = Alignment.from_pis([[0, 0], [600, 120], [1150, -80], [1700, 260], [2300, 200]], [450, 400, 600],
                                     units="m", design_speed=80).chain  # fmt: skip
        big = snake(args.edges)
        for name, chain in (("highway (demo, 13 edges)", highway), (f"snake ({len(big):,} edges)", big)):
            for suffix, write in (("step", export_step), ("igs", export_iges)):
                path = Path(folder) / f"{name.split()[0]}.{suffix}"
                write(chain, path)
                files.append((f"{name} .{suffix}", path))
        empty = medians({"empty": lambda: run_isolated(int, what="nothing", subject="-")}, 20 * args.repeat)["empty"]
        rows.append(("child process round trip (empty task)", "", f"{empty * 1000:.1f} ms", ""))
        for label, path in files:
            repeat = args.repeat if "snake" in label else 20 * args.repeat
            best = medians({"peer": lambda: in_process_check(path), "ours": lambda: check_continuity(path),
                            "shape": lambda: read_shape(path)}, repeat)  # fmt: skip
            peer, ours = best["peer"], best["ours"]
            rows.append((f"check {label}", f"{peer * 1000:,.1f} ms", f"{ours * 1000:,.1f} ms (+{(ours - peer) * 1000:,.1f} ms)",
                         f"{ours / peer:.2f}×"))  # fmt: skip
            rows.append((f"read_shape {label} (whole shape back)", "", f"{best['shape'] * 1000:,.1f} ms", ""))
    header = ("measurement", "peer: OCCT in-process", "ours: child process", "ours / peer")
    width = max(len(r[0]) for r in rows)
    print(f"{header[0]:{width}}  {header[1]:>22}  {header[2]:>28}  {header[3]:>10}")
    for row in rows:
        print(f"{row[0]:{width}}  {row[1]:>22}  {row[2]:>28}  {row[3]:>10}")
    print(machine())
    if args.out:
        write_markdown(args.out, "Checker on files: readers in a child process",
                       f"Medians of {args.repeat} interleaved runs (20× that for the small files); peer and ours in the same run.",
                       header, rows)  # fmt: skip


if __name__ == "__main__":
    main()
