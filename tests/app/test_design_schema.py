"""The design-file schema: pydantic models, their JSON Schema, the reference page and the error lines."""

import json
from pathlib import Path

import pytest

from spiral_cad.app.cli import main
from spiral_cad.app.schema import DesignFile, json_schema, schema_markdown, validate

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = sorted((ROOT / "examples").rglob("*.json"))
ROAD = {"name": "road", "type": "alignment", "pis": [[0, 0], [600, 120], [1150, -80], [1700, 260]],
        "radii": [450, 400], "spiral_angles_deg": 8}  # fmt: skip


def one(**fields) -> dict:
    return {"units": "m", "designs": [{**ROAD, **fields}]}


def test_there_are_example_design_files():
    assert ROOT / "examples" / "design.json" in EXAMPLES


@pytest.mark.parametrize("path", EXAMPLES, ids=lambda p: p.name)
def test_every_example_design_file_validates(path):
    data = json.loads(path.read_text())
    design = validate(data)
    assert [d.name for d in design.designs] == [d["name"] for d in data["designs"]]


@pytest.mark.parametrize("path", EXAMPLES, ids=lambda p: p.name)
def test_every_example_design_file_meets_the_json_schema(path):
    jsonschema = pytest.importorskip("jsonschema")
    schema = json_schema()
    jsonschema.Draft202012Validator.check_schema(schema)
    jsonschema.validate(json.loads(path.read_text()), schema, cls=jsonschema.Draft202012Validator)


MALFORMED = [
    ({"designs": [ROAD]}, "units: required, one of mm, cm, m, km, in, ft"),
    ({"units": "yd", "designs": [ROAD]}, "units: must be one of mm, cm, m, km, in, ft; got 'yd'"),
    ({"units": "m", "designs": []}, "designs: must hold at least 1 item(s); got 0"),
    ({"units": "m", "designs": [ROAD], "colour": 1}, "unknown top-level field(s) 'colour'"),
    (one(radii=[450, -400]), "designs[0] (road).radii[1]: must be positive; got -400"),
    (one(radii=[450]), "designs[0] (road).radii: needs one radius per interior PI (2); got 1"),
    (one(pis=[[0, 0], [1, "2"], [3, 4]]), "designs[0] (road).pis[1][1]: must be a finite number; got '2'"),
    (one(pis=[[0, 0], [1, 2]]), "designs[0] (road).pis: must be a list of at least 3 points [x, y]; got [[0, 0], [1, 2]]"),
    (
        one(spiral_angles_deg=[8, [8, 95]]),
        "designs[0] (road).spiral_angles_deg[1][1]: spiral angles are in degrees and must lie in (0, 90); got 95",
    ),
    (one(strict=1), "designs[0] (road).strict: must be true or false; got 1"),
    (
        one(cross_section={"driving_lanes": True}),
        "designs[0] (road).cross_section.driving_lanes: must be an integer from 1 to 10; got True",
    ),
    (one(cross_section={"rule": "left"}), "designs[0] (road).cross_section.rule: must be one of RHT, LHT; got 'left'"),
    (one(cant_max=100), "designs[0] (road): cant_max belong(s) to rail criteria, not road"),
    (one(max_jerk=0.5), "designs[0] (road): design criteria need design_speed"),
    (one(spiral_lengths=50), "designs[0] (road): give at most one of spiral_angles_deg and spiral_lengths"),
    (one(speed=80, colour="red"), "designs[0] (road): unknown field(s) speed, colour"),
    ({"units": "m", "designs": [{"name": "road", "type": "alignment"}]}, "designs[0] (road): missing field(s) pis, radii"),
    (
        {"units": "m", "designs": [{**ROAD, "type": "spline"}]},
        "designs[0].type: must be one of alignment, circle_chain, rounded_polyline, transition, fit, g2_path; got 'spline'",
    ),
    (
        {"units": "m", "designs": [{"name": "road"}]},
        "designs[0].type: required, one of alignment, circle_chain, rounded_polyline, transition, fit",
    ),
    ({"units": "m", "designs": [7]}, "designs[0]: must be an object; got 7"),
    (one(name="a b"), "designs[0].name: must be 1–64 characters of A–Z, a–z, 0–9, - and _ (starting with a letter or digit); got 'a b'"),
    (
        {
            "units": "m",
            "designs": [
                {"name": "c", "type": "circle_chain", "circles": [{"center": [0, 0], "radius": 1}, {"center": [5, 0], "radius": 0}]}
            ],
        },
        "designs[0] (c).circles[1].radius: must be non-zero (its sign is the travel sense); got 0",
    ),
    (
        {
            "units": "m",
            "designs": [
                {"name": "t", "type": "transition", "case": "line_to_line", "p0": [0, 0], "corner": [1, 0], "p1": [2, 1], "radius": 3}
            ],
        },
        "designs[0] (t): unknown field(s) radius",
    ),
    (
        {"units": "m", "designs": [{"name": "t", "type": "transition", "case": "spiral"}]},
        "designs[0] (t).case: must be one of line_to_circle, circle_to_circle, line_to_line, circle_in_circle; got 'spiral'",
    ),
    (
        {"units": "m", "designs": [{"name": "r", "type": "rounded_polyline", "points": [[0, 0], [1, 0], [1, 1]], "samples": {}}]},
        'designs[0] (r).samples: must be {"step": s} or {"chord_tolerance": c}',
    ),
    ({"units": "m", "designs": [ROAD, {**ROAD, "name": "ROAD"}]}, "designs[1].name: 'ROAD' is used twice"),
]


