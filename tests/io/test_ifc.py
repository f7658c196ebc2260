"""IFC 4.3 alignments: validated by ifcopenshell (schema and where rules), evaluated by its geometry
kernel against our chain, and held to buildingSMART's validation rules ALS016/ALS017 (continuity)
and ALB021–ALB023 (layout and representation agree), implemented here as their feature files state
them and proven on buildingSMART's own example files (tests/data/ifc/README.md)."""

import math
from pathlib import Path

import numpy as np
import pytest

from spiral_cad.core.kinds import ARC, LINE, SPIRAL
from spiral_cad.design import Alignment, Profile
from spiral_cad.io.ifc import GRAPH_TOLERANCE, graph_polynomials, ifc_file, layout_segments, read_ifc_alignments, write_ifc

pytest.importorskip("ifcopenshell")
import ifcopenshell  # noqa: E402
import ifcopenshell.geom  # noqa: E402
import ifcopenshell.ifcopenshell_wrapper as wrapper  # noqa: E402
import ifcopenshell.util.unit  # noqa: E402
import ifcopenshell.validate  # noqa: E402

DATA = Path(__file__).resolve().parents[1] / "data" / "ifc"
PIS = [[0, 0], [600, 120], [1150, -80], [1700, 260], [2300, 200]]
PVIS = [[10000, 120], [10700, 132], [11500, 116], [12500, 121]]
SETTINGS = ifcopenshell.geom.settings()
#: ALB023's mapping (ifc-gherkin-rules, test/files/ALB/alb023/segment_type_mapping.md).
HORIZONTAL_TYPES = {
    "BLOSSCURVE": {"IfcThirdOrderPolynomialSpiral"}, "CIRCULARARC": {"IfcCircle"}, "CLOTHOID": {"IfcClothoid"},
    "COSINECURVE": {"IfcCosineSpiral"}, "CUBIC": {"IfcPolynomialCurve"}, "HELMERTCURVE": {"IfcSecondOrderPolynomialSpiral"},
    "LINE": {"IfcLine", "IfcPolyline"}, "SINECURVE": {"IfcSineSpiral"}, "VIENNESEBEND": {"IfcSeventhOrderPolynomialSpiral"},
}  # fmt: skip
VERTICAL_TYPES = {"CIRCULARARC": {"IfcCircle"}, "CLOTHOID": {"IfcClothoid"}, "CONSTANTGRADIENT": {"IfcLine"},
                  "PARABOLICARC": {"IfcPolynomialCurve"}}  # fmt: skip
POSITION_CODES = {"CONTINUOUS", "CONTSAMEGRADIENT", "CONTSAMEGRADIENTSAMECURVATURE"}
TANGENT_CODES = {"CONTSAMEGRADIENT", "CONTSAMEGRADIENTSAMECURVATURE"}


# ------------------------------------------------- the rules, as their feature files state them


def _precision(representation) -> float:
    """The precision of the representation's geometric context (a sub-context's parent's); default 1e-5."""
    context = representation.ContextOfItems
    while context.is_a("IfcGeometricRepresentationSubContext"):
        context = context.ParentContext
    return context.Precision if context.Precision else 1e-5


def _frame(segment, at: float) -> np.ndarray:
    """ifcopenshell's 4×4 placement (SI units, columns: tangent, normal, …, position) at ``at`` metres along ``segment``."""
    function = wrapper.map_shape(SETTINGS, segment)
    return np.array(wrapper.function_item_evaluator(SETTINGS, function).evaluate(at))


def _segment_end(segment) -> np.ndarray:
    return _frame(segment, wrapper.map_shape(SETTINGS, segment).length())


def _referenced(item, wanted: str):
    """Every instance of exactly type ``wanted`` referenced from ``item`` (itself included)."""
    seen, stack, found = set(), [item], []
    while stack:
        inst = stack.pop()
        if inst.id() in seen:
            continue
        seen.add(inst.id())
        if inst.is_a() == wanted:
            found.append(inst)
        stack += [v for v in inst.file.traverse(inst, max_levels=1)[1:] if v.id() not in seen]
    return found


