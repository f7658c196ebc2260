# Fresh machine: `make demo` or `make test` create .venv and install the pinned set.
PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed
# OpenDRIVE validators (ASAM quality checker with the 1.8 XSD, pyxodr): they pin
# numpy < 2, so they live in their own small environment, never in .venv.
TOOLS       := .venv-tools
TOOLS_STAMP := $(TOOLS)/.installed

.PHONY: setup demo test check lint bench pictures clean

$(STAMP): requirements.lock pyproject.toml
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install -q pip==26.3
	$(BIN)/python -m pip install -q -r requirements.lock
	$(BIN)/python -m pip install -q --no-deps -e .
	$(BIN)/python -m pip check
	# compile the kernels once now (numba's on-disk cache), so a first demo or build does not wait for them
	$(BIN)/spiral-cad demo --out $(VENV)/first-demo > /dev/null
	touch $(STAMP)

$(TOOLS_STAMP): tools/xodr-tools.lock
	test -x $(TOOLS)/bin/python || $(PYTHON) -m venv $(TOOLS)
	$(TOOLS)/bin/python -m pip install -q pip==26.3
	$(TOOLS)/bin/python -m pip install -q -r tools/xodr-tools.lock
	$(TOOLS)/bin/python -m pip check
	touch $(TOOLS_STAMP)

setup: $(STAMP)

demo: $(STAMP)
	$(BIN)/spiral-cad demo --out out

# Everything CI runs: lint, then every test.
test: $(STAMP) $(TOOLS_STAMP) lint
	SPIRAL_CAD_XODR_TOOLS=$(abspath $(TOOLS))/bin/python $(BIN)/python -m pytest -q

# The fast tier while working: no slow, install or subprocess-heavy tests.
check: $(STAMP)
	$(BIN)/python -m pytest -q -m "not slow and not install"

# ruff (lint and format), mypy (strict for the numeric core), import-linter (layers point one way).
lint: $(STAMP)
	$(BIN)/ruff check spiral_cad spiral_cad_launcher tests benchmarks examples docs
	$(BIN)/ruff format --check spiral_cad spiral_cad_launcher tests benchmarks examples docs
	$(BIN)/mypy
	$(BIN)/lint-imports

# Every benchmarks/bench_*.py, each in its own process, writing benchmarks/results_*.md
# (the convention a script follows: benchmarks/timing.py).
bench: $(STAMP)
	$(BIN)/python benchmarks/run_all.py

# The documentation site into site/: the pinned mkdocs toolchain on top of the
# package's own set (shared packages keep requirements.lock's versions).
DOCS_STAMP := $(VENV)/.docs-installed

$(DOCS_STAMP): $(STAMP) requirements-docs.lock
	$(BIN)/python -m pip install -q -r requirements-docs.lock -c requirements.lock
	$(BIN)/python -m pip check
	touch $(DOCS_STAMP)

.PHONY: docs
docs: $(DOCS_STAMP)
	NO_MKDOCS_2_WARNING=1 $(BIN)/python -m mkdocs build --strict

pictures: $(STAMP)
	$(BIN)/python docs/make_pictures.py

clean:
	rm -rf $(VENV) $(TOOLS) out build .pytest_cache .hypothesis
