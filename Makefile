# Two commands do all the set-up on a fresh machine with Python 3.11 and pip:
#   make demo   - create .venv, install uvms-pin, run the main scenario into out/demo
#   make test   - create .venv, install uvms-pin with dev tools, lint and run the test suite
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed
DEMO_SCENARIO ?= scenarios/realistic_force_tracking.toml
DEMO_OUT ?= out/demo

.PHONY: demo test lint bench clean

$(STAMP): pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e '.[dev]'
	touch $(STAMP)

demo: $(STAMP)
	$(BIN)/uvms-pin run $(DEMO_SCENARIO) --out $(DEMO_OUT)

lint: $(STAMP)
	$(BIN)/ruff check .
	$(BIN)/ruff format --check .

test: $(STAMP) lint
	$(BIN)/python -m pytest -q

bench: $(STAMP)
	$(BIN)/python benchmarks/bench_dynamics.py

clean:
	rm -rf $(VENV) out build *.egg-info