def continuity_warnings(model, precision: float | None = None) -> list[str]:
    """ALS016 (IfcCompositeCurve of a 'Curve2D' representation: position and tangency) and ALS017
    (IfcGradientCurve of a 'Curve3D' one: position and vertical gradient): for each pair of consecutive
    IfcCurveSegments, the end of segment n as ifcopenshell evaluates it against the start of segment
    n + 1, in the length unit, where the Transition code of n claims that continuity. Position within
    the context precision p (or ``precision``); tangency within atan2(p, |SegmentLength|); gradient within p."""
    scale = ifcopenshell.util.unit.calculate_unit_scale(model, "LENGTHUNIT")
    warnings = []
    for alignment in model.by_type("IfcAlignment"):
        for rep in alignment.Representation.Representations if alignment.Representation else ():
            rule = {"Curve2D": ("ALS016", "IfcCompositeCurve"), "Curve3D": ("ALS017", "IfcGradientCurve")}.get(rep.RepresentationType)
            if rule is None:
                continue
            name, wanted = rule
            p = _precision(rep) if precision is None else precision
            for curve in (c for item in rep.Items for c in _referenced(item, wanted)):
                for current, following in zip(curve.Segments[:-1], curve.Segments[1:]):
                    end, start = _segment_end(current), _frame(following, 0.0)
                    where = f"{name} #{current.id()}→#{following.id()}"
                    if current.Transition in POSITION_CODES:
                        gap = float(np.hypot(*(end[:2, 3] - start[:2, 3]))) / scale
                        if gap > p:
                            warnings.append(f"{where}: position {gap:.3g} > {p:g}")
                    if current.Transition in TANGENT_CODES and name == "ALS016":
                        turn = abs(math.atan2(end[1, 0], end[0, 0]) - math.atan2(start[1, 0], start[0, 0]))
                        turn = min(turn, 2 * math.pi - turn)
                        limit = math.atan2(p, abs(current.SegmentLength.wrappedValue))
                        if turn > limit:
                            warnings.append(f"{where}: tangent {turn:.3g} rad > {limit:.3g}")
                    if current.Transition in TANGENT_CODES and name == "ALS017":
                        jump = abs(end[1, 0] / end[0, 0] - start[1, 0] / start[0, 0])
                        if jump > p:
                            warnings.append(f"{where}: gradient {jump:.3g} > {p:g}")
    return warnings


def agreement_errors(model) -> list[str]:
    """ALB021 (the representation's curve type needs/forbids the layouts), ALB022 (as many curve segments
    as layout segments, a Helmert curve counting two) and ALB023 (each layout segment's type maps to its
    curve segment's ParentCurve type), for every alignment with both layouts and a representation."""
    errors = []
    for alignment in model.by_type("IfcAlignment"):
        layouts = {obj.is_a(): obj for rel in alignment.IsNestedBy for obj in rel.RelatedObjects}
        if not layouts or alignment.Representation is None:
            continue
        items = [(rep.RepresentationIdentifier, item) for rep in alignment.Representation.Representations for item in rep.Items]
        curves = {}
        for identifier, item in items:
            kind = item.is_a()
            if kind == "IfcSegmentedReferenceCurve" and "IfcAlignmentCant" not in layouts:
                errors.append("ALB021: IfcSegmentedReferenceCurve without IfcAlignmentCant")
            if kind == "IfcGradientCurve" and ("IfcAlignmentVertical" not in layouts or "IfcAlignmentCant" in layouts):
                errors.append("ALB021: IfcGradientCurve needs IfcAlignmentVertical and no IfcAlignmentCant")
            if kind == "IfcCompositeCurve" and identifier == "Axis" and ({"IfcAlignmentVertical", "IfcAlignmentCant"} & set(layouts)):
                errors.append("ALB021: an IfcCompositeCurve as Axis with a vertical or cant layout")
            while item is not None:
                curves.setdefault(item.is_a(), item)
                item = getattr(item, "BaseCurve", None)
        for layout_type, curve_type, mapping in (("IfcAlignmentHorizontal", "IfcCompositeCurve", HORIZONTAL_TYPES),
                                                 ("IfcAlignmentVertical", "IfcGradientCurve", VERTICAL_TYPES)):  # fmt: skip
            if layout_type not in layouts or curve_type not in curves:
                continue
            logic = layout_segments(layouts[layout_type])
            segments = curves[curve_type].Segments
            expected = sum(2 if s.PredefinedType == "HELMERTCURVE" else 1 for s in logic)
            if expected != len(segments):
                errors.append(f"ALB022: {layout_type} has {expected} segments, {curve_type} {len(segments)}")
                continue
            for k, (s, c) in enumerate(zip(logic, segments)):
                if c.ParentCurve.is_a() not in mapping.get(s.PredefinedType, ()):
                    errors.append(f"ALB023: {layout_type} segment {k} {s.PredefinedType} on {c.ParentCurve.is_a()}")
    return errors


