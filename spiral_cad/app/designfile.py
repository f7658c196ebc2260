"""JSON design files: validation, building and writing every output.

A design file holds ``units`` and a list of ``designs``; each design has a
``name``, a ``type`` and the fields of that type, as the models of
``spiral_cad.app.schema`` describe them (``spiral-cad schema`` prints the
JSON Schema). Any byte sequence is either a valid design or a ``DesignError``
naming the field and the value: the file must be a regular file of at most
``MAX_DESIGN_BYTES`` (checked before it is read), it is decoded, parsed and
every field checked before anything is built, and every design is built
before anything is written. A design reads files (a G-code program) only
from its own folder. Output is all or nothing (``spiral_cad.io.staging``):
files are written into a staging folder inside the output folder and moved
into place only when all of them were written and every destination was
checked; a failure or an interrupt (Ctrl-C, SIGTERM, SIGHUP) leaves the
output folder as it was.
"""

from __future__ import annotations

import contextlib
import json
import math
import os
import re
import stat
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from functools import partial
from importlib.util import find_spec
from pathlib import Path, PurePosixPath, PureWindowsPath
from typing import Any

import numpy as np

from ..core.chain import Chain
from ..core.errors import NoSolutionError
from ..core.spiral import BezierSpiral
from ..design.tables import fixed_columns
from ..io.progress import ticking
from ..io.signals import signals_handled
from ..io.staging import Staging
from .built import (
    Built,
    BuiltAlignment,
    BuiltCircleChain,
    BuiltFit,
    BuiltLandXML,
    BuiltRoadFit,
    BuiltRounded,
    BuiltTransition,
    DesignError,
    FitResiduals,
    program_feed,
)
from .schema import (
    MAX_PIS,
    MAX_PVIS,
    NAME,
    AlignmentDesign,
    CircleChainDesign,
    DesignFile,
    FitDesign,
    RoundedPolylineDesign,
    validate,
)
from .schema import Profile as ProfileDesign

__all__ = ["MAX_PIS", "MAX_PVIS", "NAME", "Built", "BuiltFit", "BuiltRoadFit", "DesignError", "FitResiduals", "build", "load", "write"]

#: JSON integers longer than this are refused (they cannot be lengths in float64 anyway).
MAX_DIGITS = 308
#: Chains of more edges are not read back by OCCT for the continuity report (its wire repair grows
#: as N^1.8: minutes at a few hundred thousand edges; every joint was checked when the chain was
#: made), nor written as IGES (OCCT's IGES writer holds about 6 kB per edge: 1.6 GB for 280 000;
#: the STEP file holds the same exact curves).
LARGE_CHAIN_EDGES = 50_000
#: Design files larger than this are refused before they are read.
MAX_DESIGN_BYTES = 10_000_000
#: The packages of the ``cad`` extra and what needs them.
CAD_EXTRA = {
    "OCP": "IGES, the 3-D STEP of roads, the demo's gallery of G2 parts and the continuity check",
    "ezdxf": "DXF",
    "matplotlib": "plots",
    "ifcopenshell": "IFC",
}


def build_landxml(path: str | Path, max_offset: float | None = None, directions: str = "auto") -> tuple[str, list[Built]]:
    """Every alignment of a LandXML file as designs: one per G2 run (``spiral_cad.io.read_landxml``).

    Each design is named after its alignment (characters other than letters, digits, ``_`` and ``-``
    replaced by ``_``, at most 56 of them, ``_1``, ``_2`` … per G2 run); where that name is already
    taken by an earlier design (names compared ignoring case: they name files) — equal alignment
    names, names equal once sanitised or in their first 56 characters — the first free suffix
    ``_2``, ``_3`` … is added and ``renamed`` says so. ``max_offset``, ``directions``: see ``read_landxml``.

    Raises:
        DesignError: the file cannot be read or holds an element that cannot be represented.
    """
    from ..io import read_landxml

    try:
        alignments = read_landxml(path, max_offset=max_offset, directions=directions)
    except (OSError, ValueError) as e:
        raise DesignError(f"{path}: {e}") from None
    built: list[Built] = []
    taken: dict[str, str] = {}  # each design name (lower case) taken, and the alignment that took it
    for k, a in enumerate(alignments):
        stem = (re.sub(r"[^A-Za-z0-9_-]", "_", a.name).strip("_-") or f"alignment{k + 1}")[:56]
        for run, chain in enumerate(a.chains):
            wanted = stem if len(a.chains) == 1 else f"{stem}_{run + 1}"
            name, suffix = wanted, 1
            while name.lower() in taken:  # one alignment's outputs never overwrite another's
                suffix += 1
                name = f"{wanted}_{suffix}"
            renamed = "" if name == wanted else (f"alignment {a.name!r} (number {k + 1}) written as {name!r}: "
                                                 f"{wanted!r} names the outputs of alignment {taken[wanted.lower()]!r}")  # fmt: skip
            taken[name.lower()] = f"{a.name}" if len(a.chains) == 1 else f"{a.name} (G2 run {run + 1})"
            built.append(BuiltLandXML(name=name, chain=chain, source=a, run=run, renamed=renamed))
    return alignments[0].units, built


