"""A road: a G2 highway alignment swept with a cross-section into a solid (build123d).

Run: ``python examples/build123d_road.py [OUT_DIR]`` (default ./out). Writes
``road.step`` (the solid), ``road_centreline.step`` and ``road.svg`` (a
hidden-line projection of the solid) and prints the stationing table and the
G2 check of the centreline.
"""

import sys
from pathlib import Path

from build123d import BuildLine, BuildPart, BuildSketch, ExportSVG, LineType, Plane, Polygon, export_step, sweep

from spiral_cad.build123d import SpiralChain
from spiral_cad.continuity import check_continuity
from spiral_cad.design import Alignment

out = Path(sys.argv[1] if len(sys.argv) > 1 else "out")
out.mkdir(parents=True, exist_ok=True)

# Points of intersection (m), one radius per interior PI, spirals of 8° / 10°.
alignment = Alignment.from_pis(
    [(0, 0), (300, 60), (560, -40), (820, 90)],
    radii=[220, 260],
    spiral_angles=[(0.14, 0.14), (0.17, 0.12)],
    start_station=1000.0,
)
print(alignment.table(6))

with BuildPart() as road:
    with BuildLine() as centreline:
        SpiralChain(alignment.chain)
    rail = centreline.wire()
    # A 7.5 m carriageway with 2.5 % crossfall, 0.4 m thick, square to the start.
    with BuildSketch(Plane(origin=rail @ 0, x_dir=(0, 0, 1), z_dir=rail % 0)):
        Polygon((0, -3.75), (0.09, 0), (0, 3.75), (-0.4, 4.5), (-0.4, -4.5), align=None)
    sweep(path=rail)

solid = road.part
print(f"road solid valid: {solid.is_valid}, volume {solid.volume:,.1f} m³ over {alignment.chain.length:,.1f} m")
export_step(solid, str(out / "road.step"))
export_step(rail, str(out / "road_centreline.step"))

report = check_continuity(out / "road_centreline.step")
print(report.format_table())

view = solid.project_to_viewport((410, -300, 700), viewport_up=(0, 1, 0), look_at=(410, 20, 0))
svg = ExportSVG(scale=0.8)
svg.add_layer("visible", line_weight=0.2)
svg.add_layer("hidden", line_weight=0.1, line_type=LineType.ISO_DOT)
svg.add_shape(view[0], layer="visible")
svg.add_shape(view[1], layer="hidden")
svg.write(str(out / "road.svg"))
print(f"wrote {out / 'road.step'}, {out / 'road_centreline.step'}, {out / 'road.svg'}")
