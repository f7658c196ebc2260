"""A continuity report as one HTML page to turn and click: the part under zebra stripes or its curvature,
every edge coloured by its verdict, its numbers a click away.

``spiral_cad.check(…, html=…)`` and ``spiral-cad check PART.step --html OUT.html`` (``write_html_report`` of a
check already made) write one self-contained file: the numbers as JSON in the page, the viewer (``viewer.js``, WebGL 2)
inside it, nothing fetched from anywhere, so it opens from a mail or an archive years later. The page:

* the part's faces (``spiral_cad.cad.mesh.face_mesh``: the surfaces' own normals and mean curvature at
  the vertices) drawn with zebra stripes — reflections of light tubes fixed to the view, as
  ``spiral_cad.app.zebra`` draws them, so they kink at a G1 edge and flow through a G2 one — or with
  their mean curvature (red convex, blue concave), or plainly shaded; drag turns the part, the wheel
  zooms, the slider sets the stripes;
* every edge the face checker judged (``spiral_cad.cad.faces.check_faces``), coloured by its class
  (``COLOURS``); a click on an edge, or on its row in the tables, shows its numbers: the gap, the
  angle between the normals, the jump of normal curvature and where each is largest;
* the summary and a table of every edge, so that the numbers are there without WebGL too.

The address's hash chooses how it opens (``#mode=curvature&edge=12&stripes=40&view=1,-1,0.5``: ``edge`` the
face checker's edge number, ``item`` instead the page's own row, worst first), so a link can point at one edge.
"""

from __future__ import annotations

import base64
import html
import json
import math
import os
from importlib import resources
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from ..cad.continuity import COMB_COLOUR
from ..cad.faces import CLASS_COLOURS
from .zebra import DISTANCE, STRIPES, VIEW

if TYPE_CHECKING:
    from ..cad.faces import FaceEdge, FaceReport
    from ..cad.mesh import FaceMesh
    from ..continuity.joints import ContinuityReport, JointReport

__all__ = ["COLOURS", "COMB_TEETH", "LISTED", "checked_page_path", "curves_report_html", "part_report_html", "write_html_report"]

#: The colour of each verdict on the page — the face checker's edge classes (``CLASS_COLOURS``) and the
#: curve checker's joint levels — and of the lines that are no verdict: an edge of one face only (``free``),
#: a degenerate or unjudged one (``other``), a curve (``curve``) and its curvature comb (``comb``).
COLOURS = {
    **CLASS_COLOURS,
    "G0": CLASS_COLOURS["crease"],
    "none": CLASS_COLOURS["gap"],
    "free": "#9e9e9e",
    "other": "#bdbdbd",
    "curve": "#222222",
    "comb": COMB_COLOUR,
}
#: Most rows in each of the page's tables, and most G2 joints of curves drawn as points to click.
LISTED = 5_000
#: Most teeth of a curve page's curvature comb in all.
COMB_TEETH = 100_000


def _packed(values: NDArray, dtype: Any) -> str:
    return base64.b64encode(np.ascontiguousarray(values, dtype=dtype).tobytes()).decode("ascii")


def _length(value: float, units: str) -> str:
    return f"{value:.3g} {units}".rstrip()


def _point(p: tuple[float, float, float]) -> str:
    return "(" + ", ".join(f"{c:.6g}" for c in p) + ")"


def _rows(edge: FaceEdge, units: str) -> list[tuple[str, str]]:
    rows = [
        ("faces", f"{edge.faces[0]} ({edge.surfaces[0]}) – {edge.faces[1]} ({edge.surfaces[1]})" + (", a seam" if edge.seam else "")),
        ("gap", f"{_length(edge.gap, units)} at {_point(edge.gap_at)}"),
        ("angle between the normals", f"{edge.angle:.3g} rad at {_point(edge.angle_at)}"),
        ("normal-curvature jump", f"{edge.jump:.3g} (relative) at {_point(edge.jump_at)}"),
        ("curvatures across there", f"{edge.curvatures[0]:.6g} and {edge.curvatures[1]:.6g} 1/{units or 'unit'}"),
        ("samples", str(edge.samples)),
    ]
    return rows + ([("note", edge.note)] if edge.note else [])


