"""Every example script runs from plain Python and writes what it promises."""

import subprocess
import sys
from pathlib import Path

import pytest

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"
OUTPUTS = {
    "build123d_road.py": ["road.step", "road_centreline.step", "road.svg"],
    "robot_path.py": ["robot_path.png", "robot_path.svg"],
    "robot_path_3d.py": ["robot_path_3d.step", "robot_path_3d.csv", "robot_path_3d.png"],
    "handrail.py": ["handrail.step", "handrail_path.step"],
    "fig6.py": ["fig6.png", "bezier_vs_clothoid.png"],
    "cadquery_plugin.py": ["cadquery_plugin.step"],
    "continuous_corners.py": ["slab.step", "continuous_corners.png"],
}


@pytest.mark.parametrize("script", sorted(OUTPUTS))
def test_example_runs(script, tmp_path):
    target = tmp_path / OUTPUTS[script][0] if script == "cadquery_plugin.py" else tmp_path
    run = subprocess.run(
        [sys.executable, str(EXAMPLES / script), str(target)], capture_output=True, text=True, timeout=300
    )
    assert run.returncode == 0, run.stdout[-2000:] + run.stderr[-2000:]
    for name in OUTPUTS[script]:
        assert (tmp_path / name).stat().st_size > 0, name
