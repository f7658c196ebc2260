"""Command line: ``spiral-cad demo | build | check | schema``."""

from __future__ import annotations

import argparse
import logging
import math
import os
import re
import signal
import sys
import time
import warnings
from collections.abc import Callable, Sequence
from functools import partial
from importlib.util import find_spec
from pathlib import Path

from .. import circle_in_circle, circle_to_circle, line_to_circle, line_to_line
from ..core.transitions import Transition
from ..design.tables import fixed_columns
from ..io.signals import signals_handled
from .check_command import add_check
from .cli_shared import MANY_OPTIONS, PIP_CAD, add_many_options, run_on_many
from .many_inputs import escaping_streams, expand_inputs, output_collisions, wants_many
from .many_task import note_worst


def core_examples() -> list[tuple[str, Transition]]:
    """One solved instance of each of the five cases with each spiral shape (the core demo's input)."""
    nl = "near-linear"
    return [
        ("line → circle (Thm 4.1)", line_to_circle((0, 0), (1, 0), (0, 1.05), 1.0)),
        ("circle → circle, C (Thm 4.2)", circle_to_circle((0, 0), 2.0, (5, 1), 1.0)),
        ("circle → circle, S (Thm 4.3)", circle_to_circle((0, 0), -2.0, (5, 1), 1.0)),
        ("line → line (Cor 4.5)", line_to_line((0, 0), (10, 0), (15, 8))),
        ("circle in circle (5th case)", circle_in_circle((0, 0), 1.0, (0, 0.595), 0.4)),
        ("line → circle", line_to_circle((0, 0), (1, 0), (0, 1.01), 1.0, nl)),
        ("circle → circle, C", circle_to_circle((0, 0), 2.0, (2.5, 0.5), 1.0, nl)),
        ("circle → circle, S", circle_to_circle((0, 0), -2.0, (4, 0.5), 1.0, nl)),
        ("line → line", line_to_line((0, 0), (10, 0), (15, 8), shape=nl)),
        ("circle in circle", circle_in_circle((0, 0), 1.0, (0, 0.595), 0.4, nl)),
    ]


def transition_table(rows: Sequence[tuple[str, Transition]]) -> str:
    """Table of the shape, θ, end curvatures and the worst join residuals per transition."""
    columns = [("case", "30"), ("shape", "12"), ("θ°", "9.4f"), ("κ start", "10.5f"), ("κ end", "10.5f"),
               ("gap/len", "9.1e"), ("angle", "9.1e"), ("Δκ·len", "9.1e")]  # fmt: skip
    values = []
    for name, t in rows:
        joins, size = t.joins(), t.length
        values.append((name, t.shape, math.degrees(t.theta), t.spirals[0].start_curvature, t.spirals[-1].end_curvature,
                       max(j.gap for j in joins) / size, max(j.angle for j in joins), max(j.curvature_jump for j in joins) * size))  # fmt: skip
    return "\n".join(fixed_columns(columns, values))


#: The built-in default design of ``spiral-cad demo`` (the JSON format of ``build``).
DEMO_DESIGN: dict = {
    "units": "m",
    "designs": [
        {
            "name": "highway",
            "type": "alignment",
            "pis": [[0, 0], [600, 120], [1150, -80], [1700, 260], [2300, 200]],
            "radii": [450, 400, 600],
            "design_speed": 80,
            "max_jerk": 0.6,
            "start_station": 10000,
            "profile": {"pvis": [[10000, 120], [10700, 132], [11500, 116], [12500, 121]]},
        },
        {
            "name": "circles",
            "type": "circle_chain",
            "circles": [
                {"center": [0, 0], "radius": 60},
                {"center": [29.85, 0], "radius": 30},
                {"center": [150, -10], "radius": 40},
                {"center": [150, 120], "radius": -35},
            ],
        },
        {
            "name": "robot",
            "type": "rounded_polyline",
            "points": [[0, 0], [1.0, 0.1], [1.4, 0.9], [2.4, 1.0], [2.6, 0.2], [3.6, 0.4]],
            "max_curvature": 6.0,
        },
    ],
}


