"""One door per verb for files: ``export`` writes and ``read`` reads every format, chosen by the suffix.

=========  ==============================  ======================================  ===================================
format     suffixes                        ``export`` writes with                   ``read`` returns (reader)
=========  ==============================  ======================================  ===================================
step       .step .stp                      ``cad.export.export_step``              an OCCT shape (``cad.readers.read_shape``)
iges       .iges .igs                      ``cad.export.export_iges``              an OCCT shape (``cad.readers.read_shape``)
dxf        .dxf                            ``cad.export.export_dxf``               its paths (``io.dxf_read.read_dxf_paths``)
svg        .svg                            ``cad.export.export_svg``               (not read)
gcode      .nc .ngc .gcode .tap …          ``io.gcode_write.write_gcode``          its exact path (``io.gcode.read_gcode_chain``)
landxml    .xml                            ``io.landxml.write_landxml``            its alignments (``io.landxml_read.read_landxml``)
opendrive  .xodr                           ``cad.export.export_opendrive``         its roads (``io.opendrive_read.read_opendrive``)
ifc        .ifc                            ``io.ifc.write_ifc``                    its alignments (``io.ifc.read_ifc_alignments``)
samples    .csv (export)                   ``cad.export.export_samples``           —
points     .csv .txt .xyz (read)           —                                       a point table (``io.points.read_points``)
=========  ==============================  ======================================  ===================================

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

__all__ = ["EXPORTS", "READS", "export", "read"]

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
    "gcode": (GCODE_SUFFIXES, "spiral_cad.io.gcode:read_gcode_chain"),
    "landxml": ((".xml",), "spiral_cad.io.landxml_read:read_landxml"),
    "opendrive": ((".xodr",), "spiral_cad.io.opendrive_read:read_opendrive"),
    "ifc": ((".ifc",), "spiral_cad.io.ifc:read_ifc_alignments"),
    "points": ((".csv", ".txt", ".xyz"), "spiral_cad.io.points:read_points"),
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


def _path(path: Any, verb: str) -> Path:
    """``path`` as a ``Path`` (``~`` expanded), or ValueError naming what was given instead."""
    if not isinstance(path, (str, os.PathLike)) or isinstance(path, bytes):
        raise ValueError(f"{verb}: path must be a file's path (str or os.PathLike); got {type(path).__name__}")
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