@pytest.mark.parametrize("data, message", MALFORMED, ids=[m[:40] for _, m in MALFORMED])
def test_malformed_designs_are_refused_by_path_and_value(data, message):
    with pytest.raises(ValueError) as error:
        validate(data)
    assert str(error.value).startswith(message), str(error.value)


@pytest.mark.parametrize("data, message", MALFORMED, ids=[m[:40] for _, m in MALFORMED])
def test_the_json_schema_refuses_what_it_can_describe(data, message):
    """Counts and cross-field rules are the models' alone; types, ranges, names and fields are in the schema."""
    jsonschema = pytest.importorskip("jsonschema")
    if "needs one" in message or "belong(s)" in message or "need design_speed" in message or "at most one" in message \
            or "used twice" in message or "non-zero" in message or "step" in message:  # fmt: skip
        pytest.skip("a rule beyond JSON Schema")
    assert not jsonschema.Draft202012Validator(json_schema()).is_valid(data)


def test_more_problems_are_counted():
    with pytest.raises(ValueError, match=r"^designs\[0\] \(road\)\.radii\[0\]: must be positive; got -1 \(and 1 more problem\)$"):
        validate(one(radii=[-1, 400], strict="yes"))


def test_a_schema_address_is_accepted_and_ignored():
    plain = validate(one())
    named = validate({"$schema": "./design-file.schema.json", **one()})
    assert named.designs == plain.designs and named.units == plain.units
    with pytest.raises(ValueError, match=r"\$schema: must be a string; got 3"):
        validate({"$schema": 3, **one()})


def test_the_cli_prints_the_schema(capsys):
    assert main(["schema"]) == 0
    printed = json.loads(capsys.readouterr().out)
    assert printed == json_schema()
    assert printed["properties"]["units"]["enum"] == ["mm", "cm", "m", "km", "in", "ft"]
    assert printed["required"] == ["units", "designs"] and printed["additionalProperties"] is False
    assert "$schema" in printed["properties"]


def test_build_help_points_to_the_schema(capsys):
    with pytest.raises(SystemExit):
        main(["build", "--help"])
    out = capsys.readouterr().out
    assert "spiral-cad schema" in out and '"pis"' not in out  # one description of the format


def test_every_field_has_a_description_and_is_on_the_reference_page():
    page = schema_markdown()
    for name, node in json_schema()["$defs"].items():
        assert f"## {name}" in page and node.get("description"), name
        for key, field in node["properties"].items():
            if key not in ("type", "case"):
                assert field.get("description"), f"{name}.{key}"
            assert f"| `{key}` |" in page, f"{name}.{key}"
    assert "`alignment`: [AlignmentDesign](#alignmentdesign)" in page
    assert "`line_to_line` [LineToLine](#linetoline)" in page


def test_the_reference_page_is_rendered_from_the_schema():
    assert (ROOT / "docs" / "reference" / "design-files.md").read_text(encoding="utf-8") == schema_markdown()


