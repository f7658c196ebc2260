"""``spiral-cad check``: G0/G1/G2 at every joint of a STEP, IGES, DXF, OpenDRIVE, LandXML, IFC or G-code file, face to
face where a STEP/IGES file holds faces; one file, or many at once on dask."""

from __future__ import annotations

import argparse
import math
import os
import sys
from importlib.util import find_spec
from pathlib import Path

from ..continuity.joints import Continuity, ContinuityReport
from ..io.gcode import SUFFIXES as GCODE_SUFFIXES
from ..io.opendrive_check import PROFILE_LEVELS, OpenDriveReport
from .cli_shared import MANY_OPTIONS, PIP_CAD, add_many_options, run_on_many, summary_only
from .files import CHECKS
from .many_inputs import expand_inputs, wants_many
from .many_task import note_worst

__all__ = ["CHECK_SUFFIXES", "add_check", "check_file", "check_inputs"]


def check_file(args: argparse.Namespace) -> int:
    """``spiral-cad check`` of one file: 0 ok, 1 below ``--require``, 2 error.

    (Non-finite measures are graded "unmeasurable" on purpose; ``main`` keeps
    numpy's warnings about them off the terminal.)
    """
    suffix = Path(args.file).suffix.lower()
    if suffix not in CHECK_SUFFIXES and Path(args.file).exists():
        raise ValueError(f"{Path(args.file).name}: check judges STEP/IGES (.step .stp .igs .iges), DXF (.dxf), OpenDRIVE (.xodr), "
                         f"LandXML (.xml), IFC 4.3 (.ifc) and G-code ({' '.join(GCODE_SUFFIXES)}) files")  # fmt: skip
    if args.html is not None:
        from .html_report import checked_page_path

        checked_page_path(args.html, args.file)  # refused before the file is read
    if suffix == ".xodr":
        _wire_tolerances(args)
        if args.comb:
            print("error: --comb draws STEP/IGES edges; it does not apply to OpenDRIVE", file=sys.stderr)
            return 2
        from ..io.opendrive import check_opendrive

        report = check_opendrive(args.file, gap_tol=args.gap_tol, angle_tol=args.angle_tol, curvature_tol=args.curvature_tol)
        return _print_opendrive_report(report, args)
    for option in ("profiles", "links"):
        if getattr(args, option):
            print(f"error: --{option} judges OpenDRIVE files (.xodr) only", file=sys.stderr)
            return 2
    if find_spec("OCP") is None:
        print(f"error: spiral-cad check reads STEP/IGES with OCCT, which comes with the CAD extra: {PIP_CAD}", file=sys.stderr)
        return 2
    picture = _picture_options(args)  # refused before anything is read
    if args.units and suffix == ".xml":
        print("error: --units: a LandXML file states its unit in <Units> (one without is read in metres, as LandXML "
              "readers do)", file=sys.stderr)  # fmt: skip
        return 2
    if args.units and suffix == ".ifc":
        print("error: --units: an IFC file states its unit (IfcUnitAssignment)", file=sys.stderr)
        return 2
    if args.units and suffix not in _DOCUMENTS:
        print(f"error: --units is the unit of a program or drawing that states none; {Path(args.file).name} is neither",
              file=sys.stderr)  # fmt: skip
        return 2
    if suffix in _DOCUMENTS:
        if args.zebra or args.curvature_map or args.stripes is not None:
            print(f"error: --zebra, --curvature-map and --stripes draw faces; {_DOCUMENTS[suffix]} holds curves", file=sys.stderr)
            return 2
        if suffix not in (".xml", ".ifc"):  # a LandXML or IFC file's default tolerances come from its own numbers
            _wire_tolerances(args)
        return _check_document(args)
    from ..cad.faces import holds_faces

    if holds_faces(args.file):
        from .faces_check import check_face_file

        status = check_face_file(args.file, require=args.require, gap_tol=args.gap_tol, angle_tol=args.angle_tol,
                                 curvature_tol=args.curvature_tol, feature_angle=args.feature_angle, zebra=args.zebra,
                                 curvature_map=args.curvature_map, html=args.html, timing=args.timing, picture=picture,
                                 quiet=args.quiet)  # fmt: skip
        if status is not None:  # None: the reader found no faces after all, so the wires are judged
            if args.comb:  # the comb of every edge of the part, in mm as build123d and FreeCAD read
                from ..cad.continuity import curvature_comb
                from ..cad.export import export_step

                export_step(curvature_comb(args.file, units="mm"), _comb_path(args.comb, args.file),
                            name=f"{Path(args.file).name} curvature comb", units="mm")  # fmt: skip
            return status
    elif args.zebra or args.curvature_map:
        print(f"error: --zebra and --curvature-map draw faces; {Path(args.file).name!r} holds none", file=sys.stderr)
        return 2
    _wire_tolerances(args)
    return _check_shape_file(args)


