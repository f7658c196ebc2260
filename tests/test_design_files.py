"""Design files and the CLI: any byte sequence gives ``error: …`` and exit 2, units reach every file."""

import json
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from spiral_cad.cli import main

DESIGN = {"units": "m", "designs": [{"name": "t", "type": "transition", "case": "line_to_circle",
                                      "point": [0, 0], "direction": [1, 0], "center": [0, 105], "radius": 100}]}


def run_build(tmp_path, content: bytes, capsys) -> tuple[int, str, Path]:
    path = tmp_path / "design.json"
    path.write_bytes(content)
    out = tmp_path / "out"
    status = main(["build", str(path), "--out", str(out), "--no-plots"])
    return status, capsys.readouterr().err, out


def design_with(**fields) -> bytes:
    design = json.loads(json.dumps(DESIGN))
    design["designs"][0].update(fields)
    return json.dumps(design).encode()


@pytest.mark.parametrize(
    "content, message",
    [
        (design_with(type=[]), r"designs\[0\].type: must be one of"),
        (design_with(type={}), r"designs\[0\].type: must be one of"),
        (design_with(case=["line_to_circle"]), r"\.case: must be one of"),
        (b'{"units": "m", "designs": [\xff\xfe]}', r"not UTF-8 text \(byte 27: 0xff\)"),
        (design_with(radius=10**400), "integer of 401 digits"),
        (b'{"units": "m", "designs": [{"radius": 1' + b"0" * 5000 + b"}]}", "integer of 5001 digits"),
        (b"[" * 100_000 + b"]" * 100_000, "nested too deeply"),
        (design_with(name="x" * 300), r"name: must be 1–64 characters"),
        (design_with(name="../etc"), r"name: must be 1–64 characters"),
        (design_with(radius=1e-300), "line_to_circle: the solution does not fit in float64"),
        (design_with(radius=float("nan")), "NaN is not a number in JSON"),
        (json.dumps({**DESIGN, "designs": [{"name": "c", "type": "transition", "case": "line_to_line", "p0": [0, 0],
                                              "corner": [100, 0], "p1": [160, 80], "curvature": 1e15}]}).encode(),
         "line_to_line: the solution"),
        (json.dumps({"designs": DESIGN["designs"]}).encode(), "units: required"),
        (b"[]", "must be a JSON object"),
        (b"", "malformed JSON at line 1"),
    ],
)
def test_bad_design_files_print_an_error_and_write_nothing(tmp_path, capsys, content, message):
    import re

    status, err, out = run_build(tmp_path, content, capsys)
    assert status == 2
    assert err.startswith("error: ") and re.search(message, err), err
    assert "Traceback" not in err and "internal error" not in err
    assert not out.exists() or not any(out.iterdir())


@settings(max_examples=60, suppress_health_check=[HealthCheck.function_scoped_fixture], deadline=None)
@given(st.binary(max_size=300))
def test_any_bytes_give_an_error_not_a_traceback(tmp_path, capsys, content):
    status, err, _ = run_build(tmp_path, content, capsys)
    assert status == 2 and err.startswith("error: ") and "internal error" not in err


JSON = st.recursive(
    st.none() | st.booleans() | st.integers() | st.floats(allow_nan=False) | st.text(max_size=8),
    lambda inner: st.lists(inner, max_size=4) | st.dictionaries(st.text(max_size=8), inner, max_size=4),
    max_leaves=20,
)
FIELDS = ["pis", "radii", "spiral_angles_deg", "spiral_lengths", "start_station", "circles", "points", "max_curvature",
          "curvature", "method", "case", "point", "direction", "center", "radius", "p0", "corner", "p1", "center0",
          "radius0", "center1", "radius1"]


@settings(max_examples=150, suppress_health_check=[HealthCheck.function_scoped_fixture], deadline=None)
@given(st.sampled_from(["alignment", "circle_chain", "rounded_polyline", "transition"]),
       st.dictionaries(st.sampled_from(FIELDS), JSON, max_size=6))
def test_any_field_values_are_validated_by_name(tmp_path, capsys, kind, fields):
    design = {"units": "m", "designs": [{"name": "fuzz", "type": kind, **fields}]}
    status, err, _ = run_build(tmp_path, json.dumps(design).encode(), capsys)
    assert status in (0, 2)
    if status == 2:
        assert err.startswith("error: ") and "internal error" not in err, err