def schema_issues(model) -> list:
    logger = ifcopenshell.validate.json_logger()
    ifcopenshell.validate.validate(model, logger, express_rules=True)
    return logger.statements


# ---------------------------------------------------------------------- our files


@pytest.fixture(scope="module", params=[("m", "near-linear"), ("ft", "walton-meek")], ids=["m-near-linear", "ft-walton-meek"])
def road(request):
    units, shape = request.param
    factor = 1.0 if units == "m" else 1 / 0.3048
    alignment = Alignment.from_pis(np.array(PIS) * factor, np.array([450, 400, 600]) * factor, spiral_angles=0.1, units=units,
                                   start_station=10000 * factor, shape=shape)  # fmt: skip
    pvis = np.array(PVIS, dtype=float) * factor
    pvis[-1, 0] = alignment.end_station
    profile = Profile.from_pvis(pvis, curve_lengths=300 * factor, units=units, alignment=alignment)
    return alignment, profile


@pytest.mark.parametrize("with_profile", [False, True], ids=["plan", "plan+profile"])
def test_ifcopenshell_validates_the_file_and_the_rules_hold(road, with_profile, tmp_path):
    alignment, profile = road
    path = write_ifc(alignment, tmp_path / "road.ifc", profile=profile if with_profile else None, names=["road"])
    model = ifcopenshell.open(str(path))
    assert model.schema_identifier == "IFC4X3_ADD2"
    assert schema_issues(model) == []
    assert continuity_warnings(model) == []
    assert continuity_warnings(model, precision=1e-5) == []  # the rules' default, in feet too
    assert agreement_errors(model) == []
    (read,) = read_ifc_alignments(path)
    kinds = {LINE: "LINE", ARC: "CIRCULARARC", SPIRAL: "CUBIC"}
    assert [s.type for s in read.horizontal] == [kinds[int(k)] for k in alignment.chain.rows.kind] + ["LINE"]
    assert [s.curve for s in read.horizontal][:3] == ["IfcLine", "IfcPolynomialCurve", "IfcCircle"]
    np.testing.assert_allclose([s.length for s in read.horizontal[:-1]], alignment.chain.lengths, rtol=1e-15)
    assert read.horizontal[-1].length == 0.0 and np.allclose(read.horizontal[-1].start, alignment.chain.end, atol=1e-9)
    assert read.metres_per_unit == pytest.approx(1.0 if alignment.chain.units == "m" else 0.3048, rel=1e-15)
    assert read.start_station == alignment.start_station
    if with_profile:
        assert {s.type for s in read.vertical} == {"CONSTANTGRADIENT", "PARABOLICARC"} and read.vertical[-1].length == 0.0
        assert sum(s.length for s in read.vertical) == pytest.approx(alignment.chain.length, rel=1e-13)
    else:
        assert read.vertical == ()


def _project(chain, points: np.ndarray, guess: np.ndarray) -> np.ndarray:
    """Distance from each point to the chain (Newton's steps along the tangent from ``guess`` stations)."""
    s = guess.copy()
    for _ in range(6):
        s = np.clip(s + np.einsum("ij,ij->i", points - chain.point_at(s), chain.tangent_at(s)), 0.0, chain.length)
    return np.hypot(*(points - chain.point_at(s)).T)