def _landxml_report(b: BuiltLandXML, stage: Path) -> list[str]:
    """NAME_landxml.txt (per element: kind, station, offset from the file, length change, how it was rebuilt;
    the station shift, the breaks) and NAME.xodr."""
    from ..cad.export import export_opendrive

    a = b.source
    lines = [f"{a.name}: {len(a.kinds)} elements, largest offset from the file {a.offset:.3g} {a.units}, "
             f"station shift at the end {a.station_shift:.3g} {a.units}",
             "element  kind     station            offset     length change  rebuilt by"]  # fmt: skip
    lines += [f"{k:7d}  {kind:7s}  {sta:17.6f}  {off:9.3g}  {dl:13.3g}  {how}"
              for k, (kind, sta, off, dl, how) in enumerate(zip(a.kinds, a.stations, a.offsets, a.length_changes, a.methods))]  # fmt: skip
    lines += [f"break: {text}" for text in a.breaks] + [f"note: {text}" for text in a.notes]
    lines += [f"note: {b.renamed}"] if b.renamed else []
    (stage / f"{b.name}_landxml.txt").write_text("\n".join(lines) + "\n", encoding="utf-8")
    export_opendrive(b.chain, stage / f"{b.name}.xodr", name=b.name)
    return ["landxml.txt", "xodr"]


# ------------------------------------------------------------ reading


def _json_integer(text: str) -> int:
    if len(text.lstrip("-")) > MAX_DIGITS:
        raise DesignError(f"an integer of {len(text.lstrip('-'))} digits is not a length or a count")
    return int(text)


def _json_constant(text: str) -> float:
    raise DesignError(f"{text} is not a number in JSON")


def _read(source: str | Path) -> bytes:
    """The bytes of the design file ``source``: a regular file of at most ``MAX_DESIGN_BYTES``.

    The file is opened without blocking and inspected before anything is
    read, so a FIFO, a device (/dev/zero), a folder or an enormous file is
    refused at once.
    """
    label = Path(source).name or str(source)
    flags = os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_NOCTTY", 0) | getattr(os, "O_BINARY", 0)
    try:
        descriptor = os.open(source, flags)
    except OSError as e:
        raise DesignError(f"cannot read design file {label}: {e.strerror}") from None
    except ValueError as e:  # e.g. a NUL character in the path
        raise DesignError(f"cannot read design file {label!r}: {e}") from None
    try:
        info = os.fstat(descriptor)
        if stat.S_ISDIR(info.st_mode):
            raise DesignError(f"design file {label} is a folder, not a file")
        if not stat.S_ISREG(info.st_mode):
            raise DesignError(f"design file {label} is not a regular file (a device, pipe or socket)")
        if info.st_size > MAX_DESIGN_BYTES:
            raise DesignError(f"design file {label} has {info.st_size} bytes; at most {MAX_DESIGN_BYTES} are read")
        with os.fdopen(descriptor, "rb", closefd=False) as handle:
            raw = handle.read(MAX_DESIGN_BYTES + 1)
    except OSError as e:
        raise DesignError(f"cannot read design file {label}: {e.strerror}") from None
    finally:
        os.close(descriptor)
    if len(raw) > MAX_DESIGN_BYTES:  # it grew after it was inspected
        raise DesignError(f"design file {label} has more than {MAX_DESIGN_BYTES} bytes")
    return raw


def _json_object(pairs: list[tuple[str, Any]]) -> dict[str, Any]:
    """A JSON object whose keys are unique: a key given twice is refused (JSON readers disagree on which wins)."""
    found: dict[str, Any] = {}
    for key, value in pairs:
        if key in found:
            raise DesignError(f"the key {key!r} is given twice in one object")
        found[key] = value
    return found


