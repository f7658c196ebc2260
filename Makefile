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

bench: $(STAMP)
	$(BIN)/python benchmarks/bench_core.py --out benchmarks/results_core.md
	$(BIN)/python benchmarks/bench_cad.py --out benchmarks/results_cad.md
	$(BIN)/python benchmarks/bench_checker.py --out benchmarks/results_checker.md
	$(BIN)/python benchmarks/bench_rounding.py --out benchmarks/results_rounding.md
	$(BIN)/python benchmarks/bench_roads.py --out benchmarks/results_roads.md
	$(BIN)/python benchmarks/bench_fillets.py --out benchmarks/results_fillets.md
	$(BIN)/python benchmarks/bench_shapes.py --out benchmarks/results_shapes.md
	$(BIN)/python benchmarks/bench_chains.py --out benchmarks/results_chains.md

pictures: $(STAMP)
	$(BIN)/python docs/make_pictures.py

clean:
	rm -rf $(VENV) $(TOOLS) out build .pytest_cache .hypothesis