def test_ifcopenshell_evaluates_our_chain_within_a_micrometre(road, tmp_path):
    alignment, profile = road
    chain, metres = alignment.chain, 1.0 if alignment.chain.units == "m" else 0.3048
    model = ifc_file(alignment, profile=profile)
    (plan,) = model.by_type("IfcCompositeCurve", include_subtypes=False)
    function = wrapper.map_shape(SETTINGS, plan)
    evaluate = wrapper.function_item_evaluator(SETTINGS, function).evaluate
    assert function.length() == pytest.approx(chain.length * metres, abs=1e-6)
    # every segment end, through the whole curve and through each segment on its own
    ends = np.array([np.array(evaluate(float(s * metres)))[:2, 3] for s in chain.stations]) / metres
    assert np.hypot(*(ends - chain.point_at(chain.stations)).T).max() * metres < 1e-6
    for k, segment in enumerate(plan.Segments[:-1]):
        frame = _segment_end(segment)
        assert np.hypot(*(frame[:2, 3] / metres - chain.point_at(chain.stations[k + 1]))) * metres < 1e-6
        assert np.hypot(*(frame[:2, 0] - chain.tangent_at(chain.stations[k + 1] * (1 - 1e-15)))) < 1e-9
    # 3000 samples in between lie on our chain (ifcopenshell maps distance to a polynomial's parameter by
    # the graph's length, so inside a spiral its station differs from ours; its points do not)
    stations = np.linspace(0.0, chain.length, 3001)
    points = np.array([np.array(evaluate(float(s * metres)))[:2, 3] for s in stations]) / metres
    assert _project(chain, points, stations).max() * metres < 1e-6
    # and ifcopenshell's distance along is our station, inside the spirals too (2–5 m apart when the
    # spirals were written as parametric cubics): measured 0.9 µm, its quadrature's
    assert np.hypot(*(points - chain.point_at(stations)).T).max() * metres < 1e-5
    # the gradient curve: the same plan, and the profile's heights at the same distance along
    (gradient,) = model.by_type("IfcGradientCurve")
    function = wrapper.map_shape(SETTINGS, gradient)
    evaluate = wrapper.function_item_evaluator(SETTINGS, function).evaluate
    space = np.array([np.array(evaluate(float(s * metres)))[:3, 3] for s in stations[::10]]) / metres
    assert np.abs(space[:, :2] - points[::10]).max() * metres < 1e-6
    heights = profile.elevation(stations[::10] + alignment.start_station)
    assert np.abs(space[:, 2] - heights).max() * metres < 1e-6


def test_every_reading_of_a_length_along_a_spiral_is_our_station(road):
    """Each spiral is the graph y = p(x) (CoefficientsX = (0, 1)): the schema's arc length of the parametric
    curve, the concept template's graph length and ifcopenshell's are one integral, and it reaches our
    station at every point of the spiral and SegmentLength at its end (scipy's quadrature, not ours)."""
    from scipy.integrate import quad
    from scipy.optimize import brentq

    alignment, _ = road
    chain = alignment.chain
    model = ifc_file(alignment)
    (plan,) = model.by_type("IfcCompositeCurve", include_subtypes=False)
    checked = 0
    for k, segment in enumerate(plan.Segments[:-1]):
        if not segment.ParentCurve.is_a("IfcPolynomialCurve"):
            continue
        assert tuple(segment.ParentCurve.CoefficientsX) == (0.0, 1.0)
        p = np.polynomial.Polynomial(segment.ParentCurve.CoefficientsY)
        place = segment.Placement
        origin, (dx, dy) = np.array(place.Location.Coordinates), place.RefDirection.DirectionRatios
        assert np.allclose(origin, chain.point_at(chain.stations[k]), atol=1e-9)
        length = segment.SegmentLength.wrappedValue

        def graph(x, p=p):
            return quad(lambda t: math.hypot(1.0, p.deriv()(t)), 0.0, x, epsabs=0.0, epsrel=1e-13, limit=200)[0]

        for along in np.linspace(0.0, 1.0, 9)[1:] * length:
            x = brentq(lambda x, along=along: graph(x) - along, 0.0, 2.0 * length, xtol=1e-13)
            point = origin + x * np.array([dx, dy]) + p(x) * np.array([-dy, dx])
            assert np.hypot(*(point - chain.point_at(chain.stations[k] + along))) < 1e-9 * length + 2 * GRAPH_TOLERANCE
        checked += 1
    assert checked == 6