def test_out_naming_a_file_is_an_error(tmp_path, capsys):
    design = tmp_path / "d.json"
    design.write_text(json.dumps(DESIGN))
    target = tmp_path / "taken"
    target.write_text("keep me")
    assert main(["build", str(design), "--out", str(target)]) == 2
    assert "is a file, not a folder" in capsys.readouterr().err
    assert target.read_text() == "keep me"


def big_design(count: int) -> dict:
    pis = [[1000.0 * k, 300.0 * (k % 2)] for k in range(count + 2)]
    return {"units": "m", "designs": [{"name": "long", "type": "alignment", "pis": pis, "radii": 200,
                                       "spiral_angles_deg": 5}]}


def test_an_interrupted_build_leaves_nothing_behind(tmp_path):
    design = tmp_path / "big.json"
    design.write_text(json.dumps(big_design(3000)))
    out = tmp_path / "out"
    out.mkdir()
    (out / "old.txt").write_text("from before")
    process = subprocess.Popen(
        [sys.executable, "-m", "spiral_cad.cli", "build", str(design), "--out", str(out)],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
    )
    for line in process.stdout:  # wait until the writing has begun
        if line.startswith("built "):
            break
    time.sleep(0.5)
    process.send_signal(signal.SIGTERM)
    _, err = process.communicate(timeout=120)
    assert process.returncode == 130, err
    assert err.startswith("error: interrupted") and "Traceback" not in err
    assert sorted(p.name for p in out.iterdir()) == ["old.txt"]


def test_a_killed_builds_staging_folder_is_removed_by_the_next_build(tmp_path, capsys):
    out = tmp_path / "out"
    stale = out / ".spiral-cad-build-999999999-abc"
    stale.mkdir(parents=True)
    (stale / "half.step").write_text("ISO-10303-21;")
    design = tmp_path / "d.json"
    design.write_text(json.dumps(DESIGN))
    assert main(["build", str(design), "--out", str(out), "--no-plots"]) == 0
    assert not stale.exists() and (out / "t.step").exists()


@pytest.mark.parametrize("units, factor", [("mm", 1.0), ("m", 1000.0)])
def test_units_of_a_design_reach_every_file(tmp_path, capsys, units, factor):
    pytest.importorskip("OCP")
    import ezdxf
    from OCP.BRepAdaptor import BRepAdaptor_Curve
    from OCP.GCPnts import GCPnts_AbscissaPoint
    from OCP.TopAbs import TopAbs_EDGE
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopoDS import TopoDS

    from spiral_cad.occ import read_shape

    design = {"units": units, "designs": [{"name": "road", "type": "alignment", "pis": [[0, 0], [600, 120], [1150, -80],
                                           [1700, 260]], "radii": [450, 400], "spiral_angles_deg": 8}]}
    path = tmp_path / "d.json"
    path.write_text(json.dumps(design))
    out = tmp_path / "out"
    assert main(["build", str(path), "--out", str(out), "--no-plots"]) == 0
    from spiral_cad.designfile import build

    chain = build(design)[1][0].chain
    for suffix in ("step", "igs"):
        shape, length = read_shape(out / f"road.{suffix}"), 0.0  # read in mm
        explorer = TopExp_Explorer(shape, TopAbs_EDGE)
        while explorer.More():
            length += GCPnts_AbscissaPoint.Length_s(BRepAdaptor_Curve(TopoDS.Edge_s(explorer.Current())), 1e-13)
            explorer.Next()
        assert length == pytest.approx(chain.length * factor, rel=1e-12)
    assert ezdxf.readfile(out / "road.dxf").header["$INSUNITS"] == {"mm": 4, "m": 6}[units]
    assert 'width="' in (svg := (out / "road.svg").read_text()) and "mm\"" in svg
    assert f"TS [{units}]" in (out / "road_stations.csv").read_text().splitlines()[0]
    assert "1 wire of 9 edges" in (out / "road_continuity.txt").read_text().splitlines()[0]
    assert (out / "road_continuity.txt").read_text().startswith("road.step:")  # no staging path
