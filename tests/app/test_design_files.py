"""Design files and the CLI: any byte sequence gives ``error: …`` and exit 2, units reach every file."""

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from spiral_cad.app.cli import main

DESIGN = {
    "units": "m",
    "designs": [
        {
            "name": "t",
            "type": "transition",
            "case": "line_to_circle",
            "point": [0, 0],
            "direction": [1, 0],
            "center": [0, 105],
            "radius": 100,
        }
    ],
}


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
        (
            json.dumps(
                {
                    **DESIGN,
                    "designs": [
                        {
                            "name": "c",
                            "type": "transition",
                            "case": "line_to_line",
                            "p0": [0, 0],
                            "corner": [100, 0],
                            "p1": [160, 80],
                            "curvature": 1e15,
                        }
                    ],
                }
            ).encode(),
            "line_to_line: the solution",
        ),
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
FIELDS = [
    "pis",
    "radii",
    "spiral_angles_deg",
    "spiral_lengths",
    "start_station",
    "circles",
    "points",
    "max_curvature",
    "curvature",
    "method",
    "case",
    "point",
    "direction",
    "center",
    "radius",
    "p0",
    "corner",
    "p1",
    "center0",
    "radius0",
    "center1",
    "radius1",
]


@settings(max_examples=150, suppress_health_check=[HealthCheck.function_scoped_fixture], deadline=None)
@given(
    st.sampled_from(["alignment", "circle_chain", "rounded_polyline", "transition"]),
    st.dictionaries(st.sampled_from(FIELDS), JSON, max_size=6),
)
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
    return {"units": "m", "designs": [{"name": "long", "type": "alignment", "pis": pis, "radii": 200, "spiral_angles_deg": 5}]}