def _label(edge: FaceEdge) -> str:
    return f"edge {edge.index}" if edge.index >= 0 else f"knot line in face {edge.faces[0]}"


def part_report_html(report: FaceReport, mesh: FaceMesh, *, title: str | None = None, stripes: int = STRIPES,
                     view: tuple[float, float, float] = VIEW) -> str:  # fmt: skip
    """The page of a face check: ``report`` (``check_faces``) drawn on ``mesh`` (``face_mesh`` of the same
    shape, in the report's unit: its edges numbered as the report numbers them).

    Args:
        report: the face check.
        mesh: the part's mesh with its edges.
        title: the page's heading (default: the report's source).
        stripes: the zebra's stripe pairs to start with.
        view: the direction towards the viewer to start from.

    Raises:
        ValueError: a mesh whose edges are not the report's (fewer edges than the report numbers).
    """
    edges_in_mesh = len(mesh.edge_starts) - 1
    if any(e.index >= edges_in_mesh for e in report.edges):
        raise ValueError(f"the mesh holds {edges_in_mesh} edges but the report numbers edge "
                         f"{max(e.index for e in report.edges)}: mesh the shape the report judged, with face_mesh(…, edges=True)")  # fmt: skip
    units = report.units or mesh.units
    points = mesh.points
    low, high = (points.min(axis=0), points.max(axis=0)) if len(points) else (np.zeros(3), np.ones(3))
    centre = (low + high) / 2.0
    size = float(np.linalg.norm(high - low)) or 1.0
    scale = mesh.curvature_scale

    order = sorted(
        range(len(report.edges)),
        key=lambda k: (report.edges[k].level == "sharp", _RANK.get(report.edges[k].level, 9), -report.edges[k].jump),
    )
    items: list[dict[str, Any]] = []
    line_item, markers, marker_items = [-1] * edges_in_mesh, [], []
    worst_of_line: dict[int, int] = {}
    for k in order:
        edge = report.edges[k]
        item = len(items)
        items.append({"label": _label(edge), "level": edge.level, "rows": _rows(edge, units), "line": -1, "point": None})
        if edge.index >= 0 and mesh.edge_starts[edge.index + 1] - mesh.edge_starts[edge.index] >= 2:
            items[-1]["line"] = edge.index
            worst_of_line.setdefault(edge.index, item)  # the first in ``order`` is the worst of that edge
        else:  # a knot line inside a face, or an edge without points: a marker where it is worst (if measured)
            at = np.array(edge.jump_at if edge.level != "gap" else edge.gap_at) - centre
            if np.isfinite(at).all():
                items[-1]["point"] = at.tolist()
                markers.append(at)
                marker_items.append(item)
    for line, item in worst_of_line.items():
        line_item[line] = item
    free = {index for index, _ in report.free_at}
    kinds = ["free" if k in free else "other" for k in range(edges_in_mesh)]
    data = {
        "title": title or report.source,
        "units": units,
        "size": size,
        "view": [float(v) for v in view],
        "stripes": int(stripes),
        "distance": DISTANCE,
        "palette": COLOURS,
        "mesh": {
            "positions": _packed(points - centre, np.float32),
            "normals": _packed(mesh.normals, np.float32),
            "curvature": _packed(np.nan_to_num(mesh.mean_curvature), np.float32),
            "triangles": _packed(mesh.triangles, np.uint32),
            "scale": scale,
        },
        "lines": {
            "points": _packed(mesh.edge_points - centre if len(mesh.edge_points) else mesh.edge_points, np.float32),
            "starts": [int(s) for s in mesh.edge_starts],
            "items": line_item,
            "kinds": kinds,
        },
        "markers": {"points": _packed(np.array(markers).reshape(-1, 3), np.float32), "items": marker_items},
        "items": items,
    }
    controls = _MODES.format(curvature_scale=html.escape(f"±{scale:.3g} 1/{units or 'unit'}"))
    return _page(data, report.describe(), controls, "edge", "Tangent edges below G2", "Every tangent edge is G2 (or the part has none).")


