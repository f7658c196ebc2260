"""Point files in and the fit's residuals out: ``read_points`` and ``write_residuals`` on large surveys.

Run: ``.venv/bin/python benchmarks/bench_points.py [--quick] [--rows N] [--rounds N] [--out FILE]``
(the harness and its conventions: ``timing.py``). The file is a generated survey of
``--rows`` points x, y, z (17 significant digits) in three forms: CSV with a header,
whitespace-separated .xyz with a ``# units:`` line and a comment on every 100th line
(the path that strips comments line by line). The peer of each read is ``numpy.loadtxt``
of the same file without any of the checks (header, units, comments, line numbers,
finite values): the floor of the format. ``write_residuals`` writes the report's
one row per point (index, x, y, station, residual at full precision). Goal: 1 000 000 rows
read in ≤ 3 s (the fit's 10 s for a million points includes reading them).
"""

from __future__ import annotations

import tempfile
from pathlib import Path

import numpy as np
from timing import Report, arguments, compare, per_second

from spiral_cad.app.fitreport import write_residuals
from spiral_cad.io.points import read_points

#: The modules whose code these numbers measure (stamped into the results: ``timing.code_stamp``).
MEASURES = ("spiral_cad.io.points", "spiral_cad.app.fitreport")


def survey(rows: int) -> np.ndarray:
    return np.random.default_rng(24).normal(scale=1e4, size=(rows, 3))


def main() -> None:
    args = arguments(__doc__, rows=(1_000_000, 2_000), rounds=(5, 1))
    report = Report("Point files: read_points and write_residuals",
                    f"{args.rows:,} rows x, y, z; medians of {args.rounds} alternating runs.")  # fmt: skip
    points = survey(args.rows)
    with tempfile.TemporaryDirectory() as folder:
        plain = Path(folder) / "survey.csv"
        np.savetxt(plain, points, fmt="%.17g", delimiter=",", header="x,y,z", comments="")
        commented = Path(folder) / "survey.xyz"
        lines = [" ".join(f"{v!r}" for v in row) + (" # checked" if i % 100 == 0 else "") for i, row in enumerate(points.tolist())]
        commented.write_text("# units: m\n" + "\n".join(lines) + "\n", encoding="utf-8")
        for name, path, options in (("CSV, header", plain, {"delimiter": ",", "skiprows": 1}),
                                    ("whitespace, comments", commented, {"comments": "#"})):  # fmt: skip
            times = compare({"ours": lambda p=path: read_points(p),
                             "loadtxt": lambda p=path, o=options: np.loadtxt(p, **o)}, args.rounds)  # fmt: skip
            assert np.array_equal(read_points(path).points, points)
            ratio = times["loadtxt"].median / times["ours"].median
            report.add(f"read_points, {name}", times["ours"].median, "s", times["ours"], "numpy.loadtxt, no checks", ratio,
                       "≤ 3 s at 1 M rows")  # fmt: skip
            report.add(f"read_points, {name}: rate", per_second(args.rows, times["ours"]), "M rows/s")
        out = Path(folder) / "residuals.csv"
        stations, residuals = np.linspace(0.0, 1e6, args.rows), points[:, 2] * 1e-6
        times = compare({"write": lambda: write_residuals(out, points, stations, residuals, "m")}, args.rounds)
        report.add("write_residuals", times["write"].median, "s", times["write"])
        report.add("write_residuals: rate", per_second(args.rows, times["write"]), "M rows/s")
    report.finish(args)


if __name__ == "__main__":
    main()
