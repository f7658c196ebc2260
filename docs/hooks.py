"""Build-time pages and assets of the documentation site (an mkdocs hook).

- ``reference/design-files.md`` is written from the design-file schema when the
  package can render it (``schema_markdown()`` in ``spiral_cad.app.designfile``
  or ``spiral_cad.designfile``); otherwise the page says where the format is
  printed.
- ``benchmarks/results.md`` gathers ``benchmarks/results_*.md``, the tables
  ``make bench`` writes, so the numbers live in one place.
- MathJax is copied from the ``django-static-mathjax`` package into the site,
  so the mathematics renders with no network.
- ``SPIRAL_CAD_DOCS_SKIP_API`` (names separated by commas, e.g.
  ``continuity,io,cad,app``) leaves those API pages' ``:::`` directives out, for
  builds of a checkout whose package does not have those faces yet.
"""

from __future__ import annotations

import importlib
import os
import re
import shutil
from pathlib import Path

from mkdocs.structure.files import File, Files

ROOT = Path(__file__).resolve().parent.parent
MATHJAX_TARGET = "javascripts/mathjax"

FALLBACK_DESIGN_FILES = """# Design-file reference

A design file is the JSON document `spiral-cad build DESIGN.json` reads. Its
full format (every key, its type, unit and default) is printed by

```sh
spiral-cad schema
```

and summarised, with the checks made on every field, in
[Command line and design files](../guide/cli.md). `examples/design.json` is a
complete example.
"""


def _schema_markdown() -> str | None:
    """The design-file reference the package renders from its schema, if it can."""
    for module in ("spiral_cad.app.designfile", "spiral_cad.app.schema", "spiral_cad.designfile"):
        try:
            render = getattr(importlib.import_module(module), "schema_markdown", None)
        except ImportError:
            continue
        if callable(render):
            return render()
    return None


def _results_markdown() -> str:
    """Every ``benchmarks/results_*.md``, one section each, headings moved one level down."""
    parts = [
        "# Benchmark results\n",
        "The tables `make bench` wrote, one section per script "
        "(`benchmarks/results_*.md`; how they are measured: [Benchmarks](index.md)).\n",
    ]
    for path in sorted((ROOT / "benchmarks").glob("results_*.md")):
        text = path.read_text(encoding="utf-8")
        parts.append(re.sub(r"^(#+) ", r"#\1 ", text, flags=re.M))
    return "\n".join(parts)


def on_files(files: Files, config) -> Files:
    generated = {
        "reference/design-files.md": _schema_markdown() or FALLBACK_DESIGN_FILES,
        "benchmarks/results.md": _results_markdown(),
    }
    for uri, content in generated.items():
        if files.get_file_from_path(uri) is None:
            files.append(File.generated(config, uri, content=content))
    return files


def on_page_markdown(markdown: str, page, config, files) -> str:
    skipped = {name.strip() for name in os.environ.get("SPIRAL_CAD_DOCS_SKIP_API", "").split(",") if name.strip()}
    if page.file.src_uri.startswith("api/") and Path(page.file.src_uri).stem in skipped:
        note = "\n!!! note\n    Left out of this build (`SPIRAL_CAD_DOCS_SKIP_API`).\n"
        return re.sub(r"^::: .*(\n    .*)*", note, markdown, flags=re.M)
    return markdown


def on_post_build(config) -> None:
    import mathjax  # django-static-mathjax: MathJax 3's files, nothing else

    source = Path(mathjax.__file__).parent / "static" / "mathjax" / "es5"
    target = Path(config["site_dir"]) / MATHJAX_TARGET
    target.mkdir(parents=True, exist_ok=True)
    shutil.copy2(source / "tex-mml-chtml.js", target / "tex-mml-chtml.js")
    shutil.copytree(source / "output" / "chtml" / "fonts", target / "output" / "chtml" / "fonts", dirs_exist_ok=True)
