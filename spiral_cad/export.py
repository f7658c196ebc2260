"""Writers for STEP, IGES, DXF and SVG, plus the STEP/IGES readers used to check them.

Every format receives the exact curves: true lines and circular arcs, and
each spiral as its cubic Bézier (STEP/IGES through the OCCT edges of
``spiral_cad.occ``; DXF as a degree-3 SPLINE with the four control points
and Bézier knots; SVG as a ``C`` command).
"""

from __future__ import annotations

import io
import math
import os
from collections.abc import Iterable
from typing import Any
from xml.sax.saxutils import quoteattr

import numpy as np

from .core.chain import Chain
from .core.segments import Arc, Line, Segment
from .core.spiral import BezierSpiral

PathLike = str | os.PathLike

#: Knot vector of one cubic Bézier written as a B-spline (DXF SPLINE).
BEZIER_KNOTS = (0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0)


def _chains(obj: Any) -> list[Chain]:
    """``obj`` as a list of chains (a Chain or an iterable of Chains)."""
    if isinstance(obj, Chain):
        return [obj]
    if isinstance(obj, Iterable) and not isinstance(obj, (str, bytes)):
        chains = list(obj)
        if chains and all(isinstance(c, Chain) for c in chains):
            return chains
    raise ValueError(f"expected a Chain or a list of Chains; got {obj!r}")


# ------------------------------------------------------------------ STEP / IGES


def export_step(obj: Any, path: PathLike) -> None:
    """Write ``obj`` (Chain, list of Chains, build123d/CadQuery or OCP shape) as STEP (AP214).

    Reals are written with 17 significant digits, so coordinates survive
    the round trip bit for bit.

    Raises:
        ValueError: ``obj`` is of an unsupported kind.
        OSError: the writer failed.
    """
    from OCP.IFSelect import IFSelect_ReturnStatus
    from OCP.StepAP214 import StepAP214
    from OCP.STEPControl import STEPControl_AsIs, STEPControl_Writer
    from OCP.StepData import StepData_StepWriter

    from .cad.occ import as_occ_shape, quiet_messages

    writer = STEPControl_Writer()
    with quiet_messages():
        status = writer.Transfer(as_occ_shape(obj), STEPControl_AsIs)
    if status != IFSelect_ReturnStatus.IFSelect_RetDone:
        raise OSError(f"STEP transfer failed for {obj!r}")
    # STEPControl_Writer.Write prints 13 significant digits; 17 keep every double.
    printer = StepData_StepWriter(writer.Model())
    printer.FloatWriter().SetFormat("%.16E")
    printer.SendModel(StepAP214.Protocol_s())
    _print_to(printer, path, "STEP")


def _print_to(printer, path: PathLike, kind: str) -> None:
    """Write what an OCCT ``*_Writer`` printer holds to ``path``."""
    buffer = io.BytesIO()
    if not printer.Print(buffer):
        raise OSError(f"could not print the {kind} model for {os.fspath(path)!r}")
    with open(path, "wb") as handle:
        handle.write(buffer.getvalue())


def export_iges(obj: Any, path: PathLike) -> None:
    """Write ``obj`` as IGES in BRep mode, keeping circles (entity 100) and Béziers (126, exact).

    BRep mode (``write.iges.brep.mode`` = 1) writes the edges' own curves;
    nothing is converted to B-spline approximations.

    Raises:
        ValueError: ``obj`` is of an unsupported kind.
        OSError: the writer failed.
    """
    from OCP.IGESControl import IGESControl_Controller, IGESControl_Writer
    from OCP.IGESData import IGESData_IGESWriter
    from OCP.IGESSelect import IGESSelect_WorkLibrary
    from OCP.Interface import Interface_Static

    from .cad.occ import as_occ_shape, quiet_messages

    IGESControl_Controller.Init_s()
    Interface_Static.SetIVal_s("write.iges.brep.mode", 1)
    Interface_Static.SetIVal_s("write.convertsurface.mode", 0)
    writer = IGESControl_Writer("MM", 1)
    with quiet_messages():
        if not writer.AddShape(as_occ_shape(obj)):
            raise OSError(f"IGES transfer failed for {obj!r}")
        writer.ComputeModel()
    # IGESControl_Writer.Write prints reals with 9 decimals (~5e-10 absolute);
    # printing the model ourselves with 17 significant digits keeps every double.
    printer = IGESData_IGESWriter(writer.Model())
    printer.FloatWriter().SetFormat("%.16E")
    printer.SendModel(IGESSelect_WorkLibrary.DefineProtocol_s())
    _print_to(printer, path, "IGES")