def _wire_tolerances(args: argparse.Namespace) -> None:
    """The wire checks' default tolerances where none was given (the face check has its own)."""
    for name, default in (("gap_tol", 1e-7), ("angle_tol", 1e-7), ("curvature_tol", 1e-6)):
        if getattr(args, name, None) is None:
            setattr(args, name, default)


def _check_shape_file(args: argparse.Namespace) -> int:
    """Run ``spiral-cad check`` on a STEP/IGES file: the joint table; exit 0 ok, 1 below
    ``--require`` or the wrong number of pieces, 2 unreadable (``error: …`` with the reason).

    The table is ``check_continuity(file).format_table()``, as in the demo's
    ``NAME_continuity.txt``: the same numbers for the same file.
    """
    from ..cad.continuity import check_continuity, curvature_comb  # import OCP, so only when used
    from ..cad.export import export_step

    comb = _comb_path(args.comb, args.file) if args.comb else None
    report = check_continuity(args.file, gap_tol=args.gap_tol, angle_tol=args.angle_tol, curvature_tol=args.curvature_tol,
                              snap=args.snap)  # fmt: skip
    if not report.wires:
        raise ValueError(f"{report.source!r} contains no edges to check")
    if comb is not None:
        comb_shape = curvature_comb(args.file, units=report.units)  # in the unit the report is in
        export_step(comb_shape, comb, name=f"{report.source} curvature comb", units=report.units)
    _write_page(args, report)
    return _print_report(report, args)


def _write_page(args: argparse.Namespace, report: ContinuityReport) -> None:
    """``--html``: the curves' page (``spiral_cad.app.html_report``), read in the report's unit."""
    if args.html is None:
        return
    from .html_report import write_html_report

    view = _picture_options(args).get("view")  # checked before the file was read
    write_html_report(report, args.file, args.html, units=report.units or args.units, view=view,
                      **({"stripes": args.stripes} if args.stripes is not None else {}))  # fmt: skip
    print(f"web page written to {args.html}")


def _check_document(args: argparse.Namespace) -> int:
    """``spiral-cad check`` of a DXF drawing (its curves as drawn), a CNC program (its cutting paths) or a
    LandXML file (its alignments), joint by joint as a STEP file's wires (``spiral_cad.check``); the same
    exit statuses."""
    from ..cad.dxf_shape import DRAWING_UNITS
    from .files import check

    name, suffix = Path(args.file).name, Path(args.file).suffix.lower()
    if args.comb and suffix in (".xml", ".ifc"):
        raise ValueError(f"--comb draws the curves of STEP, IGES, DXF and G-code files; {_DOCUMENTS[suffix]} is judged on its numbers")
    given = {k: v for k in ("gap_tol", "angle_tol", "curvature_tol", "snap", "units") if (v := getattr(args, k)) is not None}
    report = check(args.file, **given)
    for note in [] if args.quiet else report.notes:
        print(f"note: {note}")
    if args.comb:
        from ..cad.continuity import curvature_comb
        from ..cad.document_shapes import document_shape
        from ..cad.export import export_step

        shape, units, _ = document_shape(args.file, units=args.units)
        if units == DRAWING_UNITS:
            raise ValueError(f"--comb: {name} states no unit ($INSUNITS), and a STEP file needs one")
        export_step(curvature_comb(shape, units=units), _comb_path(args.comb, args.file), name=f"{name} curvature comb", units=units)
    _write_page(args, report)
    if suffix == ".ifc":  # no rewrite in place: the alignment is designed again
        if args.pieces is None:  # its pieces are its alignments' plans and profiles, however many: as OpenDRIVE's roads
            args.pieces = report.pieces
        return _print_report(report, args, "make_g2: an alignment of lines and arcs becomes G2 with spirals between them: "
                                           "Alignment.from_pis, then spiral_cad.export(alignment, 'road.ifc')")  # fmt: skip
    done = {".dxf": "makes its paths of lines and arcs G2, every other entity kept",
            ".xml": "gives its alignments of lines and arcs spirals, the rest kept"}.get(suffix, "makes its runs of cuts G2 in place, every other line kept")  # fmt: skip
    return _print_report(report, args, f"make_g2: spiral-cad g2 {name} -o OUT{suffix} --max-deviation D {done}")


