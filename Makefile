# The two README commands: `make demo` (set up, run the main job) and `make test`.
PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
# the package alone (what `make demo` runs), then with the test and docs extras
BASE   := $(VENV)/.installed-base
STAMP  := $(VENV)/.installed
# numba's on-disk cache of the kernels, primed once per install (and again after an edit)
KERNELS := $(VENV)/.kernels-compiled

.PHONY: setup debian demo test docs bench figures lint clean

# Python writes the bytecode of a module the first time a command imports it, here also where
# the environment sets PYTHONDONTWRITEBYTECODE (as many containers do), which would otherwise
# compile every import again on every run; so the install compiles none (most of what it
# installs is never imported: compiling it all took pip 25 s of CPU of its 55).
unexport PYTHONDONTWRITEBYTECODE

# The venv's own pip installs uv, which installs the project (in a third of pip's time, as it
# downloads and unpacks in parallel); where uv cannot be had, pip does it.
INSTALL = $(BIN)/pip install -q uv && $(BIN)/uv pip install -q --python $(BIN)/python $(1) \
	  || $(BIN)/pip install -q --no-compile $(1)

$(BASE): pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(call INSTALL,-e .)
	touch $(BASE)

# (the extras in a variable: a comma in $(call ...)'s arguments would split them)
EXTRAS = -e '.[test,docs]'
$(STAMP): $(BASE)
	$(call INSTALL,$(EXTRAS))
	touch $(STAMP)

$(KERNELS): $(STAMP) $(shell find rockstudy -name '*.py')
	$(BIN)/rockstudy compile
	touch $(KERNELS)

setup: $(KERNELS)

# Debian packages the tests need: headless Chromium renders the HTML reports
debian:
	@command -v chromium >/dev/null 2>&1 || { \
	  if [ "$$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then \
	    apt-get update -qq && apt-get install -y -qq --no-install-recommends chromium; \
	  else echo "please install Debian's chromium (needed by tests/test_report.py)"; exit 1; fi; }

# The demo compiles only the kernels it runs: the study primes its own before its workers start
# while the report's closed forms compile beside it; then the report and the single-block demo,
# which compile different kernels, run side by side on two cores. `make setup` compiles every
# kernel once, for the tests, the docs and the benchmarks.
demo: $(BASE)
	rm -rf results/quickstart.zarr results/quickstart.nc
	$(BIN)/rockstudy compile --group closedforms > /dev/null & \
	  forms=$$!; $(BIN)/rockstudy run studies/quickstart.toml --out results/quickstart.zarr; \
	  run=$$?; wait $$forms && exit $$run
	$(BIN)/rockstudy report results/quickstart.zarr --out results/quickstart_report & \
	  report=$$!; $(BIN)/rockstudy demo --out results/demo; demo=$$?; \
	  wait $$report && exit $$demo

# The tests run in two processes (pytest-xdist), a test file to each at a time, the longest
# files first (tests/conftest.py)
test: $(KERNELS) debian docs
	ROCKSTUDY_DOCS_HTML=$(CURDIR)/docs/_build/html $(BIN)/python -m pytest -q -n 2 --dist loadfile --durations=15

# The documentation site (Sphinx, numpydoc, sphinx-gallery; examples executed), warnings as
# errors, into docs/_build/html
docs: $(KERNELS)
	rm -rf docs/_build docs/generated docs/auto_examples
	$(BIN)/sphinx-build -W --keep-going -q -b html docs docs/_build/html

bench: $(KERNELS)
	$(BIN)/python benchmarks/bench_engine.py
	$(BIN)/python benchmarks/bench_closedform.py
	$(BIN)/python benchmarks/bench_study.py
	$(BIN)/python benchmarks/bench_scaling.py
	$(BIN)/python benchmarks/bench_structures.py
	$(BIN)/python benchmarks/bench_report.py
	$(BIN)/python -W ignore benchmarks/bench_work_precision.py
	$(BIN)/python -W ignore benchmarks/bench_failure_maps.py
	$(BIN)/python benchmarks/bench_first_result.py

figures: $(STAMP)
	$(BIN)/rockstudy figures --out results/figures

lint: $(STAMP)
	$(BIN)/ruff check rockstudy tests benchmarks

clean:
	rm -rf $(VENV) results docs/_build docs/generated docs/auto_examples