def _parse(source: str | Path) -> Any:
    """The JSON value in the file ``source``; any byte sequence either parses or raises DesignError."""
    label = Path(source).name
    raw = _read(source)
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as e:
        raise DesignError(f"{label}: not UTF-8 text (byte {e.start}: 0x{raw[e.start]:02x})") from None
    try:
        return json.loads(text, parse_int=_json_integer, parse_constant=_json_constant, object_pairs_hook=_json_object)
    except DesignError as e:
        raise DesignError(f"{label}: {e}") from None
    except json.JSONDecodeError as e:
        raise DesignError(f"{label}: malformed JSON at line {e.lineno}, column {e.colno}: {e.msg}") from None
    except RecursionError:
        raise DesignError(f"{label}: JSON nested too deeply") from None
    except ValueError as e:  # e.g. number conversions the json module refuses
        raise DesignError(f"{label}: {e}") from None


def load(source: str | Path | dict) -> DesignFile:
    """Parse and check a design (a JSON file path or a dict): every field, before anything is built.

    Raises:
        DesignError: the file cannot be read or parsed, or the first malformed
            field, named by its JSON path and value.
    """
    data = source if isinstance(source, dict) else _parse(source)
    try:
        return validate(data)
    except ValueError as e:
        raise DesignError(str(e)) from None


# ------------------------------------------------------------- building


def _criteria(d: AlignmentDesign, where: str):
    """The RoadCriteria / RailCriteria of an alignment design, or None."""
    from ..design import RailCriteria, RoadCriteria

    if d.design_speed is None:
        return None
    try:
        return (RailCriteria if d.criteria == "rail" else RoadCriteria)(d.design_speed, **d.criteria_values())
    except ValueError as e:
        raise DesignError(f"{where}: {e}") from None


def _pairs(value: float | list, count: int) -> list[tuple[float, float]]:
    """One number for all, or per interior PI a number or an (in, out) pair: (in, out) pairs."""
    items = value if isinstance(value, list) else [value] * count
    return [tuple(item) if isinstance(item, tuple) else (item, item) for item in items]


def _alignment(d: AlignmentDesign, where: str, units: str, base: Path | None) -> BuiltAlignment:
    from ..design import Alignment
    from ..io.opendrive import CrossSection

    count = len(d.pis) - 2
    kw: dict[str, Any] = {}
    if d.spiral_angles_deg is not None:
        kw["spiral_angles"] = [(math.radians(a), math.radians(b)) for a, b in _pairs(d.spiral_angles_deg, count)]
    elif d.spiral_lengths is not None:
        kw["spiral_lengths"] = _pairs(d.spiral_lengths, count)
    alignment = Alignment.from_pis(d.pis, d.radii, start_station=d.start_station, units=units, criteria=_criteria(d, where),
                                   strict=d.strict, shape=d.spiral_shape, **kw)  # fmt: skip
    try:
        cross_section = CrossSection(**d.cross_section.model_dump())
    except ValueError as e:
        raise DesignError(f"{where}.cross_section: {e}") from None
    profile = None if d.profile is None else _profile(d.profile, f"{where}.profile", alignment, d.strict)
    return BuiltAlignment(name=d.name, chain=alignment.chain, source=alignment, cross_section=cross_section,
                          geo_reference=d.geo_reference, profile=profile)  # fmt: skip


def _profile(p: ProfileDesign, where: str, alignment: Any, strict: bool):
    """The vertical alignment of an alignment design (its stations are the alignment's chainages)."""
    from ..design import Profile, ProfileCriteria, RoadCriteria

    count = len(p.pvis) - 2
    kw: dict[str, Any] = {}
    if p.curve_lengths is not None:  # a number is a symmetric curve's whole length, a pair its halves
        kw["curve_lengths"] = p.curve_lengths
    elif p.k_values is not None:
        kw["k_values"] = p.k_values if isinstance(p.k_values, list) else [p.k_values] * count
    limits = {k: getattr(p, k) for k in ("max_grade", "min_curve_length", "terrain") if getattr(p, k) is not None}
    if isinstance(alignment.criteria, RoadCriteria):
        try:
            kw["criteria"] = ProfileCriteria(alignment.criteria.design_speed, **limits)
        except ValueError as e:
            raise DesignError(f"{where}: {e}") from None
    elif limits:
        raise DesignError(f'{where}: {", ".join(limits)} need road criteria (a design_speed with criteria "road")')
    if count and "curve_lengths" not in kw and "k_values" not in kw and "criteria" not in kw:
        raise DesignError(f"{where}: give curve_lengths or k_values (or a road design_speed to choose the curves)")
    try:
        return Profile.from_pvis(p.pvis, units=alignment.chain.units, strict=strict, alignment=alignment, **kw)
    except (NoSolutionError, ValueError) as e:
        raise DesignError(f"{where}: {e}") from None


def _circle_chain(d: CircleChainDesign, where: str, units: str, base: Path | None) -> BuiltCircleChain:
    from ..design import circle_chain

    result = circle_chain([(c.center, c.radius) for c in d.circles], units=units, shape=d.spiral_shape)
    return BuiltCircleChain(name=d.name, chain=result.chain, source=result)


