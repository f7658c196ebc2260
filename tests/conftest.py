"""Shared test settings and helpers: the hypothesis profiles (the same random examples everywhere, failures
kept in the repository's example database, a nightly size), ``outcome``, the tally of property tests whose
examples may be refused, the markers, and the groups that keep an expensive fixture on one xdist worker."""

import ast
import functools
import re
from collections import Counter
from collections.abc import Iterable
from pathlib import Path

import pytest
from hypothesis import HealthCheck, event, settings
from hypothesis.database import DirectoryBasedExampleDatabase, ExampleDatabase

#: The example database committed with the tests: every failing example hypothesis finds is saved here, so
#: that whoever found it (a newcomer's first run, CI, the nightly run) can commit it and every later run
#: replays it first.
EXAMPLES = Path(__file__).resolve().parent / ".hypothesis-examples"
#: Where pytest runs from (the test ids are relative to it).
ROOTDIR = Path(__file__).resolve().parent.parent
#: How many times more examples each property test tries in the nightly run (``make nightly``).
NIGHTLY_FACTOR = 10


class RepositoryExamples(ExampleDatabase):
    """Hypothesis's directory database, keeping only the failures, and keeping them once committed.

    Failing examples (hypothesis's primary keys) are saved into ``path``; the secondary and pareto corpora
    (examples shrunk past, targeting scores) are not kept, so a passing run writes nothing. An example is
    deleted only by the process that saved it (while hypothesis shrinks it): one found earlier stays a
    regression test after it passes. A read-only clone replays the examples and saves nothing (the directory
    database ignores a failed write), and the xdist workers share the folder safely (each file is written
    whole, then renamed into place).
    """

    def __init__(self, path: Path) -> None:
        super().__init__()
        self.store = DirectoryBasedExampleDatabase(path)
        self.saved: set[tuple[bytes, bytes]] = set()

    @staticmethod
    def kept(key: bytes) -> bool:
        return not key.endswith((b".secondary", b".pareto"))

    def fetch(self, key: bytes) -> Iterable[bytes]:
        return self.store.fetch(key) if self.kept(key) else ()

    def save(self, key: bytes, value: bytes) -> None:
        if self.kept(key):
            self.store.save(key, value)
            self.saved.add((key, value))

    def delete(self, key: bytes, value: bytes) -> None:
        if (key, value) in self.saved:
            self.store.delete(key, value)
            self.saved.discard((key, value))

    def __repr__(self) -> str:
        return f"RepositoryExamples({str(self.store.path)!r})"


# One profile for everyone (CI included): random examples, so every run may find what a fixed seed hides.
_SHARED = {
    "deadline": None,
    "database": RepositoryExamples(EXAMPLES),
    "print_blob": True,
    "suppress_health_check": [HealthCheck.too_slow, HealthCheck.function_scoped_fixture],
}
settings.register_profile("default", max_examples=150, **_SHARED)
# ``make nightly`` (``--hypothesis-profile nightly``): every property test tries NIGHTLY_FACTOR times more examples.
settings.register_profile("nightly", max_examples=150 * NIGHTLY_FACTOR, **_SHARED)
settings.load_profile("default")

#: Reprs that must never reach a message (plain numbers only).
NUMPY_REPRS = ("np.", "array(", "dtype")


class Outcomes:
    """Runs each example's ``call``: its result, or None when it refused with a clear ValueError.

    Any other exception fails the test (it propagates); a refusal must show plain numbers. The
    tally is checked when the test ends: a property test whose examples were all refused proves
    nothing, so at least ``minimum_built`` of them (default: one in twenty, and three) must have built.
    """

    def __init__(self) -> None:
        self.tally: Counter[str] = Counter()
        self.minimum_built: float = 0.05

    def __call__(self, call):
        try:
            result = call()
        except ValueError as error:
            message = str(error)
            assert message and not any(r in message for r in NUMPY_REPRS), message
            event(f"refused: {type(error).__name__}: {message[:60]}")
            self.tally["refused"] += 1
            return None
        event("built")
        self.tally["built"] += 1
        return result


@pytest.fixture
def outcome():
    """An ``Outcomes`` for one property test; its teardown asserts that enough examples were built."""
    outcomes = Outcomes()
    yield outcomes
    total = outcomes.tally["built"] + outcomes.tally["refused"]
    if total:
        assert outcomes.tally["built"] >= max(3, outcomes.minimum_built * total), (
            f"only {outcomes.tally['built']} of {total} examples were built: the property was hardly tested"
        )


