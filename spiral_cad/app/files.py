"""One door per verb for files: ``export`` writes, ``read`` reads and ``check`` judges every format, chosen by
the suffix.

=========  ==============================  ======================================  ===================================
format     suffixes                        ``export`` writes with                   ``read`` returns (reader)
=========  ==============================  ======================================  ===================================
step       .step .stp                      ``cad.export.export_step``              an OCCT shape (``cad.readers.read_shape``)
iges       .iges .igs                      ``cad.export.export_iges``              an OCCT shape (``cad.readers.read_shape``)
dxf        .dxf                            ``cad.export.export_dxf``               its paths (``io.dxf_read.read_dxf_paths``)
svg        .svg                            ``cad.export.export_svg``               (not read)
gcode      .nc .ngc .gcode .tap …          ``io.gcode_write.write_gcode``          its cutting paths (``io.gcode_paths.read_gcode_runs``)
landxml    .xml                            ``io.landxml.write_landxml``            its alignments (``io.landxml_read.read_landxml``)
opendrive  .xodr                           ``cad.export.export_opendrive``         its roads (``io.opendrive_read.read_opendrive``)
ifc        .ifc                            ``io.ifc.write_ifc``                    its alignments (``io.ifc.read_ifc_alignments``)
samples    .csv (export)                   ``cad.export.export_samples``           —
points     .csv .txt .xyz (read)           —                                       a point table (``io.points.read_points``)
=========  ==============================  ======================================  ===================================

``check`` judges STEP/IGES (face to face where the file holds faces: ``cad.faces.check_faces``, else its
curves: ``cad.continuity.check_continuity``), DXF and G-code (their curves as drawn or programmed:
``cad.document_shapes.document_shape``, then ``check_continuity``), LandXML (its elements' own numbers:
``io.landxml_check.check_landxml``), OpenDRIVE (``io.opendrive_check.check_opendrive``) and IFC 4.3
(``io.ifc_check.check_ifc``: each alignment's plan and profile); an object (a build123d or CadQuery shape, an OCCT shape, a
``Chain``) is judged face to face when it holds faces, else curve by curve.

The options are the per-format function's own keyword options (``name``, ``units``, ``dialect`` …), passed on
as given; an option the format does not take is refused by name with the ones it does. ``format=`` chooses
the format for a file whose suffix names none (``road.landxml``); a suffix that names another format is
refused rather than overridden. The per-format functions stay the documented lower level.
"""

from __future__ import annotations

import importlib
import inspect
import os
from collections.abc import Callable
from pathlib import Path
from typing import Any

from ..io.gcode import SUFFIXES as GCODE_SUFFIXES

__all__ = ["CHECKS", "EXPORTS", "READS", "check", "export", "read"]

