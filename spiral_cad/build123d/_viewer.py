"""A part's continuity in OCP CAD Viewer (``ocp_vscode``) or CQ-editor: what the face checker found, in the
viewer build123d and CadQuery users already have open."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
from build123d import Compound, Edge, Face
from OCP.AIS import AIS_Shape
from OCP.Quantity import Quantity_Color, Quantity_TOC_sRGB
from OCP.TopAbs import TopAbs_EDGE, TopAbs_FACE
from OCP.TopExp import TopExp
from OCP.TopoDS import TopoDS
from OCP.TopTools import TopTools_IndexedMapOfShape

from ..cad.continuity import COMB_COLOUR, curvature_comb
from ..cad.faces import CLASS_COLOURS, FaceReport, check_faces
from ..cad.mesh import face_mesh
from ..cad.occ import as_occ_shape

__all__ = ["show_continuity"]


def _diverging(value: float) -> str:
    """White at 0, to red at +1 (convex) and blue at −1 (concave), as the web page's curvature mode."""
    t = float(np.clip(value, -1.0, 1.0))
    white, red, blue = np.array([0.92, 0.92, 0.92]), np.array([0.70, 0.02, 0.15]), np.array([0.13, 0.30, 0.75])
    rgb = white + abs(t) * ((red if t > 0 else blue) - white)
    return "#" + "".join(f"{round(255 * c):02x}" for c in rgb)


def show_continuity(part: Any, *, port: int | None = None, comb: bool = True, show_object: Callable[..., Any] | None = None,
                    **check_options: Any) -> FaceReport:  # fmt: skip
    """Show ``part`` in OCP CAD Viewer, or in CQ-editor, with what the face checker finds: each face coloured
    by its mean curvature (red convex, blue concave, white flat; full colour at the 95th percentile of the
    part's curvatures), each judged edge in the colour of its class (``spiral_cad.cad.faces.CLASS_COLOURS``:
    G2 green, G1 orange, crease red, gap magenta, sharp dark grey) and named with its numbers, and the
    curvature comb of the tangent edges.

    Without ``show_object`` it sends to OCP CAD Viewer, in VS Code or the standalone one
    (``python -m ocp_viewer``); that needs the ``viewer`` extra (``pip install "spiral_cad[viewer]"``:
    ``ocp_vscode``). In a CQ-editor script, pass CQ-editor's own function: ``show_continuity(part,
    show_object=show_object)`` shows every face, edge and the comb as an object of its own in CQ-editor's
    tree, named as above.

    Args:
        part: a build123d, CadQuery or OCCT shape with faces (in mm).
        port: OCP CAD Viewer's port (default: the one ``ocp_vscode`` finds).
        comb: also show the curvature comb of the edges that are not sharp.
        show_object: CQ-editor's ``show_object`` (or any function called as it is, ``show_object(shape,
            name=…, options={"color": "#rrggbb"})``); edges are sent as coloured, three-pixel-wide
            ``AIS_Shape`` objects, which CQ-editor displays as they are.
        **check_options: ``check_faces``'s tolerances.

    Returns:
        The face check shown.

    Raises:
        ModuleNotFoundError: no ``show_object`` and ``ocp_vscode`` is not installed (the message names the
            extra).
        ValueError: a shape without faces, or what the checker refuses.
    """
    if show_object is None:
        try:
            from ocp_vscode import show
        except ModuleNotFoundError:
            raise ModuleNotFoundError('show_continuity sends to OCP CAD Viewer: pip install "spiral_cad[viewer]" (ocp_vscode), '
                                      "or pass show_object= in CQ-editor") from None  # fmt: skip
    elif not callable(show_object):
        raise ValueError(f"show_continuity: show_object must be CQ-editor's show_object function; got {type(show_object).__name__}")
    report, shown = _continuity_objects(part, comb, check_options)
    if show_object is None:
        show(*(s.shape for s in shown), names=[s.name for s in shown], colors=[s.colour for s in shown],
             **({"port": port} if port is not None else {}))  # fmt: skip
        return report
    for item in shown:
        colour = _occ_colour(item.colour)
        if item.face:  # CQ-editor reads a tuple of floats as linear RGB, as OCCT's colours are
            show_object(item.shape.wrapped, name=item.name, options={"color": (colour.Red(), colour.Green(), colour.Blue())})
        else:  # CQ-editor colours the shading of what it is given: lines keep the colour of an AIS_Shape
            lines = AIS_Shape(item.shape.wrapped)
            lines.SetColor(colour)
            lines.SetWidth(3.0)
            show_object(lines, name=item.name, options={})
    return report


@dataclass(frozen=True)
class _Shown:
    name: str
    shape: Any  # a build123d Face, Edge or Compound
    colour: str  # "#rrggbb"
    face: bool


def _continuity_objects(part: Any, comb: bool, check_options: dict[str, Any]) -> tuple[FaceReport, list[_Shown]]:
    """The face check of ``part`` and what shows it: each face, each judged edge and the comb, named and coloured."""
    shape = as_occ_shape(part)
    report = check_faces(shape, **check_options)
    if report.faces == 0:
        raise ValueError("show_continuity: the shape holds no faces")
    units = report.units or "mm"
    faces, edges = TopTools_IndexedMapOfShape(), TopTools_IndexedMapOfShape()
    TopExp.MapShapes_s(shape, TopAbs_FACE, faces)
    TopExp.MapShapes_s(shape, TopAbs_EDGE, edges)
    mesh = face_mesh(shape, units=units)
    # a face's mean curvature: the mean over its triangles' corners
    per_face = np.zeros(faces.Extent())
    corners = mesh.mean_curvature[mesh.triangles].mean(axis=1)
    np.add.at(per_face, mesh.face, corners)
    counts = np.bincount(mesh.face, minlength=faces.Extent())[: faces.Extent()]
    per_face = np.divide(per_face, counts, out=np.zeros_like(per_face), where=counts > 0)
    scale = mesh.curvature_scale
    shown = [_Shown(f"face {k} (mean curvature {per_face[k]:.3g} 1/{units})", Face(TopoDS.Face_s(faces.FindKey(k + 1))),
                    _diverging(per_face[k] / scale), True) for k in range(faces.Extent())]  # fmt: skip
    tangent = []
    for edge in report.edges:
        if edge.index < 0 or edge.index >= edges.Extent():
            continue  # a knot line inside a face: no edge of its own
        line = Edge(TopoDS.Edge_s(edges.FindKey(edge.index + 1)))
        name = f"edge {edge.index} {edge.level}: angle {edge.angle:.3g} rad, curvature jump {edge.jump:.3g}"
        shown.append(_Shown(name, line, CLASS_COLOURS.get(edge.level, "#000000"), False))
        if edge.level != "sharp":
            tangent.append(line)
    if comb and tangent:
        teeth = Compound(curvature_comb(Compound(tangent).wrapped, units=units))
        shown.append(_Shown("curvature comb of the tangent edges", teeth, COMB_COLOUR, False))
    return report, shown


def _occ_colour(colour: str) -> Quantity_Color:
    """OCCT's colour of ``colour`` ("#rrggbb", sRGB as on a web page)."""
    red, green, blue = (int(colour[k : k + 2], 16) / 255.0 for k in (1, 3, 5))
    return Quantity_Color(red, green, blue, Quantity_TOC_sRGB)