def _write_design(design: dict | str, out: Path, plots: bool, extra: Callable[[Path], None] | None = None,
                  max_offset: float | None = None, directions: str = "auto", prebuilt: Callable[[], tuple] | None = None,
                  allow_splits: bool = True) -> int:  # fmt: skip
    from .designfile import build, criteria_tables, summary, write

    started = time.perf_counter()
    units, built = build(design, max_offset=max_offset, directions=directions) if prebuilt is None else prebuilt()
    print(f"built {len(built)} design(s); writing to {out}/", flush=True)
    try:
        written = write(built, out, units, progress=lambda line: print(line, flush=True), plots=plots, extra=extra)
    except KeyboardInterrupt as interrupt:
        if interrupt.args:
            raise
        raise KeyboardInterrupt(f"nothing in {out}/ was changed") from None
    try:
        print()
        tables = criteria_tables(built)
        if tables:
            print(tables + "\n")
        print(summary(built, units))
        for b in built:  # "G2 (…)": the level the STEP file was checked at (G0: a part of a split path)
            note_worst((getattr(b, "shown_continuity", None) or b.continuity or "").split(" ", 1)[0])
        print(f"\nwrote {len(written.files)} files to {out}/ in {time.perf_counter() - started:.1f} s")
    except KeyboardInterrupt:
        raise KeyboardInterrupt(f"every file had been written to {out}/") from None
    if written.skipped:
        print(f"error: not written: {'; '.join(written.skipped)}. Install the CAD extra: {PIP_CAD}", file=sys.stderr)
        return 2
    split = list(dict.fromkeys(name for b in built for name in getattr(b, "split_at", ())))
    if split:
        print(f"\n{len(split)} split(s) left a kink (G0) where the parts meet:")
        for name in split:
            print(f"  {name}")
        if not allow_splits:
            print("FAIL: the path was split, so it is not G2 where the parts meet (pass --allow-splits to accept the parts)")
            return 1
    return 0


def _demo(args: argparse.Namespace) -> int:
    print("The five transitions of Walton & Meek (1996), one instance each with each spiral shape:\n")
    print(transition_table(core_examples()))
    print()
    return _write_design(DEMO_DESIGN, Path(args.out), plots=not args.no_plots, extra=partial(_demo_extras, plots=not args.no_plots))


def _demo_extras(folder: Path, plots: bool) -> None:
    """The gallery's G2 parts as STEP files (with the CAD extra) and, with ``plots``, the paper's
    Fig. 6 family beside the near-linear one and both spirals against a clothoid, written into
    ``folder`` (what needs a missing extra is reported with the rest)."""
    if find_spec("build123d") is not None:
        from .gallery import write_gallery

        write_gallery(folder)
    if not plots or find_spec("matplotlib") is None:
        return
    from .plots import plot_fig6_shapes, plot_vs_clothoid

    plot_fig6_shapes().savefig(folder / "fig6.png", dpi=110, format="png")
    both = ("walton-meek", "near-linear")
    plot_vs_clothoid(math.radians(8), 1.0, shapes=both).savefig(folder / "bezier_vs_clothoid.png", dpi=110, format="png")


#: ``build`` options that describe a ``--from-gcode`` design (a design file states them per design).
GCODE_OPTIONS = (
    "max_deviation",
    "max_curvature",
    "shape",
    "sample_step",
    "chord_tolerance",
    "name",
    "units",
    "interpreter",
    "arc_tolerance",
    "feed",
)


#: ``build`` options of ``--from-points`` only.
POINTS_OPTIONS = ("tolerance", "closed", "design_speed")
#: ``build`` options of ``--from-gcode`` only (the others it shares with ``--from-points``).
GCODE_ONLY = ("max_deviation", "interpreter", "arc_tolerance", "feed")