#: The longest file name (bytes) the usual file systems hold (ext4, APFS, NTFS in UTF-16 units).
_LONGEST_NAME = 255
#: ``export``'s formats: name → (suffixes, "module:function" of the writer).
EXPORTS: dict[str, tuple[tuple[str, ...], str]] = {
    "step": ((".step", ".stp"), "spiral_cad.cad.export:export_step"),
    "iges": ((".iges", ".igs"), "spiral_cad.cad.export:export_iges"),
    "dxf": ((".dxf",), "spiral_cad.cad.export:export_dxf"),
    "svg": ((".svg",), "spiral_cad.cad.export:export_svg"),
    "gcode": (GCODE_SUFFIXES, "spiral_cad.io.gcode_write:write_gcode"),
    "landxml": ((".xml",), "spiral_cad.io.landxml:write_landxml"),
    "opendrive": ((".xodr",), "spiral_cad.cad.export:export_opendrive"),
    "ifc": ((".ifc",), "spiral_cad.io.ifc:write_ifc"),
    "samples": ((".csv",), "spiral_cad.cad.export:export_samples"),
}
#: ``read``'s formats: name → (suffixes, "module:function" of the reader).
READS: dict[str, tuple[tuple[str, ...], str]] = {
    "step": ((".step", ".stp"), "spiral_cad.cad.readers:read_shape"),
    "iges": ((".iges", ".igs"), "spiral_cad.cad.readers:read_shape"),
    "dxf": ((".dxf",), "spiral_cad.io.dxf_read:read_dxf_paths"),
    "gcode": (GCODE_SUFFIXES, "spiral_cad.io.gcode_paths:read_gcode_runs"),
    "landxml": ((".xml",), "spiral_cad.io.landxml_read:read_landxml"),
    "opendrive": ((".xodr",), "spiral_cad.io.opendrive_read:read_opendrive"),
    "ifc": ((".ifc",), "spiral_cad.io.ifc:read_ifc_alignments"),
    "points": ((".csv", ".txt", ".xyz"), "spiral_cad.io.points:read_points"),
}
#: ``check``'s formats: name → (suffixes, "module:function" of the checker).
CHECKS: dict[str, tuple[tuple[str, ...], str]] = {
    "step": ((".step", ".stp"), "spiral_cad.app.files:_check_cad_file"),
    "iges": ((".iges", ".igs"), "spiral_cad.app.files:_check_cad_file"),
    "dxf": ((".dxf",), "spiral_cad.app.files:_check_curves"),
    "gcode": (GCODE_SUFFIXES, "spiral_cad.app.files:_check_curves"),
    "landxml": ((".xml",), "spiral_cad.app.files:_check_alignments"),
    "opendrive": ((".xodr",), "spiral_cad.app.files:_check_roads"),
    "ifc": ((".ifc",), "spiral_cad.app.files:_check_ifc"),
}


def export(obj: Any, path: str | os.PathLike, *, format: str | None = None, **options: Any) -> Any:
    """Write ``obj`` to ``path`` in the format its suffix names (or ``format``), with that format's options.

    Args:
        obj: what the format holds: a ``Chain`` or a list of them (every format), a build123d, CadQuery
            or OCP shape (STEP, IGES), an ``Alignment`` (LandXML, OpenDRIVE, IFC, G-code).
        path: the file to write.
        format: one of ``EXPORTS`` (default: chosen by the suffix of ``path``).
        **options: the keyword options of the format's writer (the table in the module docstring).

    Returns:
        What the format's writer returns (``export_samples``: the number of samples; ``write_gcode``
        and ``write_ifc``: the path written; else None).

    Raises:
        ValueError: an unknown suffix or format, an option the format does not take, or what the writer
            refuses (a name, a unit, an object it does not hold).
    """
    target = _path(path, "export")
    if len(os.fsencode(target.name)) > _LONGEST_NAME:
        raise ValueError(f"export {target.name!r:.80}…: a file name of {len(os.fsencode(target.name))} bytes; "
                         f"file systems hold at most {_LONGEST_NAME}")  # fmt: skip
    if target.is_dir():
        raise ValueError(f"export {target.name!r:.80}: is a folder; give a file's path")
    if not target.parent.is_dir():
        raise ValueError(f"export {target.name!r:.80}: its folder {str(target.parent)!r:.120} does not exist")
    writer = _chosen(EXPORTS, "export", target, format)
    return writer(obj, target, **_checked(writer, options, target))


def read(path: str | os.PathLike, *, format: str | None = None, **options: Any) -> Any:
    """Read ``path`` in the format its suffix names (or ``format``), with that format's options.

    Args:
        path: the file to read.
        format: one of ``READS`` (default: chosen by the suffix of ``path``).
        **options: the keyword options of the format's reader (the table in the module docstring).

    Returns:
        What the format's reader returns (the table in the module docstring).

    Raises:
        ValueError: an unknown suffix or format, an option the format does not take, or what the reader
            refuses (a missing or malformed file, named with the reason).
    """
    source = _path(path, "read")
    if not source.is_file():
        what = "is a folder" if source.is_dir() else "is not a regular file" if source.exists() else "does not exist"
        raise ValueError(f"read {source.name!r:.80}: the file {what}")
    reader = _chosen(READS, "read", source, format)
    return reader(source, **_checked(reader, options, source))


