"""A part's continuity in OCP CAD Viewer (``ocp_vscode``): what the face checker found, in the viewer
build123d users already have open."""

from __future__ import annotations

from typing import Any

import numpy as np
from build123d import Compound, Edge, Face
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


def show_continuity(part: Any, *, port: int | None = None, comb: bool = True, **check_options: Any) -> FaceReport:
    """Show ``part`` in OCP CAD Viewer with what the face checker finds: each face coloured by its mean
    curvature (red convex, blue concave, white flat; full colour at the 95th percentile of the part's
    curvatures), each judged edge in the colour of its class (``spiral_cad.cad.faces.CLASS_COLOURS``: G2 green,
    G1 orange, crease red, gap magenta, sharp dark grey) and named with its numbers, and the curvature comb
    of the tangent edges.

    Needs the ``viewer`` extra (``pip install "spiral_cad[viewer]"``: ``ocp_vscode``) and a viewer to send
    to: OCP CAD Viewer in VS Code, or the standalone one (``python -m ocp_viewer``).

    Args:
        part: a build123d, CadQuery or OCCT shape with faces (in mm).
        port: the viewer's port (default: the one ``ocp_vscode`` finds).
        comb: also show the curvature comb of the edges that are not sharp.
        **check_options: ``check_faces``'s tolerances.

    Returns:
        The face check shown.

    Raises:
        ModuleNotFoundError: ``ocp_vscode`` is not installed (the message names the extra).
        ValueError: a shape without faces, or what the checker refuses.
    """
    try:
        from ocp_vscode import show
    except ModuleNotFoundError:
        raise ModuleNotFoundError('show_continuity sends to OCP CAD Viewer: pip install "spiral_cad[viewer]" (ocp_vscode)') from None
    shape = as_occ_shape(part)
    report = check_faces(shape, **check_options)
    if report.faces == 0:
        raise ValueError("show_continuity: the shape holds no faces")
    faces, edges = TopTools_IndexedMapOfShape(), TopTools_IndexedMapOfShape()
    TopExp.MapShapes_s(shape, TopAbs_FACE, faces)
    TopExp.MapShapes_s(shape, TopAbs_EDGE, edges)
    mesh = face_mesh(shape, units=report.units or "mm")
    # a face's mean curvature: the mean over its triangles' corners
    per_face = np.zeros(faces.Extent())
    corners = mesh.mean_curvature[mesh.triangles].mean(axis=1)
    np.add.at(per_face, mesh.face, corners)
    counts = np.bincount(mesh.face, minlength=faces.Extent())[: faces.Extent()]
    per_face = np.divide(per_face, counts, out=np.zeros_like(per_face), where=counts > 0)
    scale = mesh.curvature_scale
    objects: list[Any] = []
    names: list[str] = []
    colours: list[str] = []
    for k in range(faces.Extent()):
        objects.append(Face(TopoDS.Face_s(faces.FindKey(k + 1))))
        names.append(f"face {k} (mean curvature {per_face[k]:.3g} 1/{report.units or 'mm'})")
        colours.append(_diverging(per_face[k] / scale))
    tangent = []
    for edge in report.edges:
        if edge.index < 0 or edge.index >= edges.Extent():
            continue  # a knot line inside a face: no edge of its own
        shown = Edge(TopoDS.Edge_s(edges.FindKey(edge.index + 1)))
        objects.append(shown)
        names.append(f"edge {edge.index} {edge.level}: angle {edge.angle:.3g} rad, curvature jump {edge.jump:.3g}")
        colours.append(CLASS_COLOURS.get(edge.level, "#000000"))
        if edge.level != "sharp":
            tangent.append(shown)
    if comb and tangent:
        objects.append(Compound(curvature_comb(Compound(tangent).wrapped, units=report.units or "mm")))
        names.append("curvature comb of the tangent edges")
        colours.append(COMB_COLOUR)
    show(*objects, names=names, colors=colours, **({"port": port} if port is not None else {}))
    return report