#: Tests of more than a few seconds on a quiet 2-core machine (``make check`` leaves them out), by
#: module or by ``module::test`` name.
SLOW = {
    "test_install.py",
    "test_faces_mutation.py::test_every_planted_local_defect_in_a_continuous_box_is_found",
    "test_linuxcnc_programs.py::test_linuxcncs_programs_build_g2_and_read_back",
    "test_g2_build.py::test_build_dxf_writes_every_output_and_refuses_by_name",
    "test_g2_build.py::test_a_landxml_alignment_of_lines_and_arcs_is_made_g2",
    "test_fit.py",
    "test_fuzz_readers.py",
    "test_examples.py",
    "test_benchmarks.py",
    "test_readme.py::test_every_block_runs",
    "test_batch.py::test_circle_to_circle_batch_equals_scalar_for_c_and_s",
    "test_batch.py::test_line_to_line_batch_equals_scalar_with_auto_and_given_curvature",
    "test_batch.py::test_circle_in_circle_batch_equals_scalar",
    "test_alignment.py::test_symmetric_curves_are_g2_and_honour_theta",
    "test_alignment.py::test_batch_built_curves_equal_the_scalar_solvers_bit_for_bit",
    "test_cadquery_plugin.py::test_example_script_runs_from_plain_python",
    "test_design_files.py::test_any_field_values_are_validated_by_name",
    "test_design_files.py::test_an_interrupted_build_leaves_nothing_behind",
    "test_design_files.py::test_mutated_example_designs_build_or_fail_with_a_design_error",
    "test_cli.py::test_ctrl_c_at_any_moment_is_one_line_and_130",
    "test_cli.py::test_a_build_whose_output_pipe_closes_ends_with_141_and_changes_nothing",
    "test_cli.py::test_build_example_design_and_check_it",
    "test_clothoid.py::test_large_turns_to_1e_13_of_the_length_against_mpmath",
    "test_clothoid.py::test_every_rate_to_1e_13_of_the_length_against_mpmath",
    "test_names.py::test_any_name_the_policy_passes_reads_back_from_every_file",
    "test_opendrive.py::test_a_broken_file_fails_the_schema",
    "test_opendrive.py::test_demo_writes_a_valid_highway_xodr",
    "test_opendrive.py::test_export_passes_the_asam_schema_and_checker_and_pyxodr_reads_the_chain",
    "test_opendrive_3d.py::test_the_3d_road_passes_the_schema_the_asam_checker_and_pyxodr_reads_its_elevation",
    "test_step_products.py::test_freecad_imports_the_road_with_import_insert",
    "test_names.py::test_hostile_names_and_geo_reference_pass_the_opendrive_schema",
    "test_names.py::test_enormous_names_and_file_names_never_crash_the_iges_writer",
    "test_near_linear.py::test_the_100_kmh_design_file_builds_end_to_end",
    "test_gcode_out.py::test_a_path_gets_its_program_and_any_chain_on_request",
    "test_landxml_build.py::test_demo_writes_a_valid_highway_xml_that_reads_back",
    "test_landxml_build.py::test_build_of_a_landxml_file_writes_every_output",
    "test_landxml_build.py::test_alignments_of_one_name_are_built_under_unique_names_and_told",
    "test_landxml_build.py::test_the_build_states_each_alignments_largest_offset_and_refuses_beyond_max_offset",
    "test_landxml_build.py::test_the_build_of_public_exports_keeps_every_element",
    "test_solids.py",
    "test_faces.py::test_freecad_evaluates_the_same_normals_and_normal_curvatures",
    "test_faces_cli.py::test_zebra_and_curvature_pictures_are_written_and_tell_g1_from_g2",
    "test_fit_cli.py",
    "test_points.py::test_a_million_rows_read_as_numpy_wrote_them",
    "test_ifc.py",
    "test_speed_guard.py::test_the_guard_fails_when_a_kernel_falls_back_to_plain_python",
    "test_make_g2.py::test_random_g1_paths_become_g2_within_the_bound",
    "test_make_g2.py::test_random_closed_filleted_polygons_become_g2",
    "test_make_g2.py::test_random_paths_with_corners_and_reversals",
}
_CAD = re.compile(r"^\s*(?:from|import) (?:build123d|cadquery|OCP)\b|importorskip\([\"'](?:build123d|cadquery|OCP)", re.M)
_SUBPROCESS = re.compile(r"\bsubprocess\b|sys\.executable")


