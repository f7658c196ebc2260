"""G0/G1/G2 at every joint of an IFC 4.3 file's alignments: the plan as its geometry runs, the profile on its
own numbers.

Each ``IfcAlignment`` gives up to two pieces:

* **the plan**: one element per segment of the horizontal ``IfcCompositeCurve`` (its representation), placed
  and run as ifcopenshell's geometry evaluates it (every parent curve IFC 4.3 allows: lines, circles,
  clothoids, the polynomial and trigonometric spirals), so a gap or a kink between segments is what a
  reader of the geometry meets. The curvature at each end is the one the matching
  ``IfcAlignmentHorizontalSegment`` states (``StartRadiusOfCurvature``, ``EndRadiusOfCurvature``; 0 is
  straight, positive turns left): the design's own numbers, exact where the geometry's would be a
  difference quotient.
* **the profile**: one element per ``IfcAlignmentVerticalSegment``, in the plane (distance along, height),
  from its own numbers: it starts at ``StartDistAlong``, ``StartHeight`` with ``StartGradient`` and ends
  ``HorizontalLength`` further where its type takes it (a constant gradient, a parabolic arc from
  ``StartGradient`` to ``EndGradient``, a circular arc between them); its curvature is that of the curve
  z(s) there. Other types (a vertical clothoid) are not measured: their joints are "unmeasurable".

Zero-length segments (the one that ends every layout) are left out; the joint is across them. The
measures and tolerances are those of every checker (``spiral_cad.continuity.joints``): by default a gap of
the file's geometric precision (its representation context's ``Precision``, 1e-5 m where it states none)
or 1e-6 of the model's size if larger, an angle of twice that gap over the shortest segment, and a
relative curvature jump of 1e-6. Lengths are in the file's unit.
"""

from __future__ import annotations

import math
import os
from dataclasses import replace
from typing import Any

import numpy as np

from ..continuity.joints import ContinuityReport, check_tolerances, classify_pieces, model_size
from .ifc import _representation_curves, layout_segments, open_alignment_model

__all__ = ["DEFAULT_PRECISION", "RELATIVE_GAP", "check_ifc"]

#: The geometric precision of a representation context that states none (IFC's default), in metres.
DEFAULT_PRECISION = 1e-5
#: The default gap tolerance's floor relative to the model's size (1 mm on a 1 km road).
RELATIVE_GAP = 1e-6
#: Segments shorter than this share of the longest are slivers: the angle tolerance is not taken from them.
_SLIVER_SHARE = 1e-3


def check_ifc(path: str | os.PathLike, *, gap_tol: float | None = None, angle_tol: float | None = None,
              curvature_tol: float | None = None) -> ContinuityReport:  # fmt: skip
    """Every joint of every alignment of the IFC 4.3 file ``path``: its plan and its profile (see the module).

    Args:
        path: the file.
        gap_tol: largest G0 gap (the file's unit); None: from the file's precision and size.
        angle_tol: largest G1 tangent angle (radians); None: from the gap and the segments' lengths.
        curvature_tol: largest G2 curvature jump, relative to ``max(|κa|, |κb|, 1/size)``; None: 1e-6.

    Returns:
        A ``ContinuityReport`` with a piece per plan and per profile (named after the alignment), its
        ``notes`` saying how the file was read and which tolerances were used.

    Raises:
        ValueError: not a readable IFC 4.3 file, no alignment with a horizontal layout and its curve, or a
            bad tolerance.
    """
    check_tolerances(**{k: v for k, v in (("gap_tol", gap_tol), ("angle_tol", angle_tol), ("curvature_tol", curvature_tol))
                        if v is not None})  # fmt: skip
    source = os.path.basename(os.fspath(path))
    model, metres = open_alignment_model(path)
    units = _unit_name(metres)
    pieces: list[tuple] = []
    lengths: list[float] = []
    notes: list[str] = []
    precisions: list[float] = []
    alignments: list[Any] = list(model.by_type("IfcAlignment"))
    for number, alignment in enumerate(alignments, 1):
        name = alignment.Name or f"alignment {number}"
        layouts = [obj for rel in alignment.IsNestedBy for obj in rel.RelatedObjects]
        horizontal = next((layout for layout in layouts if layout.is_a("IfcAlignmentHorizontal")), None)
        curve = _representation_curves(alignment).get("IfcCompositeCurve")  # the gradient curve's base curve, or its own
        if horizontal is None or curve is None:
            notes.append(f"alignment {name!r}: no horizontal layout with its IfcCompositeCurve: not judged")
            continue
        precisions.append(_precision(curve, model))
        frames, stated = _plan_frames(curve, layout_segments(horizontal), metres, name, notes)
        pieces.append(("plan", frames, False, f"{name} plan"))
        lengths += stated
        vertical = next((layout for layout in layouts if layout.is_a("IfcAlignmentVertical")), None)
        if vertical is not None:
            frames, stated = _profile_frames(layout_segments(vertical), name, notes)
            if frames:
                pieces.append(("profile", frames, False, f"{name} profile"))
                lengths += stated
    if not pieces:
        raise ValueError(f"{source}: no alignment with a horizontal layout and its curve to judge")
    points = np.array([frame[:3] for _, frames, *_ in pieces for pair in frames for frame in pair])
    size = model_size(points, source)
    stated_tolerances = []
    if gap_tol is None:
        precision = max(precisions, default=DEFAULT_PRECISION / metres)
        gap_tol = max(1e-7, precision, RELATIVE_GAP * size)
        stated_tolerances.append(f"gap {gap_tol:.3g} (the file's precision {precision:.3g}, or 1e-6 of its size)")
    if angle_tol is None:
        real = [length for length in lengths if length > _SLIVER_SHARE * max(lengths)]
        angle_tol = max(1e-7, 2.0 * gap_tol / min(real))
        stated_tolerances.append(f"angle {angle_tol:.3g} rad")
    if curvature_tol is None:
        curvature_tol = 1e-6
    report = classify_pieces(pieces, size, gap_tol=gap_tol, angle_tol=angle_tol, curvature_tol=curvature_tol, source=source,
                             element="segment", units=units)  # fmt: skip
    notes.insert(0, "the plan as ifcopenshell evaluates its curve's segments, with the curvatures its layout states; "
                    "the profile from its vertical segments' own numbers")  # fmt: skip
    if stated_tolerances:
        notes.append(f"tolerances from the file: {', '.join(stated_tolerances)}; give them to judge otherwise")
    return replace(report, notes=tuple(notes))


