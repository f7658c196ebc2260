"""Every example script runs from plain Python (a process of its own, as ``python SCRIPT FOLDER``) and
writes what it promises."""

from pathlib import Path

import pytest
from helpers import Block, run_blocks

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
OUTPUTS = {
    "build123d_road.py": ["road.step", "road_centreline.step", "road.svg"],
    "robot_path.py": ["robot_path.png", "robot_path.svg"],
    "robot_path_3d.py": ["robot_path_3d.step", "robot_path_3d.csv", "robot_path_3d.png"],
    "handrail.py": ["handrail.step", "handrail_path.step"],
    "fig6.py": ["fig6.png", "bezier_vs_clothoid.png"],
    "cadquery_plugin.py": ["cadquery_plugin.step"],
    "continuous_corners.py": ["slab.step", "continuous_corners.png"],
    "fit_points.py": ["survey.csv", "survey.step", "survey_residuals.csv", "survey_fit.png"],
}


@pytest.fixture(scope="module")
def example_outputs(tmp_path_factory):
    """Runs an example script (the name) into a folder of its own once, however many tests read its outputs."""
    folders: dict[str, Path] = {}

    def run_once(script: str) -> Path:
        if script not in folders:
            folder = tmp_path_factory.mktemp(script.removesuffix(".py"))
            target = folder / OUTPUTS[script][0] if script == "cadquery_plugin.py" else folder
            path = EXAMPLES / script
            run_blocks(path, [Block(1, path.read_text(encoding="utf-8"), None)], folder, 300, [str(path), str(target)])
            folders[script] = folder
        return folders[script]

    return run_once


@pytest.mark.parametrize("script", sorted(OUTPUTS))
def test_example_runs(script, example_outputs):
    folder = example_outputs(script)
    for name in OUTPUTS[script]:
        assert (folder / name).stat().st_size > 0, name


def test_the_road_example_writes_metres(example_outputs):
    """road.step holds the design in metres: OCCT reading it into millimetres finds a road of about 900 m, not 0.9 m."""
    pytest.importorskip("OCP")
    from OCP.Bnd import Bnd_Box
    from OCP.BRepBndLib import BRepBndLib
    from OCP.BRepGProp import BRepGProp
    from OCP.GProp import GProp_GProps
    from OCP.STEPControl import STEPControl_Reader

    tmp_path = example_outputs("build123d_road.py")
    for name in ("road.step", "road_centreline.step"):
        reader = STEPControl_Reader()
        reader.ReadFile(str(tmp_path / name))
        reader.SetSystemLengthUnit(1.0)  # millimetres
        reader.TransferRoots()
        box = Bnd_Box()
        BRepBndLib.Add_s(reader.OneShape(), box)
        x0, y0, _, x1, y1, _ = box.Get()
        assert 820e3 <= x1 - x0 <= 830e3 and 100e3 <= y1 - y0 <= 220e3, (name, x1 - x0, y1 - y0)
    # the centre line's 3-D length in mm: longer than its plan's chord, shorter than the polyline of its PIs
    props = GProp_GProps()
    reader = STEPControl_Reader()
    reader.ReadFile(str(tmp_path / "road_centreline.step"))
    reader.SetSystemLengthUnit(1.0)
    reader.TransferRoots()
    BRepGProp.LinearProperties_s(reader.OneShape(), props)
    chord = (820**2 + 90**2) ** 0.5 * 1e3
    pis = sum(
        ((bx - ax) ** 2 + (by - ay) ** 2) ** 0.5
        for (ax, ay), (bx, by) in zip([(0, 0), (300, 60), (560, -40)], [(300, 60), (560, -40), (820, 90)])
    )
    assert chord < props.Mass() < pis * 1e3 * 1.01
