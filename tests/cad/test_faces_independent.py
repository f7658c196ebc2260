"""The face checker against an independent per-edge measure (``face_independent``: OCCT's own projection
and local properties, no code shared with the checker), edge by edge, on parts whose joins are known."""

from __future__ import annotations

import pytest

pytest.importorskip("OCP")

import build123d as bd  # noqa: E402
from face_independent import measure_edges  # noqa: E402
from face_reproducers import knot_line_join  # noqa: E402

from spiral_cad.build123d import ContinuousRectangle  # noqa: E402
from spiral_cad.cad.faces import check_faces  # noqa: E402

PARTS = {
    "filleted box": lambda: bd.fillet(bd.Box(40, 20, 8).edges().filter_by(bd.Axis.Z), 2).wrapped,
    "continuous slab": lambda: bd.extrude(ContinuousRectangle(40, 20, 5), 8).wrapped,
    "knot line, pcurve tilted out of its face": lambda: knot_line_join(1e-13),
    "knot line, pcurve parameter shifted": lambda: knot_line_join(0.0, shift=0.02),
    "faces sewn 2e-5 apart": lambda: knot_line_join(0.0, apart=2e-5),
    "filleted cylinder": lambda: bd.fillet(bd.Cylinder(10, 20).edges(), 3).wrapped,
    # a wedge whose two long faces fold back by 177°: sharp, not a crease of 3° (normals nearly opposite)
    "wedge folded by 177°": lambda: bd.extrude(bd.Polygon((0, 0), (40, 1), (40, -1), align=None), 5).wrapped,
}


@pytest.mark.parametrize("name", [pytest.param(n, marks=pytest.mark.slow) if n == "continuous slab" else n for n in PARTS])
def test_the_checker_agrees_edge_by_edge_with_an_independent_measure(name):
    shape = PARTS[name]()
    report = check_faces(shape)
    ours = {e.index: e for e in report.edges if e.index >= 0 and not e.seam}
    theirs = measure_edges(shape, samples=12)
    assert theirs and set(theirs) == set(ours)
    assert {i: e.level for i, e in ours.items()} == {i: m["level"] for i, m in theirs.items()}
    for i, m in theirs.items():  # the same numbers where both are measurable
        assert ours[i].gap == pytest.approx(m["gap"], abs=1e-9 * report.size)
        if m["level"] not in ("sharp", "gap"):
            assert ours[i].jump == pytest.approx(m["jump"], abs=1e-3)