def _advice_lines(file: str, units: str) -> list[str]:
    from ..cad.g2wire import g2_advice
    from ..cad.readers import read_shape

    return g2_advice(read_shape(file, units=units or None), units or "mm")


def _print_g2_advice(file: str, units: str) -> None:
    """For a file below G2: the smallest max_deviation with which make_g2 makes each wire of lines and arcs G2.

    Worked out in a child process under the readers' time limit (``cad.sandbox``): a polyline of
    thousands of corners is stopped, not left holding the command or its worker.
    """
    from ..cad.sandbox import run_isolated

    try:
        lines = run_isolated(_advice_lines, file, units, what="make_g2's advice", subject=file)
    except ValueError as error:  # the check read the curves its own way; no advice must not fail it
        print(f"make_g2: no advice: {error}")
        return
    for line in lines:
        print(line)


def _comb_path(comb: str, checked: str) -> Path:
    """The ``--comb`` file: a .step/.stp path that is not the file being checked (by any name)."""
    path = Path(comb)
    if path.suffix.lower() not in (".step", ".stp"):
        raise ValueError(f"--comb {comb!r}: the comb is written as STEP; give a .step or .stp file")
    if path.is_dir():
        raise ValueError(f"--comb {comb!r} is a folder; give a .step or .stp file")
    if path.exists() and Path(checked).exists() and os.path.samefile(path, checked):
        raise ValueError(f"--comb {comb!r} is the file being checked; give another file")
    return path


def _print_report(report: ContinuityReport, args: argparse.Namespace, advice: str | None = None) -> int:
    """Print ``report`` for ``spiral-cad check``; exit status 0 ok, 1 below ``--require`` or not ``--pieces`` pieces.
    Below G2, ``advice`` is printed (default: make_g2's bound for each wire of the STEP/IGES file)."""
    print(summary_only(report.format_table(), args.quiet))
    note_worst(str(report.min_level))
    if getattr(args, "timing", False) and report.timing is not None and not args.quiet:
        print(report.timing_line())
    if report.min_level < Continuity.G2 and not args.quiet:  # before the verdict, which stays the last line
        if advice is None:
            _print_g2_advice(args.file, report.units)
        else:
            print(advice)
    if not args.require:
        return 0
    expected = 1 if args.pieces is None else args.pieces
    if report.pieces != expected:
        hint = "" if args.pieces is not None else " (pass --pieces N if the file holds N separate paths)"
        print(f"FAIL: {report.describe()}: {report.pieces} separate pieces, expected {expected}{hint}")
        return 1
    if not report.passes(args.require, expected):
        why = " (a measure that decides it is not a finite number)" if report.min_level is Continuity.UNMEASURABLE else ""
        print(f"FAIL: worst joint is {report.min_level}{why}, below the required {args.require}")
        return 1
    print(f"OK: {report.describe()}, every joint at least {args.require}")
    return 0