def _build(args: argparse.Namespace) -> int:
    suffix = "" if args.design is None else Path(args.design).suffix.lower()
    if suffix in (".dxf", ".xodr") or (suffix == ".xml" and args.max_deviation is not None):
        return _build_g2(args, suffix)
    landxml = [o for o, given in (("--max-offset", args.max_offset is not None), ("--directions", args.directions != "auto")) if given]
    if landxml and (args.design is None or Path(args.design).suffix.lower() != ".xml"):
        raise ValueError(f"{', '.join(landxml)}: only with a LandXML file (.xml)")
    if args.allow_splits:
        raise ValueError("--allow-splits: only with a path made G2 (a DXF drawing, or LandXML/OpenDRIVE with --max-deviation); "
                         "a G-code build splits the path where it folds back by design (for the program made G2 "
                         "in place: spiral-cad g2 PROGRAM)")  # fmt: skip
    if args.from_points is not None:
        return _write_design(points_design(args), Path(args.out), plots=not args.no_plots)
    only = [f"--{o.replace('_', '-')}" for o in POINTS_OPTIONS if getattr(args, o) not in (None, False)]
    if only:
        raise ValueError(f"{', '.join(only)}: only with --from-points")
    if args.from_gcode is None:
        given = [f"--{o.replace('_', '-')}" for o in GCODE_OPTIONS if getattr(args, o) is not None]
        if args.design is None:
            raise ValueError("give a design file, or --from-gcode FILE.nc")
        if given:
            raise ValueError(f"{', '.join(given)}: only with --from-gcode (a design file states these per design)")
        return _write_design(args.design, Path(args.out), plots=not args.no_plots, max_offset=args.max_offset, directions=args.directions)
    if args.design is not None:
        raise ValueError("give a design file or --from-gcode, not both")
    from ..io.gcode import reading_options

    stated = args.units if args.units in ("mm", "in") else None  # the unit of a program that says neither G20 nor G21
    with reading_options(args.interpreter or "builtin", args.arc_tolerance, args.units or "mm", program_units=stated):
        return _write_design(gcode_design(args), Path(args.out), plots=not args.no_plots)


#: ``build`` options a DXF drawing or an alignment file made G2 takes (the rest are refused by name).
G2_OPTIONS = ("max_deviation", "units", "shape", "name")


def _build_g2(args: argparse.Namespace, suffix: str) -> int:
    """``build FILE.dxf|.xml|.xodr --max-deviation D``: lines and arcs made G2 (``g2_build``)."""
    from .g2_build import g2_designs

    if suffix == ".xodr" and args.max_deviation is None:
        raise ValueError("an OpenDRIVE file is built with --max-deviation D (its lines and arcs made G2 within D); "
                         "check it with spiral-cad check")  # fmt: skip
    deviation = args.max_deviation
    if deviation is None:
        raise ValueError(
            f"{Path(args.design).name}: give --max-deviation (the largest distance between the drawing's path and the G2 path)"
        )
    if not 0.0 < deviation < math.inf:
        raise ValueError(f"--max-deviation must be a positive finite number; got {deviation}")
    others = [
        f"--{o.replace('_', '-')}"
        for o in (*GCODE_OPTIONS, *POINTS_OPTIONS)
        if o not in G2_OPTIONS and getattr(args, o) not in (None, False)
    ]
    others += [o for o, given in (("--from-gcode", args.from_gcode), ("--from-points", args.from_points),
                                  ("--max-offset", args.max_offset is not None), ("--directions", args.directions != "auto")) if given]  # fmt: skip
    if others:
        raise ValueError(f"{', '.join(others)}: not with a {'DXF drawing' if suffix == '.dxf' else 'road file made G2'}")
    if args.shape == "g2cbs":
        raise ValueError("--shape g2cbs rounds corners; make_g2's spirals are near-linear (default) or walton-meek")
    # the file's own unit unless --units is given (a DXF drawing is converted, a unitless one read in it)
    return _write_design(
        {},
        Path(args.out),
        plots=not args.no_plots,
        prebuilt=lambda: g2_designs(
            args.design, deviation, name=args.name, units=args.units, source_units=args.units, shape=args.shape or "near-linear"
        ),
        allow_splits=args.allow_splits,
    )