def _unit_name(metres: float) -> str:
    """The unit of ``metres`` per unit, by name where it is one of ours (else ``"m×{metres}"``, never a wrong one)."""
    from ..core.units import MM_PER_UNIT

    for name, mm in MM_PER_UNIT.items():
        if math.isclose(mm / 1000.0, metres, rel_tol=1e-12):
            return name
    return f"{metres:g} m"


def _precision(curve: Any, model: Any) -> float:
    """The precision of the representation context ``curve`` is drawn in (a sub-context's parent's), in the file's unit."""
    for representation in model.get_inverse(curve):
        if representation.is_a("IfcShapeRepresentation"):
            context = representation.ContextOfItems
            while context.is_a("IfcGeometricRepresentationSubContext"):
                context = context.ParentContext
            if context.Precision:
                return float(context.Precision)
    return DEFAULT_PRECISION


def _plan_frames(curve: Any, design: list[Any], metres: float, name: str, notes: list[str]) -> tuple[list, list[float]]:
    """Per non-zero segment of ``curve``, its (start, end) frames in the file's unit (curvature from ``design``)."""
    import ifcopenshell.geom
    import ifcopenshell.ifcopenshell_wrapper as wrapper

    settings = ifcopenshell.geom.settings()
    segments = list(curve.Segments)
    if len(design) != len(segments):
        notes.append(f"alignment {name!r}: {len(design)} horizontal segments for {len(segments)} curve segments: "
                     "curvatures taken in order")  # fmt: skip
    frames, lengths = [], []
    for k, segment in enumerate(segments):
        function = wrapper.map_shape(settings, segment)
        length = float(function.length())
        if length == 0.0:
            continue
        evaluate = wrapper.function_item_evaluator(settings, function).evaluate
        radii = (
            (float(design[k].StartRadiusOfCurvature or 0.0), float(design[k].EndRadiusOfCurvature or 0.0))
            if k < len(design)
            else (math.nan, math.nan)
        )
        ends = []
        for at, radius in ((0.0, radii[0]), (length, radii[1])):
            matrix = np.array(evaluate(at))
            point, tangent = matrix[:3, 3] / metres, matrix[:3, 0] / np.linalg.norm(matrix[:3, 0])
            curvature = 0.0 if radius == 0.0 else 1.0 / radius * metres  # 1/unit; positive turns left
            normal = np.array([-tangent[1], tangent[0], 0.0])
            ends.append((*point.tolist(), *tangent.tolist(), *(curvature * normal).tolist()))
        frames.append(tuple(ends))
        lengths.append(length / metres)
    return frames, lengths


def _profile_frames(design: list[Any], name: str, notes: list[str]) -> tuple[list, list[float]]:
    """Per non-zero vertical segment, its (start, end) frames in the plane (distance along, height)."""
    frames, lengths = [], []
    unmeasured = set()
    for segment in design:
        length = float(segment.HorizontalLength)
        if length == 0.0:
            continue
        s0, h0 = float(segment.StartDistAlong), float(segment.StartHeight)
        g0, g1 = float(segment.StartGradient), float(segment.EndGradient)
        kind = segment.PredefinedType
        if kind == "CONSTANTGRADIENT":
            rise, g1, bend = g0 * length, g0, (0.0, 0.0)
        elif kind == "PARABOLICARC":  # z'' = (g1 − g0) / L, constant
            second = (g1 - g0) / length
            rise, bend = 0.5 * (g0 + g1) * length, (second / (1 + g0 * g0) ** 1.5, second / (1 + g1 * g1) ** 1.5)
        elif kind == "CIRCULARARC" and g1 != g0:  # κ = (sin θ1 − sin θ0) / L along a circle from θ0 to θ1
            t0, t1 = math.atan(g0), math.atan(g1)
            k = (math.sin(t1) - math.sin(t0)) / length
            rise, bend = (math.cos(t0) - math.cos(t1)) / k, (k, k)
        else:
            unmeasured.add(str(kind))
            rise, bend = math.nan, (math.nan, math.nan)
        ends = []
        for point, gradient, kappa in (((s0, h0), g0, bend[0]), ((s0 + length, h0 + rise), g1, bend[1])):
            tangent = np.array([1.0, gradient, 0.0]) / math.hypot(1.0, gradient)
            ends.append((point[0], point[1], 0.0, *tangent.tolist(), *(kappa * np.array([-tangent[1], tangent[0], 0.0])).tolist()))
        frames.append(tuple(ends))
        lengths.append(length)
    if unmeasured:
        notes.append(f"alignment {name!r}: vertical {', '.join(sorted(unmeasured))} segments are not measured: their joints "
                     "are unmeasurable")  # fmt: skip
    return frames, lengths