def _print_opendrive_report(report: OpenDriveReport, args: argparse.Namespace) -> int:
    """Print ``report`` for ``spiral-cad check``: exit 1 when a road's planView is below ``--require``,
    an elevation or superelevation below ``--profiles``, a link below ``--links``, or the file does
    not hold ``--pieces`` roads; else 0."""
    print(summary_only(report.format_table(), args.quiet))
    note_worst(str(report.min_level))
    failures = []
    if args.pieces is not None and report.pieces != args.pieces:
        failures.append(f"{report.pieces} roads, expected {args.pieces}")
    if args.require and not report.passes(args.require):
        why = " (a measure that decides it is not a finite number)" if report.min_level is Continuity.UNMEASURABLE else ""
        failures.append(f"worst joint is {report.min_level}{why}, below the required {args.require}")
    profiles = getattr(args, "profiles", None)
    if profiles and PROFILE_LEVELS.index(report.profile_level) < PROFILE_LEVELS.index(profiles):
        failures.append(f"worst elevation/superelevation is {report.profile_level}, below the required {profiles}")
    links = getattr(args, "links", None)
    if links and not report.link_level >= Continuity.parse(links):
        failures.append(f"worst link is {report.link_level}, below the required {links}")
    if failures:
        print(f"FAIL: {'; '.join(failures)} ({report.describe()})")
        return 1
    demands = [f"every planView joint at least {args.require}"] if args.require else []
    demands += [f"every profile at least {profiles}"] if profiles else []
    demands += [f"every link at least {links}"] if links else []
    print(f"OK: {report.describe()}" + (f", {', '.join(demands)}" if demands else ""))
    return 0


def add_check(sub: argparse._SubParsersAction) -> None:
    """The ``check`` command and its options."""
    check = sub.add_parser(
        "check",
        help="report G0/G1/G2 continuity at every joint of a STEP, IGES, DXF, OpenDRIVE, LandXML, IFC or G-code file",
        description="Report G0/G1/G2 continuity at every joint, in the unit the file declares; a STEP/IGES file that holds "
        "faces is judged face to face at every edge they share (sharp features listed, not failed). A DXF drawing's curves "
        "(lines, arcs, circles, ellipses, splines, polylines, blocks) are judged as drawn, chained by their ends. A LandXML file's alignments are judged as "
        "stated: each element's ends, directions and radii, so a kink or a radius that differs from its neighbour's shows. A CNC program's cutting paths are judged "
        "run by run between rapids (helical moves left out). An IFC 4.3 file's alignments are judged plan and profile, as ifcopenshell evaluates "
        "their curves' segments (a profile without its gradient curve on its vertical segments' own numbers). An OpenDRIVE file is judged road by road (its planView, its elevation and superelevation in s) and link by link. Exit status: 0 ok, "
        "1 below --require, --profiles or --links (or not --pieces pieces), 2 unreadable file or bad option, "
        "141 output pipe closed early.",
    )
    check.add_argument("file", nargs="+", help="a .step/.stp, .igs/.iges, .dxf, .xodr (one piece per road), .xml (LandXML), .ifc or G-code (.nc .ngc .tap …) file; several "
                       "files, folders or glob patterns are checked in parallel (see --workers)")  # fmt: skip
    check.add_argument(
        "--require", choices=["G0", "G1", "G2"],
        help="exit 1 if any joint (OpenDRIVE: of any road's planView) is below this level or the file is not in --pieces pieces",
    )  # fmt: skip
    check.add_argument("--pieces", type=int,
                       help="how many separate paths the file should hold (default 1 with --require; OpenDRIVE: roads, "
                            "judged only when given)")  # fmt: skip
    check.add_argument("--profiles", choices=["C0", "C1", "C2"],
                       help="OpenDRIVE: exit 1 if any road's elevation or superelevation is below this continuity in s")  # fmt: skip
    check.add_argument("--links", choices=["G0", "G1", "G2"],
                       help="OpenDRIVE: exit 1 if any link between roads is below this level (junction connections lane centre to "
                       "lane centre, as a driver follows them; road links reference line to reference line)")  # fmt: skip
    check.add_argument("--snap", type=float, help="chain loose ends closer than this (model units; default 1%% of the model size)")
    check.add_argument("--comb", metavar="OUT.step",
                       help="also write the curvature comb of every edge as STEP (STEP, IGES, DXF or G-code input; never the checked file)")  # fmt: skip
    check.add_argument("--units", choices=["mm", "cm", "m", "km", "in", "ft"],
                       help="the unit of a G-code program that says neither G20 nor G21 (mm or in), or of a DXF drawing "
                            "without $INSUNITS; a file that states its unit is never relabelled")  # fmt: skip
    check.add_argument("--quiet", "-q", action="store_true",
                       help="print each file's one-line summary and the verdict, not the table, notes and advice")  # fmt: skip
    check.add_argument("--timing", action="store_true",
                       help="also print where the check spent its time: the reader's share, and whether it limits the check")  # fmt: skip
    check.add_argument(
        "--gap-tol",
        type=float,
        help="G0 gap, absolute model units (default 1e-7; faces: relative to the model size, "
        "default per edge the file's stated uncertainty or the edge's own tolerance, the larger)",
    )
    check.add_argument("--angle-tol", type=float, help="G1 tangent angle, radians (default 1e-7; faces: between the normals)")
    check.add_argument("--curvature-tol", type=float,
                       help="G2 curvature jump, relative (default 1e-6; faces: normal curvature across the edge, 1e-4)")  # fmt: skip
    check.add_argument("--feature-angle", type=float,
                       help="faces: normals further apart (radians) make a sharp feature, listed and not failed (default 5°)")  # fmt: skip
    check.add_argument("--zebra", metavar="OUT.png", help="faces: also draw zebra stripes (reflection lines) of the part as PNG")
    check.add_argument("--curvature-map", metavar="OUT.png", help="faces: also draw the mean curvature of the part as PNG")
    check.add_argument("--html", metavar="OUT.html",
                       help="also write the report as one web page to turn and click (self-contained, no network): a part "
                            "under zebra stripes or its curvature, every edge coloured by its verdict; curves with their "
                            "comb, every joint coloured by its level (STEP, IGES, DXF, G-code)")  # fmt: skip
    check.add_argument(
        "--view", metavar="X,Y,Z", help="the pictures: direction towards the viewer (default 1,-0.9,0.45: front right, a little above)"
    )
    check.add_argument(
        "--stripes", type=int, metavar="N", help="the zebra picture: stripe pairs (default 24; more for a finer look at small fillets)"
    )
    check.add_argument("--pixels", type=int, metavar="N", help="the pictures: their longer side in pixels (default 1000)")
    add_many_options(check)
    check.set_defaults(run=check_inputs)


