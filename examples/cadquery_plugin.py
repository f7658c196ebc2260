"""A G2 hairpin tube with the spiral_cad CadQuery plugin.

line → spiral → arc → spiral → line, placed on a workplane, swept with a
round profile and checked for G2 continuity.

Run inside CQ-editor to see the result (``show_object``), or from plain
Python to write a STEP file::

    python examples/cadquery_plugin.py [OUT.step]    # default: out/cadquery_plugin.step
"""

from __future__ import annotations

import sys
from pathlib import Path

import cadquery as cq

import spiral_cad as sc
import spiral_cad.cadquery  # noqa: F401  (registers the Workplane methods)
from spiral_cad.cad.continuity import check_continuity

RADIUS = 10.0  # bend radius
CENTER = (40.0, 10.5)  # bend centre: the straights are y = 0 and y = 21
TUBE = 1.5  # tube radius


def hairpin() -> sc.Chain:
    """Straight → spiral → arc → spiral → straight back, G2 throughout."""
    into = sc.line_to_circle((0.0, 0.0), (1.0, 0.0), CENTER, RADIUS)
    # The way out is the line → circle transition of the returning straight, travelled backwards.
    out = sc.line_to_circle((0.0, 2 * CENTER[1]), (1.0, 0.0), CENTER, RADIUS).reversed()
    return sc.Chain.join([into, out], start=(0.0, 0.0), end=(0.0, 2 * CENTER[1]))


def build() -> tuple[cq.Workplane, cq.Workplane]:
    """The placed path (on a raised XZ workplane) and the swept tube."""
    path = cq.Workplane("XZ", origin=(0, 0, 5)).spiralChain(hairpin())
    start = path.val().startPoint()
    tube = cq.Workplane("YZ", origin=start.toTuple()).circle(TUBE).sweep(path)
    return path, tube


path, result = build()
report = check_continuity(path.val())

if "show_object" in globals():  # CQ-editor
    show_object(result, name="hairpin tube")  # noqa: F821
    show_object(path, name="path")  # noqa: F821
else:
    print(report.format_table())
    target = Path(sys.argv[1] if len(sys.argv) > 1 else "out/cadquery_plugin.step")
    target.parent.mkdir(parents=True, exist_ok=True)
    cq.exporters.export(result, str(target))
    print(f"wrote {target} (tube volume {result.val().Volume():.6g}, path worst joint {report.min_level})")
