"""Point files in (spiral_cad.io.points): separators, headers, units, and every malformed line named."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from spiral_cad.io.points import parse_points, read_points


@pytest.mark.parametrize(
    "text, points, units",
    [
        ("0,0\n1,2\n", [[0, 0], [1, 2]], "mm"),
        ("x,y\n0,0\n1,2\n", [[0, 0], [1, 2]], "mm"),
        ("X , Y , Z\n0, 0, 5\n1, 2, 6\n", [[0, 0, 5], [1, 2, 6]], "mm"),
        ("northing;easting\n10;20\n11;21\n", [[20, 10], [21, 11]], "mm"),  # any order: x is the easting
        ("elevation easting northing\n5 1 2\n6 3 4\n", [[1, 2, 5], [3, 4, 6]], "mm"),
        ("# units: m\n# a survey\n0\t0\n\n1.5\t-2e3  # a comment\n", [[0, 0], [1.5, -2000]], "m"),
        ("x [ft],y [ft]\n0,0\n1,1\n", [[0, 0], [1, 1]], "ft"),
        ("\ufeffx,y\n0,0\n1,1\n", [[0, 0], [1, 1]], "mm"),
    ],
)
def test_variants_read(text, points, units):
    table = parse_points(text)
    np.testing.assert_array_equal(table.points, points)
    assert table.units == units and table.dim == len(points[0]) and len(table) == len(points)


def test_lines_name_points_and_units_convert():
    table = parse_points("# units: m\n\nx,y,z\n1,2,3\n# gap\n4,5,6\n", units="ft")
    assert table.units == "m" and table.lines.tolist() == [4, 6]
    mm = table.in_units("mm")
    np.testing.assert_allclose(mm.points, [[1000, 2000, 3000], [4000, 5000, 6000]])
    np.testing.assert_array_equal(mm.xy, [[1000, 2000], [4000, 5000]])
    np.testing.assert_array_equal(mm.z, [3000, 6000])
    assert parse_points("1 2\n3 4\n", units="ft").units == "ft" and parse_points("1 2\n3 4\n").z is None


@pytest.mark.parametrize(
    "text, message",
    [
        ("0,0\n1,2\n3,abc\n", "line 3: y is 'abc', not a number"),
        ("x,y\n0,0\n1\n", "line 3: 1 column, expected 2 (x, y): '1'"),
        ("0,0,0\n1,2,3,4\n", "line 2: 4 columns, expected 3 (x, y, z)"),
        ("0,0\n1,,\n", "line 2: 3 columns, expected 2"),
        ("0,0\n,1\n", "line 2: x is empty"),
        ("0,0\n1_0,1\n", "line 2: x is '1_0', not a number"),
        ("0,0\n\u0661,1\n", "line 2: x is '\u0661', not a number"),
        ("0 0\nnan 1\n", "line 2: x is 'nan'; every coordinate must be a finite number"),
        ("0 0\n1 -inf\n", "line 2: y is '-inf'"),
        ("0 0 0 0\n", "line 1: 4 columns; expected x, y or x, y, z"),
        ("0\n", "line 1: 1 column; expected x, y or x, y, z"),
        ("x,y,q\n0,0,0\n", "line 1: column 'q' is not a coordinate"),
        ("x,easting\n0,0\n", "line 1: column 'easting' names x a second time"),
        ("x,z\n0,0\n", "needs an x and a y column"),
        ("x [m],y [ft]\n0,0\n", "the header states several units (ft, m)"),
        ("x [m],y [m],curvature [1/ft]\n0,0,0\n", "the header states several units (ft, m)"),
        ("x [m],y [m],curvature [m]\n0,0,0\n", "column 'curvature [m]' states 'm', not one over a length"),
        ("s,x,y,tx,tx\n0,0,0,1,1\n", "column 'tx' names tx a second time"),
        ("# units: m\n# units: ft\n0,0\n", "line 2: unit ft differs from m stated on line 1"),
        ("# units: parsec\n0,0\n", "line 1: unit 'parsec' is not one of mm, cm, m, km, in, ft"),
        ("# units: m\nx [ft],y [ft]\n0,0\n", "line 2: unit ft differs from m"),
        ("# nothing\n\n", "no points (every line is empty or a comment)"),
        ("x y\n# none\n", "no points after the header (line 1)"),
    ],
)
def test_malformed_lines_are_named(text, message):
    with pytest.raises(ValueError) as info:
        parse_points(text, source="survey.csv")
    assert str(info.value).startswith("survey.csv: ") and message in str(info.value)


def test_a_samples_file_reads_back_as_its_points(tmp_path):
    """``export_samples`` writes station, point, tangent and curvature, each with its unit: the points come
    back, in that unit, and the other columns are set aside."""
    from spiral_cad import Chain, line_to_circle
    from spiral_cad.io.samples import write_samples

    chain = Chain(line_to_circle((0, 0), (1, 0), (50, 40), 30).spirals, units="m")
    write_samples(chain, tmp_path / "path.csv", step=1.0)
    table = read_points(tmp_path / "path.csv")
    written = np.loadtxt(tmp_path / "path.csv", delimiter=",", skiprows=1)
    assert table.units == "m" and table.dim == 3 and len(table) == len(written) > 50
    assert np.array_equal(table.points, written[:, 1:4])  # x, y, z as printed, in file order


def test_unreadable_files_are_named(tmp_path):
    with pytest.raises(ValueError, match="cannot read points file missing.csv"):
        read_points(tmp_path / "missing.csv")
    with pytest.raises(ValueError, match="it is a folder"):
        read_points(tmp_path)
    latin = tmp_path / "latin.csv"
    latin.write_bytes("x,y\n0,0 # Bösch\n".encode("latin-1"))
    with pytest.raises(ValueError, match=r"latin.csv: not UTF-8 text \(byte 11: 0xf6\)"):
        read_points(latin)
    with pytest.raises(ValueError, match="units must be one of"):
        parse_points("0 0\n", units="yards")


def test_a_million_rows_read_as_numpy_wrote_them(tmp_path):
    expected = np.random.default_rng(24).normal(scale=1e4, size=(1_000_000, 3))
    path = tmp_path / "big.xyz"
    with path.open("w") as handle:
        handle.write("# units: m\neasting northing elevation\n")
        np.savetxt(handle, expected, fmt="%.17g")
    table = read_points(path)  # its speed is measured in benchmarks/bench_points.py
    np.testing.assert_array_equal(table.points, expected)
    assert table.units == "m" and table.lines[-1] == 1_000_002


@settings(max_examples=300, deadline=None)
@given(st.text(alphabet="0123456789.,;- \t\n#xyzEnaif[]m:u_\u0661", max_size=80))
def test_any_text_is_points_or_a_named_error(text):
    """Whatever the text, a table of finite points with a line number each, or a ValueError naming the source."""
    try:
        table = parse_points(text, source="fuzz.csv")
    except ValueError as error:
        assert str(error).startswith("fuzz.csv: ") and "could not be read as a table" not in str(error)  # a line named
        return
    assert np.isfinite(table.points).all() and table.dim in (2, 3) and len(table.lines) == len(table) >= 1
    assert all(1 <= n <= len(text.splitlines()) for n in table.lines.tolist())