def check(obj_or_path: Any, *, format: str | None = None, html: str | os.PathLike | None = None, **options: Any) -> Any:
    """Judge G0/G1/G2 at every joint of a file or an object (the table in the module docstring).

    Example:
        ```python
        import spiral_cad as sc

        report = sc.check("part.step")          # a FaceReport: face to face
        report = sc.check("program.nc")         # a ContinuityReport: each cutting path
        print(report.describe())
        sc.check(part, html="part.html")        # also the page to turn and click (faces)
        ```

    Args:
        obj_or_path: a file's path, or a build123d/CadQuery/OCCT shape, a ``Chain`` or a ``Transition``.
        format: a file's format (``"step"``, ``"gcode"`` …) where its suffix names none.
        html: also write the report as one self-contained web page (``spiral_cad.app.html_report``): a
            part under zebra stripes or its curvature, every edge coloured by its verdict; curves with their
            comb, every joint coloured by its level (not for LandXML and OpenDRIVE files).
        **options: the chosen checker's keyword options (``gap_tol``, ``angle_tol``, ``curvature_tol`` …);
            for a program or drawing, ``units`` is the unit of one that states none.

    Returns:
        ``FaceReport`` for faces, ``ContinuityReport`` for curves (a drawing's, program's or LandXML file's
        ``notes`` say what was judged), ``OpenDriveReport`` for an OpenDRIVE file.

    Raises:
        ValueError: an unknown suffix or format, an option the checker does not take, or a file the reader
            refuses (named with the reason).
    """
    if html is None:
        return _check(obj_or_path, format, options)
    from .html_report import checked_page_path, write_html_report

    page = checked_page_path(html, obj_or_path, format)  # refused before anything is read
    report = _check(obj_or_path, format, options)
    source = _path(obj_or_path, "check") if isinstance(obj_or_path, (str, os.PathLike)) else obj_or_path
    write_html_report(report, source, page, units=options.get("units"))
    return report


def _check(obj_or_path: Any, format: str | None, options: dict[str, Any]) -> Any:
    """``check`` without its page."""
    if isinstance(obj_or_path, (str, os.PathLike)) and not isinstance(obj_or_path, bytes):
        source = _path(obj_or_path, "check")
        if not source.is_file():
            what = "is a folder" if source.is_dir() else "is not a regular file" if source.exists() else "does not exist"
            raise ValueError(f"check {source.name!r:.80}: the file {what}")
        return _chosen(CHECKS, "check", source, format)(source, **options)  # each checker checks its options
    if format is not None:
        raise ValueError("check: format= names a file's format; an object is judged as it is")
    if isinstance(obj_or_path, (bytes, dict)) or (isinstance(obj_or_path, (list, tuple)) and not obj_or_path):
        what = f"an empty {type(obj_or_path).__name__}" if not obj_or_path else f"a {type(obj_or_path).__name__}"
        raise ValueError(f"check: expected a file's path, a shape, a Chain or a Transition (or a list of shapes); got {what}")
    from OCP.TopAbs import TopAbs_FACE
    from OCP.TopExp import TopExp_Explorer

    from ..cad.continuity import check_continuity
    from ..cad.faces import check_faces
    from ..cad.occ import as_occ_shape
    from ..core.chain import Chain
    from ..core.transitions import Transition

    label = type(obj_or_path).__name__
    if isinstance(obj_or_path, Transition):  # its spirals, joint by joint
        obj_or_path = Chain(obj_or_path.spirals)
    try:
        shape = as_occ_shape(obj_or_path)
    except ValueError as error:
        raise ValueError(f"check: {error}") from None
    checker = check_faces if TopExp_Explorer(shape, TopAbs_FACE).More() else check_continuity
    options = _checked(checker, options, label)
    options.setdefault("label", label)
    if checker is check_continuity and hasattr(obj_or_path, "units"):  # a Chain's own unit
        options.setdefault("units", obj_or_path.units)
    return checker(shape, **options)


def _check_cad_file(path: Path, **options: Any) -> Any:
    """A STEP/IGES file: face to face where it holds faces, else curve by curve."""
    from ..cad.continuity import check_continuity
    from ..cad.faces import check_faces, holds_faces

    checker = check_faces if holds_faces(path) else check_continuity
    return checker(path, **_checked(checker, options, path))


