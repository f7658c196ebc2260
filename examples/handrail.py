"""A G2 handrail: a stair rail in space with curvature-continuous bends, swept with a circle in build123d.

Run: ``python examples/handrail.py [OUT_DIR]`` (default ./out). The rail's
centre line climbs two flights and turns at two landings; every bend lies
in the plane of its two straight runs and is a G2 spiral pair whose
smallest radius of curvature is 250 mm (``G2Polyline``). A Ø42.4 mm tube
(a standard handrail section) is swept along it into a valid solid.
Writes ``handrail.step`` (the solid), ``handrail_path.step`` (the centre
line's exact LINE and BEZIER edges) and prints the G2 check of the path.
"""

import sys
from pathlib import Path

from build123d import BuildLine, BuildPart, BuildSketch, Circle, Plane, sweep

from spiral_cad.build123d import G2Polyline
from spiral_cad.cad.continuity import check_continuity
from spiral_cad.cad.export import export_step

out = Path(sys.argv[1] if len(sys.argv) > 1 else "out")
out.mkdir(parents=True, exist_ok=True)

# centre line in mm: a flight up, a landing turning 90°, a second flight, a landing, a short run
rail = [
    (0, 0, 900),
    (3000, 0, 2700),
    (3600, 300, 2700),
    (3600, 1500, 2700),
    (600, 1500, 4500),
    (0, 1900, 4500),
    (-800, 1900, 4500),
]
with BuildPart() as handrail:
    with BuildLine() as centre:
        line = G2Polyline(*rail, radius=250)
    path = centre.wire()
    with BuildSketch(Plane(origin=path @ 0, z_dir=path % 0)):
        Circle(42.4 / 2)
    sweep(path=path)

solid = handrail.part
assert solid.is_valid, "the swept rail is not a valid solid"
export_step(solid, out / "handrail.step", units="mm")  # the design's unit; one product, the path one wire
export_step(path, out / "handrail_path.step", units="mm")
report = check_continuity(out / "handrail_path.step")
assert report.passes("G2"), report.describe()
rounded = line.rounded
print(
    f"handrail: {len(rounded.corners)} bends, centre line {rounded.chain.length:.1f} mm, "
    f"smallest radius of curvature {1 / rounded.max_curvature:.1f} mm, tube volume {solid.volume / 1e6:.3f} dm³"
)
for corner in rounded.corners:
    print(
        f"  bend at point {corner.index}: turn {2 * corner.theta * 57.29577951308232:6.2f}°, "
        f"spirals start {corner.distance:7.1f} mm from the corner, pass {corner.deviation:5.1f} mm inside it"
    )
print(report.describe())
print(f"wrote {out / 'handrail.step'} and {out / 'handrail_path.step'}")