def _rounded(d: RoundedPolylineDesign, where: str, units: str, base: Path | None) -> Built | list[Built]:
    from ..design import round_corners

    if d.points is not None:  # the model holds points or gcode
        result = round_corners(d.points, shape=d.shape, units=units, **d.rounding())
    else:
        from ..io.gcode import holds_splines, program_feeds, read_gcode_chain

        program = _own_file(str(d.gcode), base, f"{where}.gcode")
        if not holds_splines(program):  # lines and arcs: one design per G2 path
            from .gcode_build import toolpath_designs

            return toolpath_designs(d, where, units, program)
        from ..design.rounded_paths import RoundedPath  # G5: the program states its curves (our own output reads back as its chain)

        result = RoundedPath(read_gcode_chain(program, units=units), [], d.shape)
        feed = program_feed(*program_feeds(program), units)
        samples = None if d.samples is None else d.samples.options()
        return BuiltRounded(name=d.name, chain=result.chain, source=result, samples=samples, inputs=(program,), program_feed=feed)
    samples = None if d.samples is None else d.samples.options()
    return BuiltRounded(name=d.name, chain=result.chain, source=result, samples=samples)


def _fit(d: FitDesign, where: str, units: str, base: Path | None) -> Built:
    table = None
    if d.points is not None:
        points = np.asarray(d.points, dtype=np.float64)
    else:
        from ..io.points import read_points

        path = _own_file(d.points_file or "", base, f"{where}.points_file")
        table = read_points(path, units=d.points_units or units).in_units(units)
        points = table.points
    road = d.design_speed is not None or points.shape[1] == 3
    if road and d.closed:
        raise DesignError(f"{where}.closed: a road (design_speed or points with z) is open; leave closed out")
    if road and d.max_curvature is not None:
        raise DesignError(f"{where}.max_curvature: a road's curves are judged by design_speed; leave max_curvature out")
    from ..io.progress import Progress

    meter = Progress(f"{where}: fitting {len(points):,} points, steps")

    def progress(done: int, total: int) -> None:
        meter.total = total
        meter(done)

    try:
        built = _fit_road(d, points, units, progress) if road else _fit_path(d, points, units, progress)
    except ValueError as e:
        if table is None:
            raise
        # a point named by its index is also named by its line in the file
        lines = table.lines
        shown = re.sub(r"points\[(\d+)\]", lambda m: f"{m[0]} ({table.source} line {lines[int(m[1])]})"
                       if int(m[1]) < len(lines) else m[0], str(e))  # fmt: skip
        raise DesignError(f"{where}: {shown}") from None
    meter.done(meter.total or 0)
    return built


def _fit_path(d: FitDesign, points: Any, units: str, progress: Callable[[int, int], None]) -> BuiltFit:
    from .. import fit_points

    fit = fit_points(points, d.tolerance, closed=d.closed, shape=d.spiral_shape, units=units, max_curvature=d.max_curvature,
                     progress=progress)  # fmt: skip
    residuals = FitResiduals(points, fit.stations, fit.residuals, fit.tolerance, units, fit.curvature_estimate)
    samples = None if d.samples is None else d.samples.options()
    return BuiltFit(name=d.name, chain=fit.chain, source=fit, fit=residuals, closed=d.closed, samples=samples)


def _fit_road(d: FitDesign, points: Any, units: str, progress: Callable[[int, int], None]) -> BuiltRoadFit:
    """A road alignment (``Alignment.fit``), with z plan and profile (``fit_survey``)."""
    from ..core.fit import chain_distances
    from ..design import Alignment
    from ..design.survey import fit_survey
    from ..io.opendrive import CrossSection

    if d.samples is not None:
        raise DesignError("samples: a road writes its stationing, OpenDRIVE and profile; leave samples out")
    if points.shape[1] == 3:
        survey = fit_survey(points, d.tolerance, d.vertical_tolerance, d.design_speed, units=units, shape=d.spiral_shape,
                            progress=progress)  # fmt: skip
        alignment, profile = survey.alignment, survey.profile
        residuals = FitResiduals(points, survey.stations - alignment.start_station, survey.plan_residuals, d.tolerance, units,
                                 _estimate(alignment), vertical=survey.vertical_residuals)  # fmt: skip
    else:
        if d.vertical_tolerance is not None:
            raise DesignError("vertical_tolerance: the points have no z (no profile to fit)")
        alignment, profile = Alignment.fit(points, d.tolerance, d.design_speed, units=units, shape=d.spiral_shape, progress=progress), None
        distance, stations = chain_distances(alignment.chain, points)
        residuals = FitResiduals(points, stations, distance, d.tolerance, units, _estimate(alignment))
    return BuiltRoadFit(name=d.name, chain=alignment.chain, source=alignment, cross_section=CrossSection(), profile=profile,
                        fit=residuals)  # fmt: skip


