"""A road in 3-D: a G2 alignment, a vertical profile with a crest and a sag, smooth banking, one solid (build123d).

Run: ``python examples/build123d_road.py [OUT_DIR]`` (default ./out). Writes
``road.step`` (the corridor solid), ``road_centreline.step`` (the 3-D centre
line, one G2 wire) and ``road.svg`` (a hidden-line view of the solid, heights ×8), and prints the
stationing and profile tables, the corridor and the centre line's fit.

The design is in metres and so are the STEP files: they are written through
``spiral_cad.cad.export.export_step`` in the alignment's unit (build123d's own
``export_step`` declares millimetres, which would make the road an 820 mm toy).
"""

import sys
from pathlib import Path

from build123d import ExportSVG, LineType, scale

from spiral_cad.build123d import centerline_wire, corridor
from spiral_cad.cad.export import CrossSection, export_step
from spiral_cad.design import Alignment, Profile

out = Path(sys.argv[1] if len(sys.argv) > 1 else "out")
out.mkdir(parents=True, exist_ok=True)

# Plan: points of intersection (m), one radius per interior PI; the spirals are the
# shortest that meet the criteria at 60 km/h, and so is the superelevation of each curve.
alignment = Alignment.from_pis(
    [(0, 0), (300, 60), (560, -40), (820, 90)], radii=[220, 260], units="m", design_speed=60, start_station=1000.0
)
print(alignment.table(6))

# Profile: up over a crest, down into a sag; the shortest vertical curves that meet
# the stopping sight distance at 60 km/h (K = SSD²/658 on the crest, SSD²/(120 + 3.5 SSD) in the sag).
profile = Profile.from_pvis(
    [(1000, 50.0), (1260, 57.8), (1620, 47.0), (alignment.end_station, 51.0)], units="m", design_speed=60, alignment=alignment
)
print(profile.table(6))

# One 3.5 m lane each way with 1.5 m shoulders, 2.5 % crown on the tangents, 0.4 m of pavement.
road = corridor(alignment, profile, CrossSection(lane_width=3.5, shoulder_width=1.5, crossfall=0.025, depth=0.4))
print(road.describe())
print(road.centerline.describe())
units = alignment.chain.units  # the design's unit, declared in the files (nothing is rescaled)
export_step(road.solid, out / "road.step", units=units)
export_step(centerline_wire(road.centerline), out / "road_centreline.step", units=units)

# The view exaggerates heights 8× so that the crest and the sag show.
view = scale(road.solid, by=(1, 1, 8)).project_to_viewport((410, -700, 800), viewport_up=(0, 0, 1), look_at=(410, 20, 420))
svg = ExportSVG(scale=0.8)
svg.add_layer("visible", line_weight=0.2)
svg.add_layer("hidden", line_weight=0.1, line_type=LineType.ISO_DOT)
svg.add_shape(view[0], layer="visible")
svg.add_shape(view[1], layer="hidden")
svg.write(str(out / "road.svg"))
print(f"wrote {out / 'road.step'}, {out / 'road_centreline.step'}, {out / 'road.svg'}")
