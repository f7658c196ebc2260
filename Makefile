# Fresh machine: `make demo` or `make test` create .venv and install the pinned set.
PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed
DOCS_STAMP := $(VENV)/.docs-installed
# OpenDRIVE validators (ASAM quality checker with the 1.8 XSD, pyxodr): they pin
# numpy < 2, so they live in their own small environment, never in .venv.
TOOLS       := .venv-tools
TOOLS_STAMP := $(TOOLS)/.installed

.PHONY: setup demo test check nightly lint bench pictures clean rs274 freecad chromium xvfb

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

# FreeCAD's Import.insert judges our STEP files (tests/test_step_products.py). Installed from the
# distribution when apt-get can (root, Debian/Ubuntu); otherwise those tests skip, naming why. Never fatal.
freecad:
	-@test -e /usr/lib/freecad-python3/lib/Import.so \
	  || { command -v apt-get >/dev/null && [ "$$(id -u)" = 0 ] \
	       && apt-get update -q >/dev/null && DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends freecad-python3 >/dev/null; } \
	  || echo "FreeCAD not installed (apt-get install freecad-python3): its STEP import tests are skipped"

# Headless Chromium opens the built site in tests/app/test_docs.py. Installed from the distribution when
# apt-get can (root, Debian); otherwise those tests skip, naming why. Never fatal.
chromium:
	-@command -v chromium >/dev/null \
	  || { command -v apt-get >/dev/null && [ "$$(id -u)" = 0 ] \
	       && { DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends chromium >/dev/null \
	            || { apt-get update -q >/dev/null && DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends chromium >/dev/null; }; }; } \
	  || echo "Chromium not installed (apt-get install chromium): the rendered-site tests are skipped"

# A virtual X display for CQ-editor, whose 3-D view tests/cad/test_show_continuity_cq_editor.py reads back.
# Installed from the distribution when apt-get can (root, Debian); otherwise that test skips, naming why.
xvfb:
	-@command -v xvfb-run >/dev/null \
	  || { command -v apt-get >/dev/null && [ "$$(id -u)" = 0 ] \
	       && { DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends xvfb xauth >/dev/null \
	            || { apt-get update -q >/dev/null && DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends xvfb xauth >/dev/null; }; }; } \
	  || echo "Xvfb not installed (apt-get install xvfb xauth): the CQ-editor test is skipped"

# pytest on every core (pytest-xdist); the tests sharing an expensive module fixture stay on one
# worker (tests/conftest.py, shared_fixture_group). PYTEST_WORKERS=0 runs in one process.
PYTEST_WORKERS ?= auto
XDIST := -n $(PYTEST_WORKERS) --dist loadgroup

# Everything CI runs: lint and the documentation site (--strict) side by side, then every test (the docs
# tests reuse that site/). -O keeps each one's output in one piece.
test: $(STAMP) $(TOOLS_STAMP) $(DOCS_STAMP) rs274 freecad chromium xvfb
	$(MAKE) --no-print-directory -j2 -O lint docs
	SPIRAL_CAD_XODR_TOOLS=$(abspath $(TOOLS))/bin/python $(BIN)/python -m pytest -q $(XDIST) --durations=30

# The fast tier while working: no slow, install or subprocess-heavy tests.
check: $(STAMP)
	$(BIN)/python -m pytest -q $(XDIST) -m "not slow and not install"

# The nightly size: every property test with ten times its examples (the "nightly" hypothesis profile,
# tests/conftest.py). A failing example is saved in tests/.hypothesis-examples: commit it with the fix.
nightly: $(STAMP) $(TOOLS_STAMP)
	SPIRAL_CAD_XODR_TOOLS=$(abspath $(TOOLS))/bin/python $(BIN)/python -m pytest -q $(XDIST) -m hypothesis --hypothesis-profile=nightly

# ruff (lint and format), mypy (strict for the numeric core), import-linter (layers point one way).
lint: $(STAMP)
	$(BIN)/ruff check spiral_cad spiral_cad_launcher tests benchmarks examples docs
	$(BIN)/ruff format --check spiral_cad spiral_cad_launcher tests benchmarks examples docs
	$(BIN)/mypy
	$(BIN)/lint-imports

# LinuxCNC's standalone G-code interpreter rs274 (Debian package linuxcnc-uspace) for the tests of
# --interpreter rs274: installed when we are root on Debian; otherwise those tests skip, saying why.
APT_RS274 := DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends linuxcnc-uspace >/dev/null
rs274:
	@command -v rs274 >/dev/null || { [ "$$(id -u)" = 0 ] && command -v apt-get >/dev/null && \
	  { $(APT_RS274) || { apt-get update -q >/dev/null && $(APT_RS274); }; }; } || \
	  echo "note: LinuxCNC's rs274 (Debian package linuxcnc-uspace) could not be installed; its tests will skip"

# Every benchmarks/bench_*.py, each in its own process, writing benchmarks/results_*.md
# (the convention a script follows: benchmarks/timing.py).
bench: $(STAMP)
	$(BIN)/python benchmarks/run_all.py

# The documentation site into site/: the pinned mkdocs toolchain on top of the
# package's own set (shared packages keep requirements.lock's versions).

$(DOCS_STAMP): $(STAMP) requirements-docs.lock
	$(BIN)/python -m pip install -q -r requirements-docs.lock -c requirements.lock
	$(BIN)/python -m pip check
	touch $(DOCS_STAMP)

.PHONY: docs
# site/.strict-build marks a site built --strict; tests/app/test_docs.py reuses such a site while none
# of its inputs changed (mkdocs keeps dot files in site/, hence the rm).
docs: $(DOCS_STAMP)
	rm -f site/.strict-build
	NO_MKDOCS_2_WARNING=1 $(BIN)/python -m mkdocs build --strict
	touch site/.strict-build

pictures: $(STAMP)
	$(BIN)/python docs/make_pictures.py

clean:
	rm -rf $(VENV) $(TOOLS) out build site .pytest_cache .hypothesis