def _estimate(alignment: Any) -> Any:
    """The point-wise curvature estimate an ``Alignment.fit`` segmented (None without one)."""
    return None if alignment.point_fit is None else alignment.point_fit.curvature_estimate


def _own_file(given: str, base: Path | None, where: str) -> Path:
    """The file ``given`` by a design whose file is in ``base``: only a file in that folder (or below it).

    A design file may be shared; what it reads must not reach beyond its folder,
    so an absolute path, a ``..`` and a link leading outside are refused by the
    name given (never the link's target). A design given as a dict (the API)
    has no folder: its paths are the caller's.
    """
    if base is None:
        return Path(given)
    shown = f"{given!r:.200}"
    if any(p.is_absolute() or p.drive or p.root for p in (PurePosixPath(given), PureWindowsPath(given))):
        raise DesignError(f"{where}: {shown} is an absolute path; a design file reads only files in its own folder")
    if any(".." in p.parts for p in (PurePosixPath(given), PureWindowsPath(given))):
        raise DesignError(f"{where}: {shown} climbs out with '..'; a design file reads only files in its own folder")
    path = base / given
    try:
        inside = path.resolve().is_relative_to(base.resolve())
    except (OSError, RuntimeError):  # a loop of links
        raise DesignError(f"{where}: {shown} is a link that cannot be followed (a loop)") from None
    if not inside:
        raise DesignError(f"{where}: {shown} is a link leading outside the design file's folder; "
                          "a design file reads only files in its own folder")  # fmt: skip
    return path


def _transition(d: Any, where: str, units: str, base: Path | None) -> BuiltTransition:
    from ..core import transitions

    t = getattr(transitions, d.case)(**d.arguments(), shape=d.spiral_shape)
    return BuiltTransition(name=d.name, chain=Chain(t.spirals, units=units), source=t)


BUILDERS: dict[str, Callable[[Any, str, str, Path | None], Built | list[Built]]] = {
    "alignment": _alignment,
    "circle_chain": _circle_chain,
    "rounded_polyline": _rounded,
    "transition": _transition,
    "fit": _fit,
    "g2_path": lambda d, where, units, base: _g2_path(d, units, base, where),
}


def _g2_path(d: Any, units: str, base: Path | None, where: str) -> list[Built]:
    """A ``g2_path`` design: the lines and arcs of a DXF, LandXML or OpenDRIVE file made G2 (``g2_build``)."""
    from .g2_build import g2_designs

    source = _own_file(d.source, base, f"{where}.source")
    return g2_designs(source, d.max_deviation, name=d.name, units=units, source_units=d.source_units, shape=d.spiral_shape)[1]


def build(source: str | Path | dict, max_offset: float | None = None, directions: str = "auto") -> tuple[str, list[Built]]:
    """Validate and build every design of ``source``: (units, built designs).

    A LandXML file (``.xml``) is built by ``build_landxml``: every alignment, one design per G2 run
    (``max_offset``: the largest offset accepted from the file's elements; ``directions``: how the file
    counts directions; see ``read_landxml``).
    A G-code program named by a design file is read from the design file's
    folder (a dict's from the working folder).

    Raises:
        DesignError: the first malformed field or infeasible design, named as
            ``designs[i] (name)``, or a file outside the design file's folder.
    """
    if isinstance(source, (str, Path)) and Path(source).suffix.lower() == ".xml":
        return build_landxml(source, max_offset, directions)
    design_file = load(source)
    base = None if isinstance(source, dict) else Path(source).parent
    built = []
    for i, d in enumerate(design_file.designs):
        where = f"designs[{i}] ({d.name})"
        try:
            made = BUILDERS[d.type](d, where, design_file.units, base)
            for b in made if isinstance(made, list) else [made]:  # a G-code program: one design per G2 path
                if d.gcode_out is not None or isinstance(b, BuiltRounded):  # a path gets its program
                    b.gcode = {} if d.gcode_out is None else d.gcode_out.options()
                    if b.program_feed is not None and "feed" not in b.gcode:  # the program's own feeds, unless one is stated
                        b.gcode["feed"] = b.program_feed
                        if b.segment_feeds is not None:
                            b.gcode["feeds"] = b.segment_feeds
                built.append(b)
        except DesignError:
            raise
        except (NoSolutionError, ValueError) as e:
            raise DesignError(f"{where}: {e}") from None
    return design_file.units, built


# -------------------------------------------------------------- writing


