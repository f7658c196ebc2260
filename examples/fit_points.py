"""From points to G2: a surveyed road centre line fitted with lines, arcs and spirals within 10 cm.

Run: ``python examples/fit_points.py [OUT_DIR]`` (default ./out). Makes the
survey: a road of a tangent, a near-linear spiral onto a 200 m curve, a spiral
off it and a tangent (1.59 km), sampled every 5 m with 2 mm of Gaussian noise
(seeded) and rounded to millimetres, as a total station or RTK GPS gives it.
It writes the points as ``survey.csv`` (``examples/survey.csv`` is this
file) and builds them as ``spiral-cad build --from-points survey.csv
--tolerance 0.1 --units m`` does: STEP, DXF, SVG, ``survey_residuals.csv``
(every point's distance to the fitted path) and ``survey_fit.png``.
``examples/fit.json`` is the same fit as a design file.
"""

import sys
from pathlib import Path

import numpy as np

import spiral_cad as sc
from spiral_cad.app.cli import main


def survey() -> np.ndarray:
    """The surveyed points (N, 2) in metres: the road every 5 m, with 2 mm of noise, to the millimetre."""
    enter = sc.line_to_circle((0, 0), (1, 0), (400, 210), 200.0, "near-linear")
    leave = sc.line_to_circle((610, 900), (0, -1), (400, 210), 200.0, "near-linear").reversed()
    road = sc.Chain.join([enter, leave], start=(-80, 0), end=(610, 1000), units="m")
    stations = np.arange(0.0, road.length, 5.0)
    noise = np.random.default_rng(24).normal(scale=0.002, size=(len(stations), 2))
    return np.round(road.point_at(stations) + noise, 3) + 0.0  # + 0.0: no -0.000


def write_survey(path: Path) -> Path:
    """``survey()`` as CSV: a units line, a header, x and y to the millimetre."""
    rows = "\n".join(f"{x:.3f},{y:.3f}" for x, y in survey())
    path.write_text(f"# units: m\n# a road centre line surveyed every 5 m (examples/fit_points.py)\nx,y\n{rows}\n", encoding="utf-8")
    return path


if __name__ == "__main__":
    out = Path(sys.argv[1] if len(sys.argv) > 1 else "out")
    out.mkdir(parents=True, exist_ok=True)
    points = write_survey(out / "survey.csv")
    sys.exit(main(["build", "--from-points", str(points), "--tolerance", "0.1", "--units", "m", "-o", str(out)]))
