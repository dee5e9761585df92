# Two entry points, both self-contained on a fresh machine with Python 3.11:
#   make run   -- create .venv, install, start API + workers (PORT=8000 HOST=127.0.0.1
#                 DATA_DIR=./data); prints "ready on http://..." when it answers
#   make test  -- create .venv with test extras, lint, run the whole suite
PYTHON ?= python3.11
VENV := .venv
BIN := $(VENV)/bin
DATA_DIR ?= ./data
HOST ?= 127.0.0.1
PORT ?= 8000

.PHONY: run test lint format bench load clean

$(BIN)/python:
	@command -v $(PYTHON) >/dev/null 2>&1 || { echo "need $(PYTHON) on PATH (or make PYTHON=python3)"; exit 2; }
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip

# --no-compile: the install takes half the time; Python writes the .pyc files it needs on import
$(VENV)/.installed: $(BIN)/python pyproject.toml
	$(BIN)/python -m pip install --quiet --no-compile -e .
	touch $@

$(VENV)/.installed-test: $(BIN)/python pyproject.toml
	$(BIN)/python -m pip install --quiet -e '.[test,dask]'
	touch $@ $(VENV)/.installed

run: $(VENV)/.installed
	$(BIN)/gearengine serve --host $(HOST) --port $(PORT) --data-dir $(DATA_DIR)

test: $(VENV)/.installed-test
	$(BIN)/ruff check .
	$(BIN)/ruff format --check .
	$(BIN)/python -m pytest -q -n auto --dist loadfile

lint: $(VENV)/.installed-test
	$(BIN)/ruff check .
	$(BIN)/ruff format --check .

format: $(VENV)/.installed-test
	$(BIN)/ruff format .
	$(BIN)/ruff check --fix .

bench: $(VENV)/.installed-test
	$(BIN)/python benchmarks/bench_kernels.py
	$(BIN)/python benchmarks/bench_sweep.py
	$(BIN)/python benchmarks/bench_melnikov.py
	$(BIN)/python benchmarks/bench_floquet.py
	$(BIN)/python benchmarks/bench_map.py

load: $(VENV)/.installed-test
	$(BIN)/python benchmarks/load.py --clients 50 --seconds 60

clean:
	rm -rf $(VENV) .pytest_cache .ruff_cache