def missing_cad_extra() -> list[str]:
    """The packages of the ``cad`` extra that are not installed."""
    return [name for name in CAD_EXTRA if find_spec(name) is None]


@dataclass
class Written:
    """What ``write`` produced: the files, and what it could not write without the CAD extra."""

    files: list[Path]
    skipped: list[str]


def write(
    built: list[Built],
    out: str | Path,
    units: str,
    progress: Callable[[str], None] = print,
    plots: bool = True,
    extra: Callable[[Path], None] | None = None,
) -> Written:
    """Write every output of every design into ``out``, all or nothing (see the module docstring).

    Per design: STEP and SVG (always), the stationing CSV of alignments, and
    with the ``cad`` extra IGES, DXF, the plan and curvature plots (unless
    ``plots`` is False) and the continuity report of the STEP file as OCCT
    reads it. Without the extra those are skipped and named in
    ``Written.skipped``. ``extra``, if given, writes more files into the
    folder it is passed (the staging folder); they are committed with the rest.

    Raises:
        ValueError: ``out`` is a file, cannot be created or written, or a
            file in it cannot be replaced (a folder, read-only); nothing in
            ``out`` was changed.
        OSError: writing or moving a file failed; nothing in ``out`` was changed.
        KeyboardInterrupt: Ctrl-C, SIGTERM or SIGHUP; nothing in ``out`` was changed.
    """
    _refuse_overwriting_inputs(built, Path(out))
    missing = missing_cad_extra()
    with Staging(out) as staging, _interrupts_raise():
        for b in built:
            started = time.perf_counter()
            names = _write_design(b, staging.folder, units, missing, plots)
            progress(
                f"  {b.name}: {b.kind}, {len(b.chain)} segments, length {b.chain.length:.6g} {units} "
                f"→ {', '.join(names)} ({time.perf_counter() - started:.1f} s)"
            )
        if extra is not None:
            before = set(staging.files())
            extra(staging.folder)
            added = [p.name for p in staging.files() if p not in before]
            if added:
                progress(f"  also → {', '.join(added)}")
        written = staging.commit()
    skipped = [f"{CAD_EXTRA[name]} (needs {name})" for name in missing if plots or name != "matplotlib"]
    return Written(written, skipped)


def _refuse_overwriting_inputs(built: list[Built], out: Path) -> None:
    """Refuse, before anything is written, outputs that would replace a file a design was read from.

    Every output of a design is named NAME.ext or NAME_what.ext in ``out``: ``build --from-gcode
    d/part.ngc --out d`` would replace the program with its rounded one (part.ngc).
    """
    inputs = [source for b in built for source in b.inputs]
    if not inputs or not out.is_dir():
        return
    for b in built:
        for source in inputs:
            if not source.name.startswith((f"{b.name}.", f"{b.name}_")) or not source.parent.is_dir():
                continue
            if os.path.samefile(source.parent, out):
                raise ValueError(f"{b.name}: the output {str(out / source.name)!r} would replace the input {str(source)!r}; "
                                 "nothing was written: give another output folder (--out) or name (--name)")  # fmt: skip


def _write_design(b: Built, stage: Path, units: str, missing: list[str], plots: bool) -> list[str]:
    """Write one design's files into ``stage``; returns what follows the name of each file written.

    The STEP file goes first; then two child processes work beside this one:
    OCCT reads the STEP for the continuity report, and the DXF is written
    (ezdxf's objects are the slowest of the files), while the rest are written here.
    """
    from ..cad.export import export_dxf, export_step
    from ..cad.sandbox import Isolated

    step = stage / f"{b.name}.step"
    with ticking(f"{b.name}: writing {step.name} ({len(b.chain):,} edges)"):
        export_step(b.chain, step, name=b.name)
    reread = len(b.chain) <= LARGE_CHAIN_EDGES
    with contextlib.ExitStack() as children:
        continuity = None
        if "OCP" not in missing and reread:
            from ..cad.continuity import checking

            continuity = children.enter_context(checking(step))  # as `spiral-cad check` reads it: the same numbers
        dxf = None
        if "ezdxf" not in missing:
            dxf = children.enter_context(Isolated(partial(export_dxf, name=b.name), b.chain, stage / f"{b.name}.dxf",
                                                  what="the DXF writer", subject=f"{b.name}.dxf"))  # fmt: skip
        names = ["step"] + _write_others(b, stage, units, missing, plots)
        if dxf is not None:
            with ticking(f"{b.name}: writing {b.name}.dxf (beside the others)"):
                dxf.result()
            names.append("dxf")
        if continuity is None:
            if not reread:
                b.continuity = (f"G2 by the chain's own joint checks ({len(b.chain):,} edges: OCCT's re-read of the STEP, "
                                f"whose wire repair grows as N^1.8, is skipped above {LARGE_CHAIN_EDGES:,})")  # fmt: skip
            return names
        with ticking(f"{b.name}: continuity report (OCCT reads the STEP back)"):
            report = continuity()
    b.continuity = f"{report.min_level} ({report.describe()})"
    (stage / f"{b.name}_continuity.txt").write_text(report.format_table() + "\n", encoding="utf-8")
    return names + ["continuity.txt"]


