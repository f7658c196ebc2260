# Fresh machine: `make demo` or `make test` create .venv and install the pinned set.
PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed
# OpenDRIVE validators (ASAM quality checker with the 1.8 XSD, pyxodr): they pin
# numpy < 2, so they live in their own small environment, never in .venv.
TOOLS       := .venv-tools
TOOLS_STAMP := $(TOOLS)/.installed

.PHONY: setup demo test bench pictures clean freecad

$(STAMP): requirements.lock pyproject.toml
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install -q pip==26.3
	$(BIN)/python -m pip install -q -r requirements.lock
	$(BIN)/python -m pip install -q --no-deps -e .
	$(BIN)/python -m pip check
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

test: $(STAMP) $(TOOLS_STAMP) freecad
	SPIRAL_CAD_XODR_TOOLS=$(abspath $(TOOLS))/bin/python $(BIN)/python -m pytest -q

# Every benchmarks/bench_*.py, each in its own process, writing benchmarks/results_*.md
# (the convention a script follows: benchmarks/timing.py).
bench: $(STAMP)
	$(BIN)/python benchmarks/run_all.py

pictures: $(STAMP)
	$(BIN)/python docs/make_pictures.py

clean:
	rm -rf $(VENV) $(TOOLS) out build .pytest_cache .hypothesis
