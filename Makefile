# The two README commands: `make demo` (set up, run the main job) and `make test`.
PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed

.PHONY: setup demo test bench figures lint clean

$(STAMP): pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(BIN)/pip install --upgrade pip
	$(BIN)/pip install -e '.[test]'
	touch $(STAMP)

setup: $(STAMP)

demo: $(STAMP)
	rm -rf results/quickstart.zarr results/quickstart.nc
	$(BIN)/rockstudy run studies/quickstart.toml --out results/quickstart.zarr
	$(BIN)/rockstudy demo --out results/demo

test: $(STAMP)
	$(BIN)/python -m pytest -q

bench: $(STAMP)
	$(BIN)/python benchmarks/bench_engine.py
	$(BIN)/python benchmarks/bench_closedform.py
	$(BIN)/python benchmarks/bench_study.py

figures: $(STAMP)
	$(BIN)/rockstudy figures --out results/figures

lint: $(STAMP)
	$(BIN)/ruff check rockstudy tests benchmarks

clean:
	rm -rf $(VENV) results
