"""``spiral-cad g2``: a user's document in, the same document out, made G2 (one file in, one file out).

The document's kind is told by its suffix, through ``REWRITERS``: a table from suffix to the function
that rewrites that kind of document in place, ``function(src, dst, max_deviation, **options) -> report``,
where the report has ``lines()`` (the short report, one line per path) and ``below_g2`` (what was left
below G2: split, or kept as it was for a reason; the command exits 1 on it unless splits are allowed). G-code programs (``.nc .ngc .gcode .tap``) are
registered here (``spiral_cad.io.gcode_inplace.rewrite_gcode_g2``), and so are DXF drawings
(``spiral_cad.io.dxf_g2.rewrite_dxf_g2``), LandXML files (``spiral_cad.io.landxml_g2.rewrite_landxml_g2``)
OpenDRIVE files (``spiral_cad.io.opendrive_g2.rewrite_opendrive_g2``) and the wires of STEP and IGES
files (``spiral_cad.cad.step_g2.rewrite_step_g2``, ``rewrite_iges_g2``);
other kinds register with ``register_rewriter``; any other suffix is an error naming it.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from pathlib import Path
from typing import Any

from ..io.gcode_inplace import GCODE_SUFFIXES

__all__ = ["REWRITERS", "make_document_g2", "register_rewriter", "rewriter_for"]

Rewriter = Callable[..., Any]

#: Suffix (lower case, with its dot) → the function that makes such a document G2 in place.
REWRITERS: dict[str, Rewriter] = {}


def register_rewriter(suffixes: tuple[str, ...], function: Rewriter) -> None:
    """Make ``function(src, dst, max_deviation, **options)`` the rewriter of documents ending in ``suffixes``.

    Raises:
        ValueError: a suffix without its leading dot.
    """
    for suffix in suffixes:
        if not suffix.startswith("."):
            raise ValueError(f"a suffix starts with a dot; got {suffix!r}")
        REWRITERS[suffix.lower()] = function


def _gcode(src: str | os.PathLike, dst: str | os.PathLike, max_deviation: float, **options: Any) -> Any:
    from ..io.gcode_inplace import rewrite_gcode_g2

    if options.get("units", "mm") not in ("mm", "in"):
        raise ValueError(f"{Path(src).name}: a G-code program is in mm (G21) or in (G20); got units={options['units']!r}")
    return rewrite_gcode_g2(src, dst, max_deviation, **options)


def _refuse(src: str | os.PathLike, options: dict[str, Any], name: str, why: str) -> None:
    """Refuse an option this kind of document does not take, by name."""
    if name in options:
        raise ValueError(f"{Path(src).name}: {name}={options[name]!r} does not apply ({why})")


def _dxf(src: str | os.PathLike, dst: str | os.PathLike, max_deviation: float, **options: Any) -> Any:
    from ..io.dxf_g2 import rewrite_dxf_g2

    _refuse(src, options, "dialect", "a G-code option")
    return rewrite_dxf_g2(Path(src), Path(dst), max_deviation, **options)


def _landxml(src: str | os.PathLike, dst: str | os.PathLike, max_deviation: float, **options: Any) -> Any:
    from ..io.landxml_g2 import rewrite_landxml_g2

    _refuse(src, options, "units", "a LandXML file states its own unit, and max_deviation is in it")
    _refuse(src, options, "dialect", "a G-code option")
    return rewrite_landxml_g2(Path(src), Path(dst), max_deviation, **options)


def _opendrive(src: str | os.PathLike, dst: str | os.PathLike, max_deviation: float, **options: Any) -> Any:
    from ..io.opendrive_g2 import rewrite_opendrive_g2

    _refuse(src, options, "units", "an OpenDRIVE file is in metres, and max_deviation is in metres")
    _refuse(src, options, "dialect", "a G-code option")
    return rewrite_opendrive_g2(Path(src), Path(dst), max_deviation, **options)


def _step(src: str | os.PathLike, dst: str | os.PathLike, max_deviation: float, **options: Any) -> Any:
    from ..cad.step_g2 import rewrite_step_g2

    _refuse(src, options, "units", "a STEP file states its own unit, and max_deviation is in it")
    _refuse(src, options, "dialect", "a G-code option")
    return rewrite_step_g2(src, dst, max_deviation, **options)


def _iges(src: str | os.PathLike, dst: str | os.PathLike, max_deviation: float, **options: Any) -> Any:
    from ..cad.step_g2 import rewrite_iges_g2

    _refuse(src, options, "units", "an IGES file states its own unit, and max_deviation is in it")
    _refuse(src, options, "dialect", "a G-code option")
    return rewrite_iges_g2(src, dst, max_deviation, **options)


register_rewriter(GCODE_SUFFIXES, _gcode)
register_rewriter((".dxf",), _dxf)
register_rewriter((".xml",), _landxml)
register_rewriter((".xodr",), _opendrive)
register_rewriter((".step", ".stp"), _step)
register_rewriter((".igs", ".iges"), _iges)


def rewriter_for(path: str | os.PathLike) -> Rewriter:
    """The rewriter of a document, by its suffix.

    Raises:
        ValueError: a suffix with no rewriter (naming it, and the suffixes that have one).
    """
    suffix = Path(path).suffix.lower()
    if suffix in REWRITERS:
        return REWRITERS[suffix]
    known = " ".join(sorted(REWRITERS))
    raise ValueError(f"{Path(path).name}: no document kind has the suffix {suffix or '(none)'!r}; documents made G2 in place: {known}")


def make_document_g2(src: str | os.PathLike, dst: str | os.PathLike, max_deviation: float, **options: Any) -> Any:
    """Make the document ``src`` G2 in place within ``max_deviation`` (the document's own unit) and write it to ``dst``.

    Args:
        src, dst: the input and output files (the output's suffix must be the input's kind).
        max_deviation: the bound, in the document's unit (a G-code program's G20/G21).
        options: the kind's own options (G-code: ``dialect``, ``shape``, ``units``).

    Returns:
        The kind's report (``lines()``: the short report; ``below_g2``: what was left below G2, split or kept
        as it was for a reason).

    Raises:
        ValueError: a suffix with no rewriter, an output of another kind, what the rewriter refuses.
        OSError: a file could not be read or written.
    """
    function = rewriter_for(src)
    if rewriter_for(dst) is not function:
        raise ValueError(f"the output {Path(dst).name} is not the kind of document {Path(src).name} is")
    if Path(src).resolve() == Path(dst).resolve() or (Path(src).exists() and Path(dst).exists() and os.path.samefile(src, dst)):
        raise ValueError(f"the output {Path(dst).name} is the input: write to another file")  # (a link to it, too)
    if not Path(dst).parent.is_dir():
        raise ValueError(f"the output's folder {str(Path(dst).parent)!r} does not exist")
    return function(src, dst, max_deviation, **options)