def test_models_are_typed():
    design = validate({"units": "mm", "designs": [
        {"name": "r", "type": "rounded_polyline", "points": [[0, 0, 0], [2, 0, 1], [3, 1, 1]], "method": "g2cbs",
         "samples": {"step": 0.5}},
        {"name": "t", "type": "transition", "case": "line_to_circle", "point": [0, 0], "direction": [1, 0],
         "center": [0, 105], "radius": 100}]})  # fmt: skip
    rounded, transition = design.designs
    assert rounded.points == [(0.0, 0.0, 0.0), (2.0, 0.0, 1.0), (3.0, 1.0, 1.0)] and rounded.shape == "g2cbs"
    assert rounded.samples.options() == {"step": 0.5}
    assert transition.arguments() == {"point": (0.0, 0.0), "direction": (1.0, 0.0), "center": (0.0, 105.0), "radius": 100.0}
    assert isinstance(design, DesignFile)


def test_the_choices_are_the_librarys():
    from typing import get_args

    from spiral_cad.app.schema import CornerShape, Terrain, TransitionShape, Units
    from spiral_cad.core.shapes import CORNER_SHAPES, TRANSITION_SHAPES
    from spiral_cad.core.units import UNITS
    from spiral_cad.design.profile import TERRAINS

    assert get_args(Units) == UNITS and get_args(Terrain) == TERRAINS
    assert get_args(TransitionShape) == TRANSITION_SHAPES and get_args(CornerShape) == CORNER_SHAPES


FIT = {"name": "survey", "type": "fit", "points": [[0, 0], [1, 0.1], [2, 0.4]], "tolerance": 0.05}


@pytest.mark.parametrize(
    "edit, message",
    [
        ({"points": None}, "designs[0] (survey): give points or points_file (one of them)"),
        ({"points_file": "survey.csv"}, "designs[0] (survey): give points or points_file (one of them)"),
        ({"tolerance": 0}, "designs[0] (survey).tolerance: must be positive; got 0"),
        ({"tolerance": None}, "designs[0] (survey): missing field(s) tolerance"),
        ({"points": [[0, 0], [1, 1]]}, "designs[0] (survey).points: must be a list of at least 3 points"),
        ({"points": [[0, 0], [1, 1], [2, 2, 2]]}, "designs[0] (survey).points[2]: must be a point like the first"),
        ({"closed": "yes"}, "designs[0] (survey).closed: must be true or false; got 'yes'"),
        ({"spiral_shape": "g2cbs"}, "designs[0] (survey).spiral_shape: must be one of walton-meek, near-linear; got 'g2cbs'"),
        ({"points_units": "m"}, "designs[0] (survey): points_units states the unit of a points_file"),
        ({"points": None, "points_file": ""}, "designs[0] (survey).points_file: must be the path of a points file"),
        ({"design_speed": -80}, "designs[0] (survey).design_speed: must be positive; got -80"),
        ({"vertical_tolerance": 0}, "designs[0] (survey).vertical_tolerance: must be positive; got 0"),
        ({"smoothing": 1}, "designs[0] (survey): unknown field(s) smoothing"),
    ],
)
def test_fit_designs_are_checked(edit, message):
    design = {k: v for k, v in {**FIT, **edit}.items() if v is not None}  # None: the field left out
    with pytest.raises(ValueError) as info:
        validate({"units": "m", "designs": [design]})
    assert str(info.value).startswith(message)


def test_fit_models_are_typed():
    inline, from_file = validate({"units": "m", "designs": [
        {**FIT, "closed": True, "design_speed": 60, "samples": {"step": 1}},
        {"name": "file", "type": "fit", "points_file": "trace.csv", "points_units": "ft", "tolerance": 0.1,
         "spiral_shape": "walton-meek", "max_curvature": 0.01}]}).designs  # fmt: skip
    assert inline.points == [(0.0, 0.0), (1.0, 0.1), (2.0, 0.4)] and inline.closed and inline.design_speed == 60.0
    assert inline.spiral_shape == "near-linear" and inline.samples.options() == {"step": 1.0}
    assert (from_file.points_file, from_file.points_units, from_file.tolerance) == ("trace.csv", "ft", 0.1)
    assert from_file.closed is False and from_file.max_curvature == 0.01
    page = schema_markdown()
    assert "`fit`: [FitDesign](#fitdesign)" in page and "| `points_file` |" in page