def _write_others(b: Built, stage: Path, units: str, missing: list[str], plots: bool) -> list[str]:
    """Every file of a design but its STEP, DXF and continuity report."""
    from ..cad.export import export_svg

    names = []
    if b.chain.dim == 2:  # SVG is a plane output (the plots draw a path in space as its plan)
        with ticking(f"{b.name}: writing {b.name}.svg"):
            export_svg(b.chain, stage / f"{b.name}.svg", name=b.name)
        names.append("svg")
    if b.gcode is not None:
        from ..io.gcode_write import write_gcode

        try:
            with ticking(f"{b.name}: writing {b.name}.ngc"):
                write_gcode(b.chain, stage / f"{b.name}.ngc", name=b.name, **b.gcode)
        except ValueError as error:  # name the design and the file: a design file may hold many
            raise ValueError(f"{b.name}.ngc: {error}") from None
        names.append("ngc")
    if isinstance(b, BuiltRounded | BuiltFit) and b.samples:
        from ..cad.export import export_samples

        with ticking(f"{b.name}: writing {b.name}_samples.csv"):
            export_samples(b.chain, stage / f"{b.name}_samples.csv", **b.samples)
        names.append("samples.csv")
    if isinstance(b, BuiltAlignment):
        from ..cad.export import export_opendrive

        profile = b.profile
        b.source.to_csv(stage / f"{b.name}_stations.csv")
        export_opendrive(b.source, stage / f"{b.name}.xodr", name=b.name, cross_section=b.cross_section,
                         geo_reference=b.geo_reference, profile=profile)  # fmt: skip
        names += ["stations.csv", "xodr"]
        from ..io.landxml import write_landxml

        write_landxml(b.source, stage / f"{b.name}.xml", name=b.name, profile=profile)
        names.append("xml")
        if "ifcopenshell" not in missing:
            from ..cad.export import originating_system
            from ..io.ifc import write_ifc

            write_ifc(b.source, stage / f"{b.name}.ifc", profile=profile, names=[b.name], project=b.name,
                      application=originating_system())  # fmt: skip
            names.append("ifc")
        if b.source.checks:
            b.source.criteria_to_csv(stage / f"{b.name}_criteria.csv")
            names.append("criteria.csv")
        if profile is not None:
            profile.to_csv(stage / f"{b.name}_profile.csv")
            names.append("profile.csv")
            if "OCP" not in missing:
                names += _road_3d(b, profile, stage, units)
    if isinstance(b, BuiltLandXML):
        names += _landxml_report(b, stage)
    elif getattr(b, "road", False):  # an alignment made G2 (build FILE.xml --max-deviation D): also its OpenDRIVE
        from ..cad.export import export_opendrive

        export_opendrive(b.chain, stage / f"{b.name}.xodr", name=b.name)
        names.append("xodr")
    if "OCP" not in missing and len(b.chain) > LARGE_CHAIN_EDGES:
        names.append(f"no igs ({len(b.chain):,} edges, above {LARGE_CHAIN_EDGES:,}: the STEP file holds the same exact curves)")
    elif "OCP" not in missing:
        from ..cad.export import export_iges

        export_iges(b.chain, stage / f"{b.name}.igs", name=b.name)
        names.append("igs")
    if isinstance(b, BuiltFit | BuiltRoadFit):
        names += _fit_report(b, b.fit, stage, plots and "matplotlib" not in missing)
    if plots and "matplotlib" not in missing:
        names += _plots(b, stage)
    return names


def _fit_report(b: Built, fit: FitResiduals, stage: Path, plot: bool) -> list[str]:
    """NAME_residuals.csv (every point's station and distance to the path) and the plot NAME_fit.png."""
    from .fitreport import write_residuals

    write_residuals(stage / f"{b.name}_residuals.csv", fit.points, fit.stations, fit.residuals, fit.units, vertical=fit.vertical)
    if not plot:
        return ["residuals.csv"]
    from .fitreport import plot_fit

    figure = plot_fit(b.chain, fit.stations, fit.residuals, fit.tolerance, fit.estimate, vertical=fit.vertical)
    figure.suptitle(f"{b.name} — {b.kind}")
    figure.savefig(stage / f"{b.name}_fit.png", dpi=110)
    return ["residuals.csv", "fit.png"]


