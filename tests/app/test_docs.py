"""The documentation site: every Python block of its pages runs, every name, file and command-line option
it gives exists (the README's too), and it builds and opens.

Each page's ``python`` blocks run top to bottom in one fresh namespace (a
page is read like one Python session), in a subprocess whose working folder
is a temporary one. A block that cannot run by design is preceded by the line
``<!-- docs: skip (the reason) -->``; it is still compiled.

The site test builds with ``mkdocs build --strict`` (the toolchain of
``requirements-docs.lock``, which ``make docs`` installs), or reuses the
``site/`` that ``make docs`` built strictly after the last change to any of
its inputs (``make test`` builds it just before pytest), and opens pages in
headless Chromium served over HTTP: the title, the navigation, every request
answered and no error on the console.
"""

from __future__ import annotations

import ast
import importlib
import importlib.util
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest
from helpers import CHROMIUM_FLAGS, Block, chromium, python_blocks, run_blocks, serve, unresolved

ROOT = Path(__file__).resolve().parents[2]
DOCS = ROOT / "docs"
PAGES = sorted(DOCS.rglob("*.md"))


# Runs the blocks given on stdin as [first line, code] pairs; tracebacks show the page's own line numbers.
def rel(page: Path) -> str:
    return str(page.relative_to(ROOT))


PAGES_WITH_CODE = [p for p in PAGES if python_blocks(p.read_text(encoding="utf-8"), "docs", rel(p))]


def test_the_extractor_finds_blocks_markers_and_line_numbers():
    text = "# t\n\n```python\nx = 1\n```\n\n<!-- docs: skip (needs a GUI) -->\n```python\nshow(x)\n```\n```sh\nls\n```\n"
    assert python_blocks(text, "docs") == [Block(4, "x = 1\n", None), Block(9, "show(x)\n", "needs a GUI")]
    assert len(PAGES_WITH_CODE) >= 8, "the tutorials lost their Python blocks?"


@pytest.mark.parametrize("page", PAGES, ids=rel)
def test_every_block_is_valid_python(page):
    for block in python_blocks(page.read_text(encoding="utf-8"), "docs", rel(page)):
        ast.parse(block.code, filename=f"{rel(page)}:{block.first_line}")


@pytest.mark.slow
@pytest.mark.subprocess
@pytest.mark.cad
@pytest.mark.parametrize("page", PAGES_WITH_CODE, ids=rel)
def test_every_block_runs(page, tmp_path):
    run_blocks(page, python_blocks(page.read_text(encoding="utf-8"), "docs", rel(page)), tmp_path, timeout=900)


def _dotted_names() -> list[tuple[str, str]]:
    found = set()
    for page in PAGES:
        for dotted in re.findall(r"`(spiral_cad(?:\.\w+)+)", page.read_text(encoding="utf-8")):
            found.add((rel(page), dotted))
    return sorted(found)


# The layer packages the API pages document; the prose names them only as packages.
@pytest.mark.parametrize(("page", "dotted"), _dotted_names(), ids=lambda x: x)
def test_every_dotted_name_in_the_text_exists(page, dotted):
    """Names the prose gives in full (`spiral_cad.design.fillet_path`) import as written."""
    problem = unresolved(dotted)
    assert problem is None, f"{page}: {problem}"


def test_every_page_is_in_the_navigation_and_every_image_exists():
    config = (ROOT / "mkdocs.yml").read_text(encoding="utf-8")
    in_nav = set(re.findall(r":\s+(\S+\.md)\s*$", config, flags=re.M))
    generated = {"reference/design-files.md", "benchmarks/results.md"}
    on_disk = {str(p.relative_to(DOCS)) for p in PAGES}
    assert on_disk - in_nav == set(), "pages missing from the nav"
    assert in_nav - on_disk - generated == set(), "nav entries without a page"
    for page in PAGES:
        for target in re.findall(r"!\[[^\]]*\]\(([^)]+)\)", page.read_text(encoding="utf-8")):
            assert (page.parent / target).resolve().is_file(), f"{rel(page)}: no image {target}"


def test_the_mathematics_cites_the_paper_and_the_api_pages_render_the_faces():
    math = (DOCS / "math" / "index.md").read_text(encoding="utf-8")
    assert "Walton" in math and "1996" in math
    for face in (
        "spiral_cad",
        "spiral_cad.design",
        "spiral_cad.build123d",
        "spiral_cad.cadquery",
        "spiral_cad.continuity",
        "spiral_cad.io",
        "spiral_cad.cad",
        "spiral_cad.app",
    ):
        name = "spiral_cad" if face == "spiral_cad" else face.split(".")[1]
        assert f"::: {face}\n" in (DOCS / "api" / f"{name}.md").read_text(encoding="utf-8")


# --- the built site, opened in a browser -------------------------------------------------------

