"""SVG: one path per chain with exact commands (L, A, cubic C), drawn at true size.

``width``/``height`` carry a physical unit (mm for metric designs, in for
in/ft) and the ``viewBox`` is in the chain's own units, so a viewer or an
importer (Inkscape) shows the drawing at its real size and the path data
keep the model coordinates. The design name is the ``title`` and, as an
XML name (``formats.names.xml_id``), the ``id`` of the group (``NAME-drawing``)
and of the path; with several chains each path's id is ``NAME-k``.
"""

from __future__ import annotations

import math
import numbers
import os
from collections.abc import Sequence
from xml.sax.saxutils import escape, quoteattr

import numpy as np

from ..core.chain import Chain
from ..core.segments import Arc, Line, Segment
from ..core.spiral import BezierSpiral
from ..core.units import IMPERIAL, MM_PER_UNIT
from .decimals import shortest_decimal
from .names import xml_id


def _num(value: float) -> str:
    return shortest_decimal(value, "SVG")


def _point(p) -> str:
    return f"{_num(p[0])} {_num(-p[1])}"  # SVG's y axis points down


def _commands(seg: Segment) -> list[str]:
    if isinstance(seg, Line):
        return [f"L {_point(seg.end)}"]
    if isinstance(seg, BezierSpiral):
        _, b1, b2, b3 = seg.control_points
        return [f"C {_point(b1)} {_point(b2)} {_point(b3)}"]
    if isinstance(seg, Arc):
        # Pieces of at most 180° need no large-arc flag; with y flipped a
        # counterclockwise arc turns with sweep-flag 0.
        pieces = max(1, math.ceil(seg.sweep / math.pi - 1e-12))
        r, flag = _num(abs(seg.radius)), 0 if seg.radius > 0 else 1
        ends = seg.point(np.arange(1, pieces + 1) / pieces)
        return [f"A {r} {r} 0 0 {flag} {_point(p)}" for p in ends]
    raise ValueError(f"segment must be a Line, Arc or BezierSpiral; got {seg!r}")


def svg_path(chain: Chain) -> str:
    """The ``d`` attribute of one SVG path for ``chain`` (y flipped)."""
    commands = [f"M {_point(chain.start)}"]
    for seg in chain:
        commands.extend(_commands(seg))
    return " ".join(commands)


def svg_text(chains: Sequence[Chain], name: str, units: str, margin: float = 0.05) -> str:
    """The SVG document (see the module docstring); ``margin`` is a fraction of the drawing's size.

    Raises:
        ValueError: a margin that is not a finite number ≥ 0.
    """
    if isinstance(margin, bool) or not isinstance(margin, numbers.Real) or not 0.0 <= margin < math.inf:
        raise ValueError(f"margin must be a finite number ≥ 0 (a fraction of the drawing's size); got {margin!r:.40}")
    points = np.vstack([c.sample(64) for c in chains])
    lo, hi = points.min(axis=0), points.max(axis=0)
    size = float(np.hypot(*(hi - lo))) or 1.0
    pad = margin * size
    x, y = lo[0] - pad, -hi[1] - pad
    width, height = hi[0] - lo[0] + 2 * pad, hi[1] - lo[1] + 2 * pad
    physical, per_unit = ("in", MM_PER_UNIT[units] / 25.4) if units in IMPERIAL else ("mm", MM_PER_UNIT[units])
    ids = [xml_id(name)] if len(chains) == 1 else [xml_id(f"{name}-{i + 1}") for i in range(len(chains))]
    lines = [
        '<?xml version="1.0" encoding="UTF-8"?>',
        f'<svg xmlns="http://www.w3.org/2000/svg" width="{_num(width * per_unit)}{physical}" '
        f'height="{_num(height * per_unit)}{physical}" viewBox="{_num(x)} {_num(y)} {_num(width)} {_num(height)}">',
        f"<title>{escape(name)} (units: {units})</title>",
        f'<g id={quoteattr(xml_id(name + "-drawing"))} fill="none" stroke="black" stroke-width="{_num(0.004 * size)}" '
        'stroke-linecap="round" stroke-linejoin="round">',
    ]
    lines += [f"<path id={quoteattr(i)} d={quoteattr(svg_path(chain))}/>" for i, chain in zip(ids, chains)]
    lines += ["</g>", "</svg>", ""]
    return "\n".join(lines)


def write_svg(chains: Sequence[Chain], path: str | os.PathLike, name: str, units: str, margin: float = 0.05) -> None:
    """Write ``svg_text(chains, name, units, margin)`` to ``path`` (UTF-8); ``cad.export.export_svg`` checks the arguments first.

    The text is made before the file is opened: a refused argument leaves an existing file as it was.

    Raises:
        ValueError: as ``svg_text``.
        OSError: the file could not be written.
    """
    text = svg_text(chains, name, units, margin)
    with open(path, "w", encoding="utf-8") as handle:
        handle.write(text)
