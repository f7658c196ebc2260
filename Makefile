# Fresh machine: `make demo` or `make test` create .venv and install the pinned set.
PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed
# OpenDRIVE validators (ASAM quality checker with the 1.8 XSD, pyxodr): they pin
# numpy < 2, so they live in their own small environment, never in .venv.
TOOLS       := .venv-tools
TOOLS_STAMP := $(TOOLS)/.installed

.PHONY: setup demo test bench pictures clean

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

test: $(STAMP) $(TOOLS_STAMP)
	SPIRAL_CAD_XODR_TOOLS=$(abspath $(TOOLS))/bin/python $(BIN)/python -m pytest -q

# Every benchmarks/bench_*.py, each in its own process, writing benchmarks/results_*.md
# (the convention a script follows: benchmarks/timing.py).
bench: $(STAMP)
	$(BIN)/python benchmarks/run_all.py

pictures: $(STAMP)
	$(BIN)/python docs/make_pictures.py

clean:
	rm -rf $(VENV) $(TOOLS) out build .pytest_cache .hypothesis
