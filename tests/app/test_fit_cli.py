"""From points to G2 on the command line and in design files: build --from-points, the design kind "fit",
the residuals CSV and the fit plot, judged by readers we did not write (OCCT, ezdxf, csv)."""

import csv
import json
import runpy
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial import cKDTree

import spiral_cad as sc
from spiral_cad.app.cli import main
from spiral_cad.app.designfile import BuiltFit, DesignError, build
from spiral_cad.app.fitreport import plot_fit, shown_points, write_residuals

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
TOLERANCE = 0.1


def road() -> sc.Chain:
    """A tangent, a spiral onto a 200 m curve, a spiral off it and a tangent (metres)."""
    enter = sc.line_to_circle((0, 0), (1, 0), (400, 210), 200.0, "near-linear")
    leave = sc.line_to_circle((610, 900), (0, -1), (400, 210), 200.0, "near-linear").reversed()
    return sc.Chain.join([enter, leave], start=(-80, 0), end=(610, 1000), units="m")


def traced(step: float = 5.0, sigma: float = 0.002, seed: int = 7) -> np.ndarray:
    """Points along ``road()`` every ``step`` with Gaussian noise ``sigma`` (2 % of the tolerance)."""
    chain = road()
    s = np.arange(0.0, chain.length, step)
    return chain.point_at(s) + np.random.default_rng(seed).normal(scale=sigma, size=(len(s), 2))


def distances(chain: sc.Chain, points: np.ndarray, count: int = 400_001) -> tuple[np.ndarray, np.ndarray]:
    """Each point's distance to ``chain`` and its station, measured independently of the fit: the chain sampled
    densely (chord error below 1e-7 here) and each point projected onto the two sample chords beside its nearest sample."""
    s = np.linspace(0.0, chain.length, count)
    xy = chain.point_at(s)
    nearest = cKDTree(xy).query(points)[1]
    best = np.full(len(points), np.inf)
    station = np.zeros(len(points))
    for j0 in (np.maximum(nearest - 1, 0), np.minimum(nearest, count - 2)):
        a, b = xy[j0], xy[j0 + 1]
        t = np.clip(np.einsum("ij,ij->i", points - a, b - a) / np.einsum("ij,ij->i", b - a, b - a), 0.0, 1.0)
        d = np.linalg.norm(a + t[:, None] * (b - a) - points, axis=1)
        closer = d < best
        best[closer], station[closer] = d[closer], (s[j0] + t * (s[j0 + 1] - s[j0]))[closer]
    return best, station


def read_table(path: Path) -> tuple[list[str], np.ndarray]:
    with path.open(newline="", encoding="utf-8") as handle:
        rows = list(csv.reader(handle))
    return rows[0], np.array(rows[1:], dtype=float)


# ------------------------------------------------------------------ the command line


def write_csv(path: Path, text: str) -> Path:
    path.write_text(text, encoding="utf-8")
    return path


