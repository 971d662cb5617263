# Two commands do everything on a fresh machine:
#   make demo   create .venv, install urdsl, run the demo
#   make test   install the test dependencies too, run the whole suite
PYTHON ?= python3
VENV   := .venv
PY     := $(VENV)/bin/python
STAMP  := $(VENV)/.urdsl-installed
TSTAMP := $(VENV)/.urdsl-test-installed

.PHONY: demo test lint bench fuzz clean

$(PY):
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip

$(STAMP): pyproject.toml | $(PY)
	$(PY) -m pip install --quiet -e .
	touch $@

$(TSTAMP): pyproject.toml $(STAMP)
	$(PY) -m pip install --quiet -e '.[test]'
	touch $@

demo: $(STAMP)
	$(PY) -m urdsl.demo

test: $(TSTAMP)
	$(PY) -m ruff check urdsl tests bench programs grammar
	$(PY) -m pytest -q

# longer fuzzing: FUZZ_SECONDS per target (default 60), FUZZ_SEED to vary the inputs
FUZZ_SECONDS ?= 60
FUZZ_SEED ?= 14
fuzz: $(TSTAMP)
	URDSL_FUZZ_SECONDS=$(FUZZ_SECONDS) URDSL_FUZZ_SEED=$(FUZZ_SEED) $(PY) -m pytest -q -s tests/test_fuzz_*.py

bench: $(TSTAMP)
	$(PY) bench/parse_bench.py

clean:
	rm -rf $(VENV) build *.egg-info out
