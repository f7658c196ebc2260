"""``spiral-cad check`` on a STEP/IGES file that holds faces: the face-to-face table, the verdict,
and the zebra and curvature pictures (``--zebra``, ``--curvature-map``)."""

from __future__ import annotations

import warnings
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING

from ..cad.faces import FEATURE_ANGLE, check_faces
from .cli_shared import summary_only
from .many import note_worst

if TYPE_CHECKING:
    from matplotlib.figure import Figure  # matplotlib is imported only when a picture is drawn

__all__ = ["check_face_file"]


def _png(option: str, path: str | None) -> Path | None:
    """The ``--zebra``/``--curvature-map`` file: a .png path whose folder exists."""
    if path is None:
        return None
    p = Path(path)
    if p.suffix.lower() != ".png":
        raise ValueError(f"--{option} {path!r}: the picture is written as PNG; give a .png file")
    if p.is_dir() or not p.parent.is_dir():
        raise ValueError(f"--{option} {path!r}: " + ("a folder" if p.is_dir() else f"no folder {str(p.parent)!r}"))
    return p


def _picture(draw: Callable[[], Figure], path: Path, what: str) -> None:
    """Draw and write one picture; a failure names the stage (drawing or writing) and the file, and a
    warning (nothing visible) is printed."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            fig = draw()
        except MemoryError:
            raise ValueError(f"drawing the {what} for {str(path)!r} ran out of memory") from None
    for warning in caught:
        print(f"warning: {what}: {warning.message}")
    try:
        fig.savefig(path, dpi=100, bbox_inches="tight")  # the picture pixel for pixel
    except OSError as error:
        raise ValueError(f"cannot write the {what} to {str(path)!r}: {error.strerror or error}") from None
    print(f"{what} written to {path}")


def check_face_file(file: str, *, require: str | None = None, gap_tol: float | None = None, angle_tol: float | None = None,
                    curvature_tol: float | None = None, feature_angle: float | None = None, zebra: str | None = None,
                    curvature_map: str | None = None, html: str | None = None, timing: bool = False,
                    picture: dict | None = None, quiet: bool = False) -> int | None:  # fmt: skip
    """Judge the faces of ``file`` and print the table; draw the pictures asked for.

    Tolerances left None take ``check_faces``'s defaults (gap: the file's stated precision and the edges' own tolerances, angle 1e-7 rad, curvature jump 1e-4). ``require`` "G2" or "G1" fails any
    tangent edge below it (and "G0" any gap); sharp features are listed, never failed. ``timing``
    also prints how long the check took; ``quiet`` prints the table's first line (the summary) and the
    verdict only. ``picture`` holds the pictures' options (``view``, ``pixels``;
    the zebra's ``stripes``), as ``plot_zebra`` and ``plot_curvature_map`` take them; ``html`` the web page
    to write (``spiral_cad.app.html_report``; its path checked by the caller before the file is read), which
    opens with the same view and stripes.

    Returns:
        0 ok, 1 below ``require``, None when the reader found no faces or one lone face (no
        shared edge): the caller then judges the wires, the lone face's boundary among them.

    Raises:
        ValueError: an unreadable file or a bad option (printed as ``error: …`` by the CLI).
    """
    zebra_png, map_png = _png("zebra", zebra), _png("curvature-map", curvature_map)
    report = check_faces(
        file,
        gap_tol=gap_tol,
        angle_tol=1e-7 if angle_tol is None else angle_tol,
        curvature_tol=1e-4 if curvature_tol is None else curvature_tol,
        feature_angle=FEATURE_ANGLE if feature_angle is None else feature_angle,
    )
    if report.faces == 0:
        return None
    print(summary_only(report.table(), quiet))
    if report.faces == 1 and not report.edges:
        # a lone face shares no edge: what can be judged is its boundary, the curve chain it is
        print("a lone face shares no edge: its boundary is judged as the curve chain it is")
        return None
    note_worst(report.worst)
    if timing and not quiet:
        print(f"time {report.seconds:.3g} s for {report.faces} faces and {len(report.edges)} edges, reading included")
    if zebra_png is not None or map_png is not None:
        from ..cad.mesh import face_mesh
        from .zebra import plot_curvature_map, plot_zebra

        options = dict(picture or {})
        stripes = {"stripes": options.pop("stripes")} if "stripes" in options else {}
        mesh = face_mesh(file, units=report.units, **{k: v for k, v in options.items() if k == "pixels"})
        if zebra_png is not None:
            _picture(lambda: plot_zebra(mesh, title=f"{report.source}: zebra", **options, **stripes), zebra_png, "zebra stripes")
        if map_png is not None:
            _picture(lambda: plot_curvature_map(mesh, title=f"{report.source}: mean curvature", **options), map_png, "curvature map")
    if html is not None:
        from .html_report import write_html_report

        options = {k: v for k, v in (picture or {}).items() if k in ("view", "stripes")}
        write_html_report(report, file, html, **options)
        print(f"web page written to {html}")
    if not require:
        return 0
    if not report.edges:
        print(f"FAIL: no shared edges were judged, so nothing shows {require} ({report.describe()}); "
              "the faces meet nowhere, even after sewing")  # fmt: skip
        return 1
    level = "crease" if require == "G0" else require  # a crease is G0, not G1
    worst = report.worst
    if worst == "gap" or (level != "crease" and not report.passes(level)):
        print(f"FAIL: worst tangent edge is {worst}, below the required {require} ({report.describe()})")
        return 1
    print(f"OK: {report.describe()}, every tangent edge at least {require}; sharp features listed, not judged")
    return 0
