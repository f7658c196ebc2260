"""README.md: short, the pitch first, every Python block runs, every name and link exists.

The long material lives in the documentation site (tests/test_docs.py checks
its pages the same way).

The blocks run top to bottom in one fresh namespace, as a reader pasting
them into one Python session would (a later block may use a name an earlier
one defined), in a subprocess whose working folder is a temporary one (the
files the blocks write land there). A block that cannot run by design is
preceded by the line ``<!-- readme: skip (the reason) -->``; it is still
compiled.
"""

import ast
import re
from pathlib import Path

import pytest
from helpers import Block, python_blocks, run_blocks, unresolved

README = Path(__file__).resolve().parents[2] / "README.md"

# Runs the blocks given on stdin as [first line, code] pairs; tracebacks show README.md's own line numbers.
BLOCKS = python_blocks(README.read_text(encoding="utf-8"), "readme", "README.md")


def test_the_extractor_finds_blocks_markers_and_line_numbers():
    text = "# t\n\n```python\nx = 1\n```\n\n<!-- readme: skip (needs a GUI) -->\n```python\nshow(x)\n```\n```sh\nls\n```\n"
    assert python_blocks(text, "readme") == [Block(4, "x = 1\n", None), Block(9, "show(x)\n", "needs a GUI")]
    assert len(BLOCKS) >= 2, "README.md lost its Python blocks?"


@pytest.mark.parametrize("block", BLOCKS, ids=[f"line {b.first_line}" for b in BLOCKS])
def test_every_block_is_valid_python(block):
    ast.parse(block.code, filename=f"README.md:{block.first_line}")


def test_every_block_runs(tmp_path):
    run_blocks(README, BLOCKS, tmp_path, timeout=600)


DOTTED = sorted(set(re.findall(r"`(spiral_cad(?:\.\w+)+)", README.read_text(encoding="utf-8"))))


@pytest.mark.parametrize("dotted", DOTTED)
def test_every_dotted_name_in_the_text_exists(dotted):
    """Names the prose gives in full (`spiral_cad.design.fillet_path`) import as written."""
    problem = unresolved(dotted)
    assert problem is None, problem


TEXT = README.read_text(encoding="utf-8")


def test_the_readme_is_short_and_starts_with_the_pitch_and_a_picture():
    lines = TEXT.splitlines()
    assert len(lines) <= 200, f"README.md has {len(lines)} lines; the long material belongs in docs/"
    first_code = next(i for i, line in enumerate(lines) if line.startswith("```"))
    first_image = next(i for i, line in enumerate(lines) if line.startswith("!["))
    assert first_image < first_code, "the pitch and one picture come before any command"
    assert "Walton & Meek" in "\n".join(lines[:first_image])


def test_the_readme_gives_the_commands_the_extras_and_the_site():
    for needed in ("make demo", "make test", "make docs", 'pip install ".[cad]"', "pip install .", "site/"):
        assert needed in TEXT, needed
    assert "MATH.md" not in TEXT, "the mathematics is on the site (docs/math/), not in a reference file"


@pytest.mark.parametrize("target", sorted(set(re.findall(r"\]\(([^)#\s]+)(?:#[^)]*)?\)", TEXT))))
def test_every_link_and_picture_exists(target):
    assert (README.parent / target).exists(), target