def test_graph_polynomials_follow_the_cubic_or_say_they_do_not():
    rng = np.random.default_rng(3)
    theta = rng.uniform(0.05, 1.4, 200)  # turns of spirals in their start frames
    u = np.linspace(0.0, 1.0, 401)
    # cubic spirals' shapes: x(u) = u + small terms, y(u) = a·u² + b·u³ turning by θ at the end
    poly = np.column_stack([np.full(200, 100.0), rng.uniform(-5, 5, 200), rng.uniform(-5, 5, 200), np.zeros(200), np.zeros(200)])
    poly[:, 4] = 100.0 * np.tan(theta) / 3.0 * rng.uniform(0.3, 0.7, 200)
    poly[:, 3] = (100.0 * np.tan(theta) - 3.0 * poly[:, 4]) / 2.0 * (1 + 0 * theta)
    coefficients, error = graph_polynomials(poly, 1e-7)
    x = poly[:, :1] * u + poly[:, 1:2] * u**2 + poly[:, 2:3] * u**3
    y = poly[:, 3:4] * u**2 + poly[:, 4:5] * u**3
    measured = np.array([np.abs(np.polynomial.polynomial.polyval(xi, c) - yi).max() for xi, yi, c in zip(x, y, coefficients)])
    assert np.all(measured <= 1.05 * error + 1e-12)  # the error it states is the error there is (401 points, not its 129)
    assert np.all(error[theta < 0.6] <= 1e-7)  # moderate turns always fit


@pytest.mark.parametrize("shape, theta", [("near-linear", 0.8), ("walton-meek", 1.0)])
def test_a_hairpins_stations_agree_with_ifcopenshell(shape, theta):
    """Spirals turning 46° and 57° (once up to 24 m apart inside them): ifcopenshell's distance along is our
    station; a spiral no graph polynomial follows within 10 nm is written as its halves."""
    alignment = Alignment.from_pis([[0, 0], [600, 0], [0, 500]], [60], spiral_angles=theta, units="m", shape=shape)
    chain = alignment.chain
    model = ifc_file(alignment)
    (plan,) = model.by_type("IfcCompositeCurve", include_subtypes=False)
    lengths = [abs(segment.SegmentLength.wrappedValue) for segment in plan.Segments[:-1]]
    assert len(lengths) > len(chain) and sum(lengths) == pytest.approx(chain.length, rel=1e-12)  # spirals halved
    evaluate = wrapper.function_item_evaluator(SETTINGS, wrapper.map_shape(SETTINGS, plan)).evaluate
    stations = np.linspace(0.0, chain.length, 2001)
    points = np.array([np.array(evaluate(float(s)))[:2, 3] for s in stations])
    assert np.hypot(*(points - chain.point_at(stations)).T).max() < 1e-5  # measured 0.7 and 1.3 µm
    ends = np.concatenate([[0.0], np.cumsum(lengths)])
    points = np.array([np.array(evaluate(float(s)))[:2, 3] for s in ends])
    assert np.hypot(*(points - chain.point_at(np.minimum(ends, chain.length))).T).max() < 1e-6  # measured 0.7 and 0.9 µm
    assert not continuity_warnings(model) and not agreement_errors(model) and not schema_issues(model)


# ------------------------------------------------- buildingSMART's files, and a broken copy of ours


@pytest.mark.parametrize("name", ["pass-als016-scenario01-metric_continuous", "pass-als017-scenario01-imperial_continuous"])
def test_the_rule_checks_pass_on_buildingsmarts_continuous_examples(name):
    import ifcopenshell.api.alignment

    model = ifcopenshell.open(str(DATA / f"{name}.ifc"))
    assert continuity_warnings(model) == []
    assert agreement_errors(model) == []
    (read,) = read_ifc_alignments(model)
    (alignment,) = model.by_type("IfcAlignment")
    theirs = ifcopenshell.api.alignment.get_layout_segments(ifcopenshell.api.alignment.get_horizontal_layout(alignment))
    assert [s.type for s in read.horizontal] == [s.DesignParameters.PredefinedType for s in theirs]
    assert all(s.curve in HORIZONTAL_TYPES[s.type] for s in read.horizontal)
    assert all(s.curve in VERTICAL_TYPES[s.type] for s in read.vertical)
    assert read.horizontal[-1].length == 0.0 and read.vertical[-1].length == 0.0


@pytest.mark.parametrize(("name", "found"), [("fail-als016-scenario01-imperial_break_in_position", "ALS016"),
                                             ("fail-als017-scenario02-metric_break_in_vertical_gradient", "ALS017")])  # fmt: skip
