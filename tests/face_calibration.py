"""Calibration of the face checker on a file another CAD system wrote (issue 39): the checker's verdict per
shared edge (``check_faces`` on the file, as ``spiral-cad check`` reads it) beside the independent measure
(``face_independent.measure_edges`` on the same file read in a child, with the precision the file states),
and the CAD system the file's header names."""

from __future__ import annotations

import math
import re
import time
from functools import partial
from pathlib import Path

from face_independent import measure_edges

from spiral_cad.cad.faces import check_faces
from spiral_cad.cad.readers import read_file

#: a verdict's rank: what passes a ``--require`` of G2 passes every lower one; a sharp feature is listed,
#: not failed, so it ranks with G2 (a checker's "sharp" where the measure finds a gap is a false pass)
RANK = {"unmeasurable": 0, "gap": 0, "crease": 1, "G1": 2, "G2": 3, "sharp": 3}


def originating_system(path: str | Path) -> str:
    """The CAD system a STEP/IGES file's header names (STEP ``FILE_NAME``'s originating system, else its
    preprocessor, else ``FILE_DESCRIPTION``; IGES's global section's system id), or ``"unknown"``."""
    text = Path(path).read_bytes()[:4000].decode("latin-1")
    if text.lstrip().upper().startswith("ISO-10303-21"):
        text = re.sub(r"/\*.*?\*/", "", text, flags=re.S)
        found = re.search(r"FILE_NAME\s*\((.*?)\)\s*;", text, flags=re.S)
        if found:
            fields = re.findall(r"'((?:[^']|'')*)'|\(([^()]*)\)", found.group(1))
            strings = [a if a or not b else b for a, b in fields]
            for i in (5, 4):
                if len(strings) > i and strings[i].strip(" '"):
                    return strings[i].strip()
        found = re.search(r"FILE_DESCRIPTION\s*\(\s*\(\s*'([^']*)'", text)
        return found.group(1) if found and found.group(1) else "unknown"
    g = "".join(line[:72] for line in text.splitlines() if len(line) >= 73 and line[72] == "G")
    delimiter = g[2] if g.startswith("1H") else ","
    fields, i = [], 0
    while i < len(g) and len(fields) < 7:
        found = re.match(r"\s*(\d+)H", g[i:])
        if found:
            n = int(found.group(1))
            fields.append(g[i + found.end() : i + found.end() + n])
            i += found.end() + n + 1
        else:
            end = g.find(delimiter, i)
            end = len(g) if end < 0 else end
            fields.append(g[i:end].strip())
            i = end + 1
    for k in (4, 5):
        if len(fields) > k and fields[k].strip() and fields[k] != "{unspecified}":
            return fields[k].strip()
    return "unknown"


def _sewn(shape, tolerance: float = 1e-6):
    """``shape`` with coinciding free edges sewn at ``tolerance`` × its size (as any reader of a file written
    unstitched would), only when it has free edges."""
    from OCP.Bnd import Bnd_Box
    from OCP.BRepBndLib import BRepBndLib
    from OCP.BRepBuilderAPI import BRepBuilderAPI_Sewing
    from OCP.ShapeAnalysis import ShapeAnalysis_FreeBounds
    from OCP.TopAbs import TopAbs_EDGE
    from OCP.TopExp import TopExp_Explorer

    box = Bnd_Box()
    BRepBndLib.Add_s(shape, box, False)
    if box.IsVoid():
        return shape
    analysis = ShapeAnalysis_FreeBounds(shape)
    explorer = TopExp_Explorer(analysis.GetClosedWires(), TopAbs_EDGE)
    open_explorer = TopExp_Explorer(analysis.GetOpenWires(), TopAbs_EDGE)
    if not explorer.More() and not open_explorer.More():
        return shape
    sewing = BRepBuilderAPI_Sewing(tolerance * math.sqrt(box.SquareExtent()))
    sewing.SetNonManifoldMode(True)
    sewing.Add(shape)
    sewing.Perform()
    return sewing.SewedShape() if sewing.NbContigousEdges() + sewing.NbMultipleEdges() else shape


def _independent(shape, stated: float, samples: int, dense: int, ours: dict[int, str]) -> dict[int, dict]:
    """The measure's class of every shared edge; where it differs from ``ours`` (the checker's), measured
    again at ``dense`` points (a gap or a tangent stretch between its ``samples`` points is then seen)."""
    shape = _sewn(shape)
    found = {i: m["level"] for i, m in measure_edges(shape, samples=samples, stated=stated).items()}
    disputed = {i for i, level in found.items() if ours.get(i, level) != level}
    if disputed:
        found.update({i: m["level"] for i, m in measure_edges(shape, dense, stated=stated, only=disputed).items()})
    return {i: {"level": level, "dense": i in disputed} for i, level in found.items()}


def compare_file(path: str | Path, samples: int = 12, dense: int = 200) -> dict:
    """Both verdicts on every shared edge of the file at ``path``: counts of edges, agreements, false
    passes (the checker's verdict ranks above the measure's, ``RANK``), false failures (below), the
    disagreements themselves (edges where the two differ at ``samples`` points are measured again at
    ``dense``), the edges the measure could not judge, and the checker's time per face."""
    started = time.perf_counter()
    report = check_faces(path)
    seconds = time.perf_counter() - started
    ours = {e.index: e.level for e in report.edges if e.index >= 0 and not e.seam}
    _, theirs = read_file(path, "mm", partial(_independent, samples=samples, dense=dense, ours=ours), stated=True)
    shared = sorted(set(ours) & set(theirs))
    rows = [(i, ours[i], theirs[i]["level"]) for i in shared]
    return {
        "faces": report.faces,
        "edges": len(shared),
        "only_checker": len(set(ours) - set(theirs)),
        "only_measure": len(set(theirs) - set(ours)),
        "agree": sum(a == b for _, a, b in rows),
        "remeasured": sum(theirs[i]["dense"] for i in shared),
        "unmeasurable": [r for r in rows if r[2] == "unmeasurable" and r[1] != "unmeasurable"],
        "false_pass": [r for r in rows if RANK[r[1]] > RANK[r[2]] and r[2] != "unmeasurable"],
        "false_fail": [r for r in rows if RANK[r[1]] < RANK[r[2]]],
        "other": [r for r in rows if r[1] != r[2] and RANK[r[1]] == RANK[r[2]]],
        "seconds": seconds,
        "ms_per_face": 1e3 * report.seconds / max(report.faces, 1),
        "worst": report.worst,
        "gap_from": report.gap_from,
    }