def _check_numbers(args: argparse.Namespace, keys: tuple[str, ...]) -> None:
    """Refuse a non-positive or infinite number among ``keys``, and samples given two ways."""
    if args.sample_step is not None and args.chord_tolerance is not None:
        raise ValueError("give --sample-step or --chord-tolerance, not both")
    for key in keys:
        value = getattr(args, key)
        if value is not None and not 0.0 < value < math.inf:
            raise ValueError(f"--{key.replace('_', '-')} must be a positive finite number; got {value}")


def gcode_design(args: argparse.Namespace) -> dict:
    """The design of ``build --from-gcode``: one ``rounded_polyline`` of the program's moves, with samples."""
    if args.max_deviation is None and args.max_curvature is None:
        raise ValueError("--from-gcode needs --max-deviation (the tolerance at every corner) and/or --max-curvature")
    _check_numbers(args, ("max_deviation", "max_curvature", "sample_step", "chord_tolerance", "feed"))
    stem = re.sub(r"[^A-Za-z0-9_-]", "_", Path(args.from_gcode).stem).lstrip("_-")[:64] or "toolpath"
    design = {"name": args.name or stem, "type": "rounded_polyline", "gcode": args.from_gcode, "spiral_shape": args.shape or "walton-meek"}
    for key in ("max_deviation", "max_curvature"):
        if getattr(args, key) is not None:
            design[key] = getattr(args, key)
    if args.sample_step is not None:
        design["samples"] = {"step": args.sample_step}
    else:
        default = (args.max_deviation / 10.0 or args.max_deviation) if args.max_deviation is not None else 0.001
        design["samples"] = {"chord_tolerance": args.chord_tolerance if args.chord_tolerance is not None else default}
    if args.feed is not None:  # else the program's own feed
        design["gcode_out"] = {"feed": args.feed}
    return {"units": args.units or "mm", "designs": [design]}


def points_design(args: argparse.Namespace) -> dict:
    """The design of ``build --from-points``: one ``fit`` design of the file's points, the path within
    ``--tolerance`` of every point (a road alignment with ``--design-speed``)."""
    if args.design is not None or args.from_gcode is not None:
        raise ValueError("give --from-points, a design file or --from-gcode, one of them")
    given = [f"--{o.replace('_', '-')}" for o in GCODE_ONLY if getattr(args, o) is not None]
    if given:
        raise ValueError(f"{', '.join(given)}: only with --from-gcode")
    if args.tolerance is None:
        raise ValueError("--from-points needs --tolerance (the largest distance from any point to the fitted path)")
    _check_numbers(args, ("tolerance", "max_curvature", "design_speed", "sample_step", "chord_tolerance"))
    if args.shape == "g2cbs":
        raise ValueError("--shape g2cbs rounds corners; a fit's spirals are near-linear or walton-meek")
    stem = re.sub(r"[^A-Za-z0-9_-]", "_", Path(args.from_points).stem).lstrip("_-")[:64] or "points"
    design = {"name": args.name or stem, "type": "fit", "points_file": args.from_points, "tolerance": args.tolerance,
              "closed": args.closed, "spiral_shape": args.shape or "near-linear"}  # fmt: skip
    for key in ("max_curvature", "design_speed"):
        if getattr(args, key) is not None:
            design[key] = getattr(args, key)
    if args.sample_step is not None or args.chord_tolerance is not None:
        design["samples"] = {"step": args.sample_step} if args.sample_step is not None else {"chord_tolerance": args.chord_tolerance}
    return {"units": args.units or "mm", "designs": [design]}


#: Exit status when the output pipe closes early (``| head -1``): 128 + SIGPIPE, what a
#: shell reports for a command a closed pipe stopped (a build then changes nothing).
CLOSED_PIPE = 141