def test_the_rule_checks_find_the_breaks_in_buildingsmarts_failing_examples(name, found):
    # (the ALS016 file also breaks ALS017: its gradient segments give the horizontal length as
    # SegmentLength, where the gradient curve's own length along is meant — its ALS017 twin corrects that)
    warnings = continuity_warnings(ifcopenshell.open(str(DATA / f"{name}.ifc")))
    kind = "position" if "position" in name else "gradient"
    assert any(w.startswith(found) and f": {kind} " in w for w in warnings)


def test_the_checks_fail_on_broken_copies_of_our_file(tmp_path):
    alignment = Alignment.from_pis(PIS, [450, 400, 600], spiral_angles=0.1, units="m", start_station=10000)
    pvis = np.array(PVIS, dtype=float)
    pvis[-1, 0] = alignment.end_station
    profile = Profile.from_pvis(pvis, curve_lengths=300, units="m", alignment=alignment)
    path = write_ifc(alignment, tmp_path / "road.ifc", profile=profile)

    def broken(change) -> object:
        model = ifcopenshell.open(str(path))
        change(model)
        return model

    def plan(model):
        return model.by_type("IfcCompositeCurve", include_subtypes=False)[0].Segments

    def moved(model):  # the third segment (an arc) starts 1e-4 m away from where the spiral before it ends
        location = plan(model)[2].Placement.Location
        location.Coordinates = (location.Coordinates[0] + 1e-4, location.Coordinates[1])

    def turned(model):  # the second spiral starts 1e-6 rad off the arc's end direction
        direction = plan(model)[3].Placement.RefDirection
        x, y = direction.DirectionRatios
        direction.DirectionRatios = (x * math.cos(1e-6) - y * math.sin(1e-6), x * math.sin(1e-6) + y * math.cos(1e-6))

    def kinked(model):  # the second grade starts 1e-4 steeper than the parabola before it ends
        direction = model.by_type("IfcGradientCurve")[0].Segments[2].Placement.RefDirection
        x, y = direction.DirectionRatios
        direction.DirectionRatios = (x, y + 1e-4)

    assert any(": position " in w for w in continuity_warnings(broken(moved)))
    assert any(": tangent " in w for w in continuity_warnings(broken(turned)))
    assert any(w.startswith("ALS017") and ": gradient " in w for w in continuity_warnings(broken(kinked)))

    def retyped(model):  # a CUBIC segment on a circle
        plan(model)[1].ParentCurve = model.createIfcCircle(plan(model)[2].ParentCurve.Position, 100.0)

    def dropped(model):  # one curve segment fewer than the layout has
        curve = model.by_type("IfcCompositeCurve", include_subtypes=False)[0]
        curve.Segments = curve.Segments[:1] + curve.Segments[2:]

    assert agreement_errors(broken(retyped)) == ["ALB023: IfcAlignmentHorizontal segment 1 CUBIC on IfcCircle"]
    assert agreement_errors(broken(dropped)) == ["ALB022: IfcAlignmentHorizontal has 14 segments, IfcCompositeCurve 13"]

    def negative(model):  # a layout length the schema forbids (IfcNonNegativeLengthMeasure)
        model.by_type("IfcAlignmentHorizontalSegment")[0].SegmentLength = -1.0

    assert schema_issues(broken(negative))


def test_units_are_declared_and_converted(tmp_path):
    alignment = Alignment.from_pis(PIS, [450, 400, 600], spiral_angles=0.1, units="m")
    for units, kind, name in (("m", "IfcSIUnit", "METRE"), ("mm", "IfcSIUnit", "METRE"), ("ft", "IfcConversionBasedUnit", "foot")):
        model = ifc_file(alignment, units=units)
        (length,) = [u for u in model.by_type("IfcProject")[0].UnitsInContext.Units if u.UnitType == "LENGTHUNIT"]
        assert length.is_a() == kind and length.Name == name
        (read,) = read_ifc_alignments(model)
        metres = read.metres_per_unit
        assert metres == pytest.approx({"m": 1.0, "mm": 1e-3, "ft": 0.3048}[units], rel=1e-15)
        assert sum(s.length for s in read.horizontal) * metres == pytest.approx(alignment.chain.length, rel=1e-13)
        assert continuity_warnings(model) == []