@pytest.mark.parametrize(
    "text, message",
    [
        ("x,y\n0,0\n1,0\n2,abc\n", "error: designs[0] (trace): trace.csv: line 4: y is 'abc', not a number"),
        ("0 0\n1 0 0\n", "error: designs[0] (trace): trace.csv: line 2: 3 columns, expected 2 (x, y)"),
        ("0,0\n1,nan\n2,0\n", "error: designs[0] (trace): trace.csv: line 2: y is 'nan'; every coordinate must be a finite number"),
        ("# units: furlong\n0,0\n", "error: designs[0] (trace): trace.csv: line 1: unit 'furlong' is not one of"),
        ("", "error: designs[0] (trace): trace.csv: no points"),
    ],
)
def test_bad_points_files_exit_2_naming_the_line(tmp_path, capsys, text, message):
    path = write_csv(tmp_path / "trace.csv", text)
    assert main(["build", "--from-points", str(path), "--tolerance", "0.1", "-o", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert err.startswith(message) and "Traceback" not in err and err.count("\n") == 1
    assert not (tmp_path / "out").exists() or not any((tmp_path / "out").iterdir())


@pytest.mark.parametrize(
    "options, message",
    [
        ([], "error: --from-points needs --tolerance"),
        (["--tolerance", "0"], "error: --tolerance must be a positive finite number; got 0.0"),
        (["--tolerance", "nan"], "error: --tolerance must be a positive finite number; got nan"),
        (["--tolerance", "1", "--max-deviation", "1"], "error: --max-deviation: only with --from-gcode"),
        (["--tolerance", "1", "--shape", "g2cbs"], "error: --shape g2cbs rounds corners"),
        (["--tolerance", "1", "--sample-step", "1", "--chord-tolerance", "1"], "error: give --sample-step or --chord-tolerance"),
        (["--tolerance", "1", "--from-gcode", "a.nc"], "error: give --from-points, a design file or --from-gcode"),
    ],
)
def test_bad_options_are_named(tmp_path, capsys, options, message):
    path = write_csv(tmp_path / "trace.csv", "0,0\n1,0\n2,0\n")
    assert main(["build", "--from-points", str(path), *options]) == 2
    assert capsys.readouterr().err.startswith(message)


def test_a_road_fit_writes_the_road_files_and_judges_the_curves(tmp_path, capsys):
    """--design-speed: the alignment through the points (Alignment.fit), its criteria, OpenDRIVE and residuals."""
    points = traced()
    path = write_csv(tmp_path / "road.csv", "x,y\n" + "\n".join(f"{x!r},{y!r}" for x, y in points.tolist()))
    out = tmp_path / "out"
    assert main(["build", "--from-points", str(path), "--tolerance", "0.1", "--units", "m", "--design-speed", "60",
                 "--no-plots", "-o", str(out)]) == 0  # fmt: skip
    printed = capsys.readouterr().out
    assert "road: RoadCriteria, design speed 60 km/h" in printed and "fit (alignment)" in printed
    names = {p.name for p in out.iterdir()}
    assert {"road.xodr", "road_stations.csv", "road_criteria.csv", "road_residuals.csv", "road.step"} <= names
    assert main(["check", str(out / "road.xodr"), "--require", "G2"]) == 0
    _, table = read_table(out / "road_residuals.csv")
    from spiral_cad.design import Alignment

    chain = Alignment.fit(points, 0.1, 60, units="m").chain
    measured, _ = distances(chain, points)
    np.testing.assert_allclose(table[:, 4], measured, atol=1e-6)
    assert measured.max() <= 0.1


def test_a_3d_survey_is_plan_and_profile(tmp_path, capsys):
    """x, y, z: the plan within the tolerance, the profile within the vertical tolerance, the road in 3-D."""
    points = traced()
    s = 5.0 * np.arange(len(points))
    z = 100.0 + 0.04 * s - 2.5e-5 * s**2  # a crest over the whole road
    rows = "\n".join(f"{x!r} {y!r} {h!r}" for x, y, h in np.column_stack([points, z]).tolist())
    write_csv(tmp_path / "survey.xyz", f"# units: m\neasting northing elevation\n{rows}\n")
    design = {"units": "m", "designs": [{"name": "s3", "type": "fit", "points_file": "survey.xyz", "tolerance": 0.1,
                                         "vertical_tolerance": 0.02}]}  # fmt: skip
    (tmp_path / "fit.json").write_text(json.dumps(design))
    out = tmp_path / "out"
    assert main(["build", str(tmp_path / "fit.json"), "--no-plots", "-o", str(out)]) == 0
    assert "fit (alignment + profile)" in capsys.readouterr().out
    assert {"s3_profile.csv", "s3_3d.step", "s3.xodr"} <= {p.name for p in out.iterdir()}
    header, table = read_table(out / "s3_residuals.csv")
    assert header[-2:] == ["z [m]", "vertical_residual [m]"]
    np.testing.assert_array_equal(table[:, 5], z)
    assert np.abs(table[:, 4]).max() <= 0.1 and table[:, 6].max() <= 0.02
    _, (built,) = build(tmp_path / "fit.json")
    elevation = built.profile.elevation(np.clip(table[:, 3] + built.source.start_station, *built.profile.pvis[[0, -1], 0]))
    np.testing.assert_allclose(np.abs(elevation - z), table[:, 6], atol=1e-9)


@pytest.mark.parametrize(
    "options, message",
    [
        (["--design-speed", "60", "--closed"], ".closed: a road (design_speed or points with z) is open"),
        (["--design-speed", "60", "--max-curvature", "0.1"], ".max_curvature: a road's curves are judged by design_speed"),
        (["--design-speed", "60", "--sample-step", "1"], "samples: a road writes its stationing"),
    ],
)
def test_road_fits_refuse_what_a_road_does_not_take(tmp_path, capsys, options, message):
    path = write_csv(tmp_path / "trace.csv", "0,0\n1,0\n2,0\n")
    assert main(["build", "--from-points", str(path), "--tolerance", "0.1", *options, "-o", str(tmp_path / "out")]) == 2
    assert message in capsys.readouterr().err


def test_points_options_need_from_points(capsys):
    assert main(["build", str(EXAMPLES / "design.json"), "--tolerance", "1", "--closed"]) == 2
    assert capsys.readouterr().err.startswith("error: --tolerance, --closed: only with --from-points")


def test_a_bad_file_from_a_child_process_prints_no_traceback(tmp_path):
    path = write_csv(tmp_path / "trace.xyz", "0 0\n1 0\n2 x\n")
    run = subprocess.run([sys.executable, "-m", "spiral_cad.app.cli", "build", "--from-points", str(path), "--tolerance", "1",
                          "-o", str(tmp_path / "out")], capture_output=True, text=True, timeout=120)  # fmt: skip
    assert run.returncode == 2 and run.stderr == "error: designs[0] (trace): trace.xyz: line 3: y is 'x', not a number\n"


def test_build_from_points_writes_a_g2_path_within_tolerance(tmp_path, capsys):
    """A surveyed road (every 5 m, σ = 2 mm) comes back as its five pieces, within 10 cm, G2 as OCCT reads it."""
    points = traced()
    lines = "\n".join(f"{y!r} {x!r}" for x, y in points.tolist())  # northing first: the header says so
    path = write_csv(tmp_path / "trace.txt", f"# units: m\nnorthing easting\n{lines}\n")
    out = tmp_path / "out"
    assert main(["build", "--from-points", str(path), "--tolerance", str(TOLERANCE), "--units", "m", "-o", str(out)]) == 0
    printed = capsys.readouterr().out
    names = {p.name for p in out.iterdir()}
    assert {"trace.step", "trace.svg", "trace_residuals.csv"} <= names
    assert f"trace: {len(points):,} points within" in printed and "(tolerance 0.1 m)" in printed

    from spiral_cad.cad.continuity import check_continuity

    report = check_continuity(out / "trace.step", units="m")
    assert report.passes("G2") and report.pieces == 1

    header, table = read_table(out / "trace_residuals.csv")
    assert header == ["index", "x [m]", "y [m]", "station [m]", "residual [m]"]
    np.testing.assert_array_equal(table[:, 0], np.arange(len(points)))
    np.testing.assert_array_equal(table[:, 1:3], points)
    assert np.abs(table[:, 4]).max() <= TOLERANCE


# ------------------------------------------------------------------ design files


@pytest.fixture(scope="module")
def fitted(tmp_path_factory):
    """The example design file (examples/fit.json) built and written once."""
    out = tmp_path_factory.mktemp("fit") / "out"
    assert main(["build", str(EXAMPLES / "fit.json"), "-o", str(out)]) == 0
    return out


def test_the_fit_design_builds_typed():
    units, (built,) = build(EXAMPLES / "fit.json")
    assert units == "m" and isinstance(built, BuiltFit) and built.kind == "fit"
    assert built.fit.points.shape == (318, 2) and built.source.max_residual <= TOLERANCE
    # the noise-free road has five pieces: the 2 mm noise adds none
    assert len(built.chain) == 5, [type(seg).__name__ for seg in built.chain]


def test_the_fit_design_writes_files_readers_open(fitted):
    names = {p.name for p in fitted.iterdir()}
    assert {"survey.step", "survey.dxf", "survey.svg", "survey_samples.csv", "survey_residuals.csv", "survey_fit.png"} <= names
    from spiral_cad.cad.continuity import check_continuity

    assert check_continuity(fitted / "survey.step", units="m").passes("G2")
    ezdxf = pytest.importorskip("ezdxf")
    document = ezdxf.readfile(fitted / "survey.dxf")
    assert len(document.modelspace()) >= 1 and document.units == 6  # 6: metres
    assert (fitted / "survey_fit.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_residuals_agree_with_an_independent_distance(fitted):
    """Every residual of the CSV is the point's distance to the fitted path as dense sampling measures it."""
    _, (built,) = build(EXAMPLES / "fit.json")
    header, table = read_table(fitted / "survey_residuals.csv")
    measured, station = distances(built.chain, table[:, 1:3])
    np.testing.assert_allclose(np.abs(table[:, 4]), measured, atol=1e-6)
    np.testing.assert_allclose(table[:, 3], station, atol=1e-3)
    assert measured.max() <= TOLERANCE


def test_the_example_survey_is_what_its_script_generates(tmp_path):
    script = runpy.run_path(str(EXAMPLES / "fit_points.py"))
    written = script["write_survey"](tmp_path / "survey.csv")
    assert written.read_bytes() == (EXAMPLES / "survey.csv").read_bytes()


def test_points_files_stay_in_the_design_files_folder(tmp_path):
    design = {"units": "m", "designs": [{"name": "a", "type": "fit", "points_file": "../survey.csv", "tolerance": 0.1}]}
    path = tmp_path / "fit.json"
    path.write_text(json.dumps(design))
    with pytest.raises(DesignError, match=r"designs\[0\] \(a\).points_file: '../survey.csv' climbs out with '..'"):
        build(path)


def test_points_files_convert_to_the_design_units(tmp_path):
    (tmp_path / "trace.csv").write_text("x,y\n" + "\n".join(f"{x!r},{y!r}" for x, y in (traced() * 1000.0).tolist()))
    design = {"units": "m", "designs": [{"name": "a", "type": "fit", "points_file": "trace.csv", "points_units": "mm",
                                         "tolerance": 0.1}]}  # fmt: skip
    path = tmp_path / "fit.json"
    path.write_text(json.dumps(design))
    _, (built,) = build(path)
    np.testing.assert_allclose(built.fit.points, traced(), rtol=1e-15)
    assert built.chain.units == "m" and built.source.max_residual <= 0.1
    assert abs(built.chain.length - 5.0 * (len(built.fit.points) - 1)) < 0.5  # from the first point to the last


# ------------------------------------------------------------------ the report from arrays


def test_residuals_csv_round_trips(tmp_path):
    points = np.array([[0.0, 1.0], [2.5, -0.0], [1e-17, 3.0]])
    path = write_residuals(tmp_path / "r.csv", points, [0.0, 1.5, 2.25], [0.01, -0.02, 0.0], "ft")
    header, table = read_table(path)
    assert header == ["index", "x [ft]", "y [ft]", "station [ft]", "residual [ft]"]
    np.testing.assert_array_equal(table, [[0, 0.0, 1.0, 0.0, 0.01], [1, 2.5, 0.0, 1.5, -0.02], [2, 1e-17, 3.0, 2.25, 0.0]])
    assert "-0.0," not in path.read_text()
    with pytest.raises(ValueError, match="one row per point"):
        write_residuals(tmp_path / "r.csv", points, [0.0, 1.0], [0.0, 0.0, 0.0], "ft")


def test_shown_points_keep_the_worst_of_each_run():
    r = np.zeros(1_000)
    r[[3, 517, 998]] = [0.5, -0.9, 0.2]
    shown = shown_points(r, most=100)
    assert len(shown) == 100 and {3, 517, 998} <= set(shown.tolist())
    assert shown_points(r, most=1_000).tolist() == list(range(1_000))


def test_the_fit_plot_draws_residuals_band_and_both_curvatures():
    chain = road()
    s = np.linspace(0.0, chain.length, 50)
    r = np.sin(s) * 0.05
    estimate = chain.curvature_at(s) + 1e-4
    fig = plot_fit(chain, s, r, TOLERANCE, estimate)
    top, bottom = fig.axes
    (dots,) = [c for c in top.collections if c.get_gid() == "residuals"]
    np.testing.assert_allclose(dots.get_offsets(), np.column_stack([s, r]))
    (band,) = [p for p in top.patches if p.get_gid() == "tolerance"]
    assert band.get_y() == -TOLERANCE and band.get_height() == 2 * TOLERANCE
    (behind,) = [c for c in bottom.collections if c.get_gid() == "estimate"]
    np.testing.assert_allclose(behind.get_offsets(), np.column_stack([s, estimate]))
    lines = [c for c in bottom.collections if (c.get_gid() or "").startswith("curvature-")]
    assert {c.get_gid() for c in lines} == {"curvature-Line", "curvature-Arc", "curvature-BezierSpiral"}
    assert behind.get_zorder() < min(c.get_zorder() for c in lines)
    assert not [c for c in top.collections if c.get_gid() == "vertical"]
    (vertical,) = [c for c in plot_fit(chain, s, r, TOLERANCE, vertical=r * 0.5).axes[0].collections if c.get_gid() == "vertical"]
    np.testing.assert_allclose(vertical.get_offsets(), np.column_stack([s, r * 0.5]))


def test_a_closed_fit_in_a_design_file_closes(tmp_path):
    """Points around a circle, inline and closed: one arc all round, ending where it starts, G2 as OCCT reads it."""
    t = np.linspace(0.0, 2.0 * np.pi, 90, endpoint=False)
    points = np.column_stack([30.0 * np.cos(t), 30.0 * np.sin(t)]).tolist()
    design = {"units": "mm", "designs": [{"name": "ring", "type": "fit", "points": points, "tolerance": 0.01, "closed": True}]}
    path = tmp_path / "ring.json"
    path.write_text(json.dumps(design))
    assert main(["build", str(path), "-o", str(tmp_path / "out"), "--no-plots"]) == 0
    _, (built,) = build(path)
    assert built.kind == "fit (closed)" and np.allclose(built.chain.start, built.chain.end, atol=1e-9)
    measured, _ = distances(built.chain, np.asarray(points))
    assert measured.max() <= 0.01
    from spiral_cad.cad.continuity import check_continuity

    assert check_continuity(tmp_path / "out" / "ring.step").passes("G2")
    header, table = read_table(tmp_path / "out" / "ring_residuals.csv")
    assert len(table) == 90 and not (tmp_path / "out" / "ring_fit.png").exists()  # --no-plots: no plot


@pytest.mark.parametrize(
    "text, message",
    [
        ("x,y\n0,0\n0,0\n0,0\n", "fit_points needs at least 3 distinct points; got 1 (of 3 points)"),
        ("# a U-turn\n0 0\n10 0\n20 0\n10 0.001\n0 0.002\n", "the points double back at points[2] (trace.csv line 4)"),
    ],
)
def test_points_no_fit_can_follow_are_refused_naming_the_line(tmp_path, capsys, text, message):
    path = write_csv(tmp_path / "trace.csv", text)
    assert main(["build", "--from-points", str(path), "--tolerance", "0.01", "-o", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: designs[0] (trace): ") and message in err and "Traceback" not in err


def test_collinear_points_with_repeats_are_one_line(tmp_path):
    path = write_csv(tmp_path / "trace.csv", "0,0\n1,0\n1,0\n2,0\n3,0\n")
    assert main(["build", "--from-points", str(path), "--tolerance", "0.01", "-o", str(tmp_path / "out"), "--no-plots"]) == 0
    header, table = read_table(tmp_path / "out" / "trace_residuals.csv")
    assert len(table) == 5 and np.abs(table[:, 4]).max() <= 1e-12
    np.testing.assert_allclose(table[:, 3], [0, 1, 1, 2, 3], atol=1e-12)


def test_a_road_fit_reports_the_point_wise_curvature_estimate():
    """A road fit (Alignment.fit) carries the estimate its PointFit segmented, for the report plot's dots."""
    points = traced()
    design = {"units": "m", "designs": [{"name": "road", "type": "fit", "points": points.tolist(), "tolerance": 0.1,
                                         "design_speed": 60}]}  # fmt: skip
    _, (built,) = build(design)
    estimate = np.asarray(built.fit.estimate)
    assert estimate.shape == (len(points),)
    fitted = built.source.point_fit
    np.testing.assert_array_equal(estimate, fitted.curvature_estimate)
    # The estimate follows the fitted curvature where the curvature is steady (an arc's middle).
    s = np.asarray(built.fit.stations)
    kappa = built.chain.curvature_at(np.clip(s, 0.0, built.chain.length))
    steady = np.abs(kappa) > 0.5 * np.abs(kappa).max()
    assert steady.any() and np.median(np.abs(estimate[steady] - kappa[steady])) <= 0.2 * np.abs(kappa).max()


@pytest.mark.parametrize(
    "text, message",
    [
        ("1,1\n0,0\n0,1e300\n", "points and tolerance must lie within ±1e+150"),
        ("0,0\n1e-310,0\n2e-310,1e-310\n", "at least 3 distinct points"),
    ],
)
def test_extreme_coordinates_exit_2_naming_the_scale(tmp_path, capsys, text, message):
    """Any float64 points: a fit or a named refusal, never an internal error."""
    path = write_csv(tmp_path / "trace.csv", text)
    assert main(["build", "--from-points", str(path), "--tolerance", "1e-8", "-o", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: ") and message in err and "internal error" not in err and "Traceback" not in err