def _check_curves(path: Path, **options: Any) -> Any:
    """A DXF drawing or a G-code program: its curves (``document_shape``), joint by joint."""
    import dataclasses

    from ..cad.continuity import check_continuity
    from ..cad.document_shapes import document_shape
    from ..cad.dxf_shape import DRAWING_UNITS

    options = _checked(check_continuity, options, path)
    shape, units, notes = document_shape(path, units=options.pop("units", None))  # the unit of a file that states none
    options["units"] = None if units == DRAWING_UNITS else units
    options.setdefault("label", path.name)
    return dataclasses.replace(check_continuity(shape, **options), notes=tuple(notes))


def _check_alignments(path: Path, **options: Any) -> Any:
    """A LandXML file: alignment by alignment, on the file's own numbers."""
    from ..io.landxml_check import check_landxml

    return check_landxml(path, **_checked(check_landxml, options, path))


def _check_roads(path: Path, **options: Any) -> Any:
    """An OpenDRIVE file: road by road and link by link."""
    from ..io.opendrive_check import check_opendrive

    return check_opendrive(path, **_checked(check_opendrive, options, path))


def _check_ifc(path: Path, **options: Any) -> Any:
    """An IFC 4.3 file: each alignment's plan as its geometry runs and its profile on its own numbers."""
    from ..io.ifc_check import check_ifc

    return check_ifc(path, **_checked(check_ifc, options, path))


def _path(path: Any, verb: str) -> Path:
    """``path`` as a ``Path`` (``~`` expanded), or ValueError naming what was given instead."""
    if not isinstance(path, (str, os.PathLike)) or isinstance(path, bytes):
        raise ValueError(f"{verb}: path must be a file's path (str or os.PathLike); got {type(path).__name__}")
    if not os.fspath(path):
        raise ValueError(f"{verb}: path is empty; give a file's path")
    return Path(path).expanduser()


def _chosen(formats: dict[str, tuple[tuple[str, ...], str]], verb: str, path: str | os.PathLike, format: str | None) -> Callable[..., Any]:
    """The function of ``format`` (any case, a leading dot allowed), or of the format whose suffixes hold
    ``path``'s; a suffix that names another format than ``format`` is refused."""
    suffix = Path(path).suffix.lower()
    found = [name for name, (suffixes, _) in formats.items() if suffix in suffixes]
    if format is not None:
        chosen = format.lower().lstrip(".") if isinstance(format, str) else ""
        chosen = next((name for name, (suffixes, _) in formats.items() if f".{chosen}" in suffixes), chosen)
        if chosen not in formats:
            raise ValueError(f"format must be one of {', '.join(formats)} for {verb}; got {format!r:.40}")
        if found and chosen not in found:
            raise ValueError(f"{verb} {Path(path).name!r:.80}: format={format!r} but the suffix {suffix!r} names "
                             f"{' or '.join(found)}; rename the file or leave format= out")  # fmt: skip
    else:
        if not found:
            known = " ".join(s for suffixes, _ in formats.values() for s in suffixes)
            raise ValueError(f"{verb} {Path(path).name!r:.80}: the suffix {suffix or '(none)'!r} names no format {verb} knows "
                             f"({known}); give format= one of {', '.join(formats)}")  # fmt: skip
        chosen = found[0]
    module, name = formats[chosen][1].split(":")
    return getattr(importlib.import_module(module), name)


def _checked(function: Callable[..., Any], options: dict[str, Any], path: str | os.PathLike) -> dict[str, Any]:
    """``options`` when ``function`` takes each of them by keyword; else ValueError naming the one it does not."""
    parameters = list(inspect.signature(function).parameters.values())[1:]  # after the object or the path
    taken = [p.name for p in parameters if p.kind in (p.POSITIONAL_OR_KEYWORD, p.KEYWORD_ONLY) and p.name != "path"]
    for key in options:
        if key not in taken:
            raise ValueError(f"{Path(path).name!r:.80}: {function.__name__} takes the options {', '.join(taken) or '(none)'}; "
                             f"got {key!r:.40}")  # fmt: skip
    return options