#: Written into site/ by ``make docs`` once ``mkdocs build --strict`` succeeded (mkdocs keeps dot files).
BUILT_MARK = ".strict-build"


def _site_inputs() -> list[Path]:
    """Every file the site is made from: its pages and assets, its configuration and hooks, the docstrings of
    the API pages, the benchmark tables the results page gathers."""
    return [
        ROOT / "mkdocs.yml",
        ROOT / "requirements-docs.lock",
        *(path for path in DOCS.rglob("*") if path.is_file()),
        *(ROOT / "spiral_cad").rglob("*.py"),
        *(ROOT / "benchmarks").glob("results_*.md"),
    ]


def current_site(built: Path = ROOT / "site") -> Path | None:
    """``built`` when ``make docs`` built it with ``--strict`` after the last change to any of its inputs."""
    mark = built / BUILT_MARK
    if not mark.is_file() or not (built / "index.html").is_file():
        return None
    made = mark.stat().st_mtime
    return built if all(path.stat().st_mtime <= made for path in _site_inputs()) else None


def test_a_site_is_reused_only_when_built_strictly_after_its_inputs(tmp_path):
    assert current_site(tmp_path) is None
    (tmp_path / "index.html").write_text("<title>spiral_cad</title>", encoding="utf-8")
    assert current_site(tmp_path) is None  # no mark: the build failed or was not `make docs`
    mark = tmp_path / BUILT_MARK
    mark.touch()
    newest = max(path.stat().st_mtime for path in _site_inputs())
    os.utime(mark, (newest + 1, newest + 1))
    assert current_site(tmp_path) == tmp_path
    os.utime(mark, (newest - 1, newest - 1))
    assert current_site(tmp_path) is None  # a page changed since


@pytest.fixture(scope="module")
def site(tmp_path_factory) -> Path:
    """The site ``make docs`` built (``make test`` builds it before pytest) when it is current, else a strict build."""
    try:
        import mkdocs  # noqa: F401
        import mkdocstrings  # noqa: F401
    except ImportError:
        pytest.skip("the documentation toolchain is not installed here (make docs installs requirements-docs.lock)")
    # API pages of faces this checkout does not have yet are left out, as the hook documents.
    missing = [name for name in ("continuity", "io", "cad", "app") if importlib.util.find_spec(f"spiral_cad.{name}") is None]
    if not missing and (built := current_site()) is not None:
        return built
    out = tmp_path_factory.mktemp("site")
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")]), "NO_MKDOCS_2_WARNING": "1"}
    if missing:
        env["SPIRAL_CAD_DOCS_SKIP_API"] = ",".join(missing)
    done = subprocess.run(
        [sys.executable, "-m", "mkdocs", "build", "--strict", "--site-dir", str(out)],
        cwd=ROOT,
        env=env,
        capture_output=True,
        text=True,
        timeout=900,
    )
    assert done.returncode == 0, done.stderr[-4000:]
    return out


def _open(url: str, tmp_path: Path) -> tuple[str, str]:
    """The DOM Chromium built for ``url`` and the console lines it logged."""
    done = subprocess.run(
        [
            chromium(),
            *CHROMIUM_FLAGS,
            f"--user-data-dir={tmp_path / 'profile'}",
            "--enable-logging=stderr",
            "--v=0",
            "--virtual-time-budget=8000",
            "--dump-dom",
            url,
        ],
        capture_output=True,
        text=True,
        timeout=180,
    )
    assert done.returncode == 0, done.stderr[-3000:]
    console = [line for line in done.stderr.splitlines() if "CONSOLE" in line]
    return done.stdout, "\n".join(console)


@pytest.mark.slow
@pytest.mark.subprocess
@pytest.mark.parametrize(
    ("path", "title", "text"),
    [
        ("index.html", "spiral_cad", "cubic Bézier spiral"),
        ("api/design.html", "spiral_cad.design", "Alignment"),
        ("math/index.html", "The Walton–Meek spiral", "mjx-container"),
    ],
)
def test_the_site_opens_in_a_browser(site, tmp_path, path, title, text):
    server = serve(site)
    try:
        dom, console = _open(f"http://127.0.0.1:{server.server_address[1]}/{path}", tmp_path)
    finally:
        server.shutdown()
    assert re.search(r"<title>[^<]*" + re.escape(title), dom), dom[:2000]
    assert 'class="md-nav' in dom and "Getting started" in dom and "Tutorials" in dom
    assert text in dom
    assert server.failed == [], f"requests not answered: {server.failed}"
    # Chromium logs every console message at one level; the site logs none, so any line is a fault.
    assert console == "", console