def test_malformed_input_is_refused_by_name():
    alignment = Alignment.from_pis(PIS, [450, 400, 600], spiral_angles=0.1, units="m")
    feet = Alignment.from_pis(PIS, [450, 400, 600], spiral_angles=0.1, units="ft")
    with pytest.raises(ValueError, match="share one length unit"):
        ifc_file([alignment, feet])
    with pytest.raises(ValueError, match="one profile"):
        ifc_file([alignment, alignment], profile=[None])
    with pytest.raises(ValueError, match="units must be one of"):
        ifc_file(alignment, units="furlong")
    with pytest.raises(ValueError, match="an Alignment"):
        ifc_file([])
    with pytest.raises(ValueError, match="not a readable IFC file"):
        read_ifc_alignments(DATA / "README.md")


def test_the_design_file_build_writes_the_ifc_or_names_it_skipped(tmp_path, monkeypatch):
    from spiral_cad.app import designfile

    design = {"units": "m", "designs": [{"name": "road", "type": "alignment", "pis": PIS[:4], "radii": [450, 400],
                                         "spiral_angles_deg": 5.0}]}  # fmt: skip
    units, built = designfile.build(design)
    written = designfile.write(built, tmp_path / "with", units, progress=lambda _: None, plots=False)
    (read,) = read_ifc_alignments(tmp_path / "with" / "road.ifc")
    assert read.name == "road" and len(read.horizontal) == len(built[0].chain) + 1
    assert not any("IFC" in s for s in written.skipped)
    monkeypatch.setattr(designfile, "missing_cad_extra", lambda: ["ifcopenshell"])
    written = designfile.write(built, tmp_path / "without", units, progress=lambda _: None, plots=False)
    assert not (tmp_path / "without" / "road.ifc").exists() and (tmp_path / "without" / "road.xodr").exists()
    assert written.skipped == ["IFC (needs ifcopenshell)"]


def test_names_that_ifc_labels_cannot_hold_are_refused_by_name(tmp_path):
    """IfcLabel holds at most 255 characters of text: a longer or control-character name is refused, naming it."""
    alignment = Alignment.from_pis(PIS, [450, 400, 600], spiral_angles=0.1, units="m")
    with pytest.raises(ValueError, match=r"names\[0\]"):
        write_ifc(alignment, tmp_path / "long.ifc", names=["x" * 256])
    with pytest.raises(ValueError, match="project"):
        write_ifc(alignment, tmp_path / "ctl.ifc", project="a\x01b")
    assert not (tmp_path / "long.ifc").exists() and not (tmp_path / "ctl.ifc").exists()


def test_global_ids_are_ifc_compressed_version_4_uuids_and_unique():
    import ifcopenshell.guid

    from spiral_cad.io.ifc import _guids

    made = _guids(5000)
    assert len(set(made)) == 5000 and all(len(g) == 22 for g in made)
    for g in made[:200]:
        expanded = ifcopenshell.guid.expand(g)  # ifcopenshell's own decoding, back and forth
        assert ifcopenshell.guid.compress(expanded) == g and expanded[12] == "4" and expanded[16] in "89ab"


def test_a_plane_chain_is_written_as_write_landxml_takes_it(tmp_path):
    """``write_ifc(chain)`` as ``write_landxml(chain)``: one alignment, stations from 0, read by ifcopenshell
    with its layout segments ending where the chain's pieces end."""
    import spiral_cad as sc

    enter = sc.line_to_circle((0, 0), (1, 0), (100, 60), 50.0)
    leave = sc.line_to_circle((300, 150), (-1, -1), (100, 60), 50.0).reversed()
    chain = sc.Chain.join([enter, leave], start=(-20, 0), end=(400, 250), units="m")
    model = ifcopenshell.open(str(write_ifc(chain, tmp_path / "chain.ifc")))
    assert len(model.by_type("IfcAlignment")) == 1
    segments = [s.DesignParameters for s in model.by_type("IfcAlignmentSegment")]
    assert math.isclose(sum(s.SegmentLength for s in segments), chain.length, rel_tol=1e-9)
    with pytest.raises(ValueError, match="an Alignment or a plane Chain"):
        write_ifc([chain, "road"], tmp_path / "bad.ifc")