#: The files ``check`` looks for in a folder it is given.
#: What each kind of document judged as curves is called in messages.
_DOCUMENTS = {".dxf": "a DXF drawing", ".xml": "a LandXML file", ".ifc": "an IFC file", **dict.fromkeys(GCODE_SUFFIXES, "a CNC program")}
#: Every suffix ``check`` judges (``spiral_cad.check``'s table).
CHECK_SUFFIXES = tuple(suffix for suffixes, _ in CHECKS.values() for suffix in suffixes)


def _picture_options(args: argparse.Namespace) -> dict:
    """``--view``, ``--stripes`` and ``--pixels`` as the pictures' keyword arguments (only those given)."""
    options: dict = {}
    if args.view is not None:
        try:
            view = tuple(float(x) for x in args.view.split(","))
        except ValueError:
            view = ()
        if len(view) != 3 or not all(map(math.isfinite, view)) or not any(view):
            raise ValueError(f"--view must be three numbers X,Y,Z, not all zero (a direction towards the viewer); got {args.view!r}")
        options["view"] = view
    if args.stripes is not None:
        options["stripes"] = args.stripes
    if args.pixels is not None:
        options["pixels"] = args.pixels
    drawn = args.zebra or args.curvature_map or (args.html and "pixels" not in options)
    if options and not drawn:
        raise ValueError(f"{', '.join('--' + k for k in options)}: only with --zebra or --curvature-map"
                         + ("" if "pixels" in options else " (--view and --stripes: or --html)"))  # fmt: skip
    if options:
        from .zebra import check_picture_options

        check_picture_options(**options)
    return options


def check_inputs(args: argparse.Namespace) -> int:
    """``spiral-cad check``: one file as ever (no cluster), or many on dask (``many.py``)."""
    if not wants_many(args.file, CHECK_SUFFIXES) and all(getattr(args, o) is None for o in MANY_OPTIONS):
        args.file = args.file[0]
        return check_file(args)
    files = expand_inputs(args.file, CHECK_SUFFIXES)
    drawn = [f"--{o.replace('_', '-')}" for o in ("comb", "zebra", "curvature_map", "html") if getattr(args, o)]
    if drawn and len(files) > 1:
        raise ValueError(f"{', '.join(drawn)}: each writes one file; give one file to check")
    where = os.path.abspath if args.scheduler else str  # a remote worker's working folder is not ours
    return run_on_many(args, check_file, files, [{"file": where(f)} for f in files], "checked")