def _hooks():
    pytest.importorskip("mkdocs", reason="the documentation toolchain is not installed here (make docs installs it)")
    spec = importlib.util.spec_from_file_location("docs_hooks", DOCS / "hooks.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_the_design_file_page_comes_from_the_schema_when_the_package_renders_it(monkeypatch):
    hooks = _hooks()
    import types

    fake = types.ModuleType("spiral_cad.app.designfile")
    fake.schema_markdown = lambda: "# Design files\n\nrendered from the schema\n"
    monkeypatch.setitem(sys.modules, "spiral_cad.app.designfile", fake)
    assert hooks._schema_markdown() == "# Design files\n\nrendered from the schema\n"
    monkeypatch.setitem(sys.modules, "spiral_cad.app.designfile", types.ModuleType("spiral_cad.app.designfile"))
    for module in ("spiral_cad.app.schema", "spiral_cad.designfile"):
        monkeypatch.setitem(sys.modules, module, types.ModuleType(module))
    assert hooks._schema_markdown() is None  # then the page says `spiral-cad schema` prints the format
    assert "spiral-cad schema" in hooks.FALLBACK_DESIGN_FILES


def test_the_results_page_gathers_every_benchmark_table():
    text = _hooks()._results_markdown()
    for path in (ROOT / "benchmarks").glob("results_*.md"):
        title = path.read_text(encoding="utf-8").splitlines()[0].lstrip("# ")
        assert f"## {title}" in text, path.name


README = ROOT / "README.md"
#: Folders of the repository a page may name a file in (`examples/design.json`).
_FOLDERS = ("examples", "benchmarks", "docs", "tests", "spiral_cad", "tools")


def _texts() -> list[tuple[str, str]]:
    return [(rel(page), page.read_text(encoding="utf-8")) for page in [*PAGES, README]]


def _cli_options() -> dict[str, set[str]]:
    """Each ``spiral-cad`` command and the options it takes (the parser's own; ``""``: the program's)."""
    import argparse

    from spiral_cad.app.cli import _parser

    parser = _parser()
    options = {"": {s for a in parser._actions for s in a.option_strings}}
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for verb, sub in action.choices.items():
                options[verb] = {s for a in sub._actions for s in a.option_strings}
    return options


def _commands() -> list[tuple[str, str, str]]:
    """(page, command, option) for every ``--option`` written after ``spiral-cad COMMAND`` on one line."""
    found = set()
    for page, text in _texts():
        for line in text.splitlines():
            for match in re.finditer(r"spiral-cad ((?:\w|\|)+)([^`\n]*)", line):
                for verb in match[1].split("|"):
                    for option in re.findall(r"(?<![\w-])(--[a-z][\w-]*)", match[2].split("spiral-cad ")[0]):
                        found.add((page, verb, option))
    return sorted(found)


@pytest.mark.parametrize(("page", "verb", "option"), _commands(), ids=lambda x: x)
def test_every_option_a_page_gives_a_command_is_one_it_takes(page, verb, option):
    options = _cli_options()
    assert verb in options, f"{page}: spiral-cad has no command {verb!r}"
    assert option in options[verb] | options[""], f"{page}: spiral-cad {verb} takes no {option}"


def _files() -> list[tuple[str, str]]:
    found = set()
    for page, text in _texts():
        for path in re.findall(rf"`((?:{'|'.join(_FOLDERS)})/[\w./-]*\w)`", text):
            found.add((page, path))
    return sorted(found)


@pytest.mark.parametrize(("page", "path"), _files(), ids=lambda x: x)
def test_every_file_a_page_names_exists(page, path):
    assert (ROOT / path).exists(), f"{page}: {path} does not exist"


@pytest.mark.parametrize("dotted", sorted(set(re.findall(r"`(spiral_cad(?:\.\w+)+)", README.read_text(encoding="utf-8")))))
def test_every_dotted_name_in_the_readme_exists(dotted):
    problem = unresolved(dotted)
    assert problem is None, f"README.md: {problem}"


def test_the_name_checks_catch_what_does_not_exist(tmp_path):
    """The extractors find a wrong option, a missing file and a wrong name (so that a rename is caught)."""
    assert "--max-deviation" in _cli_options()["g2"] and "--g3" not in _cli_options()["check"]
    assert unresolved("spiral_cad.design.no_such_function") is not None
    assert any(path == "examples/design.json" for _, path in _files())
    assert any(verb == "check" and option == "--require" for _, verb, option in _commands())


def test_every_page_the_command_lines_help_names_exists():
    import argparse

    from spiral_cad.app.cli import _parser

    parser = _parser()
    helps = [parser.format_help()]
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            helps += [sub.format_help() for sub in action.choices.values()]
    named = set(re.findall(r"(docs/[\w/.-]+\.md|README\.md|examples/[\w.-]+)", " ".join(helps).replace("\n", " ")))
    assert "docs/tutorials/paths.md" in named
    assert all((ROOT / path).exists() for path in named), sorted(p for p in named if not (ROOT / p).exists())
    assert "README: " not in " ".join(helps)  # a README section the README does not have