def _build_inputs(args: argparse.Namespace) -> int:
    """``spiral-cad build``: one design or program as ever, or many on dask, each into OUT/ its name.

    Many programs or point files come as a folder or pattern after ``--from-gcode``/``--from-points``,
    or as the shell expands one (the first after the option, the others where a design file goes).
    """
    from ..io.gcode import SUFFIXES as GCODE_SUFFIXES

    if args.g2 is not None:  # the old name of the bound, kept for one release
        if args.max_deviation is not None:
            raise ValueError("give --max-deviation only (--g2 is its old name, the same bound)")
        print("warning: --g2 is deprecated and will be removed: the same bound is --max-deviation D", file=sys.stderr)
        args.max_deviation, args.g2 = args.g2, None
    designs: list[str] = args.design
    field, inputs = "design", designs
    suffixes: tuple[str, ...] = (".json", ".xml", ".dxf", ".xodr")
    for option, kinds in (("from_gcode", GCODE_SUFFIXES), ("from_points", (".csv", ".txt", ".xyz"))):
        if designs and args.from_gcode is None and args.from_points is None and all(Path(d).suffix.lower() in kinds for d in designs):
            setattr(args, option, designs[0])  # the kind from the suffix: build part.nc is build --from-gcode part.nc
            designs = designs[1:]
        first = getattr(args, option)
        if first is not None:
            expanded = bool(designs) and all(Path(d).suffix.lower() in kinds for d in designs)
            field, inputs, suffixes = option, [first, *designs] if expanded else [first], kinds
    if not wants_many(inputs, suffixes) and all(getattr(args, o) is None for o in MANY_OPTIONS):
        args.design = designs[0] if designs else None
        return _build(args)
    if field != "design" and inputs == [getattr(args, field)] and designs:
        raise ValueError(f"give design files or --{field.replace('_', '-')}, not both")
    files = expand_inputs(inputs, suffixes)
    where = os.path.abspath if args.scheduler else str
    top = os.path.commonpath([os.path.dirname(os.path.abspath(f)) for f in files])
    outs = [Path(args.out) / Path(os.path.relpath(os.path.abspath(f), top)).with_suffix("") for f in files]
    output_collisions(files, outs)  # before anything runs
    changes = [{"design": None, field: where(f), "out": where(str(out))} for f, out in zip(files, outs)]
    return run_on_many(args, _build, files, changes, "built")


def _add_g2(sub: argparse._SubParsersAction) -> None:
    g2 = sub.add_parser(
        "g2",
        help="a document made G2 in place: the same document back (a CNC program: same lines, runs of cuts G2)",
        description="Make a document G2 in place within --max-deviation: one file in, one file out, kind by suffix "
        "(G-code .nc .ngc .gcode .tap, DXF .dxf, LandXML .xml, OpenDRIVE .xodr, STEP .step .stp, IGES .igs .iges). A CNC program keeps every line that is not a cutting "
        "move as it is (rapids, plunges, retracts, tool, spindle, coolant, dwells, stops, probes, comments); each run of "
        "G1/G2/G3 cuts in XY at one Z and one feed is made G2 (make_g2: arcs kept), its first and last points and its "
        "feed kept. A run that cannot be made G2 within the bound is kept as it is and named in the report. A DXF "
        "drawing's paths of lines and arcs (and the splines and ellipses in them, read as biarcs within 0.3 of the bound) "
        "are written back as LINE, ARC and exact SPLINE pieces on their own layers, every other entity kept; a LandXML file's alignments of lines and arcs get spirals, stations recomputed, the rest kept; "
        "an OpenDRIVE file's roads of lines and arcs get spirals (paramPoly3), their ends fixed, their length and every s position "
        "along them (lanes, elevation, objects, signals) carried to the new reference line, the rest kept; a STEP or IGES file's wires that are not G2 get spirals (lines and arcs kept), its solids, faces, names, colours and layers kept.",
    )
    g2.add_argument("input", help="the document (.nc .ngc .gcode .tap, .dxf, .xml, .xodr, .step .stp, .igs .iges)")
    g2.add_argument("-o", "--output", required=True, help="the output document (same kind)")
    g2.add_argument("--max-deviation", type=float, required=True, metavar="D",
                    help="the largest distance between the input's path and the output's, in the document's unit (G20/G21; OpenDRIVE: m; STEP/IGES: the file's)")  # fmt: skip
    g2.add_argument("--dialect", choices=["linuxcnc", "generic"],
                    help="G-code: linuxcnc (transitions as G5 cubics, exact; default) or generic (biarcs G2/G3: grbl, Klipper)")  # fmt: skip
    g2.add_argument("--units", choices=["mm", "cm", "m", "in", "ft"],
                    help="G-code (mm or in): the unit of a program that says neither G20 nor G21; DXF: the unit of "
                         "--max-deviation (default the drawing's $INSUNITS; a unitless drawing: drawing units)")  # fmt: skip
    g2.add_argument("--allow-splits", action="store_true",
                    help="exit 0 even when something was left below G2 (a run or path split, or kept as it is for the "
                         "reason the report names); without it such a document is still written, and the command exits 1")  # fmt: skip
    g2.set_defaults(run=_g2)


