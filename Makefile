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

# Longer fuzzing (issue 14): every tests/test_fuzz_*.py target runs URDSL_FUZZ_SECONDS
# (default 120) with a fresh seed unless URDSL_FUZZ_SEED is given; a failure prints the seed
# and case that rebuild its input.
fuzz: $(TSTAMP)
	URDSL_FUZZ_SECONDS=$${URDSL_FUZZ_SECONDS:-120} URDSL_FUZZ_SEED=$${URDSL_FUZZ_SEED:-$$(date +%s)} \
	  $(PY) -m pytest -q -s -p no:cacheprovider tests/test_fuzz_protocol.py tests/test_fuzz_script.py tests/test_fuzz_check.py

bench: $(TSTAMP)
	$(PY) bench/parse_bench.py

clean:
	rm -rf $(VENV) build *.egg-info out