def curves_report_html(report: ContinuityReport, shape: Any, *, title: str | None = None,
                       view: tuple[float, float, float] | None = None) -> str:  # fmt: skip
    """The page of a curve check: ``report`` (``check_continuity``) over the curves of ``shape`` (a shape
    with edges, in the report's unit), each joint a point coloured by its level, with the curvature comb.

    A long program stays a page a browser opens: the comb has at most ``COMB_TEETH`` teeth in all (fewer per
    edge), and beyond ``LISTED`` G2 joints only those below G2 are points to click (the page says how many
    are not).

    Args:
        report: the curve check.
        shape: the curves judged (a build123d, CadQuery or OCCT shape, or a ``Chain``).
        title: the page's heading (default: the report's source).
        view: the direction towards the viewer to start from (default: from above for flat curves, else ``VIEW``).
    """
    from ..cad.continuity import curvature_comb
    from ..cad.mesh import edge_lines
    from ..cad.occ import as_occ_shape
    from ..continuity.joints import Continuity

    occ = as_occ_shape(shape)
    curves = [line for line in edge_lines(occ, max(report.size, 1e-300) / 4000.0) if len(line) >= 2]
    teeth = max(2, min(24, COMB_TEETH // max(len(curves), 1)))
    comb = [line for line in edge_lines(curvature_comb(occ, per_edge=teeth), max(report.size, 1e-300) / 4000.0) if len(line) >= 2]
    everything = np.vstack([*curves, *comb]) if curves or comb else np.zeros((1, 3))
    low, high = everything.min(axis=0), everything.max(axis=0)
    centre, size = (low + high) / 2.0, float(np.linalg.norm(high - low)) or 1.0
    units = report.units
    joints = [(w, j) for w in report.wires for j in w.joints]
    order = sorted(range(len(joints)), key=lambda k: (int(joints[k][1].level), -joints[k][1].relative_curvature_jump))
    below = sum(1 for _, joint in joints if joint.level != Continuity.G2)
    left_out = max(0, len(order) - max(below, LISTED))
    order = order[: len(order) - left_out]  # the worst first: only G2 joints are left out
    items, markers = [], []
    for k in order:
        wire, joint = joints[k]
        at = np.array(joint.point) - centre
        items.append({"label": f"piece {wire.index} joint {joint.index}", "level": str(joint.level), "rows": _joint_rows(joint, units),
                      "line": -1, "point": at.tolist() if np.isfinite(at).all() else None})  # fmt: skip
        markers.append(at)
    known = [k for k, m in enumerate(markers) if np.isfinite(m).all()]
    lines = curves + comb
    flat = float(np.ptp(everything[:, 2])) <= 1e-9 * size
    data = {
        "title": title or report.source,
        "units": units,
        "size": size,
        "view": [float(v) for v in (view if view is not None else (0.0, 0.0, 1.0) if flat else VIEW)],  # a drawing from above
        "stripes": STRIPES,
        "distance": DISTANCE,
        "palette": COLOURS,
        "mesh": None,
        "lines": {
            "points": _packed(np.vstack([np.zeros((0, 3)), *lines]) - centre, np.float32),
            "starts": [0, *np.cumsum([len(line) for line in lines]).tolist()],
            "items": [-1] * len(lines),
            "kinds": ["curve"] * len(curves) + ["comb"] * len(comb),
        },
        "markers": {"points": _packed(np.array([markers[k] for k in known]).reshape(-1, 3), np.float32), "items": known},
        "items": items,
    }
    summary = report.describe() + (f"; {left_out} of its G2 joints are not drawn as points (the page shows {LISTED})" if left_out else "")
    return _page(data, summary, _CURVES, "joint", "Joints below G2", "Every joint is G2 (or the curves have none).")


def _joint_rows(joint: JointReport, units: str) -> list[tuple[str, str]]:
    unit = units or "unit"
    return [
        ("where", _point(joint.point)),
        ("gap", _length(joint.gap, units)),
        ("angle between the tangents", f"{joint.angle:.3g} rad"),
        ("curvature jump", f"{joint.relative_curvature_jump:.3g} (relative), {joint.curvature_jump:.3g} 1/{unit}"),
        ("curvatures before and after", f"{joint.curvature_before:.6g} and {joint.curvature_after:.6g} 1/{unit}"),
        ("osculating planes turn", "—" if math.isnan(joint.plane_change) else f"{joint.plane_change:.3g} rad"),
    ]


def _page(data: dict[str, Any], summary: str, controls: str, what: str, below_title: str, all_good: str) -> str:
    """The page around ``data`` (the viewer's input): the heading, the legend of levels, the controls, the
    view, the table of the items below G2 and of every item."""
    items = data["items"]
    counts: dict[str, int] = {}
    for item in items:
        counts[item["level"]] = counts.get(item["level"], 0) + 1
    legend = " ".join(
        f'<span class="level" style="color:{COLOURS.get(level, "#000")}">■ {html.escape(level)} {count}</span>'
        for level, count in sorted(counts.items(), key=lambda kv: _RANK.get(kv[0], 9))
    )
    below = [k for k, item in enumerate(items) if item["level"] not in ("G2", "sharp")]
    more_below = f"<p>… and {len(below) - LISTED} more below G2.</p>" if len(below) > LISTED else ""
    below = below[:LISTED]  # the worst first
    listed = list(range(min(len(items), LISTED)))
    return _PAGE.format(
        title=html.escape(str(data["title"])),
        summary=html.escape(summary),
        legend=legend,
        controls=controls,
        below_title=html.escape(below_title),
        below=_table(items, below, what) + more_below if below else f"<p>{html.escape(all_good)}</p>",
        every=f"Every {what} judged",
        all_items=_table(items, listed, what),
        more=f"<p>… and {len(items) - len(listed)} more.</p>" if len(items) > len(listed) else "",
        # every "<" escaped: no text in the data ("</script>", "<!--<script>" in a name) can end its block
        data=json.dumps(data, separators=(",", ":"), allow_nan=False).replace("<", "\\u003c"),
        script=resources.files(__package__).joinpath("viewer.js").read_text(encoding="utf-8").replace("</", "<\\/"),
    )


#: Worst first: what is judged, by how far it is from G2.
_RANK = {"unmeasurable": 0, "none": 1, "gap": 1, "G0": 2, "crease": 2, "G1": 3, "G2": 4, "sharp": 5}


def _table(items: list[dict[str, Any]], which: list[int], what: str) -> str:
    """The rows ``which`` of ``items``: label, level and the first three numbers (a click selects it)."""
    if not which:
        return ""
    head = (
        f"<tr><th>{html.escape(what)}</th><th>class</th>"
        + "".join(f"<th>{html.escape(key)}</th>" for key, _ in items[which[0]]["rows"][1:4])
        + "</tr>"
    )
    body = "".join(
        f'<tr data-item="{k}"><td>{html.escape(items[k]["label"])}</td>'
        f'<td style="color:{COLOURS.get(items[k]["level"], "#000")}">{html.escape(items[k]["level"])}</td>'
        + "".join(f"<td>{html.escape(value)}</td>" for _, value in items[k]["rows"][1:4])
        + "</tr>"
        for k in which
    )
    return f'<table class="items">{head}{body}</table>'


#: The controls of a part's page: how the faces are drawn.
_MODES = """<label><input type="radio" name="mode" id="mode-zebra"> zebra</label>
<label><input type="radio" name="mode" id="mode-curvature"> mean curvature ({curvature_scale}: red convex, blue concave)</label>
<label><input type="radio" name="mode" id="mode-shaded"> shaded</label>
<label>stripes <input type="range" id="stripes" min="1" max="200" step="1"></label>
<label><input type="checkbox" id="lines" checked> edges</label>
<span>drag to turn, wheel to zoom, click an edge</span>"""
#: The controls of a curve's page.
_CURVES = """<label><input type="checkbox" id="lines" checked> curves, comb and joints</label>
<span>drag to turn, wheel to zoom, click a joint</span>"""

_PAGE = """<!doctype html>
<html lang="en"><head><meta charset="utf-8">
<meta name="viewport" content="width=device-width, initial-scale=1">
<link rel="icon" href="data:,">
<title>{title}: continuity</title>
<style>
body {{ font: 14px/1.4 system-ui, sans-serif; margin: 0; color: #222; }}
header {{ padding: 8px 14px; border-bottom: 1px solid #ddd; }}
header h1 {{ font-size: 18px; margin: 0 0 4px; }}
.bar {{ display: flex; gap: 14px; align-items: center; flex-wrap: wrap; padding: 6px 14px; border-bottom: 1px solid #eee; }}
.main {{ display: flex; height: 70vh; min-height: 360px; }}
#view {{ flex: 1; min-width: 0; height: 100%; display: block; cursor: grab; touch-action: none; }}
#item {{ width: 330px; overflow: auto; padding: 8px 12px; border-left: 1px solid #eee; }}
#item h2 {{ font-size: 16px; margin: 4px 0 8px; }}
#item table td {{ vertical-align: top; padding: 2px 6px 2px 0; }}
.level {{ margin-right: 8px; white-space: nowrap; }}
section {{ padding: 8px 14px; }}
table.items {{ border-collapse: collapse; font-size: 13px; }}
table.items td, table.items th {{ border-bottom: 1px solid #eee; padding: 2px 8px; text-align: left; }}
table.items tr[data-item] {{ cursor: pointer; }}
table.items tr[data-item]:hover {{ background: #f3f7ff; }}
#status {{ color: #a00; }}
</style></head>
<body>
<header><h1>{title}</h1><div>{summary}</div><div>{legend}</div></header>
<div class="bar">{controls} <span id="status"></span></div>
<div class="main"><canvas id="view"></canvas><div id="item"></div></div>
<section><h2>{below_title}</h2>{below}</section>
<section><details><summary>{every}</summary>{all_items}{more}</details></section>
<script type="application/json" id="spiral-data">{data}</script>
<script>{script}</script>
</body></html>
"""


def checked_page_path(path: str | os.PathLike, source: Any = None, format: str | None = None) -> Path:
    """``path`` as the page to write of ``source`` (read as ``format``, if given): a .html (or .htm) file whose
    folder exists, not the source itself, of something the page draws (not a LandXML, OpenDRIVE or IFC file); else
    ValueError naming it."""
    named = str(format).lower().lstrip(".") if format is not None else ""
    if named in ("landxml", "xml", "opendrive", "xodr", "ifc") or (
        isinstance(source, (str, os.PathLike)) and Path(source).suffix.lower() in (".xml", ".xodr", ".ifc")
    ):
        raise ValueError(f"html: {Path(source).name!r:.80} is judged on its own numbers (spiral-cad check prints them); "
                         "the page draws STEP/IGES parts and curves, DXF drawings and G-code programs")  # fmt: skip
    if not isinstance(path, (str, os.PathLike)) or isinstance(path, bytes) or not os.fspath(path):
        raise ValueError(f"html must be a .html file's path; got {path!r:.80}")
    target = Path(path).expanduser()
    if target.suffix.lower() not in (".html", ".htm"):
        raise ValueError(f"html {str(path)!r:.80}: the report is a web page; give a .html file")
    if target.is_dir() or not target.parent.is_dir():
        raise ValueError(f"html {str(path)!r:.80}: " + ("is a folder" if target.is_dir() else f"no folder {str(target.parent)!r:.80}"))
    if isinstance(source, (str, os.PathLike)) and target.exists() and Path(source).exists() and os.path.samefile(target, source):
        raise ValueError(f"html {str(path)!r:.80} is the file being checked (by another name); give another file")
    return target


def write_html_report(report: Any, source: Any, path: str | os.PathLike, *, units: str | None = None,
                      stripes: int | None = None, view: tuple[float, float, float] | None = None) -> None:  # fmt: skip
    """Write the page of ``report``, the check of ``source``, to ``path``: a part's faces (``part_report_html``)
    or curves joint by joint (``curves_report_html``). ``spiral_cad.check(source, html=path)`` judges and
    writes it in one call.

    Args:
        report: the check of ``source``: a ``FaceReport`` or a ``ContinuityReport``.
        source: what was judged: a STEP/IGES, DXF or G-code path, or a build123d, CadQuery or OCCT shape,
            a ``Chain``.
        path: the page to write (.html or .htm; its folder must exist), written whole or not at all.
        units: for a file, the unit it was read in (None: the unit it declares); for a shape, its unit (mm).
        stripes: the zebra's stripe pairs a part's page opens with (1–200, default ``STRIPES``).
        view: the direction towards the viewer the page opens from (default: ``VIEW`` for a part, from
            above for flat curves).

    Raises:
        ValueError: a path that is not .html, a folder that does not exist, a LandXML or OpenDRIVE file
            (judged on its numbers, not drawn here), a report of no faces and no curves, or what the reader
            refuses.
    """
    from ..cad.faces import FaceReport
    from ..cad.mesh import face_mesh
    from ..continuity.joints import ContinuityReport

    target = checked_page_path(path, source)
    if stripes is not None and not (isinstance(stripes, int) and not isinstance(stripes, bool) and 1 <= stripes <= 200):
        raise ValueError(f"stripes must be a whole number from 1 to 200; got {stripes!r:.40}")
    is_file = isinstance(source, (str, os.PathLike))
    if isinstance(report, FaceReport):
        if report.faces == 0:
            raise ValueError(f"html: {report.source or 'the shape'} holds no faces to draw")
        unit = (report.units or None) if is_file else (units or report.units or "mm")
        mesh = face_mesh(source, units=unit, edges=True)
        page = part_report_html(report, mesh, stripes=STRIPES if stripes is None else stripes, view=VIEW if view is None else view)
    elif isinstance(report, ContinuityReport):
        if stripes is not None:
            raise ValueError("stripes: the zebra is drawn on a part's faces; a page of curves has none")
        page = curves_report_html(report, _curves_of(source, units) if is_file else source, view=view)
    else:
        raise ValueError(f"html: a {type(report).__name__} is not drawn; the page draws parts and curves")
    _write_whole(target, page)


def _write_whole(target: Path, page: str) -> None:
    """Write ``page`` to ``target`` all or nothing: a temporary file beside it (``io.staging.temporary_beside``),
    then renamed over it (a page already there is kept if writing fails; a link at ``target`` is replaced,
    never written through)."""
    from ..io.staging import temporary_beside

    temporary = temporary_beside(target, ".html")
    try:
        Path(temporary).write_bytes(page.encode("utf-8", errors="replace"))  # a name that is no UTF-8 shows "?"
        os.chmod(temporary, 0o644)
        os.replace(temporary, target)
    except OSError as error:
        Path(temporary).unlink(missing_ok=True)
        raise ValueError(f"cannot write the report to {str(target)!r}: {error.strerror or error}") from None


def _curves_of(path: str | os.PathLike, units: str | None) -> Any:
    """The curves the checker judged in the file at ``path``: a drawing's or program's (``document_shape``),
    else a STEP/IGES file's, in the unit the report is in."""
    from ..cad.document_shapes import document_shape
    from ..cad.readers import IGES_SUFFIXES, STEP_SUFFIXES, read_shape

    if Path(path).suffix.lower() in (*STEP_SUFFIXES, *IGES_SUFFIXES):
        return read_shape(path, units=units)
    return document_shape(path, units=units)[0]