def pytest_collection_modifyitems(config, items):
    """Markers by what a test module needs: ``cad`` (imports OCP, build123d or CadQuery, or lives in
    tests/cad), ``subprocess`` (runs a program), ``install`` (tests/app/test_install.py), ``slow`` (``SLOW``);
    in the nightly profile, NIGHTLY_FACTOR times the examples a property test asks for with its own
    ``@settings(max_examples=…)``."""
    texts: dict[Path, str] = {}
    nightly = settings.get_current_profile_name() == "nightly"
    scaled: set[int] = set()
    for item in items:
        path = Path(item.fspath)
        text = texts.setdefault(path, path.read_text(encoding="utf-8"))
        if path.parent.name == "cad" or _CAD.search(text):
            item.add_marker(pytest.mark.cad)
        if _SUBPROCESS.search(text):
            item.add_marker(pytest.mark.subprocess)
        if path.name == "test_install.py":
            item.add_marker(pytest.mark.install)
        if path.name in SLOW or f"{path.name}::{item.originalname}" in SLOW:
            item.add_marker(pytest.mark.slow)
        test = getattr(item, "obj", None)
        chosen = getattr(test, "_hypothesis_internal_use_settings", None)
        if nightly and chosen is not None and id(test) not in scaled:
            scaled.add(id(test))
            if chosen.max_examples < settings.default.max_examples:
                test._hypothesis_internal_use_settings = settings(chosen, max_examples=chosen.max_examples * NIGHTLY_FACTOR)


# --- xdist: tests sharing an expensive fixture run on one worker -----------------------------------------


def _decorator_call(node: ast.expr, *dotted: str) -> ast.Call | None:
    """``node`` as a call of one of the ``dotted`` names (``pytest.fixture(...)``), or None."""
    call = node if isinstance(node, ast.Call) else None
    target = call.func if call else node
    return (call or ast.Call(func=target, args=[], keywords=[])) if ast.unparse(target) in dotted else None


@functools.cache
def shared_groups(path: Path) -> dict[str, str]:
    """The test functions of a test module that go to one xdist worker, with their group.

    A test that uses, directly or through another fixture of its module, a module- or session-scoped
    fixture of its module shares it with the other such tests (group: the module); a test marked
    ``@pytest.mark.xdist_group("name")`` joins that group. Read from the source, so the controller, which
    collects no tests, can group the test ids the workers send.
    """
    try:
        tree = ast.parse(path.read_text(encoding="utf-8"))
    except (OSError, SyntaxError, UnicodeDecodeError):
        return {}
    functions = [node for node in ast.walk(tree) if isinstance(node, ast.FunctionDef)]
    needs: dict[str, set[str]] = {}  # fixture -> the fixtures it requests
    shared: set[str] = set()
    for function in functions:
        for decorator in function.decorator_list:
            if (call := _decorator_call(decorator, "pytest.fixture", "fixture")) is not None:
                needs[function.name] = {argument.arg for argument in function.args.args}
                scope = next((k.value for k in call.keywords if k.arg == "scope"), None)
                if isinstance(scope, ast.Constant) and scope.value in ("module", "session"):
                    shared.add(function.name)
    grew = True
    while grew:  # a fixture that requests a shared one is shared too
        grew = False
        for name, requested in needs.items():
            if name not in shared and requested & shared:
                shared.add(name)
                grew = True
    module = path.relative_to(ROOTDIR).as_posix() if path.is_relative_to(ROOTDIR) else path.as_posix()
    groups = {}
    for function in functions:
        if not function.name.startswith("test"):
            continue
        for decorator in function.decorator_list:
            call = _decorator_call(decorator, "pytest.mark.xdist_group")
            if call is not None and call.args and isinstance(call.args[0], ast.Constant):
                groups[function.name] = str(call.args[0].value)
        if function.name not in groups and {argument.arg for argument in function.args.args} & shared:
            groups[function.name] = module
    return groups


def xdist_scope(nodeid: str) -> str:
    """The xdist work unit of a test id: its group (``shared_groups``), or the test alone."""
    path, _, rest = nodeid.partition("::")
    name = rest.split("::")[-1].split("[")[0]
    return shared_groups(ROOTDIR / path).get(name, nodeid)


@pytest.hookimpl(optionalhook=True)
def pytest_xdist_make_scheduler(config, log):
    """``--dist loadgroup``: like xdist's own, with the groups of ``shared_groups`` (xdist marks a group by
    renaming the test ids, which pytest 9 no longer lets it do)."""
    if config.getvalue("dist") != "loadgroup":
        return None
    from xdist.scheduler import LoadScopeScheduling

    class SharedFixtureScheduling(LoadScopeScheduling):
        def _split_scope(self, nodeid: str) -> str:
            return xdist_scope(nodeid)

    return SharedFixtureScheduling(config, log)


@pytest.fixture(scope="session")
def short_road():
    """(alignment, profile) of a short road in metres with a crest and a sag whose vertical curves end on
    spirals and arcs (not at plan joints): the corridor and STEP tests share it."""
    from spiral_cad.design import Alignment, Profile

    alignment = Alignment.from_pis([(0, 0), (220, 10), (430, 120)], 200, units="m", design_speed=60)
    end = alignment.end_station
    profile = Profile.from_pvis([(0, 10), (150, 14), (320, 8), (end, 10)], units="m", design_speed=60, alignment=alignment)
    return alignment, profile
