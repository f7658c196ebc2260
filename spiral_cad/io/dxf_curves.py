"""A DXF ``SPLINE`` or ``ELLIPSE`` in the plane as biarc parts (``spiral_cad.io.curve_biarcs``), so that the paths
it belongs to can be made G2 with it (``spiral_cad.io.dxf_g2``).

The curve is evaluated from the entity's own definition: a ``SPLINE``'s control points, knots, weights and
degree (ezdxf's construction tool, which also turns a spline given by fit points into control points), an
``ELLIPSE``'s centre, major axis, ratio and parameters. A single cubic Bézier span (what a G2 rewrite writes for
each spiral) is not turned into biarcs: it is kept as the exact curve it is.
"""

from __future__ import annotations

import math
from functools import partial
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy.interpolate import BSpline

from ..core.segments import Arc, Segment
from .curve_biarcs import curve_biarcs, rational_spline_at

__all__ = ["CURVES", "curve_parts"]

#: The entities read as biarcs.
CURVES = ("SPLINE", "ELLIPSE")


def curve_parts(entity: Any, kind: str, tolerance: float) -> list[tuple] | None:
    """The parts (as ``dxf_read`` gives them: ``("line", start, end, None)``, ``("arc", start, end, (centre, normal,
    sweep))``) of biarcs within ``tolerance`` of a plane ``SPLINE`` or ``ELLIPSE`` at z = 0; None for a curve
    kept as it is (out of that plane, a single cubic Bézier span, one that cannot be evaluated).

    Raises:
        ValueError: a curve that needs more biarcs than ``curve_biarcs`` makes.
    """
    try:
        found = _spline(entity) if kind == "SPLINE" else _ellipse(entity) if kind == "ELLIPSE" else None
    except (ValueError, ArithmeticError, AttributeError, IndexError):  # a malformed curve: kept as it is
        return None
    if found is None:
        return None
    at, breaks = found
    return [_part(segment) for segment in curve_biarcs(at, breaks, tolerance)]


def _part(segment: Segment) -> tuple:
    start, end = (np.append(np.asarray(p, dtype=float), 0.0) for p in (segment.start, segment.end))
    if not isinstance(segment, Arc):
        return ("line", start, end, None)
    return ("arc", start, end, (np.append(np.asarray(segment.center, dtype=float), 0.0),
                                np.array([0.0, 0.0, math.copysign(1.0, segment.radius)]), float(segment.sweep)))  # fmt: skip


def _unit(d: NDArray[np.float64]) -> NDArray[np.float64]:
    with np.errstate(invalid="ignore", divide="ignore"):
        return d / np.linalg.norm(d, axis=-1, keepdims=True)


def _spline(entity: Any) -> tuple[Any, NDArray[np.float64]] | None:
    tool = entity.construction_tool()
    controls = np.array([tuple(p) for p in tool.control_points], dtype=float)
    knots = np.array(tool.knots(), dtype=float)
    degree = int(tool.degree)
    weights = np.array(tool.weights(), dtype=float) if tool.is_rational else np.ones(len(controls))
    if len(controls) < degree + 1 or np.abs(controls[:, 2]).max() > 0.0 or not np.all(weights > 0.0):
        return None
    if degree == 3 and len(controls) == 4 and not tool.is_rational:
        return None  # one cubic Bézier span: exact as it is
    curve = BSpline(knots, np.column_stack([controls[:, :2] * weights[:, None], weights]), degree)
    lo, hi = float(knots[degree]), float(knots[len(knots) - degree - 1])
    breaks = np.unique(knots[(knots >= lo) & (knots <= hi)])
    return partial(rational_spline_at, curve), breaks


def _ellipse(entity: Any) -> tuple[Any, NDArray[np.float64]] | None:
    centre = np.array(tuple(entity.dxf.center), dtype=float)
    major = np.array(tuple(entity.dxf.major_axis), dtype=float)
    normal = np.array(tuple(entity.dxf.get("extrusion", (0.0, 0.0, 1.0))), dtype=float)
    if centre[2] != 0.0 or major[2] != 0.0 or not (normal[0] == normal[1] == 0.0 and normal[2] != 0.0):
        return None
    minor = float(entity.dxf.ratio) * np.cross(normal / np.linalg.norm(normal), major)
    t0, t1 = float(entity.dxf.start_param), float(entity.dxf.end_param)
    t1 = t1 if t1 > t0 else t1 + 2.0 * math.pi  # the curve runs counter-clockwise about its extrusion

    def at(t: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        c, s = np.cos(t)[:, None], np.sin(t)[:, None]
        return centre[:2] + c * major[:2] + s * minor[:2], _unit(-s * major[:2] + c * minor[:2])

    quarters = max(1, math.ceil((t1 - t0) / (math.pi / 2.0)))
    return at, np.linspace(t0, t1, quarters + 1)