def _road_3d(b: BuiltAlignment, profile: Any, stage: Path, units: str) -> list[str]:
    """NAME_3d.step: the corridor solid and the 3-D centre line, their measured fit in the file's description."""
    from build123d import Compound

    from ..cad.corridor import centerline_wire, corridor
    from ..cad.export import originating_system
    from ..cad.step_occ import write_shape_step

    road = corridor(b.source, profile, b.cross_section)
    line = road.centerline
    fit = (
        f"{b.name} in 3-D: corridor solid and centre line (plan exact; z within {line.deviation:.3g} {units} of the "
        f"profile, tolerance {line.tolerance:.3g} {units}; corridor edges within {road.roadway.deviation:.3g} {units}); "
        f"centre line one wire, {line.continuity()}"
    )
    write_shape_step(Compound([road.solid, centerline_wire(line)]), stage / f"{b.name}_3d.step", b.name, units,
                     originating_system(), description=fit)  # fmt: skip
    b.road_3d = f"{line.describe()}; {road.describe()}"
    return ["3d.step"]


def _plots(b: Built, stage: Path) -> list[str]:
    from .plots import plot_curvature, plot_plan

    names = []
    for suffix, plot in (("plan", plot_plan), ("curvature", plot_curvature)):
        fig = plot(b.chain)
        fig.suptitle(f"{b.name} — {b.kind}")
        fig.savefig(stage / f"{b.name}_{suffix}.png", dpi=110)
        names.append(f"{suffix}.png")
    return names


@contextmanager
def _interrupts_raise() -> Iterator[None]:
    """Turn SIGTERM and SIGHUP into KeyboardInterrupt while files are written, so cleanup runs
    (also when a library turned the interrupt into another exception: OCP's "ImportError:
    initialization failed" during a long import)."""
    with signals_handled(("SIGTERM", "SIGHUP"), interrupt=True) as received:
        try:
            yield
        except Exception:
            if received:
                raise KeyboardInterrupt from None
            raise


def criteria_tables(built: list[Built]) -> str:
    """The criteria table of every alignment designed with criteria and the table of every profile,
    with their violations."""
    parts = []
    for b in built:
        if not isinstance(b, BuiltAlignment):
            continue
        if b.source.checks:
            broken = sum(1 for c in b.source.checks if not c.ok)
            verdict = "every curve meets the criteria" if not broken else f"{broken} curve(s) violate the criteria"
            parts.append(f"{b.name}: {b.source.criteria_table()}\n{b.name}: {verdict}")
        profile = b.profile
        if profile is not None:
            broken = sum(1 for c in profile.checks if not c.ok)
            verdict = "" if not profile.checks else (f"\n{b.name}: every PVI meets the profile criteria" if not broken
                                                     else f"\n{b.name}: {broken} PVI(s) violate the profile criteria")  # fmt: skip
            parts.append(f"{b.name} profile: {profile.table(6)}{verdict}")
    return "\n\n".join(parts)


def summary(built: list[Built], units: str) -> str:
    """One line per design: kind, spiral shape, segments, length, peak |κ| and the checked continuity."""
    columns = [("design", "14"), ("kind", "30"), ("spiral shape", "13"), ("segments", "8d"), (f"length {units}", "12.3f"),
               ("max |κ|", "10.5f"), (" continuity (of the STEP file)", "")]  # fmt: skip
    rows = []
    for b in built:
        peak = max(max(abs(seg.start_curvature), abs(seg.end_curvature)) for seg in b.chain)  # spirals are monotone
        shapes = sorted({seg.shape or "not stated" for seg in b.chain if isinstance(seg, BezierSpiral)}) or ["-"]
        shown = getattr(b, "shown_continuity", None) or b.continuity or "-"  # a part of a split path: G0 at the splits
        rows.append((b.name, b.kind, "+".join(shapes), len(b.chain), b.chain.length, peak, f" {shown}"))
    lines = fixed_columns(columns, rows)
    lines += [f"{b.name}: {b.road_3d}" for b in built if b.road_3d]
    lines += [f"{b.name}: {b.fit.line()}" for b in built if isinstance(b, BuiltFit | BuiltRoadFit)]
    lines += [f"{b.name}: {note}" for b in built for note in getattr(b, "notes", ())]
    lines += [f"{b.name}: {b.renamed}" for b in built if isinstance(b, BuiltLandXML) and b.renamed]
    lines += [f"{b.name}: {b.landxml_offset()}" for b in built if isinstance(b, BuiltLandXML) and b.run == 0]
    return "\n".join(lines)