def _g2(args: argparse.Namespace) -> int:
    from .g2_document import make_document_g2

    options: dict[str, object] = {}  # only what was given: each kind takes its own options
    if args.dialect:
        options["dialect"] = args.dialect
    if args.units:
        options["units"] = args.units
    report = make_document_g2(args.input, args.output, args.max_deviation, **options)
    for line in report.lines():
        print(line)
    print(f"wrote {args.output}")
    if report.below_g2 and not args.allow_splits:
        print(f"FAIL: {len(report.below_g2)} left below G2 (named above); pass --allow-splits to accept them")
        return 1
    return 0


def _schema(args: argparse.Namespace) -> int:
    """``spiral-cad schema``: the JSON Schema of design files, the one description of the format."""
    from .schema import schema_text

    print(schema_text())
    return 0


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="spiral-cad",
        description="Exact G2 (curvature-continuous) cubic Bézier spiral transitions for CAD.",
        epilog=(
            "examples:\n"
            "  spiral-cad demo --out out                  the built-in design: STEP, IGES, DXF, SVG, plots, CSV\n"
            "  spiral-cad build examples/design.json      your own design file (spiral-cad schema prints the format)\n"
            "  spiral-cad build --from-gcode part.nc --max-deviation 0.01   a CNC program rounded G2: STEP and samples\n"
            "  spiral-cad build --from-points survey.csv --tolerance 0.05 --units m   lines, arcs and spirals within 5 cm\n"
            "  spiral-cad g2 part.nc --max-deviation 0.01 -o part_g2.nc   the same program back, its cuts made G2\n"
            "  spiral-cad check out/highway.step --require G2   G0/G1/G2 at every joint; exit 1 below G2\n"
            "  spiral-cad check out/highway.xodr --require G2 --profiles C1 --links G1   every road, profile and link of an OpenDRIVE map"
        ),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    sub = parser.add_subparsers(dest="command", required=True)
    demo = sub.add_parser(
        "demo",
        help="build the built-in design (highway alignment, circle chain, rounded robot path) and write every output",
    )
    demo.add_argument("--out", default="out", help="output folder (default: out)")
    demo.add_argument("--no-plots", action="store_true", help="skip the PNG plots (the slowest output for long chains)")
    demo.set_defaults(run=_demo)
    build = sub.add_parser(
        "build",
        help="build a JSON design file and write STEP, IGES, DXF, SVG, plots, tables and a continuity report",
        description="Build a JSON design file (spiral-cad schema prints its JSON Schema, the format's reference) or a G-code program.",
    )
    build.add_argument(
        "design",
        nargs="*",
        help="the design file (.json), a LandXML file (.xml: every alignment), a DXF drawing (.dxf: its "
        "lines and arcs chained into paths, made G2 within --max-deviation; --units for a unitless drawing) or an OpenDRIVE "
        "file (.xodr, with --max-deviation), a CNC program (.nc .ngc .gcode .tap: as --from-gcode) or points (.csv .txt .xyz: as --from-points); "
        "several files, folders or glob patterns are built in parallel, each into OUT/ its name (see --workers)",
    )
    build.add_argument("-o", "--out", default="out", help="output folder (default: out)")
    build.add_argument("--no-plots", action="store_true", help="skip the PNG plots (the slowest output for long chains)")
    build.add_argument("--max-offset", type=float, metavar="LENGTH",
                       help="LandXML: the largest offset accepted between a file's element and ours, in the file's unit "
                            "(default: 5%% of each element's length; inf accepts any)")  # fmt: skip
    build.add_argument("--g2", type=float, metavar="D", help="deprecated: the old name of --max-deviation")
    build.add_argument("--allow-splits", action="store_true",
                       help="DXF, LandXML, OpenDRIVE (made G2): accept a path split into G2 parts (at a reversal or a corner "
                            "too sharp; G0 where the parts meet) and exit 0; without it such a build exits 1")  # fmt: skip
    build.add_argument("--directions", choices=["auto", "east-ccw", "north-cw"], default="auto",
                       help="LandXML: how the file counts directions: counter-clockwise from east or clockwise from north "
                            "(default auto: told from the file's own points)")  # fmt: skip
    gcode = build.add_argument_group(
        "G-code", "make a CNC program's path G2 and write STEP, IGES, DXF, samples, the continuity report and NAME.ngc,\n"
        "the G2 program at the program's feed (never over the input). Lines stay lines and arcs (G2/G3, any plane)\n"
        "true arcs; the path is split where it folds straight back (a plunge and its retract): one design NAME_1,\n"
        "NAME_2, ... per G2 path. A program with G5 splines is read as the exact path it states; other codes are\n"
        "refused by name and line (the G-code subset: docs/tutorials/paths.md, G-code in)")  # fmt: skip
    gcode.add_argument("--from-gcode", metavar="FILE.nc", help="the program to round (instead of a design file)")
    gcode.add_argument("--max-deviation", type=float, metavar="D",
                       help="the largest distance between the input's path and the G2 path, in its unit: a program's (at "
                            "corners and tangent joints), a DXF drawing's, or a LandXML or OpenDRIVE file's alignments of "
                            "lines and arcs (made G2: arcs kept true arcs, spirals between; one design per alignment or road)")  # fmt: skip
    gcode.add_argument("--max-curvature", type=float, help="the curvature bound (1/unit)")
    gcode.add_argument("--shape", choices=["walton-meek", "near-linear", "g2cbs"],
                       help="spiral shape (default near-linear for a drawing, a road file and --from-points; walton-meek for "
                            "--from-gcode, whose corners may turn further than near-linear pairs reach, 100°)")  # fmt: skip
    gcode.add_argument("--sample-step", type=float, help="samples at most this far apart along the path")
    gcode.add_argument("--chord-tolerance", type=float,
                       help="samples close enough that the path strays at most this far from their chords "
                            "(default: a tenth of --max-deviation, else 0.001)")  # fmt: skip
    gcode.add_argument("--units", choices=["mm", "cm", "m", "km", "in", "ft"],
                       help="the unit of the outputs and of every length above (default mm; the program's G20/G21 is converted); "
                            "mm or in also states the unit of a program that says neither G20 nor G21 (refused otherwise)")  # fmt: skip
    gcode.add_argument("--name", help="the design's name (default: the program's file name)")
    gcode.add_argument("--feed", type=float,
                       help="the F word of the rounded program NAME.ngc, in its unit per minute (default: the program's "
                            "own F, the lowest if it has several)")  # fmt: skip
    gcode.add_argument(
        "--interpreter",
        choices=["builtin", "rs274"],
        help="builtin (default: straight moves and arcs, no parameters) or rs274 (LinuxCNC's own, full NGC; "
        "Debian package linuxcnc-uspace)",
    )
    gcode.add_argument(
        "--arc-tolerance", type=float,
        help="helical arcs (G2/G3 that also move along the plane's normal) become chords at most this far from them "
             "(default a tenth of --max-deviation; the rest is the G2 path's); plane arcs stay arcs",
    )  # fmt: skip
    fit = build.add_argument_group(
        "points", "fit lines, arcs and spirals G2 to measured or digitised points, every point within --tolerance; also\n"
        "writes NAME_residuals.csv and NAME_fit.png (--units, --name, --max-curvature, the samples as above; --shape\n"
        "near-linear by default)")  # fmt: skip
    fit.add_argument("--from-points", metavar="FILE.csv",
                     help="columns x, y (CSV or whitespace; header optional; '# units: m' states the file's unit, "
                          "else --units)")  # fmt: skip
    fit.add_argument("--tolerance", type=float, help="the largest distance from any point to the fitted path")
    fit.add_argument("--closed", action="store_true", help="the points go round a closed path (G2 at the closing joint)")
    fit.add_argument(
        "--design-speed",
        type=float,
        help="fit a road alignment and judge its curves at this speed (km/h; mph in ft); a file with z is a road anyway (plan and profile)",
    )
    add_many_options(build)
    build.set_defaults(run=_build_inputs)
    add_check(sub)
    _add_g2(sub)
    schema = sub.add_parser("schema", help="print the JSON Schema of design files (the format of build)")
    schema.set_defaults(run=_schema)
    return parser