# ------------------------------------------------------------------------ DXF


def _dxf_add(msp, seg: Segment) -> None:
    if isinstance(seg, Line):
        msp.add_line(tuple(seg.start), tuple(seg.end))
    elif isinstance(seg, Arc):
        # DXF arcs run counterclockwise: a clockwise arc is written from its end.
        a, b = math.degrees(seg.start_angle), math.degrees(seg.start_angle + math.copysign(seg.sweep, seg.radius))
        start, end = (a, b) if seg.radius > 0 else (b, a)
        msp.add_arc(tuple(seg.center), abs(seg.radius), start, end)
    elif isinstance(seg, BezierSpiral):
        spline = msp.add_open_spline([(*p, 0.0) for p in seg.control_points.tolist()], degree=3, knots=BEZIER_KNOTS)
        spline.dxf.flags |= spline.PLANAR
    else:
        raise ValueError(f"segment must be a Line, Arc or BezierSpiral; got {seg!r}")


def export_dxf(obj: Chain | Iterable[Chain], path: PathLike) -> None:
    """Write chains as DXF (R2010): LINE, ARC and exact cubic SPLINE entities, in travel order.

    A full-circle arc is written as an ARC from an angle to itself plus 360°.
    """
    import ezdxf

    doc = ezdxf.new("R2010", setup=False)
    msp = doc.modelspace()
    for chain in _chains(obj):
        for seg in chain:
            _dxf_add(msp, seg)
    doc.saveas(os.fspath(path))


# ------------------------------------------------------------------------ SVG


def _num(value: float) -> str:
    return f"{value:.15g}"


def _svg_point(p) -> str:
    return f"{_num(p[0])} {_num(-p[1])}"  # SVG's y axis points down


def _svg_commands(seg: Segment) -> list[str]:
    if isinstance(seg, Line):
        return [f"L {_svg_point(seg.end)}"]
    if isinstance(seg, BezierSpiral):
        _, b1, b2, b3 = seg.control_points
        return [f"C {_svg_point(b1)} {_svg_point(b2)} {_svg_point(b3)}"]
    if isinstance(seg, Arc):
        # Pieces of at most 180° need no large-arc flag; with y flipped a
        # counterclockwise arc turns with sweep-flag 0.
        pieces = max(1, math.ceil(seg.sweep / math.pi - 1e-12))
        r, flag = _num(abs(seg.radius)), 0 if seg.radius > 0 else 1
        ends = seg.point(np.arange(1, pieces + 1) / pieces)
        return [f"A {r} {r} 0 0 {flag} {_svg_point(p)}" for p in ends]
    raise ValueError(f"segment must be a Line, Arc or BezierSpiral; got {seg!r}")


def svg_path(chain: Chain) -> str:
    """The ``d`` attribute of one SVG path for ``chain`` (y flipped)."""
    commands = [f"M {_svg_point(chain.start)}"]
    for seg in chain:
        commands.extend(_svg_commands(seg))
    return " ".join(commands)


def export_svg(obj: Chain | Iterable[Chain], path: PathLike, margin: float = 0.05) -> None:
    """Write chains as an SVG drawing: one ``path`` per chain, viewBox fitted.

    Args:
        obj: a Chain or a list of Chains.
        path: output file.
        margin: border around the drawing, as a fraction of its size.
    """
    chains = _chains(obj)
    points = np.vstack([c.sample(64) for c in chains])
    lo, hi = points.min(axis=0), points.max(axis=0)
    size = float(np.hypot(*(hi - lo))) or 1.0
    pad = margin * size
    x, y = lo[0] - pad, -hi[1] - pad
    width, height = hi[0] - lo[0] + 2 * pad, hi[1] - lo[1] + 2 * pad
    stroke = _num(0.004 * size)
    lines = [
        '<?xml version="1.0" encoding="UTF-8"?>',
        f'<svg xmlns="http://www.w3.org/2000/svg" viewBox="{_num(x)} {_num(y)} {_num(width)} {_num(height)}">',
        f'<g fill="none" stroke="black" stroke-width="{stroke}" stroke-linecap="round" stroke-linejoin="round">',
    ]
    lines += [f"<path d={quoteattr(svg_path(chain))}/>" for chain in chains]
    lines += ["</g>", "</svg>", ""]
    with open(path, "w", encoding="utf-8") as handle:
        handle.write("\n".join(lines))