def test_an_interrupted_build_leaves_nothing_behind(tmp_path):
    design = tmp_path / "big.json"
    design.write_text(json.dumps(big_design(3000)))
    out = tmp_path / "out"
    out.mkdir()
    (out / "old.txt").write_text("from before")
    process = subprocess.Popen(
        [sys.executable, "-m", "spiral_cad.app.cli", "build", str(design), "--out", str(out)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    for line in process.stdout:  # wait until the writing has begun
        if line.startswith("built "):
            break
    time.sleep(0.5)
    process.send_signal(signal.SIGTERM)
    _, err = process.communicate(timeout=120)
    assert process.returncode == 130, err
    assert err == f"error: interrupted; nothing in {out}/ was changed\n"
    assert sorted(p.name for p in out.iterdir()) == ["old.txt"]


def test_a_killed_builds_staging_folder_is_removed_by_the_next_build_only_if_it_is_ours(tmp_path, capsys):
    from spiral_cad.io.staging import MARKER, _marker_text

    out = tmp_path / "out"
    stale = out / ".spiral-cad-build-999999999-abc"
    stale.mkdir(parents=True)
    (stale / "half.step").write_text("ISO-10303-21;")
    (stale / MARKER).write_text(_marker_text(999999999))
    foreign = out / ".spiral-cad-build-999999998-xyz"  # named like ours, no marker: the user's
    foreign.mkdir()
    (foreign / "precious.txt").write_text("keep me")
    design = tmp_path / "d.json"
    design.write_text(json.dumps(DESIGN))
    assert main(["build", str(design), "--out", str(out), "--no-plots"]) == 0
    assert not stale.exists() and (out / "t.step").exists()
    assert (foreign / "precious.txt").read_text() == "keep me"


@pytest.mark.parametrize("units, factor", [("mm", 1.0), ("m", 1000.0)])
def test_units_of_a_design_reach_every_file(tmp_path, capsys, units, factor):
    pytest.importorskip("OCP")
    import ezdxf
    from OCP.BRepAdaptor import BRepAdaptor_Curve
    from OCP.GCPnts import GCPnts_AbscissaPoint
    from OCP.TopAbs import TopAbs_EDGE
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopoDS import TopoDS

    from spiral_cad.cad.readers import read_shape

    design = {
        "units": units,
        "designs": [
            {
                "name": "road",
                "type": "alignment",
                "pis": [[0, 0], [600, 120], [1150, -80], [1700, 260]],
                "radii": [450, 400],
                "spiral_angles_deg": 8,
            }
        ],
    }
    path = tmp_path / "d.json"
    path.write_text(json.dumps(design))
    out = tmp_path / "out"
    assert main(["build", str(path), "--out", str(out), "--no-plots"]) == 0
    from spiral_cad.app.designfile import build

    chain = build(design)[1][0].chain
    for suffix in ("step", "igs"):
        shape, length = read_shape(out / f"road.{suffix}"), 0.0  # read in mm
        explorer = TopExp_Explorer(shape, TopAbs_EDGE)
        while explorer.More():
            length += GCPnts_AbscissaPoint.Length_s(BRepAdaptor_Curve(TopoDS.Edge_s(explorer.Current())), 1e-13)
            explorer.Next()
        assert length == pytest.approx(chain.length * factor, rel=1e-12)
    assert ezdxf.readfile(out / "road.dxf").header["$INSUNITS"] == {"mm": 4, "m": 6}[units]
    assert 'width="' in (svg := (out / "road.svg").read_text()) and 'mm"' in svg
    assert f"TS [{units}]" in (out / "road_stations.csv").read_text().splitlines()[0]
    assert "1 wire of 9 edges" in (out / "road_continuity.txt").read_text().splitlines()[0]
    assert (out / "road_continuity.txt").read_text().startswith("road.step:")  # no staging path


@pytest.mark.parametrize("criteria", ["road", "rail"])
def test_criteria_and_stations_csv_hold_plain_numbers_with_units(tmp_path, criteria):
    """np.float64(0.0407…) once stood in every banking cell: float() could not read it."""
    from helpers import assert_plain_csv

    from spiral_cad.design import Alignment

    pis, radii = [[0, 0], [600, 120], [1150, -80], [1700, 260]], [450, 400]
    if criteria == "road":
        alignment = Alignment.from_pis(pis, radii, units="m", design_speed=80)
    else:
        alignment = Alignment.from_pis(pis, radii, units="m", criteria=_rail())
    for write, name in ((alignment.criteria_to_csv, "criteria.csv"), (alignment.to_csv, "stations.csv")):
        assert_plain_csv(write(tmp_path / name))
    for row in alignment.criteria_rows() + alignment.rows():
        assert all(type(value) in (int, float, str) for value in row.values()), row
    assert "np." not in alignment.criteria_table() + alignment.table()


def _rail():
    from spiral_cad.design import RailCriteria

    return RailCriteria(80)


# --------------------------------------------------- all-or-nothing output

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "design.json"
EXAMPLE_FILES = [
    f"{name}{suffix}" for name in ("rail", "loop", "cnc", "ramp") for suffix in (".step", ".svg", ".igs", "_continuity.txt", ".dxf")
] + ["rail_stations.csv", "rail.xodr"]


def test_one_blocked_destination_leaves_every_existing_file_untouched(tmp_path, capsys):
    """A folder named rail.step once let a build replace 8 other files, then exit 2."""
    pytest.importorskip("OCP")
    out = tmp_path / "out"
    out.mkdir()
    for name in EXAMPLE_FILES:
        (out / name).write_text(f"old {name}")
    (out / "rail.step").unlink()
    (out / "rail.step").mkdir()
    before = {p.name: p.read_bytes() if p.is_file() else None for p in out.iterdir()}
    assert main(["build", str(EXAMPLE), "--out", str(out), "--no-plots"]) == 2
    err = capsys.readouterr().err
    assert err == f"error: cannot replace files in {str(out)!r}: rail.step is a folder; nothing there was changed\n"
    assert {p.name: p.read_bytes() if p.is_file() else None for p in out.iterdir()} == before


# ------------------------------------------------ the design file itself


def test_a_control_character_in_geo_reference_is_an_error_not_an_unreadable_file(tmp_path, capsys):
    design = {
        "units": "m",
        "designs": [
            {
                "name": "road",
                "type": "alignment",
                "pis": [[0, 0], [600, 120], [1150, -80]],
                "radii": [450],
                "spiral_angles_deg": 8,
                "geo_reference": "\u0001",
            }
        ],
    }
    status, err, out = run_build(tmp_path, json.dumps(design).encode(), capsys)
    assert status == 2
    assert err.startswith(r"error: designs[0] (road).geo_reference must be printable text; it holds U+0001")
    assert not out.exists()


def test_names_differing_only_in_case_are_refused(tmp_path, capsys):
    twice = {"units": "m", "designs": [DESIGN["designs"][0], {**DESIGN["designs"][0], "name": "T"}]}
    status, err, _ = run_build(tmp_path, json.dumps(twice).encode(), capsys)
    assert status == 2 and "designs[1].name: 'T' is used twice (names may not differ only in case" in err


@pytest.mark.parametrize("kind", ["device", "folder", "too large", "fifo"])
def test_design_files_that_are_not_regular_or_too_large_are_refused_before_reading(tmp_path, kind):
    from spiral_cad.app.designfile import MAX_DESIGN_BYTES

    path = {"device": Path("/dev/zero"), "folder": tmp_path}.get(kind, tmp_path / "design.json")
    if kind == "too large":
        with path.open("wb") as handle:
            handle.truncate(MAX_DESIGN_BYTES + 1)  # sparse: no time spent writing it
    elif kind == "fifo":
        os.mkfifo(path)  # reading it would wait for a writer forever
    if not path.exists():
        pytest.skip(f"no {path} here")
    started = time.perf_counter()
    done = subprocess.run([sys.executable, "-m", "spiral_cad.app.cli", "build", str(path), "--out", str(tmp_path / "out")],
                          capture_output=True, text=True, timeout=120)  # fmt: skip
    expected = {"device": "is not a regular file (a device, pipe or socket)", "folder": "is a folder, not a file",
                "too large": f"has {MAX_DESIGN_BYTES + 1} bytes; at most {MAX_DESIGN_BYTES} are read",
                "fifo": "is not a regular file"}  # fmt: skip
    assert done.returncode == 2 and done.stderr.startswith("error: design file ") and expected[kind] in done.stderr
    assert len(done.stderr.splitlines()) == 1 and time.perf_counter() - started < 60


def _at(data, path):
    for key in path:
        data = data[key]
    return data


def paths_of(data, prefix=()) -> list[tuple]:
    found = [prefix]
    items = data.items() if isinstance(data, dict) else enumerate(data) if isinstance(data, list) else ()
    for key, value in items:
        found += paths_of(value, (*prefix, key))
    return found


def edited(data, edits):
    """``data`` with each edit applied: ("scale", path, factor), ("set", path, value) or ("delete", path, None)."""
    data = json.loads(json.dumps(data))
    for kind, path, value in edits:
        try:
            parent = _at(data, path[:-1])
            if kind == "delete":
                del parent[path[-1]]
            else:
                parent[path[-1]] = parent[path[-1]] * value if kind == "scale" else value
        except (KeyError, IndexError, TypeError):  # an earlier edit removed or replaced the path
            continue
    return data


EXAMPLE_DATA = json.loads(EXAMPLE.read_text())
EXAMPLE_PATHS = paths_of(EXAMPLE_DATA)[1:]
NUMERIC_PATHS = [p for p in EXAMPLE_PATHS if isinstance(_at(EXAMPLE_DATA, p), (int, float)) and not isinstance(_at(EXAMPLE_DATA, p), bool)]
FACTORS = st.sampled_from([0.5, 0.9, 1.1, 2.0]) | st.sampled_from([1e-300, 1e-9, 1e9, 1e300, -1.0, 0])
EDITS = (
    st.tuples(st.just("scale"), st.sampled_from(NUMERIC_PATHS), FACTORS)
    | st.tuples(st.just("set"), st.sampled_from(EXAMPLE_PATHS), JSON)
    | st.tuples(st.just("delete"), st.sampled_from(EXAMPLE_PATHS), st.none())
)
BYTE_FLIPS = st.just([]) | st.just([]) | st.lists(st.tuples(st.integers(0, 10_000), st.integers(0, 255)), min_size=1, max_size=2)


@settings(max_examples=40, suppress_health_check=[HealthCheck.function_scoped_fixture], deadline=None)
@given(st.lists(EDITS, max_size=2), BYTE_FLIPS)
def test_mutated_example_designs_build_or_fail_with_a_design_error(tmp_path, edits, flips):
    """The design loader's one rule, through the API: files, or a ValueError (exit 2) — nothing else."""
    from spiral_cad.app.designfile import build, write

    raw = bytearray(json.dumps(edited(EXAMPLE_DATA, edits)).encode())
    for position, byte in flips:
        raw[position % len(raw)] = byte
    source = tmp_path / "design.json"
    source.write_bytes(bytes(raw))
    out = tmp_path / "out"
    try:
        units, built = build(source)
        written = write(built, out, units, progress=lambda line: None, plots=False)
    except ValueError:
        return
    assert written.files and all(p.is_file() and p.parent == out for p in written.files)


def test_messages_and_reprs_show_plain_numbers():
    """sc.Line((0, 0), (0, 0)) once said "both are (np.float64(0.0), np.float64(0.0))"."""
    import numpy as np

    import spiral_cad as sc

    f = np.float64
    texts = [repr(sc.Line((f(0), 0), (1, f(2)))), repr(sc.Arc((f(0), 0), f(1), f(0), f(1))),
             repr(sc.Chain(sc.line_to_circle((0, 0), (1, 0), (0, f(1.05)), f(1)).spirals))]  # fmt: skip
    for bad in (lambda: sc.Line((f(0), f(0)), (0, 0)), lambda: sc.Line((f(-1e308), 0), (f(1e308), 0))):
        with pytest.raises(ValueError) as error, np.errstate(over="ignore"):  # the length overflows: that is the point
            bad()
        texts.append(str(error.value))
    assert texts[3] == "Line needs distinct end points; both are (0.0, 0.0)"
    assert not [t for t in texts if "np." in t or "float64(" in t], texts


# ------------------------------------------- files a design may read

POCKET = Path(__file__).resolve().parents[2] / "examples" / "pocket.nc"


def gcode_design(folder: Path, program: str) -> Path:
    """A design file in ``folder`` that rounds the G-code program ``program``."""
    path = folder / "design.json"
    path.write_text(json.dumps({"units": "mm", "designs": [{"name": "cnc", "type": "rounded_polyline",
                                                            "gcode": program, "max_deviation": 0.5}]}))  # fmt: skip
    return path


@pytest.fixture
def shared(tmp_path) -> Path:
    """A design folder inside ``tmp_path``, beside a program and a secret outside it."""
    folder = tmp_path / "designs"
    (folder / "programs").mkdir(parents=True)
    (tmp_path / "router.nc").write_bytes(POCKET.read_bytes())
    (tmp_path / "secret-target.nc").write_bytes(POCKET.read_bytes())
    return folder


@pytest.mark.parametrize("program", ["../router.nc", "programs/../../router.nc", "..\\router.nc"])
def test_a_design_cannot_climb_out_of_its_folder(shared, program):
    from spiral_cad.app.designfile import DesignError, build

    with pytest.raises(DesignError) as error:
        build(gcode_design(shared, program))
    assert str(error.value) == (f"designs[0] (cnc).gcode: {program!r} climbs out with '..'; a design file reads only "
                                "files in its own folder")  # fmt: skip


def test_a_design_cannot_read_an_absolute_path(shared):
    from spiral_cad.app.designfile import DesignError, build

    program = str(shared.parent / "router.nc")
    with pytest.raises(DesignError, match=r"^designs\[0\] \(cnc\)\.gcode: .* is an absolute path; a design file reads only"):
        build(gcode_design(shared, program))


def test_a_link_out_of_the_folder_is_refused_by_its_own_name(shared, capsys):
    link = shared / "programs" / "part.nc"
    link.symlink_to(shared.parent / "secret-target.nc")
    design = gcode_design(shared, "programs/part.nc")
    assert main(["build", str(design), "--out", str(shared / "out"), "--no-plots"]) == 2
    err = capsys.readouterr().err
    assert err == ("error: designs[0] (cnc).gcode: 'programs/part.nc' is a link leading outside the design file's "
                   "folder; a design file reads only files in its own folder\n")  # fmt: skip
    assert "secret" not in err and not (shared / "out").exists()


def test_a_folder_link_out_of_the_folder_is_refused(shared):
    from spiral_cad.app.designfile import DesignError, build

    (shared / "elsewhere").symlink_to(shared.parent)
    with pytest.raises(DesignError, match=r"'elsewhere/router.nc' is a link leading outside"):
        build(gcode_design(shared, "elsewhere/router.nc"))


def test_programs_in_the_folder_and_below_it_are_read_also_through_links(shared):
    from spiral_cad.app.designfile import build

    (shared / "programs" / "pocket.nc").write_bytes(POCKET.read_bytes())
    (shared / "same.nc").symlink_to(shared / "programs" / "pocket.nc")
    lengths = [build(gcode_design(shared, program))[1][0].chain.length for program in ("programs/pocket.nc", "same.nc")]
    assert lengths[0] == lengths[1] > 0


def test_a_missing_program_is_named_as_given(shared):
    from spiral_cad.app.designfile import DesignError, build

    (shared / "gone.nc").symlink_to(shared / "nowhere.nc")
    with pytest.raises(DesignError, match=r"^designs\[0\] \(cnc\): gone.nc: the G-code file is missing$"):
        build(gcode_design(shared, "gone.nc"))


def test_built_designs_are_typed_by_kind():
    from spiral_cad.app.designfile import (
        BuiltAlignment,
        BuiltCircleChain,
        BuiltRounded,
        BuiltTransition,
        build,
        summary,
    )

    units, built = build(EXAMPLE)
    assert units == "m"
    assert [type(b) for b in built] == [BuiltAlignment, BuiltCircleChain, BuiltRounded, BuiltTransition]
    rail, loop, cnc, ramp = built
    assert rail.kind == "alignment" and rail.profile is None and rail.cross_section.driving_lanes == 1
    assert ramp.kind == f"transition ({ramp.source.kind})" and cnc.samples is None
    assert summary(built, units).count("\n") == len(built) + 1


def test_a_chain_too_long_for_occts_reread_and_iges_is_reported_by_its_own_joint_checks(tmp_path, monkeypatch, capsys):
    pytest.importorskip("OCP")
    from spiral_cad.app import designfile

    (tmp_path / "pocket.nc").write_bytes(POCKET.read_bytes())
    design = {"units": "mm", "designs": [{"name": "pocket", "type": "rounded_polyline", "gcode": "pocket.nc", "max_deviation": 0.05}]}
    (tmp_path / "pocket.json").write_text(json.dumps(design))
    monkeypatch.setattr(designfile, "LARGE_CHAIN_EDGES", 3)
    assert main(["build", str(tmp_path / "pocket.json"), "--out", str(tmp_path / "out"), "--no-plots"]) == 0
    out = capsys.readouterr().out
    assert "G2 by the chain's own joint checks" in out and "skipped above 3" in out
    assert not (tmp_path / "out" / "pocket_continuity.txt").exists()
    assert not (tmp_path / "out" / "pocket.igs").exists() and "no igs (" in out
    assert (tmp_path / "out" / "pocket.step").is_file()


def test_a_key_given_twice_in_one_object_is_refused(tmp_path):
    from spiral_cad.app.designfile import DesignError, build

    path = tmp_path / "twice.json"
    path.write_text('{"units": "mm", "designs": [{"name": "a", "name": "b", "type": "rounded_polyline", '
                    '"points": [[0, 0], [1, 0], [1, 1]], "max_curvature": 1}]}')  # fmt: skip
    with pytest.raises(DesignError, match=r"twice.json: the key 'name' is given twice in one object"):
        build(path)