def _interrupted(received: list[int], detail: str) -> int:
    """The one line and the exit status of a command stopped by a signal: 130 Ctrl-C, 143 SIGTERM."""
    number = received[0] if received else int(signal.SIGINT)  # also a KeyboardInterrupt raised without a signal
    what = "terminated" if number == signal.SIGTERM else "interrupted"
    print(f"error: {what}{f'; {detail}' if detail else ''}", file=sys.stderr)
    return 128 + number


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; returns the exit status (0 ok, 1 check failed, 2 error, 130 interrupted,
    141 output pipe closed early).

    Every error is printed as one ``error: …`` line on stderr, never as a
    traceback; Ctrl-C at any moment gives ``error: interrupted`` and 130, SIGTERM
    ``error: terminated`` and 143 (nothing committed after the signal);
    Python warnings and libraries' log messages are not shown (what matters is an error or in the report:
    ezdxf's "non-unique entity handle" is in the report as its audit's finding).
    """
    logging.getLogger("ezdxf").setLevel(logging.CRITICAL)
    escaping_streams()  # a file name of any bytes is printed, escaped, never an encoding error
    with signals_handled(("SIGINT", "SIGTERM"), interrupt=True) as interrupted, warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            args = _parser().parse_args(argv)
            status = args.run(args)
            sys.stdout.flush()
            if interrupted:  # its KeyboardInterrupt was swallowed (raised in a __del__): still stopped
                return _interrupted(interrupted, "")
            return status
        except BrokenPipeError:
            try:  # the interpreter's last flush must not fail again
                os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
            except (OSError, ValueError, AttributeError):
                pass
            return CLOSED_PIPE
        except KeyboardInterrupt as interrupt:
            return _interrupted(interrupted, str(interrupt))
        except Exception as error:
            if interrupted:  # Ctrl-C, wrapped by a library into another exception
                return _interrupted(interrupted, "")
            if isinstance(error, (ValueError, OSError)):  # DesignError, NoSolutionError, file system errors
                print(f"error: {error}", file=sys.stderr)
            else:  # a bug: still no traceback, but say so
                print(f"error: internal error ({type(error).__name__}: {error}); please report it", file=sys.stderr)
            return 2


if __name__ == "__main__":
    sys.exit(main())
